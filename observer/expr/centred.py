"""Interval automatic differentiation and the centred (mean-value) form (thesis §2.3.2.1, Eq. 2.20).

Forward-mode automatic differentiation on the traced DAG of a :class:`~.expr.Function`: every node
carries its enclosure ``[v_k]`` on the box and the enclosure ``[∂v_k/∂x_i]`` of its partial derivatives
over the box, by the chain rule in interval arithmetic (:mod:`.arith`, :mod:`.trig`, outward rounded).
The outputs' derivatives make the interval Jacobian ``[J_f]([x])`` (Eq. 2.20's ``[f']``). The mean-value
theorem then gives the *centred form*

    ``[f]_c([x]) = [f]({m}) + [J_f]([x]) · ([x] - m)``,   ``m`` the midpoint of ``[x]``,

an inclusion function whose overestimation shrinks quadratically with the width of ``[x]`` (the natural
form's only linearly, when a variable occurs several times), so it pays on small boxes.

The theorem needs ``f`` continuous on ``[x]`` and differentiable almost everywhere along every segment
from ``m``, with its derivative in ``[J_f]([x])``. The chain rule encloses the derivative of the
Lipschitz operations ``abs``, ``min``, ``max`` by the hull of their pieces' derivatives. Where a node's
argument may leave the interior of its domain (``sqrt``, ``log`` at ``<= 0``, a divisor or a negative
power's base that may be 0, ``asin``/``acos`` outside ``(-1, 1)``, a pole of ``tan``) or ``atan2`` may meet
its cut ``{x <= 0, y = 0}`` (where it jumps by ``2π``), the row is *not valid*: its centred form is
``(-∞, +∞)`` and only the natural form counts. :func:`centred_image` intersects nothing itself; the
contractors and separators intersect it with the natural form when asked (``centred=True``).

>>> from digslam.observer import Box, Function
>>> f = Function(lambda x: x[0] * x[0] - 2 * x[0] * x[1] + x[1] * x[1])    # (x0 - x1)², 3 occurrences each
>>> lo, hi = np.array([[0.9, 0.9]]), np.array([[1.1, 1.1]])
>>> f.eval((lo, hi)).hi[0] > 0.4, centred_image(f, lo, hi)[1][0, 0] < 0.09     # natural vs centred
(np.True_, np.True_)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core import arith as A
from digslam.observer.core import trig as T
from digslam.observer.core.boxes import empty_rows, midpoint
from digslam.observer.core.types import Pair

__all__ = ["jacobian", "centred_image", "jacobian_numpy", "centred_image_numpy"]

_INF = np.inf


def _scale(c: Pair, d: Pair) -> Pair:
    """``[c]·[d]`` with ``[c]`` per row ``(N,)`` and ``[d]`` per row and variable ``(N, n)``."""
    return A.mul((c[0][:, None], c[1][:, None]), d)


def _inside(a: Pair, lo: float, hi: float) -> np.ndarray:
    """``[a] ⊂ (lo, hi)`` (the open domain): the row's derivative rule is valid."""
    return (a[0] > lo) & (a[1] < hi)


