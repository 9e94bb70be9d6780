"""Compiled forward-backward (HC4-revise, thesis §2.4.1.2) and ``f⁻¹([y])`` separation on a tape.

One kernel call runs a whole batch, node by node (the op dispatch is paid once per node, not per
box): the forward pass evaluates every node of the :class:`~.tape_jit.Tape` on every box (natural
inclusion, Eq. 2.21), the outputs are intersected with ``[y]`` and the backward pass applies the
projection rules of :mod:`.backward` (their scalar forms are here) down to the variables. A box is
empty as soon as any node is. :func:`sep_box` gives both parts of the separator of Theorem 2.1
(Eq. 2.51) for a box ``[y]``: ``x_out`` from ``[y]``, ``x_in`` as the hull of the projections of
the ``2m`` half-spaces making up the (open) complement of ``[y]``, each projected as its closure and
skipped on the boxes whose image ``[f_j]([x])`` lies on ``[y]``'s side of it (then no point of the box
is strictly beyond that bound, though the closure may touch it: a point with ``f = y⁻`` is inside).

>>> t = Tape.of(Function(lambda x: x[0] ** 2 + x[1] ** 2))
>>> lo, hi = np.array([[0.0, 0.0]]), np.array([[2.0, 2.0]])
>>> rlo, rhi = hc4(t, lo, hi, np.array([[0.0]]), np.array([[1.0]]))   # x² + y² <= 1
>>> bool(rlo[0, 0] == 0.0 and 1.0 <= rhi[0, 0] < 1.0 + 1e-15)
True
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.scalar_jit import (
    iadd,
    iexp,
    ilog,
    imul,
    isqr,
    isqrt,
    isub,
    ixdiv,
    meet,
    njit,
)
from digslam.observer.expr.centred_jit import centre_outputs, centres
from digslam.observer.expr.tape_jit import (
    ABS,
    ADD,
    CONST,
    DIV,
    EXP,
    LOG,
    MUL,
    NEG,
    SQR,
    SQRT,
    SUB,
    VAR,
    Tape,
    fwd_op,
)

_INF = math.inf
_KW = {"error_model": "numpy"}


@njit(**_KW)
def _forward(code: np.ndarray, cst: np.ndarray, lo: np.ndarray, hi: np.ndarray, v: np.ndarray) -> None:
    """``v (2, K, N)``: enclosures of every node on every box (empty boxes give empty nodes)."""
    nb = lo.shape[0]
    for k in range(code.shape[0]):
        op, a, b, p = code[k, 0], code[k, 1], code[k, 2], code[k, 3]
        if op == VAR:
            for r in range(nb):
                v[0, k, r], v[1, k, r] = lo[r, p], hi[r, p]
        elif op == CONST:
            v[0, k], v[1, k] = cst[k, 0], cst[k, 1]
        else:
            bb = max(b, 0)
            for r in range(nb):
                v[0, k, r], v[1, k, r] = fwd_op(op, v[0, a, r], v[1, a, r], v[0, bb, r], v[1, bb, r], p)
    for r in range(nb):
        for i in range(lo.shape[1]):
            if lo[r, i] > hi[r, i]:
                v[0, :, r], v[1, :, r] = _INF, -_INF


@njit(**_KW)
def _rule(op: int, zl: float, zh: float, xl: float, xh: float, yl: float, yh: float,
          p: int) -> tuple[float, float, float, float]:  # fmt: skip
    """Projection rule of :mod:`.backward` for ``z = op(x, y)``: the contracted ``x, y``."""
    if op == ADD:
        tl, th = isub(zl, zh, yl, yh)
        xl, xh = meet(xl, xh, tl, th)
        tl, th = isub(zl, zh, xl, xh)
        return xl, xh, tl, th
    if op == SUB:
        tl, th = iadd(zl, zh, yl, yh)
        xl, xh = meet(xl, xh, tl, th)
        tl, th = isub(xl, xh, zl, zh)
        return xl, xh, tl, th
    if op == MUL:
        xl, xh = mul_rev(zl, zh, yl, yh, xl, xh)
        yl, yh = mul_rev(zl, zh, xl, xh, yl, yh)
        return xl, xh, yl, yh
    if op == DIV:
        tl, th = imul(zl, zh, yl, yh)
        xl, xh = meet(xl, xh, tl, th)
        yl, yh = mul_rev(xl, xh, zl, zh, yl, yh)
        if yl == 0.0 and yh == 0.0:  # a divisor left at {0}: no point
            return _INF, -_INF, _INF, -_INF
        return xl, xh, yl, yh
    pl, ph = meet(zl, zh, 0.0, _INF)
    if op == NEG:
        tl, th = -zh, -zl
    elif op == SQR:
        tl, th = isqrt(zl, zh)
        tl, th = symmetric(xl, xh, tl, th)
    elif op == SQRT:
        tl, th = isqr(pl, ph)
    elif op == EXP:
        tl, th = ilog(pl, ph)
    elif op == LOG:
        tl, th = iexp(zl, zh)
    elif op == ABS:
        tl, th = symmetric(xl, xh, pl, ph)
    else:  # POWN
        tl, th = _pown_rev(zl, zh, xl, xh, p)
    xl, xh = meet(xl, xh, tl, th)
    return xl, xh, -_INF, _INF


@njit(**_KW)
def _backward(code: np.ndarray, w: np.ndarray, alive: np.ndarray) -> None:
    """Projection rules from the last node down (Ex. 2.4) on ``w (2, K, N)``; a box dies (``alive``
    false) as soon as one of its nodes is empty."""
    nb = w.shape[2]
    for k in range(code.shape[0] - 1, -1, -1):
        op, a, b, p = code[k, 0], code[k, 1], code[k, 2], code[k, 3]
        for r in range(nb):
            if not alive[r]:
                continue
            zl, zh = w[0, k, r], w[1, k, r]
            if zl > zh:
                alive[r] = False
            elif op != VAR and op != CONST:
                yl, yh = (w[0, b, r], w[1, b, r]) if b >= 0 else (-_INF, _INF)
                xl, xh, yl, yh = _rule(op, zl, zh, w[0, a, r], w[1, a, r], yl, yh, p)
                w[0, a, r], w[1, a, r] = xl, xh
                alive[r] = xl <= xh
                if b >= 0:
                    yl, yh = meet(w[0, b, r], w[1, b, r], yl, yh)
                    w[0, b, r], w[1, b, r] = yl, yh
                    alive[r] &= yl <= yh


@njit(**_KW)
def mul_rev(cl: float, ch: float, bl: float, bh: float, al: float, ah: float) -> tuple[float, float]:
    """``[a] ∩ {t : ∃ s ∈ [b], t·s ∈ [c]}``, as :func:`.backward.mul_rev` (``[b]`` split at 0)."""
    if cl <= 0.0 <= ch and bl <= 0.0 <= bh:
        return al, ah
    rl, rh = _INF, -_INF
    for sl, sh in ((bl, min(bh, 0.0)), (max(bl, 0.0), bh)):
        if sl <= sh:
            ql, qh = ixdiv(cl, ch, sl, sh)
            ql, qh = meet(al, ah, ql, qh)
            rl, rh = min(rl, ql), max(rh, qh)
    return rl, rh


@njit(**_KW)
def symmetric(xl: float, xh: float, rl: float, rh: float) -> tuple[float, float]:
    """``[x] ∩ ([r] ∪ -[r])``."""
    pl, ph = meet(xl, xh, rl, rh)
    nl, nh = meet(xl, xh, -rh, -rl)
    return min(pl, nl), max(ph, nh)


@njit(**_KW)
def root(zl: float, zh: float, n: int) -> tuple[float, float]:
    """Enclosure of ``[z]^(1/n)`` for ``[z] ⊂ [0, ∞)`` as ``exp(log(z)/n)``, as :mod:`.backward`."""
    ll, lh = ilog(zl, zh)
    ql, qh = ixdiv(ll, lh, float(n), float(n))
    rl, rh = iexp(ql, qh)
    if zl <= 0.0 and zl <= zh:
        rl = 0.0
    if zh == 0.0:
        rh = 0.0
    return rl, rh


@njit(**_KW)
def _pown_rev(zl: float, zh: float, xl: float, xh: float, n: int) -> tuple[float, float]:
    """``[x] ∩ {t : tⁿ ∈ [z]}``, as :func:`.backward.b_pown`."""
    if n == 0:
        return (xl, xh) if zl <= 1.0 <= zh else (_INF, -_INF)
    if n < 0:
        zl, zh = ixdiv(1.0, 1.0, zl, zh)
        n = -n
    tl, th = meet(zl, zh, 0.0, _INF)
    pl, ph = root(tl, th, n)
    if n % 2 == 0:
        return symmetric(xl, xh, pl, ph)
    tl, th = meet(-zh, -zl, 0.0, _INF)
    ql, qh = root(tl, th, n)
    al, ah = meet(xl, xh, pl, ph)
    bl, bh = meet(xl, xh, -qh, -ql)
    return min(al, bl), max(ah, bh)


@njit(**_KW)
def _contract(code: np.ndarray, outs: np.ndarray, v: np.ndarray, w: np.ndarray, alive: np.ndarray,
              y: np.ndarray, j0: int, per_box: bool) -> None:  # fmt: skip
    """``w = v``, outputs met with ``[y]`` (``y (2, m)``, or ``(2, N, m)`` when ``per_box``; only output
    ``j0`` when ``j0 >= 0``), then the backward pass."""
    for k in range(w.shape[1]):  # element by element: an array copy would compile numba's shape check
        for r in range(w.shape[2]):
            w[0, k, r], w[1, k, r] = v[0, k, r], v[1, k, r]
    for r in range(w.shape[2]):
        alive[r] = True
    for j in range(outs.shape[0]):
        if j0 >= 0 and j != j0:
            continue
        o = outs[j]
        for r in range(w.shape[2]):
            yl, yh = (y[0, r, j], y[1, r, j]) if per_box else (y[0, 0, j], y[1, 0, j])
            w[0, o, r], w[1, o, r] = meet(w[0, o, r], w[1, o, r], yl, yh)
    _backward(code, w, alive)


@njit(**_KW)
def _store(code: np.ndarray, lo: np.ndarray, hi: np.ndarray, w: np.ndarray, alive: np.ndarray,
           res: np.ndarray, j: int, hull: bool) -> None:  # fmt: skip
    """Write (or hull into) ``res[j], res[j + 1]`` the live boxes: ``[x]`` with the variables from ``w``."""
    node = np.full(lo.shape[1], -1)
    for k in range(code.shape[0]):
        if code[k, 0] == VAR:
            node[code[k, 3]] = k
    for r in range(lo.shape[0]):
        if alive[r]:
            for i in range(lo.shape[1]):
                k = node[i]
                cl, ch = (lo[r, i], hi[r, i]) if k < 0 else (w[0, k, r], w[1, k, r])
                res[j, r, i] = min(res[j, r, i], cl) if hull else cl
                res[j + 1, r, i] = max(res[j + 1, r, i], ch) if hull else ch


@njit(**_KW)
def _separate(code: np.ndarray, outs: np.ndarray, lo: np.ndarray, hi: np.ndarray, y: np.ndarray,
              v: np.ndarray) -> np.ndarray:  # fmt: skip
    """``(4, N, n)``: ``in_lo, in_hi, out_lo, out_hi`` of the separator of ``f⁻¹([y])``, ``y (2, 1, m)``,
    from the node enclosures ``v`` of a forward pass."""
    w, alive = np.empty_like(v), np.empty(lo.shape[0], dtype=np.bool_)
    res = np.empty((4, lo.shape[0], lo.shape[1]))
    res[0::2], res[1::2] = _INF, -_INF
    _contract(code, outs, v, w, alive, y, -1, False)
    _store(code, lo, hi, w, alive, res, 2, False)
    half = np.empty_like(y)
    for j in range(outs.shape[0]):  # closed complement of [y]: y_j <= ylo_j or y_j >= yhi_j
        for side in range(2):
            half[0, 0, j], half[1, 0, j] = (-_INF, y[0, 0, j]) if side == 0 else (y[1, 0, j], _INF)
            _contract(code, outs, v, w, alive, half, j, False)
            o = outs[j]
            for r in range(lo.shape[0]):  # the complement is open: no f_j < ylo_j when [f_j]⁻ >= ylo_j
                if (v[0, o, r] >= y[0, 0, j]) if side == 0 else (v[1, o, r] <= y[1, 0, j]):
                    alive[r] = False
            _store(code, lo, hi, w, alive, res, 0, True)
    for r in range(lo.shape[0]):  # f defined nowhere on a (non-empty) box: all of it is outside f⁻¹([y])
        for j in range(outs.shape[0]):
            if v[0, outs[j], r] > v[1, outs[j], r] and res[2, r, 0] > res[3, r, 0]:
                nonempty = True
                for i in range(lo.shape[1]):
                    nonempty = nonempty and lo[r, i] <= hi[r, i]
                if nonempty:
                    for i in range(lo.shape[1]):
                        res[0, r, i], res[1, r, i] = lo[r, i], hi[r, i]
    return res


@njit(**_KW)
def _sep_box_kernel(code: np.ndarray, cst: np.ndarray, outs: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                    y: np.ndarray) -> np.ndarray:  # fmt: skip
    """:func:`_separate` after the natural forward pass."""
    v = np.empty((2, code.shape[0], lo.shape[0]))
    _forward(code, cst, lo, hi, v)
    return _separate(code, outs, lo, hi, y, v)


@njit(**_KW)
def _sep_box_centred_kernel(code: np.ndarray, cst: np.ndarray, outs: np.ndarray, lo: np.ndarray,
                            hi: np.ndarray, y: np.ndarray, mid: np.ndarray) -> np.ndarray:  # fmt: skip
    """:func:`_separate` after the forward pass, its outputs met with the mean-value form (centres
    ``mid``); a kernel of its own, so that the natural one does not compile the centred form."""
    v = np.empty((2, code.shape[0], lo.shape[0]))
    _forward(code, cst, lo, hi, v)
    centre_outputs(code, cst, outs, lo, hi, mid, v)
    return _separate(code, outs, lo, hi, y, v)


@njit(**_KW)
def _hc4_kernel(code: np.ndarray, cst: np.ndarray, outs: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                y: np.ndarray) -> np.ndarray:  # fmt: skip
    """``(2, N, n)``: HC4-revise of ``f(x_r) ∈ [y_r]`` for every row, ``y (2, N, m)``."""
    v = np.empty((2, code.shape[0], lo.shape[0]))
    w, alive = np.empty_like(v), np.empty(lo.shape[0], dtype=np.bool_)
    res = np.empty((2, lo.shape[0], lo.shape[1]))
    res[0], res[1] = _INF, -_INF
    _forward(code, cst, lo, hi, v)
    _contract(code, outs, v, w, alive, y, -1, True)
    _store(code, lo, hi, w, alive, res, 0, False)
    return res


@njit(**_KW)
def _hc4_centred_kernel(code: np.ndarray, cst: np.ndarray, outs: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                        y: np.ndarray, mid: np.ndarray) -> np.ndarray:  # fmt: skip
    """As :func:`_hc4_kernel`, the outputs met with the mean-value form (centres ``mid``) first; a kernel
    of its own, so that the natural one does not compile the centred form."""
    v = np.empty((2, code.shape[0], lo.shape[0]))
    w, alive = np.empty_like(v), np.empty(lo.shape[0], dtype=np.bool_)
    res = np.empty((2, lo.shape[0], lo.shape[1]))
    res[0], res[1] = _INF, -_INF
    _forward(code, cst, lo, hi, v)
    centre_outputs(code, cst, outs, lo, hi, mid, v)
    _contract(code, outs, v, w, alive, y, -1, True)
    _store(code, lo, hi, w, alive, res, 0, False)
    return res


@njit(**_KW)
def _image_kernel(code: np.ndarray, cst: np.ndarray, outs: np.ndarray, lo: np.ndarray,
                  hi: np.ndarray) -> np.ndarray:  # fmt: skip
    """``(2, N, m)``: the forward image ``[f]([x])``."""
    v = np.empty((2, code.shape[0], lo.shape[0]))
    _forward(code, cst, lo, hi, v)
    res = np.empty((2, lo.shape[0], outs.shape[0]))
    for j in range(outs.shape[0]):
        for r in range(lo.shape[0]):
            res[0, r, j], res[1, r, j] = v[0, outs[j], r], v[1, outs[j], r]
    return res


#: Rows per kernel call: the kernels hold ``2 K`` values per row (``K`` tape nodes), so huge batches
#: (a fine ``classify_grid``, a big paver generation) go through in blocks of bounded memory.
BLOCK = 1 << 18


def _c(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64)


def image(t: Tape, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``[f]([x])`` as an ``(N, m)`` batch (empty rows for empty boxes)."""
    lo, hi = _c(lo), _c(hi)
    if lo.shape[0] <= BLOCK:
        res = _image_kernel(t.code, t.cst, t.outputs, lo, hi)
        return res[0], res[1]
    res = np.empty((2, lo.shape[0], t.outputs.shape[0]))
    for i in range(0, lo.shape[0], BLOCK):
        res[:, i : i + BLOCK] = _image_kernel(t.code, t.cst, t.outputs, lo[i : i + BLOCK], hi[i : i + BLOCK])
    return res[0], res[1]


