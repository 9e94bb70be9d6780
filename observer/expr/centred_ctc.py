"""Centred (mean-value) backward contraction of ``f(x) ∈ [y]`` (thesis §2.3.2.1 Eq. 2.20, §3.2.2).

On a box ``[x]`` with midpoint ``m`` where the mean-value theorem holds (:mod:`.centred`), every
``x ∈ [x]`` satisfies, for each output ``j``, ``f_j(x) ∈ [f_j](m) + Σ_i [J_ji]·(x_i - m_i)``. So a point
with ``f_j(x) ∈ [y_j]`` has

    ``[J_ji]·(x_i - m_i) ∈ ([y_j] - [f_j](m)) - Σ_{k≠i} [J_jk]·([x_k] - m_k)``,

and the backward step of the product (:func:`.backward.mul_rev`) contracts ``[x_i] - m_i``. This is the
linear (first-order) forward-backward pass on the centred form; unlike HC4 on the natural form it sees
through the dependency of a variable occurring several times, and it is sharp on small boxes, where
``[J]`` is thin. Rows where the theorem may fail (``valid`` false in :func:`.centred.jacobian`) or where
``f(m)`` is empty are left as they are, so the contraction never loses a point of ``{x | f(x) ∈ [y]}``.

>>> from digslam.observer import Function
>>> f = Function(lambda x: x[0] * x[0] - 2 * x[0] * x[1] + x[1] * x[1] + x[0])   # (x0 - x1)² + x0
>>> lo, hi = np.array([[0.9, 1.0]]), np.array([[1.1, 1.0]])                       # x1 = 1, x0 ∈ [0.9, 1.1]
>>> clo, chi = centred_contract(f, lo, hi, np.array([[1.0]]), np.array([[1.0001]]))
>>> bool(clo[0, 0] <= 1.0 and chi[0, 0] < 1.0002)                                  # x0 ∈ [1, 1.000125]
True
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core import arith as A
from digslam.observer.core.boxes import empty_rows, midpoint
from digslam.observer.core.types import Batch, Pair
from digslam.observer.expr.backward import mul_rev
from digslam.observer.expr.centred import jacobian

__all__ = ["centred_contract"]


def _at_midpoint(f: Any, mid: np.ndarray) -> Pair:
    """Outward enclosure ``[f](m)`` ``(N, m)`` of the outputs at the (degenerate) midpoint boxes."""
    from digslam.observer.expr.hc4_jit import image
    from digslam.observer.expr.tape_jit import Tape

    tape = Tape.of(f)
    if tape is not None:
        return image(tape, mid, mid)
    vals = f.forward(mid, mid)
    N = mid.shape[0]
    flo = np.stack([np.broadcast_to(vals[o][0], (N,)) for o in f.outputs], axis=1)
    fhi = np.stack([np.broadcast_to(vals[o][1], (N,)) for o in f.outputs], axis=1)
    return flo, fhi


def centred_contract(f: Any, lo: np.ndarray, hi: np.ndarray, ylo: np.ndarray, yhi: np.ndarray) -> Batch:
    """Contract the batch ``(lo, hi)`` ``(N, n)`` with respect to ``f(x) ∈ [ylo, yhi]`` ``(N, m)`` by the
    centred form (one pass over the outputs, each contraction feeding the next).

    ``[y]`` may have infinite bounds (a half-line of the complement of ``Y``) or be empty (the row
    then becomes empty only where the theorem holds: ``f`` is defined on the whole box). Empty rows stay
    empty.
    """
    lo, hi = lo.copy(), hi.copy()
    ylo = np.broadcast_to(np.asarray(ylo, dtype=np.float64), (lo.shape[0], f.m))
    yhi = np.broadcast_to(np.asarray(yhi, dtype=np.float64), (lo.shape[0], f.m))
    for j in range(f.m):
        if not (
            np.isfinite(ylo[:, j]).any() or np.isfinite(yhi[:, j]).any() or (ylo[:, j] > yhi[:, j]).any()
        ):
            continue  # f_j ∈ ℝ everywhere: nothing to contract
        live = np.flatnonzero(~empty_rows(lo, hi))
        if live.size == 0:
            break
        xlo, xhi = lo[live], hi[live]
        mid = midpoint(xlo, xhi)
        jlo, jhi, valid = jacobian(f, xlo, xhi)
        flo, fhi = _at_midpoint(f, mid)
        with np.errstate(invalid="ignore", over="ignore"):
            ok = valid[:, j] & (flo[:, j] <= fhi[:, j]) & np.isfinite(mid).all(axis=1)
            r = np.flatnonzero(ok)
            if r.size == 0:
                continue
            xlo, xhi, mid = xlo[r], xhi[r], mid[r]
            dx = A.sub((xlo, xhi), (mid, mid))
            jj = (jlo[r, j, :], jhi[r, j, :])
            terms = A.mul(jj, dx)
            rhs = A.sub((ylo[live[r], j], yhi[live[r], j]), (flo[r, j], fhi[r, j]))
            for i in range(f.n):
                rest = rhs
                for k in range(f.n):
                    if k != i:
                        rest = A.sub(rest, (terms[0][:, k], terms[1][:, k]))
                di = mul_rev(rest, (jj[0][:, i], jj[1][:, i]), (dx[0][:, i], dx[1][:, i]))
                empty = di[0] > di[1]
                xi = A.add(di, (mid[:, i], mid[:, i]))
                nlo = np.where(empty, np.inf, np.maximum(xlo[:, i], xi[0]))
                nhi = np.where(empty, -np.inf, np.minimum(xhi[:, i], xi[1]))
                dx[0][:, i], dx[1][:, i] = A.sub((nlo, nhi), (mid[:, i], mid[:, i]))
                xlo[:, i], xhi[:, i] = nlo, nhi
                t = A.mul((jj[0][:, i], jj[1][:, i]), (dx[0][:, i], dx[1][:, i]))
                terms[0][:, i], terms[1][:, i] = t
        gone = empty_rows(xlo, xhi)
        xlo[gone], xhi[gone] = np.inf, -np.inf
        lo[live[r]], hi[live[r]] = xlo, xhi
    return lo, hi