def _derivative(op: str, p: Any, z: Pair, args: list[Pair], ds: list[Pair]) -> tuple[Pair, np.ndarray | None]:
    """``[∂z]`` of ``z = op(args)`` from the arguments' enclosures and derivatives, and the rows where
    the rule holds (``None``: everywhere)."""
    a, da = args[0], ds[0]
    if op == "add":
        return A.add(da, ds[1]), None
    if op == "sub":
        return A.sub(da, ds[1]), None
    if op == "mul":
        return A.add(_scale(args[1], da), _scale(a, ds[1])), None
    if op == "div":  # (da - z·db) / b
        b = args[1]
        num = A.sub(da, _scale(z, ds[1]))
        return A.div(num, (b[0][:, None], b[1][:, None])), (b[0] > 0) | (b[1] < 0)
    if op == "neg":
        return A.neg(da), None
    if op == "sqr":
        return _scale(A.mul(a, (np.full_like(a[0], 2.0), np.full_like(a[0], 2.0))), da), None
    if op == "sqrt":
        two_z = A.add(z, z)
        return A.div(da, (two_z[0][:, None], two_z[1][:, None])), a[0] > 0
    if op == "exp":
        return _scale(z, da), None
    if op == "log":
        return A.div(da, (a[0][:, None], a[1][:, None])), a[0] > 0
    if op == "abs":
        # d|g| = sign(g)·dg where g ≠ 0 and 0 almost everywhere on {g = 0}: sign over [a]
        return _scale((np.sign(a[0]) + 0.0, np.sign(a[1]) + 0.0), da), None
    if op in ("min", "max"):
        b, db = args[1], ds[1]
        first = a[1] < b[0] if op == "min" else a[0] > b[1]  # a is the min (max) on the whole box
        second = b[1] < a[0] if op == "min" else b[0] > a[1]
        h = A.hull(da, db)
        lo = np.where(first[:, None], da[0], np.where(second[:, None], db[0], h[0]))
        hi = np.where(first[:, None], da[1], np.where(second[:, None], db[1], h[1]))
        return (lo, hi), None
    if op == "sin":
        return _scale(T.cos(a), da), None
    if op == "cos":
        return A.neg(_scale(T.sin(a), da)), None
    if op == "tan":  # 1 + tan²; a pole makes z unbounded
        one = (np.ones_like(z[0]), np.ones_like(z[0]))
        return _scale(A.add(one, A.sqr(z)), da), np.isfinite(z[0]) & np.isfinite(z[1])
    if op in ("asin", "acos"):
        one = (np.ones_like(a[0]), np.ones_like(a[0]))
        r = A.sqrt(A.sub(one, A.sqr(a)))
        q = A.div(da, (r[0][:, None], r[1][:, None]))
        return (A.neg(q) if op == "acos" else q), _inside(a, -1.0, 1.0)
    if op == "atan":
        one = (np.ones_like(a[0]), np.ones_like(a[0]))
        r = A.add(one, A.sqr(a))
        return A.div(da, (r[0][:, None], r[1][:, None])), None
    if op == "atan2":  # z = atan2(y, x): (x·dy - y·dx) / (x² + y²)
        y, x, dy, dx = a, args[1], da, ds[1]
        num = A.sub(_scale(x, dy), _scale(y, dx))
        r = A.add(A.sqr(x), A.sqr(y))
        cut = (x[0] <= 0) & (y[0] <= 0) & (y[1] >= 0)
        return A.div(num, (r[0][:, None], r[1][:, None])), ~cut
    if op == "pown":
        n = int(p)
        if n == 0:
            return (np.zeros_like(da[0]), np.zeros_like(da[1])), None
        c = A.mul(A.pown(a, n - 1), (np.full_like(a[0], float(n)), np.full_like(a[0], float(n))))
        return _scale(c, da), ((a[0] > 0) | (a[1] < 0)) if n < 0 else None
    raise ValueError(f"jacobian: no derivative rule for the operation {op!r}")


def _forward_ad(f: Any, lo: np.ndarray, hi: np.ndarray) -> tuple[list[Pair], list[Pair], list[np.ndarray]]:
    """Enclosures, derivative enclosures ``(N, n)`` and validity ``(N,)`` of every node on a batch."""
    N, n = lo.shape
    vals = f.forward(lo, hi)
    vals = [(np.broadcast_to(v[0], (N,)), np.broadcast_to(v[1], (N,))) for v in vals]
    ds: list[Pair] = []
    ok: list[np.ndarray] = []
    zeros = np.zeros((N, n))
    for k, (op, args, p) in enumerate(f.nodes):
        if op == "var":
            d = zeros.copy()
            d[:, p] = 1.0
            ds.append((d, d.copy()))
            ok.append(np.ones(N, dtype=bool))
            continue
        if op == "const":
            ds.append((zeros, zeros))
            ok.append(np.ones(N, dtype=bool))
            continue
        with np.errstate(all="ignore"):
            d, valid = _derivative(op, p, vals[k], [vals[a] for a in args], [ds[a] for a in args])
        v = np.logical_and.reduce([ok[a] for a in args])
        if valid is not None:
            v = v & valid
        ds.append(d)
        ok.append(v)
    return vals, ds, ok


