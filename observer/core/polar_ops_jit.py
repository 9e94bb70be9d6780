"""Scalar kernels of the compiled polar contractor (:mod:`.polar_jit`): angles, sector sides, products.

Each bound is stepped outward with :mod:`.scalar_jit` (``dn``/``up`` for ``+ - * /``, ``wdn``/``wup`` for
libm's ``cos``, ``sin``, ``atan2``); the sign tests of :func:`cross` carry an explicit error term.

Example:
    >>> t = np.pi / 3
    >>> cs = cos_sin(0.0, t, np.zeros(8))   # [cos 0], [sin 0] exact; [cos t], [sin t] enclose libm's values
    >>> cs[:4].tolist(), bool(cs[4] < np.cos(t) < cs[5] and cs[6] < np.sin(t) < cs[7])
    ([1.0, 1.0, 0.0, 0.0], True)
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.rounding import (
    HALF_PI_DOWN,
    HALF_PI_UP,
    PI_DOWN,
    PI_UP,
    TWO_PI_DOWN,
    TWO_PI_UP,
)
from digslam.observer.core.scalar_jit import (
    add_dn,
    add_up,
    dn,
    mul_dn,
    mul_up,
    njit,
    sqrt_dn,
    sqrt_up,
    sub_dn,
    sub_up,
    up,
    wdn,
    wup,
)

__all__ = ["cos_sin", "point_angle", "lift", "cross", "pmul", "pdiv", "disk_hull", "outside_hull"]

_INF = math.inf


@njit
def _cos_sin(t: float) -> tuple[float, float, float, float]:
    """Enclosures ``cos t ∈ [c⁻, c⁺]``, ``sin t ∈ [s⁻, s⁺]`` of a point angle (exact at 0)."""
    if t == 0.0:
        return 1.0, 1.0, 0.0, 0.0
    c, s = math.cos(t), math.sin(t)
    return max(wdn(c), -1.0), min(wup(c), 1.0), max(wdn(s), -1.0), min(wup(s), 1.0)


@njit
def cos_sin(tl: float, th: float, cs: np.ndarray) -> np.ndarray:
    """Fill ``cs`` with ``(c⁻(θ⁻), c⁺(θ⁻), s⁻(θ⁻), s⁺(θ⁻), c⁻(θ⁺), c⁺(θ⁺), s⁻(θ⁺), s⁺(θ⁺))``."""
    if math.isfinite(tl) and math.isfinite(th):
        cs[0], cs[1], cs[2], cs[3] = _cos_sin(tl)
        cs[4], cs[5], cs[6], cs[7] = _cos_sin(th)
    return cs


@njit
def _corner(y: float, x: float) -> tuple[float, float]:
    """Outward bounds of ``atan2(y, x)`` at a point off the origin, exact on the axes."""
    if y == 0.0:
        return (0.0, 0.0) if x > 0 else (PI_DOWN, PI_UP)
    if x == 0.0:
        return (HALF_PI_DOWN, HALF_PI_UP) if y > 0 else (-HALF_PI_UP, -HALF_PI_DOWN)
    t = math.atan2(y, x)
    return wdn(t), wup(t)


@njit
def _atan2(yl: float, yh: float, xl: float, xh: float) -> tuple[float, float]:
    """Hull of the angles in ``(-π, π]`` of the box minus the origin (``trig.atan2``); empty at the origin."""
    yl, yh, xl, xh = yl + 0.0, yh + 0.0, xl + 0.0, xh + 0.0
    if xl < 0 and yl < 0 <= yh:
        return -PI_UP, PI_UP
    lo, hi = _INF, -_INF
    for yc in (yl, yh):
        for xc in (xl, xh):
            if yc != 0.0 or xc != 0.0:
                d, u = _corner(yc, xc)
                lo, hi = min(lo, d), max(hi, u)
    return max(lo, -PI_UP), min(hi, PI_UP)


@njit
def point_angle(xl: float, xh: float, yl: float, yh: float) -> tuple[float, float]:
    """One representative of ``arg`` over the box, continuous across the cut (as the numpy oracle
    ``tests/polar_oracle.py`` computes it)."""
    if xh < 0:  # π + atan2(-y, -x): smooth around θ = π
        a, b = _atan2(-yh, -yl, -xh, -xl)
        return add_dn(a, PI_DOWN), add_up(b, PI_UP)
    return _atan2(yl, yh, xl, xh)


@njit
def _widen(v: float, mag: float, upward: bool) -> float:
    """``v`` moved past the error of a round-to-nearest sum of terms of magnitude ``<= mag``."""
    e = mag * 2.0**-51 + 2.0**-1072
    return up(v + e) if upward else dn(v - e)


@njit
def lift(al: float, ah: float, tl: float, th: float) -> tuple[float, float]:
    """Smallest and largest representative of ``[a] + 2kπ`` in ``[θ]`` (as the numpy oracle
    ``tests/polar_oracle.py`` lifts it)."""
    low, high = _INF, -_INF
    for is_low in (True, False):
        base = math.ceil((tl - ah) / TWO_PI_DOWN) if is_low else math.floor((th - al) / TWO_PI_DOWN)
        for dk in (-1.0, 0.0, 1.0):
            k = base + dk
            if k == 0:
                ll, lh = al, ah
            else:
                s_lo = k * (TWO_PI_DOWN if k >= 0 else TWO_PI_UP)
                s_hi = k * (TWO_PI_UP if k >= 0 else TWO_PI_DOWN)
                mag = 2.0 * (abs(s_lo) + abs(al) + abs(ah))
                ll, lh = _widen(al + s_lo, mag, False), _widen(ah + s_hi, mag, True)
            if lh >= tl and ll <= th:
                if is_low:
                    low = min(low, max(ll, tl))
                else:
                    high = max(high, min(lh, th))
    return low, high


@njit
def cross(c0: float, c1: float, s0: float, s1: float, xl: float, xh: float, yl: float, yh: float,
           upper: bool) -> float:  # fmt: skip
    """A value with the sign of an upper (or lower) bound of ``c·y - s·x`` over the box (for sign tests).

    The four products of each term are taken in round-to-nearest; each is off by at most ``|p|·2⁻⁵³``
    (``2⁻¹⁰⁷⁵`` if subnormal) and so is the difference, so ``err = (|a| + |b|)·2⁻⁵¹ + 2⁻¹⁰⁶⁰`` covers
    them all and ``a - b + err`` is an upper bound before its own rounding. Round-to-nearest is monotone
    and keeps 0, so the rounded sum is ``>= 0`` (``> 0``) whenever the exact bound is: the sign is safe.
    """
    p, q, u, v = c0 * yl, c0 * yh, c1 * yl, c1 * yh
    e, f, g, h = s0 * xl, s0 * xh, s1 * xl, s1 * xh
    if upper:
        a, b = max(max(p, q), max(u, v)), min(min(e, f), min(g, h))
    else:
        a, b = min(min(p, q), min(u, v)), max(max(e, f), max(g, h))
    err = (abs(a) + abs(b)) * 2.0**-51 + 2.0**-1060
    return a - b + err if upper else a - b - err


@njit
def pmul(a0: float, a1: float, b0: float, b1: float) -> tuple[float, float]:
    """``[a]·[b]`` for finite bounds: the round-to-nearest products' extremes stepped out by one ulp
    (each product is within half an ulp, :func:`~.scalar_jit.dn` is monotone); exact when ``[b] = 0``."""
    if b0 == 0.0 and b1 == 0.0:
        return 0.0, 0.0
    p, q, u, v = a0 * b0, a0 * b1, a1 * b0, a1 * b1
    return dn(min(min(p, q), min(u, v))), up(max(max(p, q), max(u, v)))


@njit
def pdiv(a: float, c0: float, c1: float) -> tuple[float, float]:
    """``a / [c]`` for a finite point ``a`` (the whole line when ``0 ∈ [c]``, empty when ``[c] = 0``),
    stepped out by one ulp."""
    if c0 == 0.0 and c1 == 0.0:
        return _INF, -_INF
    if c0 <= 0.0 <= c1:
        return -_INF, _INF
    p, q = a / c0, a / c1
    return dn(min(p, q)), up(max(p, q))


@njit
def _mig_mag(lo: float, hi: float) -> tuple[float, float]:
    """Smallest and largest ``|v|`` over ``[lo, hi]``."""
    return (0.0 if lo <= 0 <= hi else min(abs(lo), abs(hi))), max(abs(lo), abs(hi))


@njit
def disk_hull(xl: float, xh: float, yl: float, yh: float, r: float) -> tuple[float, float, float, float]:
    """Hull of the box ∩ the disk ``|p| <= r`` (the full-turn piece ``[0, r]×[θ, θ + 2π]``): the disk is
    convex, so ``[x]`` projects onto ``x² <= r² - mig([y])²`` exactly (and ``y`` likewise)."""
    r2 = mul_up(r, r)
    gx, gy = _mig_mag(xl, xh)[0], _mig_mag(yl, yh)[0]
    cx, cy = sub_up(r2, mul_dn(gy, gy)), sub_up(r2, mul_dn(gx, gx))
    if cx < 0 or cy < 0:
        return _INF, -_INF, _INF, -_INF
    s, t = sqrt_up(cx), sqrt_up(cy)
    xl, xh, yl, yh = max(xl, -s), min(xh, s), max(yl, -t), min(yh, t)
    if xl > xh or yl > yh:
        return _INF, -_INF, _INF, -_INF
    return xl, xh, yl, yh


@njit
def _hole(lo: float, hi: float, c: float) -> tuple[float, float]:
    """Hull of ``[lo, hi]`` minus the open ``(-s, s)``, ``s <= sqrt(c)`` (``c`` a lower bound of ``s²``)."""
    if c <= 0:
        return lo, hi
    s = sqrt_dn(c)
    a_hi, b_lo = min(hi, -s), max(lo, s)
    if lo <= a_hi:
        return lo, (hi if b_lo <= hi else a_hi)
    return (b_lo, hi) if b_lo <= hi else (_INF, -_INF)


@njit
def outside_hull(xl: float, xh: float, yl: float, yh: float, r: float) -> tuple[float, float, float, float]:
    """Hull of the box minus the open disk ``|p| < r`` (the full-turn piece ``[r, ∞]×[θ, θ + 2π]``): ``[x]``
    projects onto ``x² >= r² - mag([y])²`` exactly (and ``y`` likewise)."""
    r2 = mul_dn(r, r)
    mx, my = _mig_mag(xl, xh)[1], _mig_mag(yl, yh)[1]
    ul, uh = _hole(xl, xh, sub_dn(r2, mul_up(my, my)))
    vl, vh = _hole(yl, yh, sub_dn(r2, mul_up(mx, mx)))
    if ul > uh or vl > vh:
        return _INF, -_INF, _INF, -_INF
    return ul, uh, vl, vh
