"""Compiled kernels: numba's ``njit`` and scalar outward-rounded arithmetic for per-box loops.

The numpy kernels of :mod:`.rounding` and :mod:`.arith` pay a fixed cost per call, which dominates
small batches (a coarse paving, one observer update). Kernels compiled with :func:`njit` loop over
boxes in machine code instead; this module gives them the same guarantee as :mod:`.rounding`:

* ``+ - * /`` and ``sqrt`` are correctly rounded by IEEE 754 (round-to-nearest), so the exact result
  lies within half an ulp; one :func:`dn` / :func:`up` step outward bounds it. Sums and differences
  are tight: TwoSum recovers the exact error and the bound moves only when the rounded sum is on the
  wrong side (exact sums stay exact). ``fastmath`` is off, so nothing is reassociated; an FMA
  contraction of ``x ± φ|x|`` would round the same exact value once and still give the neighbour.
* Transcendental functions come from libm and are widened by :data:`~.rounding.LIBM_ULPS` ulps
  (:func:`wdn`, :func:`wup`).

The empty interval is ``[+inf, -inf]``, as in :mod:`.arith`; an operand with an infinite point
(``[+inf, +inf]``, ``[-inf, -inf]``) holds no real and gives the empty interval too (:func:`nil`).
Every kernel here is checked against exact rational arithmetic in ``tests/test_jit.py``.

Example:
    >>> lo, hi = imul(-1.0, 2.0, 0.1, 0.3)
    >>> lo < -0.3 and 0.6 < hi < 0.6 + 1e-15
    True
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

from digslam.observer.core.rounding import LIBM_ULPS

__all__ = ["LIBM_ULPS", "njit", "dn", "up", "wdn", "wup", "add_dn", "add_up", "sub_dn", "sub_up",
           "mul_dn", "mul_up", "div_dn", "div_up", "sqrt_dn", "sqrt_up", "nil", "imul", "isqr",
           "idiv", "isqrt"]  # fmt: skip

_INF = math.inf


def njit(*args: Any, **kwargs: Any) -> Any:
    """``numba.njit`` with this project's settings: cached on disk, no fastmath, GIL released."""
    kwargs.setdefault("cache", True)
    kwargs.setdefault("nogil", True)
    kwargs.setdefault("fastmath", False)
    return numba.njit(*args, **kwargs)


#: Rump, Zimmermann, Boldo & Melquiond (2009), as in :mod:`.rounding`: for finite ``|c| >= 2⁻⁹⁶⁰``,
#: ``c ± φ|c|`` rounds to the successor (predecessor) of ``c`` (their ``+ η`` is below half an ulp of
#: ``φ|c|`` there, and leaving it out avoids a subnormal operand); elsewhere ``nextafter``, which costs
#: several times more in compiled loops.
_PHI, _NEAR = 2.0**-53 * (1.0 + 2.0**-52), 2.0**-960


@njit(inline="always")
def dn(x: float) -> float:
    """The float below ``x``: a lower bound of any real whose round-to-nearest is ``x``."""
    a = abs(x)
    return x - a * _PHI if _NEAR <= a < _INF else np.nextafter(x, -_INF)


@njit(inline="always")
def up(x: float) -> float:
    """The float above ``x``: an upper bound of any real whose round-to-nearest is ``x``."""
    a = abs(x)
    return x + a * _PHI if _NEAR <= a < _INF else np.nextafter(x, _INF)


@njit(inline="always")
def wdn(x: float) -> float:
    """``x`` moved down by ``LIBM_ULPS`` ulps: a lower bound of a libm result's exact value."""
    for _ in range(LIBM_ULPS):
        x = dn(x)
    return x


@njit(inline="always")
def wup(x: float) -> float:
    """``x`` moved up by ``LIBM_ULPS`` ulps."""
    for _ in range(LIBM_ULPS):
        x = up(x)
    return x


@njit(inline="always")
def _sum_err(a: float, b: float, s: float) -> float:
    """TwoSum (Knuth): the exact ``a + b - s`` (NaN when an operand is infinite)."""
    t = s - a
    return (a - (s - t)) + (b - t)


@njit(inline="always")
def add_dn(a: float, b: float) -> float:
    """Lower bound of ``a + b``: exact sums stay exact (TwoSum), others step one ulp down."""
    s = a + b
    return s if _sum_err(a, b, s) >= 0.0 else dn(s)


