"""Contractors on batches of boxes and their algebra (thesis §2.4.1, Eq. 2.32–2.44).

A contractor maps a batch ``(lo, hi)`` of shape ``(N, n)`` to a batch of sub-boxes that keeps every
solution. Empty results are rows ``[+inf, -inf]``. ``&`` is the intersection ``C₁(X) ∩ C₂(X)``,
``|`` the union hull ``C₁(X) ⊔ C₂(X)``, ``@`` the composition ``C₁ ∘ C₂``, and
:class:`CtcFixPoint` iterates a contractor until it stalls.

>>> c = CtcFwdBwd(Function(lambda z, x, y: x - y - z), 0.0)   # Ex. 2.4: z = x - y
>>> r = c(Box([(4, 5), (0, 3), (-2, 2)]))
>>> r.lo.tolist(), r.hi.tolist()
([4.0, 2.0, -2.0], [5.0, 3.0, -1.0])
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from digslam.observer.core.arith import intersect
from digslam.observer.core.boxes import chunked, empty_rows, normalize_empty, validate_batch
from digslam.observer.core.interval import IntervalArray, as_pair
from digslam.observer.core.types import Batch
from digslam.observer.expr.backward import BACKWARD
from digslam.observer.expr.centred_ctc import centred_contract
from digslam.observer.expr.expr import Function
from digslam.observer.expr.hc4_jit import hc4
from digslam.observer.expr.tape_jit import Tape


class Ctc:
    """Base class. Subclasses implement :meth:`contract` on raw batches."""

    #: input dimension, or None when any dimension goes
    n: int | None = None

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        """Contract a batch ``(N, n)``; never removes a solution. Inputs are not modified."""
        raise NotImplementedError(f"{type(self).__name__}.contract")

    def __call__(self, boxes: IntervalArray | tuple[Any, Any]) -> Any:
        """Contract an :class:`IntervalArray` box ``(n,)`` or batch ``(N, n)``, or a ``(lo, hi)`` pair."""
        is_ia = isinstance(boxes, IntervalArray)
        lo, hi = boxes.pair if isinstance(boxes, IntervalArray) else boxes
        single = np.ndim(lo) == 1
        lo, hi = validate_batch(lo, hi, "boxes", self.n)
        rlo, rhi = normalize_empty(*self.contract(lo, hi))
        if single:
            rlo, rhi = rlo[0], rhi[0]
        return IntervalArray._raw(rlo, rhi) if is_ia else (rlo, rhi)

    def __and__(self, other: Ctc) -> Ctc:
        return CtcInter(self, other)

    def __or__(self, other: Ctc) -> Ctc:
        return CtcUnion(self, other)

    def __matmul__(self, other: Ctc) -> Ctc:
        return CtcCompose(self, other)


def _dim(ctcs: tuple[Ctc, ...]) -> int | None:
    dims = {c.n for c in ctcs if c.n is not None}
    if len(dims) > 1:
        raise ValueError(f"contractors: mismatched dimensions {sorted(dims)}")
    return dims.pop() if dims else None


class CtcInter(Ctc):
    """``(C₁ ∩ … ∩ C_k)(X) = C₁(X) ∩ … ∩ C_k(X)`` (Eq. 2.40)."""

    def __init__(self, *ctcs: Ctc) -> None:
        self.ctcs, self.n = ctcs, _dim(ctcs)

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        rlo, rhi = lo, hi
        for c in self.ctcs:
            clo, chi = c.contract(lo, hi)
            rlo, rhi = np.maximum(rlo, clo), np.minimum(rhi, chi)
        return normalize_empty(rlo, rhi)


class CtcUnion(Ctc):
    """``(C₁ ∪ … ∪ C_k)(X) = C₁(X) ⊔ … ⊔ C_k(X)``, the union hull (Eq. 2.41)."""

    def __init__(self, *ctcs: Ctc) -> None:
        self.ctcs, self.n = ctcs, _dim(ctcs)

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        rlo, rhi = np.full_like(lo, np.inf), np.full_like(hi, -np.inf)
        for c in self.ctcs:
            clo, chi = normalize_empty(*c.contract(lo, hi))
            rlo, rhi = np.minimum(rlo, clo), np.maximum(rhi, chi)
        return rlo, rhi


class CtcCompose(Ctc):
    """``(C₁ ∘ C₂)(X) = C₁(C₂(X))`` (Eq. 2.42): the right-hand contractor runs first."""

    def __init__(self, *ctcs: Ctc) -> None:
        self.ctcs, self.n = ctcs, _dim(ctcs)

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        for c in reversed(self.ctcs):
            lo, hi = normalize_empty(*c.contract(lo, hi))
        return lo, hi


class CtcFixPoint(Ctc):
    """Apply ``ctc`` until no box shrinks by more than ``ratio`` of its perimeter (Eq. 2.43).

    Only the boxes still shrinking are passed on each round, so a batch costs what its slowest
    boxes cost, not ``rounds × N``.
    """

    def __init__(self, ctc: Ctc, ratio: float = 0.01, max_iter: int = 100) -> None:
        if not 0.0 <= ratio < 1.0:
            raise ValueError(f"ratio: must lie in [0, 1), got {ratio}")
        if max_iter < 1:
            raise ValueError(f"max_iter: must be at least 1, got {max_iter}")
        self.ctc, self.ratio, self.max_iter, self.n = ctc, ratio, max_iter, ctc.n

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        lo, hi = lo.copy(), hi.copy()
        active = np.flatnonzero(~empty_rows(lo, hi))
        for _ in range(self.max_iter):
            if active.size == 0:
                break
            alo, ahi = lo[active], hi[active]
            clo, chi = normalize_empty(*self.ctc.contract(alo, ahi))
            lo[active], hi[active] = clo, chi
            with np.errstate(invalid="ignore", over="ignore"):
                before = (ahi - alo).sum(axis=1)
                after = (chi - clo).sum(axis=1)
                changed = (clo != alo).any(axis=1) | (chi != ahi).any(axis=1)
                shrinking = np.where(np.isfinite(before), before - after > self.ratio * before, changed)
            active = active[shrinking & ~empty_rows(clo, chi)]
        return lo, hi


class CtcFwdBwd(Ctc):
    """Forward-backward contractor (HC4-revise) for ``f(x) ∈ [y]`` (thesis §2.4.1.2, Ex. 2.4).

    Args:
        f: a :class:`~.expr.Function` ``Rⁿ → Rᵐ`` (or a callable, traced into one).
        y: the image set: an interval, a box of dimension ``m``, a number, or ``(lo, hi)`` bounds.

    One call runs one forward pass (natural inclusion of every node), intersects the outputs with
    ``[y]``, and one backward pass (projection rules of :mod:`.backward`) down to the variables:
    compiled (:mod:`.hc4_jit`) when ``f`` has a :class:`~.tape_jit.Tape`, else with numpy
    (:func:`hc4_backward`, which also serves the functions with trigonometric, ``min``/``max`` or
    ``atan2`` nodes).

    With ``centred=True`` each output's natural enclosure is first intersected with the centred
    (mean-value) form of :mod:`.centred` (Eq. 2.20, interval automatic differentiation on the DAG):
    tighter on small boxes when variables occur several times, at about twice the forward cost; off by
    default (the natural form is exact for functions where each variable occurs once, e.g. Ex. 2.7).
    The result is then contracted once more by the centred backward pass of :mod:`.centred_ctc` (the
    linear forward-backward on the mean-value form, as in codac's ``CtcInverse``).
    """

    def __init__(self, f: Function | Callable[..., Any], y: Any, centred: bool = False) -> None:
        self.centred = bool(centred)
        self.f = f if isinstance(f, Function) else Function(f)
        self.n = self.f.n
        if isinstance(y, tuple) and len(y) == 2 and not isinstance(y, IntervalArray):
            y = IntervalArray(*y)
        ylo, yhi = as_pair(y, "y")
        if np.shape(ylo) not in ((), (self.f.m,)):
            shape = np.shape(ylo)
            raise ValueError(f"y: expected an interval or a box of dimension {self.f.m}, got shape {shape}")
        ylo, yhi = np.broadcast_to(ylo, (self.f.m,)), np.broadcast_to(yhi, (self.f.m,))
        self.y = (ylo.astype(np.float64), yhi.astype(np.float64))

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        tape = Tape.of(self.f)
        if tape is not None:
            res = hc4(tape, lo, hi, *self.y, centred=self.centred)
        else:
            f, y, centred = self.f, self.y, self.centred
            res = chunked(lambda a, b: hc4_backward(f, forward(f, a, b, centred), y, a, b), lo, hi)
        if not self.centred:
            return res
        return normalize_empty(*centred_contract(self.f, *res, self.y[0][None], self.y[1][None]))


def forward(f: Function, lo: np.ndarray, hi: np.ndarray, centred: bool = False) -> list[Batch]:
    """``f.forward(lo, hi)``, with each output node met with the centred form when ``centred``."""
    vals = f.forward(lo, hi)
    if centred:
        from digslam.observer.expr.centred import centred_image_numpy

        clo, chi = centred_image_numpy(f, lo, hi)
        for j, o in enumerate(f.outputs):
            n_rows = (lo.shape[0],)
            vals[o] = intersect((np.broadcast_to(vals[o][0], n_rows), np.broadcast_to(vals[o][1], n_rows)),
                                (clo[:, j], chi[:, j]))  # fmt: skip
    return vals


def hc4_backward(
    f: Function, vals: list[tuple[np.ndarray, np.ndarray]], y: Batch, lo: np.ndarray, hi: np.ndarray
) -> Batch:
    """Backward pass of HC4-revise from forward values ``vals`` with outputs constrained to ``y``.

    ``y`` holds ``(m,)`` bounds or ``(N, m)`` per-box bounds. ``vals`` is not modified, so one forward
    pass can serve several backward passes (a separator's inner and outer parts).
    """
    vals = list(vals)
    ylo, yhi = np.asarray(y[0]), np.asarray(y[1])
    for j, o in enumerate(f.outputs):
        vals[o] = intersect(vals[o], (ylo[..., j], yhi[..., j]))
    dead = np.zeros(lo.shape[0], dtype=bool)
    for k in range(len(f.nodes) - 1, -1, -1):
        op, args, p = f.nodes[k]
        if not args:
            continue
        z = vals[k]
        dead |= z[0] > z[1]
        new = BACKWARD[op](z, *(vals[a] for a in args), p)
        for a, v in zip(args, new, strict=True):
            vals[a] = intersect(vals[a], v)
    rlo, rhi = lo.copy(), hi.copy()
    for i, k in f.var_nodes.items():
        rlo[:, i], rhi[:, i] = vals[k]
    for k, (op, _, _) in enumerate(f.nodes):
        if op in ("var", "const"):
            dead |= vals[k][0] > vals[k][1]
    rlo[dead], rhi[dead] = np.inf, -np.inf
    return rlo, rhi


__all__ = [
    "Ctc",
    "CtcCompose",
    "CtcFixPoint",
    "CtcFwdBwd",
    "CtcInter",
    "CtcUnion",
    "forward",
    "hc4_backward",
]