def jacobian_numpy(f: Any, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``[J_f]([x])`` on a batch by numpy forward-mode AD: ``(Jlo, Jhi)`` of shape ``(N, m, n)`` and the
    ``(N, m)`` mask of the outputs whose derivative rules all hold (elsewhere ``J`` is still an
    enclosure wherever ``f`` is differentiable, but the mean-value theorem may fail)."""
    _, ds, ok = _forward_ad(f, lo, hi)
    jlo = np.stack([ds[o][0] for o in f.outputs], axis=1)
    jhi = np.stack([ds[o][1] for o in f.outputs], axis=1)
    valid = np.stack([ok[o] for o in f.outputs], axis=1)
    empty = empty_rows(lo, hi)
    jlo[empty], jhi[empty] = _INF, -_INF
    return jlo, jhi, valid & ~empty[:, None]


def centred_image_numpy(f: Any, lo: np.ndarray, hi: np.ndarray) -> Pair:
    """Mean-value form ``[f]({m}) + [J_f]([x])·([x] - m)`` (numpy), ``(N, m)``; ``ℝ`` on invalid rows,
    empty on empty boxes."""
    N = lo.shape[0]
    empty = empty_rows(lo, hi)
    with np.errstate(invalid="ignore"):
        mid = np.where(empty[:, None], 0.0, midpoint(lo, hi))
    jlo, jhi, valid = jacobian_numpy(f, lo, hi)
    pvals = f.forward(mid, mid)
    dx = A.sub((lo, hi), (mid, mid))
    res_lo, res_hi = np.empty((N, f.m)), np.empty((N, f.m))
    for j, o in enumerate(f.outputs):
        acc = (np.broadcast_to(pvals[o][0], (N,)).copy(), np.broadcast_to(pvals[o][1], (N,)).copy())
        for i in range(f.n):
            acc = A.add(acc, A.mul((jlo[:, j, i], jhi[:, j, i]), (dx[0][:, i], dx[1][:, i])))
        ok = valid[:, j] & ~(acc[0] > acc[1])  # f(m) empty: m outside the domain, no claim
        res_lo[:, j] = np.where(ok, acc[0], -_INF)
        res_hi[:, j] = np.where(ok, acc[1], _INF)
    res_lo[empty], res_hi[empty] = _INF, -_INF
    return res_lo, res_hi


def jacobian(f: Any, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``[J_f]([x])`` on a batch ``(N, n)``: compiled on the :class:`~.tape_jit.Tape` when ``f`` has one
    (:func:`.centred_jit.jacobian_tape`), else by numpy (:func:`jacobian_numpy`). Returns ``(Jlo, Jhi,
    valid)`` with ``J`` of shape ``(N, m, n)`` and ``valid`` ``(N, m)`` as in :func:`jacobian_numpy`."""
    from digslam.observer.expr.centred_jit import jacobian_tape
    from digslam.observer.expr.tape_jit import Tape

    tape = Tape.of(f)
    if tape is not None:
        return jacobian_tape(tape, lo, hi)
    return jacobian_numpy(f, lo, hi)


def centred_image(f: Any, lo: np.ndarray, hi: np.ndarray) -> Pair:
    """The centred (mean-value) form of ``f`` on a batch ``(N, n)``: ``(N, m)`` bounds, ``ℝ`` on rows
    where the mean-value theorem may fail, empty on empty boxes; compiled when ``f`` has a tape."""
    from digslam.observer.expr.centred_jit import centred_tape
    from digslam.observer.expr.tape_jit import Tape

    tape = Tape.of(f)
    if tape is not None:
        return centred_tape(tape, lo, hi)
    return centred_image_numpy(f, lo, hi)
