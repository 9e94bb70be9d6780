"""Trigonometric interval kernels on batches: sin, cos, tan, asin, acos, atan, atan2.

Same conventions as :mod:`.arith`. Extrema of periodic functions are located with a rigorous
enclosure of ``x / (π/2)``: an extremum is assumed inside ``[x]`` whenever it may be, so a result is
never too narrow. Past ``|x| > 2⁵⁰`` the quadrant cannot be resolved and the result is ``[-1, 1]``.
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.arith import empty_mask, set_empty
from digslam.observer.core.types import Pair

_INF = np.inf
_FAR = 2.0**50


def _quadrants(lo: np.ndarray, hi: np.ndarray) -> Pair:
    """Outward enclosure of ``[lo, hi] / (π/2)``."""
    with np.errstate(invalid="ignore", over="ignore"):
        tlo = rnd.div_down(lo, np.where(lo >= 0, rnd.HALF_PI_UP, rnd.HALF_PI_DOWN))
        thi = rnd.div_up(hi, np.where(hi >= 0, rnd.HALF_PI_DOWN, rnd.HALF_PI_UP))
    return tlo, thi


def _has_integer(tlo: np.ndarray, thi: np.ndarray, residue: int, modulus: int) -> np.ndarray:
    """Whether some integer ``m ≡ residue (mod modulus)`` lies in ``[tlo, thi]`` (finite bounds)."""
    with np.errstate(invalid="ignore"):
        c = np.ceil(tlo)
        m = c + np.mod(residue - c, modulus)
        return m <= thi


def _unresolved(lo: np.ndarray, hi: np.ndarray, tlo: np.ndarray, thi: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore", over="ignore"):
        return ~(np.abs(tlo) <= _FAR) | ~(np.abs(thi) <= _FAR) | ~(hi - lo < rnd.TWO_PI_DOWN)


def _endpoint_bounds(fa: np.ndarray, fb: np.ndarray, exact_a: np.ndarray, exact_b: np.ndarray) -> Pair:
    da = np.where(exact_a, fa, rnd.widen_down(fa))
    db = np.where(exact_b, fb, rnd.widen_down(fb))
    ua = np.where(exact_a, fa, rnd.widen_up(fa))
    ub = np.where(exact_b, fb, rnd.widen_up(fb))
    return np.minimum(da, db), np.maximum(ua, ub)


def _periodic(a: Pair, fn: np.ufunc, max_res: int, min_res: int, exact_at_zero: bool) -> Pair:
    """sin (max at t≡1, min at t≡3 mod 4) or cos (max at t≡0, min at t≡2 mod 4)."""
    lo, hi = a
    e = empty_mask(lo, hi)
    tlo, thi = _quadrants(lo, hi)
    wide = _unresolved(lo, hi, tlo, thi)
    with np.errstate(invalid="ignore"):
        rlo, rhi = _endpoint_bounds(fn(lo), fn(hi), (lo == 0) & exact_at_zero, (hi == 0) & exact_at_zero)
    rlo = np.where(wide | _has_integer(tlo, thi, min_res, 4), -1.0, np.maximum(rlo, -1.0))
    rhi = np.where(wide | _has_integer(tlo, thi, max_res, 4), 1.0, np.minimum(rhi, 1.0))
    return set_empty(rlo + 0.0, rhi + 0.0, e)


def sin(a: Pair) -> Pair:
    """``sin([a])``."""
    return _periodic(a, np.sin, 1, 3, exact_at_zero=True)


def cos(a: Pair) -> Pair:
    """``cos([a])`` (``cos(0) = 1`` is exact and stays so)."""
    return _periodic(a, np.cos, 0, 2, exact_at_zero=True)


def tan(a: Pair) -> Pair:
    """``tan([a])``: the whole line as soon as a pole ``π/2 + kπ`` may lie in ``[a]``."""
    lo, hi = a
    e = empty_mask(lo, hi)
    tlo, thi = _quadrants(lo, hi)
    tlo_u, thi_d = _quadrants(hi, lo)[::-1]  # the other ends: [lo/(π/2)] is [tlo, tlo_u]
    with np.errstate(invalid="ignore"):
        tan_lo, tan_hi = np.tan(lo), np.tan(hi)
        # a pole only possibly at an end (within the enclosure of lo/(π/2)): a float is never a pole, and
        # next to a pole |tan| is huge with the sign of the side it lies on (libm's error is a few ulps)
        mid = _has_integer(np.nextafter(tlo_u, _INF), np.nextafter(thi_d, -_INF), 1, 2)  # surely inside
        near_lo = _has_integer(tlo, np.minimum(tlo_u, thi), 1, 2)
        near_hi = _has_integer(np.maximum(thi_d, tlo), thi, 1, 2)
        lone = (near_lo ^ near_hi) & ~mid  # one candidate pole, at one end only
        clear = lone & ((near_lo & (tan_lo < 0)) | (near_hi & (tan_hi > 0)))
    pole = _unresolved(lo, hi, tlo, thi) | (_has_integer(tlo, thi, 1, 2) & ~clear)
    with np.errstate(invalid="ignore"):
        rlo = np.where(lo == 0, 0.0, rnd.widen_down(tan_lo))
        rhi = np.where(hi == 0, 0.0, rnd.widen_up(tan_hi))
    return set_empty(np.where(pole, -_INF, rlo) + 0.0, np.where(pole, _INF, rhi) + 0.0, e)


def atan(a: Pair) -> Pair:
    """``atan([a]) ⊂ [-π/2, π/2]``."""
    lo, hi = a
    e = empty_mask(lo, hi)
    rlo = np.where(lo == 0, 0.0, np.maximum(rnd.widen_down(np.arctan(lo)), -rnd.HALF_PI_UP))
    rhi = np.where(hi == 0, 0.0, np.minimum(rnd.widen_up(np.arctan(hi)), rnd.HALF_PI_UP))
    return set_empty(rlo + 0.0, rhi + 0.0, e)


def asin(a: Pair) -> Pair:
    """``asin([a] ∩ [-1, 1])``."""
    lo, hi = np.maximum(a[0], -1.0), np.minimum(a[1], 1.0)
    e = lo > hi
    with np.errstate(invalid="ignore"):
        rlo = np.where(lo == 0, 0.0, np.maximum(rnd.widen_down(np.arcsin(lo)), -rnd.HALF_PI_UP))
        rhi = np.where(hi == 0, 0.0, np.minimum(rnd.widen_up(np.arcsin(hi)), rnd.HALF_PI_UP))
    return set_empty(rlo + 0.0, rhi + 0.0, e)


def acos(a: Pair) -> Pair:
    """``acos([a] ∩ [-1, 1]) ⊂ [0, π]`` (decreasing)."""
    lo, hi = np.maximum(a[0], -1.0), np.minimum(a[1], 1.0)
    e = lo > hi
    with np.errstate(invalid="ignore"):
        rlo = np.where(hi == 1, 0.0, np.maximum(rnd.widen_down(np.arccos(hi)), 0.0))
        rhi = np.minimum(rnd.widen_up(np.arccos(lo)), rnd.PI_UP)
    return set_empty(rlo + 0.0, rhi + 0.0, e)


def _corner_angle(y: np.ndarray, x: np.ndarray) -> Pair:
    """Outward bounds of ``atan2(y, x)`` at a point, exact on the axes; NaN at the origin."""
    with np.errstate(invalid="ignore"):
        t = np.arctan2(y, x)
        d, u = rnd.widen_down(t), rnd.widen_up(t)
    on_x = y == 0
    on_y = x == 0
    d = np.where(on_x & (x > 0), 0.0, np.where(on_x & (x < 0), rnd.PI_DOWN, d))
    u = np.where(on_x & (x > 0), 0.0, np.where(on_x & (x < 0), rnd.PI_UP, u))
    d = np.where(on_y & (y > 0), rnd.HALF_PI_DOWN, np.where(on_y & (y < 0), -rnd.HALF_PI_UP, d))
    u = np.where(on_y & (y > 0), rnd.HALF_PI_UP, np.where(on_y & (y < 0), -rnd.HALF_PI_DOWN, u))
    origin = on_x & on_y
    return np.where(origin, np.nan, d), np.where(origin, np.nan, u)


def atan2(y: Pair, x: Pair) -> Pair:
    """``atan2([y], [x])``: the hull of the angles in ``(-π, π]`` of the points of ``[y]×[x]``
    except the origin (IEEE 1788; ``atan2([0,0],[0,0]) = ∅``).

    Off the cut ``{x < 0, y = 0}`` the angle has no critical point and is monotone on every edge,
    so the corners give its range. A box that meets the cut from below reaches both ``-π`` and
    ``π``; the result is then ``[-π, π]``.
    """
    yl, yh, xl, xh = (v + 0.0 for v in np.broadcast_arrays(*y, *x))  # -0.0 -> +0.0
    e = empty_mask(yl, yh) | empty_mask(xl, xh) | ((yl == 0) & (yh == 0) & (xl == 0) & (xh == 0))
    lo, hi = np.full(yl.shape, np.inf), np.full(yl.shape, -np.inf)
    for yc in (yl, yh):
        for xc in (xl, xh):
            d, u = _corner_angle(yc, xc)
            lo, hi = np.fmin(lo, d), np.fmax(hi, u)
    full = (xl < 0) & (yl < 0) & (yh >= 0)
    lo = np.where(full, -rnd.PI_UP, np.maximum(lo, -rnd.PI_UP))
    hi = np.where(full, rnd.PI_UP, np.minimum(hi, rnd.PI_UP))
    return set_empty(lo, hi, e)


__all__ = [
    "acos",
    "asin",
    "atan",
    "atan2",
    "cos",
    "sin",
    "tan",
]
