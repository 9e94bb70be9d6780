"""Compiled interval automatic differentiation and centred form on a :class:`~.tape_jit.Tape`.

The compiled twin of :mod:`.centred` (read its docstring for the mathematics and the validity rule):
forward-mode AD one box at a time, node by node along the tape, with the outward-rounded scalar interval
primitives of :mod:`digslam.observer.core.scalar_jit`. Per box it gives the interval Jacobian
``[J_f]([x])`` (Eq. 2.20) and the mean-value form ``[f]({m}) + [J_f]([x])·([x] - m)``.
:func:`centre_outputs` intersects the latter into the output nodes of a forward pass, which is how
:mod:`.hc4_jit` runs HC4 and the separator of Theorem 2.1 with ``centred=True``. The numpy path of
:mod:`.centred` (:func:`.centred.jacobian_numpy`, which serves the functions without a tape) is checked
against it in the tests.

>>> from digslam.observer import Function
>>> t = Tape.of(Function(lambda x: x[0] * x[1]))
>>> jlo, jhi, ok = jacobian_tape(t, np.array([[1.0, 2.0]]), np.array([[3.0, 4.0]]))
>>> [round(float(v), 12) for v in (*jlo[0, 0], *jhi[0, 0])], bool(ok[0, 0])     # ∂/∂x0 = x1, ∂/∂x1 = x0
([2.0, 1.0, 4.0, 3.0], True)
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.boxes import midpoint
from digslam.observer.core.scalar_jit import (
    iadd,
    imul,
    ipown,
    isub,
    ixdiv,
    meet,
    njit,
)
from digslam.observer.expr.tape_jit import (
    ABS,
    ADD,
    CONST,
    DIV,
    EXP,
    LOG,
    MUL,
    NEG,
    POWN,
    SQR,
    SQRT,
    SUB,
    VAR,
    Tape,
    fwd_op,
)

__all__ = ["ad_row", "centre_outputs", "centre_row", "centred_tape", "centres", "jacobian_tape"]

_INF = math.inf
_KW = {"error_model": "numpy"}


@njit(**_KW)
def _sign(x: float) -> float:
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


@njit(**_KW)
def ad_row(code: np.ndarray, v: np.ndarray, r: int, n: int, d: np.ndarray, ok: np.ndarray) -> None:
    """Derivative enclosures ``d (K, n, 2)`` and validity ``ok (K,)`` of every node on box ``r``, from the
    node enclosures ``v (2, K, N)`` of a forward pass (rules of :func:`.centred._derivative`)."""
    for k in range(code.shape[0]):
        op, a, b, p = code[k, 0], code[k, 1], code[k, 2], code[k, 3]
        if op == VAR or op == CONST:
            for i in range(n):
                d[k, i, 0], d[k, i, 1] = 0.0, 0.0
            if op == VAR:
                d[k, p, 0], d[k, p, 1] = 1.0, 1.0
            ok[k] = True
            continue
        al, ah = v[0, a, r], v[1, a, r]
        zl, zh = v[0, k, r], v[1, k, r]
        valid = ok[a] and (ok[b] if b >= 0 else True)
        for i in range(n):
            dal, dah = d[a, i, 0], d[a, i, 1]
            if op == ADD:
                rl, rh = iadd(dal, dah, d[b, i, 0], d[b, i, 1])
            elif op == SUB:
                rl, rh = isub(dal, dah, d[b, i, 0], d[b, i, 1])
            elif op == MUL:
                ul, uh = imul(v[0, b, r], v[1, b, r], dal, dah)
                wl, wh = imul(al, ah, d[b, i, 0], d[b, i, 1])
                rl, rh = iadd(ul, uh, wl, wh)
            elif op == DIV:
                wl, wh = imul(zl, zh, d[b, i, 0], d[b, i, 1])
                ul, uh = isub(dal, dah, wl, wh)
                rl, rh = ixdiv(ul, uh, v[0, b, r], v[1, b, r])
            elif op == NEG:
                rl, rh = -dah, -dal
            elif op == SQR:
                cl, ch = imul(2.0, 2.0, al, ah)
                rl, rh = imul(cl, ch, dal, dah)
            elif op == SQRT:
                cl, ch = iadd(zl, zh, zl, zh)
                rl, rh = ixdiv(dal, dah, cl, ch)
            elif op == EXP:
                rl, rh = imul(zl, zh, dal, dah)
            elif op == LOG:
                rl, rh = ixdiv(dal, dah, al, ah)
            elif op == ABS:
                rl, rh = imul(_sign(al), _sign(ah), dal, dah)
            else:  # POWN
                if p == 0:
                    rl, rh = 0.0, 0.0
                else:
                    cl, ch = ipown(al, ah, p - 1)
                    cl, ch = imul(cl, ch, float(p), float(p))
                    rl, rh = imul(cl, ch, dal, dah)
            d[k, i, 0], d[k, i, 1] = rl, rh
        if op == DIV:
            valid = valid and (v[0, b, r] > 0.0 or v[1, b, r] < 0.0)
        elif op == SQRT or op == LOG:
            valid = valid and al > 0.0
        elif op == POWN and p < 0:
            valid = valid and (al > 0.0 or ah < 0.0)
        ok[k] = valid


@njit(**_KW)
def centre_row(code: np.ndarray, cst: np.ndarray, outs: np.ndarray, lo: np.ndarray, hi: np.ndarray, r: int,
               mid: np.ndarray, d: np.ndarray, ok: np.ndarray, pv: np.ndarray,
               res: np.ndarray) -> None:  # fmt: skip
    """``res (m, 2)``: the mean-value form of every output on box ``r`` (``ℝ`` where not valid), from the
    derivatives ``d``/``ok`` of :func:`ad_row`; ``mid (n,)`` the centre, ``pv (K, 2)`` scratch."""
    n = lo.shape[1]
    for k in range(code.shape[0]):  # [f]({m}): the natural form on the degenerate box
        op, a, b, p = code[k, 0], code[k, 1], code[k, 2], code[k, 3]
        if op == VAR:
            pv[k, 0], pv[k, 1] = mid[p], mid[p]
        elif op == CONST:
            pv[k, 0], pv[k, 1] = cst[k, 0], cst[k, 1]
        else:
            bb = max(b, 0)
            pv[k, 0], pv[k, 1] = fwd_op(op, pv[a, 0], pv[a, 1], pv[bb, 0], pv[bb, 1], p)
    for j in range(outs.shape[0]):
        o = outs[j]
        accl, acch = pv[o, 0], pv[o, 1]
        for i in range(n):
            xl, xh = isub(lo[r, i], hi[r, i], mid[i], mid[i])
            tl, th = imul(d[o, i, 0], d[o, i, 1], xl, xh)
            accl, acch = iadd(accl, acch, tl, th)
        if ok[o] and accl <= acch:
            res[j, 0], res[j, 1] = accl, acch
        else:
            res[j, 0], res[j, 1] = -_INF, _INF


@njit(**_KW)
def centre_outputs(code: np.ndarray, cst: np.ndarray, outs: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                   mid: np.ndarray, v: np.ndarray) -> None:  # fmt: skip
    """Intersect the output nodes of a forward pass ``v (2, K, N)`` with the centred form, box by box
    (``mid (N, n)``: the centres)."""
    K, n, m = code.shape[0], lo.shape[1], outs.shape[0]
    d, ok = np.empty((K, n, 2)), np.empty(K, dtype=np.bool_)
    pv, res = np.empty((K, 2)), np.empty((m, 2))
    for r in range(lo.shape[0]):
        if v[0, outs[0], r] > v[1, outs[0], r]:
            continue  # empty box or empty image: nothing to tighten
        ad_row(code, v, r, n, d, ok)
        centre_row(code, cst, outs, lo, hi, r, mid[r], d, ok, pv, res)
        for j in range(m):
            o = outs[j]
            v[0, o, r], v[1, o, r] = meet(v[0, o, r], v[1, o, r], res[j, 0], res[j, 1])


@njit(**_KW)
def _forward_rows(code: np.ndarray, cst: np.ndarray, lo: np.ndarray, hi: np.ndarray, v: np.ndarray) -> None:
    for r in range(lo.shape[0]):
        empty = False
        for i in range(lo.shape[1]):
            empty = empty or lo[r, i] > hi[r, i]
        for k in range(code.shape[0]):
            op, a, b, p = code[k, 0], code[k, 1], code[k, 2], code[k, 3]
            if empty:
                v[0, k, r], v[1, k, r] = _INF, -_INF
            elif op == VAR:
                v[0, k, r], v[1, k, r] = lo[r, p], hi[r, p]
            elif op == CONST:
                v[0, k, r], v[1, k, r] = cst[k, 0], cst[k, 1]
            else:
                bb = max(b, 0)
                v[0, k, r], v[1, k, r] = fwd_op(op, v[0, a, r], v[1, a, r], v[0, bb, r], v[1, bb, r], p)


@njit(**_KW)
def _jacobian_kernel(code: np.ndarray, cst: np.ndarray, outs: np.ndarray, lo: np.ndarray,
                     hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    N, K, n, m = lo.shape[0], code.shape[0], lo.shape[1], outs.shape[0]
    v = np.empty((2, K, N))
    _forward_rows(code, cst, lo, hi, v)
    jac = np.empty((2, N, m, n))
    valid = np.zeros((N, m), dtype=np.bool_)
    d, ok = np.empty((K, n, 2)), np.empty(K, dtype=np.bool_)
    for r in range(N):
        ad_row(code, v, r, n, d, ok)
        empty = False
        for i in range(n):
            empty = empty or lo[r, i] > hi[r, i]
        for j in range(m):
            for i in range(n):
                o = outs[j]
                jac[0, r, j, i], jac[1, r, j, i] = (_INF, -_INF) if empty else (d[o, i, 0], d[o, i, 1])
            valid[r, j] = ok[outs[j]] and not empty
    return jac, valid


@njit(**_KW)
def _centred_kernel(code: np.ndarray, cst: np.ndarray, outs: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                    mid: np.ndarray) -> np.ndarray:  # fmt: skip
    N, K, n, m = lo.shape[0], code.shape[0], lo.shape[1], outs.shape[0]
    v = np.empty((2, K, N))
    _forward_rows(code, cst, lo, hi, v)
    out = np.empty((2, N, m))
    d, ok = np.empty((K, n, 2)), np.empty(K, dtype=np.bool_)
    pv, res = np.empty((K, 2)), np.empty((m, 2))
    for r in range(N):
        empty = False
        for i in range(n):
            empty = empty or lo[r, i] > hi[r, i]
        if empty:
            out[0, r], out[1, r] = _INF, -_INF
            continue
        ad_row(code, v, r, n, d, ok)
        centre_row(code, cst, outs, lo, hi, r, mid[r], d, ok, pv, res)
        for j in range(m):
            out[0, r, j], out[1, r, j] = res[j, 0], res[j, 1]
    return out


def centres(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Finite centres of a batch (0 in empty rows), contiguous for the kernels."""
    with np.errstate(invalid="ignore"):
        m = midpoint(lo, hi)
    return np.ascontiguousarray(np.where(np.isnan(m), 0.0, m))


def jacobian_tape(t: Tape, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Jlo, Jhi, valid)``: ``[J_f]([x])`` ``(N, m, n)`` and the ``(N, m)`` validity mask, compiled."""
    lo, hi = np.ascontiguousarray(lo, dtype=np.float64), np.ascontiguousarray(hi, dtype=np.float64)
    jac, valid = _jacobian_kernel(t.code, t.cst, t.outputs, lo, hi)
    return jac[0], jac[1], valid


def centred_tape(t: Tape, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The mean-value form ``(N, m)`` on a batch, compiled (``ℝ`` where not valid, empty on empty boxes)."""
    lo, hi = np.ascontiguousarray(lo, dtype=np.float64), np.ascontiguousarray(hi, dtype=np.float64)
    out = _centred_kernel(t.code, t.cst, t.outputs, lo, hi, centres(lo, hi))
    return out[0], out[1]
