"""Expressions and functions: trace a Python lambda once into a DAG, then evaluate it on points or
on batches of boxes (natural inclusion function, thesis §2.3.2.2, Eq. 2.21).

>>> f = Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2)
>>> float(f([3.0, 2.5]))
1.0
>>> f.eval(Box([(2, 4), (2, 3)]))
Interval(0.0, 4.25)
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from digslam.observer.core import arith, trig
from digslam.observer.core import interval as _interval
from digslam.observer.core.boxes import chunked, empty_rows, validate_batch
from digslam.observer.core.interval import IntervalArray
from digslam.observer.core.types import Pair


class Expr:
    """A node of an expression DAG: an operation, its argument nodes and a parameter.

    ``op`` is ``"var"`` (param: coordinate index), ``"const"`` (param: ``(lo, hi)``), ``"pown"``
    (param: exponent) or one of the primitives of :data:`FORWARD`.
    """

    __slots__ = ("op", "args", "param")

    def __init__(self, op: str, args: tuple[Expr, ...] = (), param: Any = None) -> None:
        self.op, self.args, self.param = op, args, param

    def __repr__(self) -> str:
        if self.op == "var":
            return f"x[{self.param}]"
        if self.op == "const":
            lo, hi = self.param
            return repr(lo) if lo == hi else f"[{lo}, {hi}]"
        if self.op == "pown":
            return f"({self.args[0]!r})**{self.param}"
        infix = {"add": "+", "sub": "-", "mul": "*", "div": "/"}
        if self.op in infix:
            return f"({self.args[0]!r} {infix[self.op]} {self.args[1]!r})"
        return f"{self.op}({', '.join(map(repr, self.args))})"

    def __bool__(self) -> bool:
        raise TypeError("Expr: a traced function cannot branch on its argument (no `if`, `<` or `max()`)")

    def __add__(self, o: Any) -> Expr:
        return Expr("add", (self, lift(o)))

    def __radd__(self, o: Any) -> Expr:
        return Expr("add", (lift(o), self))

    def __sub__(self, o: Any) -> Expr:
        return Expr("sub", (self, lift(o)))

    def __rsub__(self, o: Any) -> Expr:
        return Expr("sub", (lift(o), self))

    def __mul__(self, o: Any) -> Expr:
        return Expr("mul", (self, lift(o)))

    def __rmul__(self, o: Any) -> Expr:
        return Expr("mul", (lift(o), self))

    def __truediv__(self, o: Any) -> Expr:
        return Expr("div", (self, lift(o)))

    def __rtruediv__(self, o: Any) -> Expr:
        return Expr("div", (lift(o), self))

    def __neg__(self) -> Expr:
        return Expr("neg", (self,))

    def __pos__(self) -> Expr:
        return self

    def __abs__(self) -> Expr:
        return Expr("abs", (self,))

    def __pow__(self, n: Any) -> Expr:
        if not isinstance(n, (int, np.integer)):
            raise ValueError(f"Expr ** n: n must be an integer, got {n!r} (use exp(n * log(x)))")
        return Expr("sqr", (self,)) if n == 2 else Expr("pown", (self,), int(n))


_interval.DEFER_TO = (Expr,)


def lift(v: Any) -> Expr:
    """An :class:`Expr` for ``v``: expressions pass, numbers and scalar intervals become constants.

    A float ``±inf`` is no real number and becomes the empty constant ``[+inf, -inf]`` (the rule of
    :func:`.interval.as_pair`): ``Function(lambda x: x[0] + inf)`` is empty everywhere."""
    if isinstance(v, Expr):
        return v
    if isinstance(v, IntervalArray):
        if v.ndim != 0:
            raise ValueError(f"constant: only scalar intervals can enter an expression, got shape {v.shape}")
        return Expr("const", (), (float(v.lo), float(v.hi)))
    if isinstance(v, (int, float, np.integer, np.floating)) and not np.isnan(v):
        if np.isinf(v):  # no real number (IEEE 1788): the empty constant, as in interval arithmetic
            return Expr("const", (), (np.inf, -np.inf))
        return Expr("const", (), (float(v), float(v)))
    raise ValueError(f"constant: cannot use {v!r} in an expression (numbers and scalar Interval only)")


def _un(k: Callable[[Pair], Pair]) -> Callable[..., Pair]:
    return lambda p, a: k(a)


def _bin(k: Callable[[Pair, Pair], Pair]) -> Callable[..., Pair]:
    return lambda p, a, b: k(a, b)


#: op -> interval kernel ``(param, *arg_pairs) -> pair``
FORWARD: dict[str, Callable[..., Pair]] = {
    "add": _bin(arith.add), "sub": _bin(arith.sub), "mul": _bin(arith.mul), "div": _bin(arith.div),
    "neg": _un(arith.neg), "sqr": _un(arith.sqr), "sqrt": _un(arith.sqrt), "exp": _un(arith.exp),
    "log": _un(arith.log), "abs": _un(arith.abs_), "min": _bin(arith.minimum), "max": _bin(arith.maximum),
    "sin": _un(trig.sin), "cos": _un(trig.cos), "tan": _un(trig.tan), "asin": _un(trig.asin),
    "acos": _un(trig.acos), "atan": _un(trig.atan), "atan2": _bin(trig.atan2),
    "pown": lambda p, a: arith.pown(a, p),
}  # fmt: skip

#: op -> point function ``(param, *args) -> array``
POINT: dict[str, Callable[..., np.ndarray]] = {
    "add": lambda p, a, b: a + b, "sub": lambda p, a, b: a - b, "mul": lambda p, a, b: a * b,
    "div": lambda p, a, b: a / b, "neg": lambda p, a: -a, "sqr": lambda p, a: a * a,
    "sqrt": lambda p, a: np.sqrt(a), "exp": lambda p, a: np.exp(a), "log": lambda p, a: np.log(a),
    "abs": lambda p, a: np.abs(a), "min": lambda p, a, b: np.minimum(a, b),
    "max": lambda p, a, b: np.maximum(a, b), "sin": lambda p, a: np.sin(a), "cos": lambda p, a: np.cos(a),
    "tan": lambda p, a: np.tan(a), "asin": lambda p, a: np.arcsin(a), "acos": lambda p, a: np.arccos(a),
    "atan": lambda p, a: np.arctan(a), "atan2": lambda p, a, b: np.arctan2(a, b),
    "pown": lambda p, a: np.power(a, float(p)),
}  # fmt: skip


class _Vars:
    """The vector argument while tracing: ``x[i]`` returns the variable node ``i``."""

    def __init__(self, n: int | None) -> None:
        self.n = n
        self.nodes: dict[int, Expr] = {}

    def __getitem__(self, i: int) -> Expr:
        if not isinstance(i, (int, np.integer)) or i < 0 or (self.n is not None and i >= self.n):
            raise ValueError(f"x[{i!r}]: index must be an integer in [0, {self.n}) (pass n= to Function)")
        return self.nodes.setdefault(int(i), Expr("var", (), int(i)))

    def __len__(self) -> int:
        if self.n is None:
            raise ValueError("Function: len(x) or unpacking x needs the dimension: pass n=")
        return self.n

    def __iter__(self) -> Any:
        return (self[i] for i in range(len(self)))


class Function:
    """A function ``f: Rⁿ → Rᵐ`` traced once from a Python callable.

    Args:
        fn: either ``lambda x: ...`` indexing a vector ``x[i]``, or ``lambda x, y, ...: ...`` taking
            ``n`` scalars. It returns one expression or a sequence of ``m`` expressions, built from
            ``+ - * /``, integer powers and the functions of :mod:`digslam.observer.expr.ops`.
        n: the input dimension; inferred from the arguments or the largest index used.

    Attributes:
        nodes: the DAG in topological order, as ``(op, argument indices, param)`` tuples.
        outputs: indices of the output nodes.
    """

    def __init__(self, fn: Callable[..., Any], n: int | None = None) -> None:
        params = [
            p for p in inspect.signature(fn).parameters.values()
            if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) and p.default is p.empty
        ]  # fmt: skip
        if len(params) == 1:
            xs = _Vars(n)
            out = fn(xs)
            n = n if n is not None else (max(xs.nodes) + 1 if xs.nodes else 0)
        elif n is not None and n != len(params):
            raise ValueError(f"n: {n} given but the function takes {len(params)} arguments")
        else:
            xs = _Vars(len(params))
            out = fn(*(xs[i] for i in range(len(params))))
            n = len(params)
        self.scalar_output = not isinstance(out, (tuple, list))
        outs = [lift(o) for o in ((out,) if self.scalar_output else out)]
        if not outs:
            raise ValueError("fn: returned no expression")
        self.n, self.m = int(n), len(outs)
        self.nodes: list[tuple[str, tuple[int, ...], Any]] = []
        index: dict[Any, int] = {}
        self.outputs = [self._topo(o, index, {}) for o in outs]
        self.var_nodes = {p: i for i, (op, _, p) in enumerate(self.nodes) if op == "var"}

    def _topo(self, root: Expr, index: dict[Any, int], seen: dict[int, int]) -> int:
        """Append the nodes under ``root`` (iterative post-order, identical sub-DAGs merged).

        Two *distinct* interval constants with width stay distinct nodes even when their intervals are
        equal: each stands for its own unknown value in the interval, and the backward pass contracts a
        node from all its uses, so merging them would couple them (an unsound contraction, e.g. ``sin`` and
        ``cos`` of a bearing in ``[42°, 48°]`` give the same interval). The same constant object used twice
        is one value and one node; point constants merge freely."""
        stack: list[tuple[Expr, bool]] = [(root, False)]
        while stack:
            e, done = stack.pop()
            if id(e) in seen:
                continue
            if not done:
                stack.append((e, True))
                stack.extend((a, False) for a in e.args if id(a) not in seen)
                continue
            key = (e.op, tuple(seen[id(a)] for a in e.args), e.param)
            ikey: Any = key
            if e.op == "const" and e.param[0] != e.param[1]:
                ikey = (key, id(e))  # an uncertain constant: its own node (see above)
            if ikey not in index:
                index[ikey] = len(self.nodes)
                self.nodes.append(key)
            seen[id(e)] = index[ikey]
        return seen[id(root)]

    def __repr__(self) -> str:
        return f"Function(n={self.n}, m={self.m}, nodes={len(self.nodes)})"

    def __call__(self, x: Any) -> np.ndarray:
        """Point evaluation: ``x`` of shape ``(n,)`` or ``(N, n)``; returns ``()``/``(N,)`` or ``(.., m)``."""
        x = np.asarray(x, dtype=np.float64)
        if x.shape[-1:] != (self.n,):
            raise ValueError(f"x: expected points of dimension {self.n}, got shape {x.shape}")
        vals: list[np.ndarray] = []
        for op, args, p in self.nodes:
            if op == "var":
                vals.append(x[..., p])
            elif op == "const":
                if p[0] != p[1]:
                    raise ValueError(f"point evaluation: constant [{p[0]}, {p[1]}] is not a number")
                vals.append(np.asarray(p[0]))
            else:
                with np.errstate(all="ignore"):
                    vals.append(POINT[op](p, *(vals[a] for a in args)))
        res = [np.broadcast_to(vals[o], x.shape[:-1]) for o in self.outputs]
        return res[0] if self.scalar_output else np.stack(res, axis=-1)

    def forward(self, lo: np.ndarray, hi: np.ndarray) -> list[Pair]:
        """Natural inclusion of every node on a batch ``(N, n)``: one ``(lo, hi)`` pair per node."""
        shape = lo.shape[:-1]
        vals: list[Pair] = []
        for op, args, p in self.nodes:
            if op == "var":
                vals.append((lo[..., p], hi[..., p]))
            elif op == "const":
                vals.append((np.full(shape, p[0]), np.full(shape, p[1])))
            else:
                vals.append(FORWARD[op](p, *(vals[a] for a in args)))
        return vals

    def _eval_batch(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        vals = self.forward(lo, hi)
        outs = [vals[o] for o in self.outputs]
        rlo = np.stack([np.broadcast_to(o[0], lo.shape[:1]) for o in outs], axis=-1)
        rhi = np.stack([np.broadcast_to(o[1], lo.shape[:1]) for o in outs], axis=-1)
        empty = empty_rows(lo, hi)[:, None]
        return np.where(empty, np.inf, rlo), np.where(empty, -np.inf, rhi)

    def eval(self, boxes: IntervalArray | Sequence[np.ndarray]) -> IntervalArray:
        """Natural inclusion function ``[f]`` (Eq. 2.21) on a box ``(n,)`` or a batch ``(N, n)``."""
        single = isinstance(boxes, IntervalArray) and boxes.ndim == 1
        lo, hi = boxes.pair if isinstance(boxes, IntervalArray) else boxes
        lo, hi = validate_batch(lo, hi, "boxes", self.n)
        rlo, rhi = chunked(self._eval_batch, lo, hi)
        if self.scalar_output:
            rlo, rhi = rlo[:, 0], rhi[:, 0]
        return IntervalArray._raw(rlo[0], rhi[0]) if single else IntervalArray._raw(rlo, rhi)

    def jacobian(self, boxes: IntervalArray | Sequence[np.ndarray]) -> IntervalArray:
        """Interval Jacobian ``[J_f]([x])`` (Eq. 2.20's ``[f']``) by automatic differentiation on the DAG
        (:func:`.centred.jacobian`; compiled when ``f`` has a tape): ``(m, n)`` for a box, ``(N, m, n)``
        for a batch, ``(n,)``/``(N, n)`` for a scalar function."""
        from digslam.observer.expr.centred import jacobian

        single = isinstance(boxes, IntervalArray) and boxes.ndim == 1
        lo, hi = boxes.pair if isinstance(boxes, IntervalArray) else boxes
        lo, hi = validate_batch(lo, hi, "boxes", self.n)
        jlo, jhi, _ = jacobian(self, lo, hi)
        if self.scalar_output:
            jlo, jhi = jlo[:, 0], jhi[:, 0]
        return IntervalArray._raw(jlo[0], jhi[0]) if single else IntervalArray._raw(jlo, jhi)

    def eval_centred(self, boxes: IntervalArray | Sequence[np.ndarray]) -> IntervalArray:
        """Centred (mean-value) inclusion ``[f]({m}) + [J_f]([x])·([x] - m)`` met with the natural one
        (Eq. 2.20–2.21; :func:`.centred.centred_image`), shaped as :meth:`eval`."""
        from digslam.observer.expr.centred import centred_image

        single = isinstance(boxes, IntervalArray) and boxes.ndim == 1
        lo, hi = boxes.pair if isinstance(boxes, IntervalArray) else boxes
        lo, hi = validate_batch(lo, hi, "boxes", self.n)
        nlo, nhi = chunked(self._eval_batch, lo, hi)
        clo, chi = centred_image(self, lo, hi)
        rlo, rhi = np.maximum(nlo, clo), np.minimum(nhi, chi)
        empty = (rlo > rhi).any(axis=1, keepdims=True)
        rlo, rhi = np.where(empty, np.inf, rlo), np.where(empty, -np.inf, rhi)
        if self.scalar_output:
            rlo, rhi = rlo[:, 0], rhi[:, 0]
        return IntervalArray._raw(rlo[0], rhi[0]) if single else IntervalArray._raw(rlo, rhi)


__all__ = [
    "Expr",
    "FORWARD",
    "Function",
    "POINT",
    "lift",
]
