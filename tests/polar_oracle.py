"""The numpy oracle of the polar kernels (:mod:`digslam.observer.core.polar_jit`), for the tests only.

The construction of the minimal polar contractor (thesis §3.2.3, Eq. 3.22-3.34) written with numpy batch
arithmetic (:mod:`digslam.observer.core.arith`, :mod:`~digslam.observer.core.trig`, outward rounded), and the
pie separator of :class:`~digslam.observer.polar.sep.SepPiInv` and
:class:`~digslam.observer.polar.sep.SepLandmark` built from it by Theorem 3.2 (:func:`project_contract`):
the compiled kernels must agree with it up to outward rounding (``tests/observer/polar/test_polar_jit.py``).
It is slower than the kernels, so only the tests run it.

How. On the base octant ``x, y, ρ >= 0, θ ∈ [0, π/4]`` every coordinate is monotone along every boundary
piece of ``[x]×[y] ∩ π([ρ]×[θ])``, so the hull is reached at vertices of that region; the symmetries only
add the points where a piece crosses an octant border with an extremum (the axes). One vectorised pass
takes the hull of the region's candidate extreme points in all octants at once (box corners, box edges ∩
circles ``|p| = ρ±``, box edges ∩ rays ``θ±``, rays ∩ circles, circles ∩ axes, feet of the edges on the
axes, the origin), each enclosed by outward interval arithmetic, kept when it may lie in the region and
clipped to ``[p]``. ``σ₄`` (``ρ < 0``) is applied explicitly, and ``γ`` (``θ + 2kπ``) by lifting every
candidate angle to the smallest and the largest representative in ``[θ]`` with a rigorous enclosure of
``2kπ``. Beyond ``|θ| > 2⁵⁰`` (or unbounded) θ is left as is; a box unbounded in both ``[ρ]`` and
``[x]×[y]`` is only clipped by ``|x|, |y| <= ρ <= |(x, y)|``.
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core import arith as A
from digslam.observer.core import rounding as rnd
from digslam.observer.core import trig as T
from digslam.observer.core.boxes import chunked, empty_rows, normalize_empty
from digslam.observer.core.types import Batch, Pair
from digslam.observer.polar.ctc import CtcPolar
from digslam.observer.polar.sep import SepLandmark, SepPiInv, project_contract

_INF = np.inf
_FAR = 2.0**50
_PI = (rnd.PI_DOWN, rnd.PI_UP)
_2PI = (rnd.TWO_PI_DOWN, rnd.TWO_PI_UP)


def _pt(v: np.ndarray) -> Pair:
    return v, v


def _widen(v: np.ndarray, mag: np.ndarray, up: bool) -> np.ndarray:
    """``v`` moved outward past the error of a round-to-nearest sum of terms of magnitude ``<= mag``.

    A sum or product rounded to nearest is off by at most ``mag·2⁻⁵³``; moving by ``mag·2⁻⁵¹`` (itself
    at least two ulps of ``v``) and rounding again still lands on the right side.
    """
    e = mag * 2.0**-51 + 2.0**-1072
    return v + e if up else v - e


def _mul_nonneg(a: Pair, b: Pair) -> Pair:
    """``[a]·[b]`` for ``[a] >= 0`` (a range), outward by :func:`_widen`; empty if either is."""
    with np.errstate(invalid="ignore", over="ignore"):
        p, q, u, v = a[0] * b[0], a[1] * b[0], a[0] * b[1], a[1] * b[1]
        lo, hi = np.minimum(p, q), np.maximum(u, v)
        lo, hi = _widen(lo, np.abs(lo), up=False), _widen(hi, np.abs(hi), up=True)
    lo, hi = np.where(np.isnan(lo), -_INF, lo), np.where(np.isnan(hi), _INF, hi)  # 0·∞: no claim
    return A.set_empty(lo, hi, (a[0] > a[1]) | (b[0] > b[1]))


def _point_angle(x: Pair, y: Pair) -> Pair:
    """Enclosure of one representative of ``arg(x, y)``, continuous across the cut at ``±π``."""
    left = x[1] < 0  # x < 0: use π + atan2(-y, -x), whose branch is smooth around θ = π
    yy = (np.where(left, -y[1], y[0]), np.where(left, -y[0], y[1]))
    xx = (np.where(left, -x[1], x[0]), np.where(left, -x[0], x[1]))
    a_lo, a_hi = T.atan2(yy, xx)
    with np.errstate(invalid="ignore"):
        b_lo = _widen(a_lo + _PI[0], np.abs(a_lo) + 4.0, up=False)
        b_hi = _widen(a_hi + _PI[1], np.abs(a_hi) + 4.0, up=True)
    return np.where(left, b_lo, a_lo), np.where(left, b_hi, a_hi)


def _lift(a: Pair, t: Pair) -> tuple[np.ndarray, np.ndarray]:
    """Smallest and largest representative of ``a + 2kπ`` in ``[t]`` (outward), ``(+inf, -inf)`` if none.

    ``a`` must be finite. ``a + k·2π`` is computed in round-to-nearest and widened by :func:`_widen`
    (exact for ``k = 0``); the three integers nearest each estimate of ``k`` are tried.
    """
    with np.errstate(invalid="ignore", over="ignore"):
        k_lo = np.nan_to_num(np.ceil((t[0] - a[1]) / rnd.TWO_PI_DOWN))
        k_hi = np.nan_to_num(np.floor((t[1] - a[0]) / rnd.TWO_PI_DOWN))
    low, high = np.full_like(a[0], _INF), np.full_like(a[0], -_INF)
    for base, is_low in ((k_lo, True), (k_hi, False)):
        for dk in (-1.0, 0.0, 1.0):
            k = base + dk
            pos = k >= 0
            s_lo = k * np.where(pos, _2PI[0], _2PI[1])
            s_hi = k * np.where(pos, _2PI[1], _2PI[0])
            mag = np.abs(s_lo) + np.abs(a[0]) + np.abs(a[1])
            ll = np.where(k == 0, a[0], _widen(a[0] + s_lo, 2 * mag, up=False))
            lh = np.where(k == 0, a[1], _widen(a[1] + s_hi, 2 * mag, up=True))
            ok = (lh >= t[0]) & (ll <= t[1])
            if is_low:
                low = np.where(ok, np.minimum(low, np.maximum(ll, t[0])), low)
            else:
                high = np.where(ok, np.maximum(high, np.minimum(lh, t[1])), high)
    return low, high


def _stack(parts: list[Pair]) -> Pair:
    return np.concatenate([p[0] for p in parts], axis=1), np.concatenate([p[1] for p in parts], axis=1)


def _in_sector(
    px: Pair, py: Pair, c: Pair, s: Pair, tl: np.ndarray, th: np.ndarray, resolved: np.ndarray
) -> np.ndarray:
    """Whether points ``(N, K)`` may have an angle in ``[θ⁻, θ⁺]`` modulo 2π (cross-product signs).

    The sector is ``{e(θ⁻) × p >= 0} ∩ {p × e(θ⁺) >= 0}`` for an aperture up to π, their union from π
    to 2π; an aperture that may reach 2π (or an unresolved θ) lets every point through.
    """
    mid = lambda p: (0.5 * p[0] + 0.5 * p[1], 0.5 * p[1] - 0.5 * p[0])  # noqa: E731
    with np.errstate(invalid="ignore"):
        (xm, xr), (ym, yr) = mid(px), mid(py)
        (cm, cr), (sm, sr) = mid(c), mid(s)

    def cross_max(k: int, sign: float) -> np.ndarray:
        """Upper bound of ``sign·(c_k·y - s_k·x)`` in midpoint-radius form, with a generous rounding term."""
        a, ar, b, br = cm[:, k : k + 1], cr[:, k : k + 1], sm[:, k : k + 1], sr[:, k : k + 1]
        rad = np.abs(a) * yr + np.abs(ym) * ar + ar * yr + np.abs(b) * xr + np.abs(xm) * br + br * xr
        big = np.abs(a * ym) + np.abs(b * xm) + rad
        return sign * (a * ym - b * xm) + rad + big * 2.0**-48 + 2.0**-1000

    with np.errstate(invalid="ignore", over="ignore"):
        after_lo = cross_max(0, 1.0) >= 0  # e(θ⁻) × p may be >= 0
        before_hi = cross_max(1, -1.0) >= 0  # p × e(θ⁺) may be >= 0
    w = rnd.sub_up(th, tl)[:, None]
    full = (w >= rnd.TWO_PI_DOWN) | ~resolved[:, None]
    return full | np.where(w < rnd.PI_DOWN, after_lo & before_hi, after_lo | before_hi)


def _contract_pos(
    x: Pair, y: Pair, r: Pair, t: Pair, need_theta: bool = True
) -> tuple[Pair, Pair, Pair, Pair]:
    """Minimal contraction on ``ρ >= 0`` (all arrays ``(N,)``); infeasible rows come back empty.

    With ``need_theta=False`` θ is returned as given (only ``x, y, ρ`` are contracted, minimally)."""
    r = A.intersect(r, (np.zeros_like(r[0]), np.full_like(r[1], _INF)))
    x = A.intersect(x, (-r[1], r[1]))
    y = A.intersect(y, (-r[1], r[1]))
    mag = A.sqrt(A.add(A.sqr(x), A.sqr(y)))
    r = A.intersect(r, mag)
    dead = (x[0] > x[1]) | (y[0] > y[1]) | (r[0] > r[1]) | (t[0] > t[1])
    bounded = (
        np.isfinite(x[0]) & np.isfinite(x[1]) & np.isfinite(y[0]) & np.isfinite(y[1]) & np.isfinite(r[1])
    )
    resolved = np.isfinite(t[0]) & np.isfinite(t[1]) & (np.abs(t[0]) <= _FAR) & (np.abs(t[1]) <= _FAR)
    ok = ~dead & bounded
    # placeholder values keep the arithmetic NaN-free on rows that are not computed
    z = np.zeros_like(x[0])
    xl, xh = np.where(ok, x[0], z), np.where(ok, x[1], z)
    yl, yh = np.where(ok, y[0], z), np.where(ok, y[1], z)
    rl, rh = np.where(ok, r[0], z), np.where(ok, r[1], z)
    tl, th = np.where(resolved, t[0], z), np.where(resolved, t[1], z)
    col = lambda *v: np.stack(v, axis=1)  # noqa: E731
    X, Y, R, TT = col(xl, xh), col(yl, yh), col(rl, rh), col(tl, th)  # (N, 2)
    cands: list[tuple[Pair, Pair, Pair, Pair | None]] = []  # (x, y, ρ, angle or None = exact ray angle)
    # box corners
    cx, cy = _pt(col(xl, xl, xh, xh)), _pt(col(yl, yh, yl, yh))
    cands.append((cx, cy, A.sqrt(A.add(A.sqr(cx), A.sqr(cy))), None))
    # edges x = a (and y = b) ∩ circles |p| = ρ±: two points each
    for E, vertical in ((X, True), (Y, False)):
        a = _pt(np.repeat(E, 2, axis=1))  # (a0, a0, a1, a1)
        rr = _pt(np.tile(R, 2))  # (r0, r1, r0, r1)
        h = A.sqrt(A.sub(A.sqr(rr), A.sqr(a)))
        other = _stack([h, A.neg(h)])
        aa, rr2 = _stack([a, a]), _stack([rr, rr])
        cands.append((aa, other, rr2, None) if vertical else (other, aa, rr2, None))
    # rays θ± ∩ edges and ∩ circles (angle exact)
    c, s = T.cos(_pt(TT)), T.sin(_pt(TT))  # (N, 2)
    ang = _pt(np.repeat(TT, 2, axis=1))
    c2, s2 = (np.repeat(c[0], 2, 1), np.repeat(c[1], 2, 1)), (np.repeat(s[0], 2, 1), np.repeat(s[1], 2, 1))
    rb = (np.repeat(rl, 4).reshape(-1, 4), np.repeat(rh, 4).reshape(-1, 4))
    for E, vertical in ((X, True), (Y, False)):
        a = _pt(np.tile(E, 2))
        rho = A.intersect(A.div(a, c2 if vertical else s2), rb)
        other = _mul_nonneg(rho, s2 if vertical else c2)
        cands.append((a, other, rho, ang) if vertical else (other, a, rho, ang))
    rr = _pt(np.tile(R, 2))
    cands.append((_mul_nonneg(rr, c2), _mul_nonneg(rr, s2), rr, ang))
    # circles ∩ axes: (±ρ, 0), (0, ±ρ)
    zero = _pt(np.zeros((xl.shape[0], 4)))
    rr = _pt(np.tile(R, 2))
    cands.append((_stack([rr, A.neg(rr)]), _stack([zero, zero]), _stack([rr, rr]), None))
    cands.append((_stack([zero, zero]), _stack([rr, A.neg(rr)]), _stack([rr, rr]), None))
    # feet of the edges on the axes
    fx, fy = _pt(col(xl, xh, z, z)), _pt(col(z, z, yl, yh))
    cands.append((fx, fy, A.abs_(_stack([_pt(X), _pt(Y)])), None))

    # all candidates side by side: (N, K) enclosures
    ray = np.concatenate([np.full(c[0][0].shape[1], c[3] is not None) for c in cands])
    cx, cy, cr = (_stack([c[i] for c in cands]) for i in range(3))
    bx, by, br = (
        (x[0][:, None], x[1][:, None]),
        (y[0][:, None], y[1][:, None]),
        (r[0][:, None], r[1][:, None]),
    )
    ix, iy, ir = A.intersect(cx, bx), A.intersect(cy, by), A.intersect(cr, br)
    valid = (ix[0] <= ix[1]) & (iy[0] <= iy[1]) & (ir[0] <= ir[1]) & (resolved[:, None] | ~ray)
    if need_theta:  # angle of each off-ray point, lifted into [θ]
        ca = _point_angle((cx[0][:, ~ray], cx[1][:, ~ray]), (cy[0][:, ~ray], cy[1][:, ~ray]))
        ra = _stack([c[3] for c in cands if c[3] is not None])
        ang_lo, ang_hi = np.empty_like(cx[0]), np.empty_like(cx[0])
        ang_lo[:, ~ray], ang_hi[:, ~ray] = ca
        ang_lo[:, ray], ang_hi[:, ray] = ra
        fin = np.isfinite(ang_lo) & np.isfinite(ang_hi) & (ang_lo <= ang_hi)
        valid &= fin
        low, high = _lift(
            (np.where(fin, ang_lo, 0.0), np.where(fin, ang_hi, 0.0)), (tl[:, None], th[:, None])
        )
        low = np.where(resolved[:, None], low, t[0][:, None])
        high = np.where(resolved[:, None], high, t[1][:, None])
        valid &= low <= high
    else:  # only whether each point may lie in the angular sector
        valid[:, ~ray] &= _in_sector((cx[0][:, ~ray], cx[1][:, ~ray]), (cy[0][:, ~ray], cy[1][:, ~ray]),
                                     c, s, tl, th, resolved)  # fmt: skip
        low, high = np.broadcast_to(t[0][:, None], valid.shape), np.broadcast_to(t[1][:, None], valid.shape)
    acc = []
    for v_lo, v_hi in (ix, iy, ir, (low, high)):
        acc.append(np.where(valid, v_lo, _INF).min(axis=1))
        acc.append(np.where(valid, v_hi, -_INF).max(axis=1))
    # the origin, where every θ is consistent
    origin = (x[0] <= 0) & (x[1] >= 0) & (y[0] <= 0) & (y[1] >= 0) & (r[0] <= 0)
    for i, v in enumerate((0.0, 0.0, 0.0)):
        acc[2 * i] = np.where(origin, np.minimum(acc[2 * i], v), acc[2 * i])
        acc[2 * i + 1] = np.where(origin, np.maximum(acc[2 * i + 1], v), acc[2 * i + 1])
    acc[6] = np.where(origin, t[0], acc[6])
    acc[7] = np.where(origin, t[1], acc[7])
    # rows not computed: clipped input (unbounded) or empty
    out = []
    for i, v in enumerate((x, y, r, t)):
        lo = np.where(ok, acc[2 * i], v[0])
        hi = np.where(ok, acc[2 * i + 1], v[1])
        lo, hi = np.where(dead, _INF, lo), np.where(dead, -_INF, hi)
        out.append(A.set_empty(lo, hi, lo > hi))
    return out[0], out[1], out[2], out[3]


def contract_polar(lo: np.ndarray, hi: np.ndarray, need_theta: bool = True) -> Batch:
    """``⟦Π ∩ [p]⟧`` for a batch of boxes ``(x, y, ρ, θ)`` of shape ``(N, 4)`` (Eq. 3.34).

    With ``need_theta=False`` the θ column is only intersected with what ``σ₄`` implies (cheaper: the
    separators on ``(x, y)`` need the ``x, y`` faces only)."""
    n = lo.shape[0]
    x, y, r, t = ((lo[:, i], hi[:, i]) for i in range(4))
    # σ₄ (Eq. 3.32): (x, y, ρ, θ) ∈ Π ⇔ (x, y, -ρ, θ + π) ∈ Π; the rows with ρ < 0 go through it
    neg = np.flatnonzero(r[0] < 0)
    pi = (np.full(neg.size, _PI[0]), np.full(neg.size, _PI[1]))
    sel = lambda p, idx: (p[0][idx], p[1][idx])  # noqa: E731
    cat = lambda p, q: (np.concatenate([p[0], q[0]]), np.concatenate([p[1], q[1]]))  # noqa: E731
    xs, ys = cat(x, sel(x, neg)), cat(y, sel(y, neg))
    rs, ts = cat(r, A.neg(sel(r, neg))), cat(t, A.add(sel(t, neg), pi))
    cx, cy, cr, ct = _contract_pos(xs, ys, rs, ts, need_theta)
    res_lo = np.stack([cx[0][:n], cy[0][:n], cr[0][:n], ct[0][:n]], axis=1)
    res_hi = np.stack([cx[1][:n], cy[1][:n], cr[1][:n], ct[1][:n]], axis=1)
    if neg.size:
        nr = A.neg((cr[0][n:], cr[1][n:]))
        nt = A.intersect(A.sub((ct[0][n:], ct[1][n:]), pi), sel(t, neg))
        nlo = np.stack([cx[0][n:], cy[0][n:], nr[0], nt[0]], axis=1)
        nhi = np.stack([cx[1][n:], cy[1][n:], nr[1], nt[1]], axis=1)
        nlo, nhi = normalize_empty(nlo, nhi)
        plo, phi = normalize_empty(res_lo[neg], res_hi[neg])
        res_lo[neg], res_hi[neg] = np.minimum(plo, nlo), np.maximum(phi, nhi)
    return normalize_empty(res_lo, res_hi)


class CtcPolarNumpy(CtcPolar):
    """:class:`CtcPolar` computed by :func:`contract_polar` (the compiled kernel's oracle)."""

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        if lo.ndim != 2 or lo.shape[1] != 4:
            raise ValueError(f"CtcPolar: boxes must have shape (N, 4) = (x, y, ρ, θ), got {lo.shape}")
        return chunked(lambda a, b: contract_polar(a, b, self.need_theta), lo, hi)


def _distance_range(lo: np.ndarray, hi: np.ndarray) -> Batch:
    """Safe bounds of ``|p|`` over each ``(x, y)`` box (relative margin far above rounding)."""
    mig = np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(np.abs(lo), np.abs(hi)))
    mag = np.maximum(np.abs(lo), np.abs(hi))
    with np.errstate(over="ignore", invalid="ignore"):
        dmin = np.sqrt((mig * mig).sum(axis=1)) * (1 - 2.0**-40)
        dmax = np.sqrt((mag * mag).sum(axis=1)) * (1 + 2.0**-40) + 2.0**-1000
    return dmin, np.where(np.isnan(dmax), _INF, dmax)