def _run_hc4(t: Tape, lo: np.ndarray, hi: np.ndarray, y: np.ndarray, centred: bool) -> np.ndarray:
    if centred:
        return _hc4_centred_kernel(t.code, t.cst, t.outputs, lo, hi, y, centres(lo, hi))
    return _hc4_kernel(t.code, t.cst, t.outputs, lo, hi, y)


def _run_sep(t: Tape, lo: np.ndarray, hi: np.ndarray, y: np.ndarray, centred: bool) -> np.ndarray:
    if centred:
        return _sep_box_centred_kernel(t.code, t.cst, t.outputs, lo, hi, y, centres(lo, hi))
    return _sep_box_kernel(t.code, t.cst, t.outputs, lo, hi, y)


def hc4(t: Tape, lo: np.ndarray, hi: np.ndarray, ylo: np.ndarray, yhi: np.ndarray,
        centred: bool = False) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """HC4-revise of ``f(x) ∈ [y]`` on a batch; ``[y]`` is ``(m,)`` or ``(N, m)`` per box. With
    ``centred``, each output's natural enclosure is first met with the mean-value form
    (:mod:`.centred_jit`)."""
    shape = (lo.shape[0], t.outputs.shape[0])
    y = np.stack([np.broadcast_to(ylo, shape), np.broadcast_to(yhi, shape)]).astype(np.float64)
    lo, hi = _c(lo), _c(hi)
    if lo.shape[0] <= BLOCK:
        res = _run_hc4(t, lo, hi, y, centred)
        return res[0], res[1]
    res = np.empty((2, *lo.shape))
    for i in range(0, lo.shape[0], BLOCK):
        b = slice(i, i + BLOCK)
        res[:, b] = _run_hc4(t, lo[b], hi[b], np.ascontiguousarray(y[:, b]), centred)
    return res[0], res[1]


def sep_box(t: Tape, lo: np.ndarray, hi: np.ndarray, y: np.ndarray, centred: bool = False) -> np.ndarray:
    """``(4, N, n)``: ``x_in`` (lo, hi) then ``x_out`` of the separator of ``f⁻¹([y])``, ``y (2, m)``."""
    lo, hi, yy = _c(lo), _c(hi), _c(y)[:, None, :]
    if lo.shape[0] <= BLOCK:
        return _run_sep(t, lo, hi, yy, centred)
    res = np.empty((4, *lo.shape))
    for i in range(0, lo.shape[0], BLOCK):
        b = slice(i, i + BLOCK)
        res[:, b] = _run_sep(t, lo[b], hi[b], yy, centred)
    return res


__all__ = [
    "BLOCK",
    "hc4",
    "image",
    "mul_rev",
    "root",
    "sep_box",
    "symmetric",
]
