"""Compiled minimal polar contractor (thesis §3.2.3, Eq. 3.22–3.34): one machine-code loop per batch.

The construction of :mod:`digslam.observer.polar.ctc` (read its docstring): on ``ρ >= 0`` the hull of
``[x]×[y]×[ρ]×[θ] ∩ Π`` is the hull of the candidate extreme points (box corners, box edges ∩ circles
``|p| = ρ±``, box edges ∩ rays ``θ±``, rays ∩ circles, circles ∩ axes, feet of the edges on the
axes, the origin), each enclosed with :mod:`.scalar_jit`'s outward-rounded scalar arithmetic, intersected
with the box and kept when it may lie in the region (Eq. 3.28 on the base domain, the symmetries of
Prop. 3.4 by taking all octants at once); ``σ₄`` (``ρ < 0``, Eq. 3.32) is applied explicitly, ``γ``
(``θ + 2kπ``) by lifting each angle to its extreme representatives in ``[θ]``. A candidate is
intersected with the box *before* its angle is taken, so the result is never larger than that of the
numpy oracle of the tests (``tests/polar_oracle.py``).

Example:
    >>> box = np.array([[1.0, 1.0, 0.0, -10.0]]), np.array([[2.0, 2.0, 10.0, 10.0]])
    >>> lo, hi = ctc_polar_batch(*box, True)
    >>> [round(float(v), 6) for v in lo[0]], [round(float(v), 6) for v in hi[0]]
    ([1.0, 1.0, 1.414214, -5.819538], [2.0, 2.0, 2.828427, 7.390334])
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.polar_ops_jit import (
    cos_sin,
    cross,
    disk_hull,
    lift,
    outside_hull,
    pdiv,
    pmul,
    point_angle,
)
from digslam.observer.core.rounding import PI_DOWN, PI_UP, TWO_PI_DOWN, TWO_PI_UP
from digslam.observer.core.scalar_jit import (
    add_dn,
    add_up,
    isqrt,
    mul_dn,
    mul_up,
    njit,
    sqrt_dn,
    sqrt_up,
    sub_dn,
    sub_up,
)

__all__ = ["contract_pos", "ctc_polar_batch", "sep_pie_batch"]

_INF = math.inf
_FAR = 2.0**50


@njit
def _push(cd: np.ndarray, k: int, xl: float, xh: float, yl: float, yh: float, rl: float, rh: float,
          ray: float) -> int:  # fmt: skip
    """Store candidate ``[x]×[y]×[ρ]`` (at the exact angle ``ray``, NaN if off-ray) as row ``k``."""
    cd[k, 0], cd[k, 1], cd[k, 2], cd[k, 3], cd[k, 4], cd[k, 5], cd[k, 6] = xl, xh, yl, yh, rl, rh, ray
    return k + 1


@njit
def _fold(b: np.ndarray, acc: np.ndarray, cs: np.ndarray, mode: int, nt: bool, cd: np.ndarray,
          n: int) -> None:  # fmt: skip
    """Hull into ``acc`` of the ``n`` candidates of ``cd`` that may lie in the region, clipped to ``b``.

    ``mode``: 0 every angle is in the sector, 1 aperture below π (both sides), 2 the union of the
    sides, -1 θ unresolved (kept as given).
    """
    for k in range(n):
        xl, xh, yl, yh = max(cd[k, 0], b[0]), min(cd[k, 1], b[1]), max(cd[k, 2], b[2]), min(cd[k, 3], b[3])
        rl, rh, ray = max(cd[k, 4], b[4]), min(cd[k, 5], b[5]), cd[k, 6]
        if not (xl <= xh and yl <= yh and rl <= rh):
            continue
        lo_t, hi_t = b[6], b[7]
        if ray == ray:
            if nt:
                lo_t, hi_t = ray, ray
        elif nt and mode != -1:
            al, ah = point_angle(xl, xh, yl, yh)
            if not (al <= ah and math.isfinite(al) and math.isfinite(ah)):
                continue
            lo_t, hi_t = lift(al, ah, b[6], b[7])
            if lo_t > hi_t:
                continue
        elif mode > 0:
            after = cross(cs[0], cs[1], cs[2], cs[3], xl, xh, yl, yh, True) >= 0  # e(θ⁻) × p may be >= 0
            before = cross(cs[4], cs[5], cs[6], cs[7], xl, xh, yl, yh, False) <= 0  # p × e(θ⁺) may be >= 0
            if not ((after and before) if mode == 1 else (after or before)):
                continue
        acc[0], acc[1], acc[2], acc[3] = min(acc[0], xl), max(acc[1], xh), min(acc[2], yl), max(acc[3], yh)
        acc[4], acc[5] = min(acc[4], rl), max(acc[5], rh)
        acc[6], acc[7] = min(acc[6], lo_t), max(acc[7], hi_t)


@njit
def contract_pos(b: np.ndarray, cs: np.ndarray, nt: bool, acc: np.ndarray, cd: np.ndarray, cs2: np.ndarray,
                 mode2: int, acc2: np.ndarray) -> None:  # fmt: skip
    """Minimal contraction of ``b = (x⁻, x⁺, y⁻, y⁺, ρ⁻, ρ⁺, θ⁻, θ⁺)`` on ``ρ >= 0``, into ``acc`` (8,).

    ``cs`` is :func:`cos_sin` of ``θ``'s bounds (used only when they are finite). ``acc`` receives the
    contracted box, or ``(inf, -inf)`` in every column when infeasible. With ``nt=False`` θ is only
    passed through (the ``x, y, ρ`` faces are still minimal). ``cd`` is a ``(48, 7)`` scratch buffer.
    With ``mode2 >= 0`` (and ``nt=False``) the same candidates also give, into ``acc2``, the contraction
    for the sector of sides ``cs2`` (a pie and the rest of its turn share every candidate point).
    """
    acc[0::2], acc[1::2] = _INF, -_INF
    acc2[0::2], acc2[1::2] = _INF, -_INF
    tl, th = b[6], b[7]
    b[4] = max(b[4], 0.0)
    r_in, r_hi = b[4], b[5]
    rh = r_hi
    b[0], b[1], b[2], b[3] = max(b[0], -rh), min(b[1], rh), max(b[2], -rh), min(b[3], rh)
    xl, xh, yl, yh = b[0], b[1], b[2], b[3]
    if not (xl <= xh and yl <= yh and b[4] <= b[5] and tl <= th):
        return
    mx, my = max(abs(xl), abs(xh)), max(abs(yl), abs(yh))
    gx = 0.0 if xl <= 0 <= xh else min(abs(xl), abs(xh))
    gy = 0.0 if yl <= 0 <= yh else min(abs(yl), abs(yh))
    b[4] = max(b[4], sqrt_dn(add_dn(mul_dn(gx, gx), mul_dn(gy, gy))))
    b[5] = min(b[5], sqrt_up(add_up(mul_up(mx, mx), mul_up(my, my))))
    rl, rh = b[4], b[5]
    if rl > rh:
        return
    # a radius set by the box's own distance range meets it only at its nearest or farthest point, a
    # corner or a foot: the circle-based candidates are skipped for it
    cut_l, cut_h = rl > r_in, rh < r_hi
    if not (math.isfinite(xl) and math.isfinite(xh) and math.isfinite(yl) and math.isfinite(yh)
            and math.isfinite(rh)):  # fmt: skip
        acc[:] = b
        if mode2 >= 0:
            acc2[:] = b
        return
    resolved = math.isfinite(tl) and math.isfinite(th) and abs(tl) <= _FAR and abs(th) <= _FAR
    w = sub_up(th, tl)
    mode = 0 if (w >= TWO_PI_DOWN or not resolved) else (1 if w < PI_DOWN else 2)
    if nt and not resolved:
        mode = -1  # angles are not lifted: θ stays as given
    nan, k = math.nan, 0
    xl2, xh2, yl2, yh2 = mul_dn(xl, xl), mul_dn(xh, xh), mul_dn(yl, yl), mul_dn(yh, yh)
    Xl2, Xh2, Yl2, Yh2 = mul_up(xl, xl), mul_up(xh, xh), mul_up(yl, yl), mul_up(yh, yh)
    for cx, c2, C2 in ((xl, xl2, Xl2), (xh, xh2, Xh2)):  # corners
        for cy, d2, D2 in ((yl, yl2, Yl2), (yh, yh2, Yh2)):
            k = _push(cd, k, cx, cx, cy, cy, sqrt_dn(add_dn(c2, d2)), sqrt_up(add_up(C2, D2)), nan)
    for rr, cut in ((rl, cut_l), (rh, cut_h)):
        if cut:
            continue
        q2, Q2 = mul_dn(rr, rr), mul_up(rr, rr)
        for a, a2, A2, vert in ((xl, xl2, Xl2, True), (xh, xh2, Xh2, True), (yl, yl2, Yl2, False),
                                (yh, yh2, Yh2, False)):  # edges ∩ circles  # fmt: skip
            if Q2 >= a2:
                hl, hh = isqrt(sub_dn(q2, A2), sub_up(Q2, a2))
                if vert:
                    k = _push(cd, k, a, a, hl, hh, rr, rr, nan)
                    k = _push(cd, k, a, a, -hh, -hl, rr, rr, nan)
                else:
                    k = _push(cd, k, hl, hh, a, a, rr, rr, nan)
                    k = _push(cd, k, -hh, -hl, a, a, rr, rr, nan)
    if resolved and (nt or mode != 0):  # rays θ± ∩ edges and ∩ circles (not extreme on a full turn)
        for q in (0, 4):
            t = tl if q == 0 else th
            c0, c1, s0, s1 = cs[q], cs[q + 1], cs[q + 2], cs[q + 3]
            lo_c = cross(c0, c1, s0, s1, xl, xh, yl, yh, False)
            hi_c = cross(c0, c1, s0, s1, xl, xh, yl, yh, True)
            if lo_c > 0 or hi_c < 0:
                continue  # the box is strictly on one side of the ray's line
            for a, vert in ((xl, True), (xh, True), (yl, False), (yh, False)):
                p0, p1 = pdiv(a, c0, c1) if vert else pdiv(a, s0, s1)
                p0, p1 = max(p0, rl), min(p1, rh)
                if p0 <= p1:
                    if vert:
                        o0, o1 = pmul(p0, p1, s0, s1)
                        k = _push(cd, k, a, a, o0, o1, p0, p1, t)
                    else:
                        o0, o1 = pmul(p0, p1, c0, c1)
                        k = _push(cd, k, o0, o1, a, a, p0, p1, t)
            for rr, cut in ((rl, cut_l), (rh, cut_h)):
                if cut:
                    continue
                u0, u1 = pmul(rr, rr, c0, c1)
                v0, v1 = pmul(rr, rr, s0, s1)
                k = _push(cd, k, u0, u1, v0, v1, rr, rr, t)
    for rr, cut in ((rl, cut_l), (rh, cut_h)):  # circles ∩ axes
        if cut:
            continue
        k = _push(cd, k, rr, rr, 0.0, 0.0, rr, rr, nan)
        k = _push(cd, k, -rr, -rr, 0.0, 0.0, rr, rr, nan)
        k = _push(cd, k, 0.0, 0.0, rr, rr, rr, rr, nan)
        k = _push(cd, k, 0.0, 0.0, -rr, -rr, rr, rr, nan)
    for a in (xl, xh):  # feet of the edges on the axes
        k = _push(cd, k, a, a, 0.0, 0.0, abs(a), abs(a), nan)
    for a in (yl, yh):
        k = _push(cd, k, 0.0, 0.0, a, a, abs(a), abs(a), nan)
    _fold(b, acc, cs, mode, nt, cd, k)
    if mode2 >= 0:
        _fold(b, acc2, cs2, mode2, nt, cd, k)
    for ac in (acc, acc2):
        if xl <= 0 <= xh and yl <= 0 <= yh and rl <= 0:  # the origin: every θ
            for i in range(3):
                ac[2 * i], ac[2 * i + 1] = min(ac[2 * i], 0.0), max(ac[2 * i + 1], 0.0)
            ac[6], ac[7] = tl, th
        if not (ac[0] <= ac[1] and ac[2] <= ac[3] and ac[4] <= ac[5] and ac[6] <= ac[7]):
            ac[0::2], ac[1::2] = _INF, -_INF


@njit
def ctc_polar_batch(lo: np.ndarray, hi: np.ndarray, nt: bool) -> tuple[np.ndarray, np.ndarray]:
    """``⟦Π ∩ [p]⟧`` for every row of an ``(N, 4)`` batch ``(x, y, ρ, θ)`` (Eq. 3.34); empty rows ``±inf``."""
    n = lo.shape[0]
    olo, ohi = np.empty((n, 4)), np.empty((n, 4))
    b, acc, neg, cs, cd = np.empty(8), np.empty(8), np.empty(8), np.zeros(8), np.empty((48, 7))
    for i in range(n):
        for j in range(4):
            olo[i, j], ohi[i, j] = _INF, -_INF
        if lo[i, 2] <= hi[i, 2] and hi[i, 2] >= 0:  # ρ >= 0 part
            for j in range(4):
                b[2 * j], b[2 * j + 1] = lo[i, j], hi[i, j]
            contract_pos(b, cos_sin(b[6], b[7], cs), nt, acc, cd, cs, -1, neg)
            for j in range(4):
                olo[i, j], ohi[i, j] = acc[2 * j], acc[2 * j + 1]
        if lo[i, 2] < 0 and lo[i, 2] <= hi[i, 2]:  # σ₄: (x, y, -ρ, θ + π)
            b[0], b[1], b[2], b[3] = lo[i, 0], hi[i, 0], lo[i, 1], hi[i, 1]
            b[4], b[5] = -hi[i, 2], -lo[i, 2]
            b[6], b[7] = add_dn(lo[i, 3], PI_DOWN), add_up(hi[i, 3], PI_UP)
            contract_pos(b, cos_sin(b[6], b[7], cs), nt, neg, cd, cs, -1, acc)
            if neg[0] <= neg[1]:
                neg[4], neg[5] = -neg[5], -neg[4]
                neg[6], neg[7] = max(sub_dn(neg[6], PI_UP), lo[i, 3]), min(sub_up(neg[7], PI_DOWN), hi[i, 3])
                for j in range(4):
                    olo[i, j], ohi[i, j] = min(olo[i, j], neg[2 * j]), max(ohi[i, j], neg[2 * j + 1])
        if not (olo[i, 0] <= ohi[i, 0] and olo[i, 1] <= ohi[i, 1] and olo[i, 2] <= ohi[i, 2]
                and olo[i, 3] <= ohi[i, 3]):  # fmt: skip
            for j in range(4):
                olo[i, j], ohi[i, j] = _INF, -_INF
    return olo, ohi


@njit
def sep_pie_batch(lo: np.ndarray, hi: np.ndarray, m: np.ndarray, reflect: bool, pieces: np.ndarray,
                  cs: np.ndarray, convex: bool) -> np.ndarray:  # fmt: skip
    """Theorem 3.2 for the pie (Eq. 3.53): ``x_out = ⊔ ∂ₓC([x], pie)``, ``x_in = ⊔ ∂ₓC([x], [y]), [y] ∈ Ȳ``.

    Args:
        lo, hi: ``(N, 2)`` boxes. With ``reflect``, each box is mapped by ``g_m(x) = m - x`` (Eq. 3.55)
            before and after, and the results are intersected with it (the landmark separator, Eq. 3.56).
        pieces: ``(k, 4)`` rows ``(ρ⁻, ρ⁺, θ⁻, θ⁺)``: row 0 is the pie, the others cover its complement;
            row 1 is the rest of the turn ``[θ⁺, θ⁻ + 2π]`` at the pie's ranges, so its extreme points are
            the pie's candidates (its rays are the pie's), folded with its own sides.
        cs: ``(k, 8)`` :func:`cos_sin` of each piece's θ bounds; row 0 also gives the cone's sides.
        convex: whether the pie's aperture is below π (then boxes are first sorted by their corners).

    Returns:
        ``(4, N, 2)``: ``in_lo, in_hi, out_lo, out_hi`` (:meth:`.Sep.separate_stacked`); empty rows are
        ``(inf, -inf)``.
    """
    n, k = lo.shape[0], pieces.shape[0]
    res = np.full((4, n, 2), _INF)
    res[1], res[3] = -_INF, -_INF
    b, acc, acc2, cd = np.empty(8), np.empty(8), np.empty(8), np.empty((48, 7))
    w1 = sub_up(pieces[1, 3], pieces[1, 2]) if k > 1 else 0.0
    mode1 = 0 if w1 >= TWO_PI_DOWN else (1 if w1 < PI_DOWN else 2)
    c0, c1, s0, s1 = cs[0, 0], cs[0, 1], cs[0, 2], cs[0, 3]
    d0, d1, e0, e1 = cs[0, 4], cs[0, 5], cs[0, 6], cs[0, 7]
    for i in range(n):
        xl, xh, yl, yh = lo[i, 0], hi[i, 0], lo[i, 1], hi[i, 1]
        if not (xl <= xh and yl <= yh):
            continue
        if reflect:
            xl, xh, yl, yh = sub_dn(m[0], xh), sub_up(m[0], xl), sub_dn(m[1], yh), sub_up(m[1], yl)
        mx, my = max(abs(xl), abs(xh)), max(abs(yl), abs(yh))
        gx = 0.0 if xl <= 0 <= xh else min(abs(xl), abs(xh))
        gy = 0.0 if yl <= 0 <= yh else min(abs(yl), abs(yh))
        dmin = sqrt_dn(add_dn(mul_dn(gx, gx), mul_dn(gy, gy)))
        dmax = sqrt_up(add_up(mul_up(mx, mx), mul_up(my, my)))
        inside = outside = False
        bounded = math.isfinite(mx) and math.isfinite(my)
        if convex and math.isfinite(mx) and math.isfinite(my):  # corners against e(θ⁻) × p and p × e(θ⁺)
            a_lo = cross(c0, c1, s0, s1, xl, xh, yl, yh, False)
            a_hi = cross(c0, c1, s0, s1, xl, xh, yl, yh, True)
            b_lo = cross(d0, d1, e0, e1, xl, xh, yl, yh, False)
            b_hi = cross(d0, d1, e0, e1, xl, xh, yl, yh, True)
            inside = a_lo > 0 and b_hi < 0  # in the open cone
            outside = a_hi < 0 or b_lo > 0  # out of the closed cone
        live0 = not (dmax < pieces[0, 0] or dmin > pieces[0, 1] or outside)
        live1 = k > 1 and not (dmax < pieces[1, 0] or dmin > pieces[1, 1] or inside)
        for j in range(k):
            if (j == 0 and not live0) or (j == 1 and (not live1 or live0)):
                continue
            if j > 1 and (dmax < pieces[j, 0] or dmin > pieces[j, 1]):
                continue
            turn = j > 1 and sub_dn(pieces[j, 3], pieces[j, 2]) >= TWO_PI_UP and bounded
            if turn and (pieces[j, 0] == 0.0 or pieces[j, 1] == _INF):  # a disk or its outside: closed form
                if pieces[j, 0] == 0.0:
                    acc[0], acc[1], acc[2], acc[3] = disk_hull(xl, xh, yl, yh, pieces[j, 1])
                else:
                    acc[0], acc[1], acc[2], acc[3] = outside_hull(xl, xh, yl, yh, pieces[j, 0])
                acc2[0], acc2[1], acc2[2], acc2[3] = _INF, -_INF, _INF, -_INF
            else:
                b[0], b[1], b[2], b[3] = xl, xh, yl, yh
                b[4], b[5], b[6], b[7] = pieces[j, 0], pieces[j, 1], pieces[j, 2], pieces[j, 3]
                contract_pos(b, cs[j], False, acc, cd, cs[1], mode1 if (j == 0 and live1) else -1, acc2)
            for g, ac in ((2 if j == 0 else 0, acc), (0, acc2)):
                res[g, i, 0], res[g, i, 1] = min(res[g, i, 0], ac[0]), min(res[g, i, 1], ac[2])
                res[g + 1, i, 0] = max(res[g + 1, i, 0], ac[1])
                res[g + 1, i, 1] = max(res[g + 1, i, 1], ac[3])
        for g in (0, 2):
            ul, uh, vl, vh = res[g, i, 0], res[g + 1, i, 0], res[g, i, 1], res[g + 1, i, 1]
            if reflect and ul <= uh and vl <= vh:
                ul, uh, vl, vh = sub_dn(m[0], uh), sub_up(m[0], ul), sub_dn(m[1], vh), sub_up(m[1], vl)
                ul, uh, vl, vh = max(ul, lo[i, 0]), min(uh, hi[i, 0]), max(vl, lo[i, 1]), min(vh, hi[i, 1])
            if not (ul <= uh and vl <= vh):
                ul, uh, vl, vh = _INF, -_INF, _INF, -_INF
            res[g, i, 0], res[g + 1, i, 0], res[g, i, 1], res[g + 1, i, 1] = ul, uh, vl, vh
    return res