def _cone_sides(sep: SepPiInv, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Boxes certainly inside the open cone ``θ⁻ < arg p < θ⁺``, and certainly outside the closed one.

    Each corner is tested against the two half-planes ``e(θ⁻) × p > 0`` and ``p × e(θ⁺) > 0`` with a
    margin far above the rounding of the cross products (``cos``/``sin`` to a few ulps).
    """
    t0, t1 = sep.theta
    cs = (np.cos(t0), np.sin(t0), np.cos(t1), np.sin(t1))
    xs = np.stack([lo[:, 0], lo[:, 0], hi[:, 0], hi[:, 0]], axis=1)
    ys = np.stack([lo[:, 1], hi[:, 1], lo[:, 1], hi[:, 1]], axis=1)
    with np.errstate(invalid="ignore", over="ignore"):
        margin = (np.abs(xs) + np.abs(ys)) * 2.0**-44 + 2.0**-1000
        a = cs[0] * ys - cs[1] * xs  # e(θ⁻) × p
        b = cs[3] * xs - cs[2] * ys  # p × e(θ⁺)
        inside = ((a > margin) & (b > margin)).all(axis=1)
        outside = (a < -margin).all(axis=1) | (b < -margin).all(axis=1)
    finite = np.isfinite(lo).all(axis=1) & np.isfinite(hi).all(axis=1)
    return inside & finite, outside & finite


def sep_pie_numpy(sep: SepPiInv, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
    """``sep.separate(lo, hi)`` through :func:`project_contract` and :class:`CtcPolarNumpy` (Theorem 3.2):
    the pie ``sep.pie`` and its complement ``sep.ybar`` projected on the ``(x, y)`` boxes."""
    cols = np.array([0, 1])
    dmin, dmax = _distance_range(lo, hi)
    ok = ~empty_rows(lo, hi)
    # a piece [r0, r1]×[θ] can only meet boxes whose distance range meets [r0, r1]
    rl, rh = np.r_[sep.pie[0][:, 0], sep.ybar[0][:, 0]], np.r_[sep.pie[1][:, 0], sep.ybar[1][:, 0]]
    live = ok[:, None] & (dmax[:, None] >= rl[None]) & (dmin[:, None] <= rh[None])
    if sep.convex:  # aperture < π: the cone is convex, decide it from the corners
        inside, outside = _cone_sides(sep, lo, hi)
        live[:, 0] &= ~outside  # the pie misses a box outside the cone
        live[:, 1] &= ~inside  # the rest of the turn misses a box inside the open cone
    ylo, yhi = np.r_[sep.pie[0], sep.ybar[0]], np.r_[sep.pie[1], sep.ybar[1]]
    groups = np.r_[0, np.ones(len(sep.ybar[0]), dtype=np.int64)]
    ctc = CtcPolarNumpy(need_theta=False)
    xout, xin = project_contract(ctc, cols, lo, hi, ylo, yhi, live=live, groups=groups, n_groups=2)
    return xin, xout


def _g(m: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> Batch:
    """``g_m(x) = m - x`` on a batch (Eq. 3.55), rounded outward; empty rows stay empty."""
    e = empty_rows(lo, hi)[:, None]
    glo, ghi = rnd.sub_down(m, hi), rnd.sub_up(m, lo)
    return np.where(e, _INF, glo), np.where(e, -_INF, ghi)


def sep_landmark_numpy(sep: SepLandmark, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
    """``sep.separate(lo, hi)`` as ``g_m ∘ S_{π⁻¹}`` with :func:`sep_pie_numpy` (Eq. 3.54-3.56)."""
    ulo, uhi = _g(sep.m, lo, hi)
    res = []
    for b in sep_pie_numpy(sep.pie, ulo, uhi):
        xlo, xhi = _g(sep.m, *b)
        res.append(normalize_empty(np.maximum(xlo, lo), np.minimum(xhi, hi)))
    return res[0], res[1]