@njit(inline="always")
def add_up(a: float, b: float) -> float:
    """Upper bound of ``a + b``."""
    s = a + b
    return s if _sum_err(a, b, s) <= 0.0 else up(s)


@njit(inline="always")
def sub_dn(a: float, b: float) -> float:
    """Lower bound of ``a - b``."""
    return add_dn(a, -b)


@njit(inline="always")
def sub_up(a: float, b: float) -> float:
    """Upper bound of ``a - b``."""
    return add_up(a, -b)


@njit(inline="always")
def mul_dn(a: float, b: float) -> float:
    """Lower bound of ``a * b``, with ``0 * inf = 0`` (interval convention)."""
    if a == 0.0 or b == 0.0:
        return 0.0
    return dn(a * b)


@njit(inline="always")
def mul_up(a: float, b: float) -> float:
    """Upper bound of ``a * b``, with ``0 * inf = 0``."""
    if a == 0.0 or b == 0.0:
        return 0.0
    return up(a * b)


@njit(inline="always")
def div_dn(a: float, b: float) -> float:
    """Lower bound of ``a / b`` for ``b != 0``."""
    return dn(a / b)


@njit(inline="always")
def div_up(a: float, b: float) -> float:
    """Upper bound of ``a / b`` for ``b != 0``."""
    return up(a / b)


@njit(inline="always")
def sqrt_dn(a: float) -> float:
    """Lower bound of ``sqrt(a)`` for ``a >= 0`` (never below 0)."""
    r = math.sqrt(a)
    return r if r == 0.0 else dn(r)


@njit(inline="always")
def sqrt_up(a: float) -> float:
    """Upper bound of ``sqrt(a)`` for ``a >= 0`` (exact for 0)."""
    r = math.sqrt(a)
    return r if r == 0.0 else up(r)


@njit(inline="always")
def nil(al: float, ah: float) -> bool:
    """Whether ``[al, ah]`` holds no real: empty (``al > ah``) or an infinite point (``al = +∞`` or
    ``ah = -∞``; IEEE 1788: ``±∞`` is no real number, so an operation with it is empty)."""
    return al > ah or al == _INF or ah == -_INF


@njit(inline="always")
def imul(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """``[a] * [b]`` (Eq. 2.6); empty in, empty out."""
    if nil(al, ah) or nil(bl, bh):
        return _INF, -_INF
    lo = min(min(mul_dn(al, bl), mul_dn(al, bh)), min(mul_dn(ah, bl), mul_dn(ah, bh)))
    hi = max(max(mul_up(al, bl), mul_up(al, bh)), max(mul_up(ah, bl), mul_up(ah, bh)))
    return lo, hi


@njit(inline="always")
def isqr(al: float, ah: float) -> tuple[float, float]:
    """``[a]²``, tighter than ``[a] * [a]`` when ``0 ∈ [a]``."""
    if nil(al, ah):
        return _INF, -_INF
    if al >= 0.0:
        return mul_dn(al, al), mul_up(ah, ah)
    if ah <= 0.0:
        return mul_dn(ah, ah), mul_up(al, al)
    m = max(-al, ah)
    return 0.0, mul_up(m, m)


@njit(inline="always")
def idiv(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """``[a] / [b]`` (Eq. 2.7); the whole line when ``0 ∈ [b]`` (a hull, never wrong)."""
    if nil(al, ah) or nil(bl, bh):
        return _INF, -_INF
    if bl <= 0.0 <= bh:
        if bl == 0.0 and bh == 0.0:
            return _INF, -_INF
        return -_INF, _INF
    lo = min(min(div_dn(al, bl), div_dn(al, bh)), min(div_dn(ah, bl), div_dn(ah, bh)))
    hi = max(max(div_up(al, bl), div_up(al, bh)), max(div_up(ah, bl), div_up(ah, bh)))
    return lo, hi


@njit(inline="always")
def isqrt(al: float, ah: float) -> tuple[float, float]:
    """``sqrt([a] ∩ [0, ∞))``; empty when ``[a] < 0``."""
    if nil(al, ah) or ah < 0.0:
        return _INF, -_INF
    return sqrt_dn(max(al, 0.0)), sqrt_up(ah)
