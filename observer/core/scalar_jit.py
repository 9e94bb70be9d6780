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

Every scalar interval primitive of the project's kernels lives here: :func:`meet`, :func:`iadd`,
:func:`isub`, :func:`imul` (and its one-step bounds for finite intervals, :func:`imul_lo`, :func:`imul_hi`),
:func:`idiv` (the hull), :func:`ixdiv` (set-based), :func:`isqr`, :func:`isqrt`, :func:`iexp`, :func:`ilog`,
:func:`ipown`, :func:`iabs`. The empty interval is ``[+inf, -inf]``, as in
:mod:`.arith`; an operand with an infinite point (``[+inf, +inf]``, ``[-inf, -inf]``) holds no real and gives
the empty interval too (:func:`nil`). Every kernel here is checked against exact rational arithmetic in
``tests/observer/core/test_scalar_jit.py``.

Example:
    >>> lo, hi = imul(-1.0, 2.0, 0.1, 0.3)
    >>> lo < -0.3 and 0.6 < hi < 0.6 + 1e-15
    True
    >>> lo, hi = ixdiv(1.0, 2.0, 0.0, 1.0)       # set-based division: [1,2]/[0,1] = [1, +inf]
    >>> 1.0 - 1e-15 < lo <= 1.0 and hi == float("inf")
    True
    >>> iadd(0.1, 0.2, 1.0, 1.0)[0] < 1.1 < iadd(0.1, 0.2, 1.0, 1.0)[1]     # outward rounded
    True
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

from digslam.observer.core.rounding import LIBM_ULPS

__all__ = ["LIBM_ULPS", "njit", "dn", "up", "wdn", "wup", "add_dn", "add_up", "sub_dn", "sub_up",
           "mul_dn", "mul_up", "div_dn", "div_up", "sqrt_dn", "sqrt_up", "nil", "meet", "iadd", "isub",
           "imul", "imul_lo", "imul_hi", "isqr", "idiv", "ixdiv", "isqrt", "iexp", "ilog", "ipown",
           "iabs"]  # fmt: skip

_INF = math.inf


def njit(*args: Any, **kwargs: Any) -> Any:
    """``numba.njit`` with this project's settings: cached on disk, no fastmath, GIL released.

    Small helpers take ``forceinline=True``: LLVM inlines them into their callers (its ``alwaysinline``),
    as fast as numba's ``inline="always"``, which inlines at the level of numba's IR and retypes the
    helper at every call site (compile time superlinear in the nesting: minutes for the tape kernels).
    A few leaves that divide keep ``inline="always"``, so that they take their caller's error model."""
    kwargs.setdefault("cache", True)
    kwargs.setdefault("nogil", True)
    kwargs.setdefault("fastmath", False)
    return numba.njit(*args, **kwargs)


#: Rump, Zimmermann, Boldo & Melquiond (2009), as in :mod:`.rounding`: for finite ``|c| >= 2⁻⁹⁶⁰``,
#: ``c ± φ|c|`` rounds to the successor (predecessor) of ``c`` (their ``+ η`` is below half an ulp of
#: ``φ|c|`` there, and leaving it out avoids a subnormal operand); elsewhere ``nextafter``, which costs
#: several times more in compiled loops.
_PHI, _NEAR = 2.0**-53 * (1.0 + 2.0**-52), 2.0**-960


@njit(forceinline=True)
def dn(x: float) -> float:
    """The float below ``x``: a lower bound of any real whose round-to-nearest is ``x``."""
    a = abs(x)
    return x - a * _PHI if _NEAR <= a < _INF else np.nextafter(x, -_INF)


@njit(forceinline=True)
def up(x: float) -> float:
    """The float above ``x``: an upper bound of any real whose round-to-nearest is ``x``."""
    a = abs(x)
    return x + a * _PHI if _NEAR <= a < _INF else np.nextafter(x, _INF)


@njit(forceinline=True)
def wdn(x: float) -> float:
    """``x`` moved down by ``LIBM_ULPS`` ulps: a lower bound of a libm result's exact value."""
    for _ in range(LIBM_ULPS):
        x = dn(x)
    return x


@njit(forceinline=True)
def wup(x: float) -> float:
    """``x`` moved up by ``LIBM_ULPS`` ulps."""
    for _ in range(LIBM_ULPS):
        x = up(x)
    return x


@njit(forceinline=True)
def _sum_err(a: float, b: float, s: float) -> float:
    """TwoSum (Knuth): the exact ``a + b - s`` (NaN when an operand is infinite)."""
    t = s - a
    return (a - (s - t)) + (b - t)


@njit(forceinline=True)
def add_dn(a: float, b: float) -> float:
    """Lower bound of ``a + b``: exact sums stay exact (TwoSum), others step one ulp down."""
    s = a + b
    return s if _sum_err(a, b, s) >= 0.0 else dn(s)


@njit(forceinline=True)
def add_up(a: float, b: float) -> float:
    """Upper bound of ``a + b``."""
    s = a + b
    return s if _sum_err(a, b, s) <= 0.0 else up(s)


@njit(forceinline=True)
def sub_dn(a: float, b: float) -> float:
    """Lower bound of ``a - b``."""
    return add_dn(a, -b)


@njit(forceinline=True)
def sub_up(a: float, b: float) -> float:
    """Upper bound of ``a - b``."""
    return add_up(a, -b)


@njit(forceinline=True)
def mul_dn(a: float, b: float) -> float:
    """Lower bound of ``a * b``, with ``0 * inf = 0`` (interval convention)."""
    if a == 0.0 or b == 0.0:
        return 0.0
    return dn(a * b)


@njit(forceinline=True)
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


@njit(forceinline=True)
def sqrt_dn(a: float) -> float:
    """Lower bound of ``sqrt(a)`` for ``a >= 0`` (never below 0)."""
    r = math.sqrt(a)
    return r if r == 0.0 else dn(r)


@njit(forceinline=True)
def sqrt_up(a: float) -> float:
    """Upper bound of ``sqrt(a)`` for ``a >= 0`` (exact for 0)."""
    r = math.sqrt(a)
    return r if r == 0.0 else up(r)


@njit(forceinline=True)
def nil(al: float, ah: float) -> bool:
    """Whether ``[al, ah]`` holds no real: empty (``al > ah``) or an infinite point (``al = +∞`` or
    ``ah = -∞``; IEEE 1788: ``±∞`` is no real number, so an operation with it is empty)."""
    return al > ah or al == _INF or ah == -_INF


@njit(forceinline=True)
def imul(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """``[a] * [b]`` (Eq. 2.6); empty in, empty out."""
    if nil(al, ah) or nil(bl, bh):
        return _INF, -_INF
    lo = min(min(mul_dn(al, bl), mul_dn(al, bh)), min(mul_dn(ah, bl), mul_dn(ah, bh)))
    hi = max(max(mul_up(al, bl), mul_up(al, bh)), max(mul_up(ah, bl), mul_up(ah, bh)))
    return lo, hi


@njit(forceinline=True)
def imul_lo(al: float, ah: float, bl: float, bh: float) -> float:
    """Lower bound of ``[a]·[b]`` for finite bounds, in one rounding step: the smallest of the four
    round-to-nearest corner products, one :func:`dn` step down. Each product is within half an ulp of its
    exact value and :func:`dn` is monotone, so that step bounds them all. One step instead of
    :func:`imul`'s four, and one ulp looser where the smallest product is an exact 0 (``-2⁻¹⁰⁷⁴``, where
    :func:`imul` keeps 0); a non-finite bound may give NaN."""
    return dn(min(al * bl, al * bh, ah * bl, ah * bh))


@njit(forceinline=True)
def imul_hi(al: float, ah: float, bl: float, bh: float) -> float:
    """Upper bound of ``[a]·[b]`` for finite bounds: the largest corner product, one :func:`up` step up
    (:func:`imul_lo`'s argument)."""
    return up(max(al * bl, al * bh, ah * bl, ah * bh))


@njit(forceinline=True)
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


@njit(forceinline=True)
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


@njit(forceinline=True)
def isqrt(al: float, ah: float) -> tuple[float, float]:
    """``sqrt([a] ∩ [0, ∞))``; empty when ``[a] < 0``."""
    if nil(al, ah) or ah < 0.0:
        return _INF, -_INF
    return sqrt_dn(max(al, 0.0)), sqrt_up(ah)


@njit(forceinline=True)
def meet(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """``[a] ∩ [b]`` (Eq. 2.3)."""
    lo, hi = max(al, bl), min(ah, bh)
    return (lo, hi) if lo <= hi and lo < _INF and hi > -_INF else (_INF, -_INF)


@njit(forceinline=True)
def _nan_lo(x: float) -> float:
    return -_INF if x != x else x


@njit(forceinline=True)
def _nan_hi(x: float) -> float:
    return _INF if x != x else x


@njit(forceinline=True)
def iadd(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """``[a] + [b]`` (Eq. 2.5)."""
    if nil(al, ah) or nil(bl, bh):
        return _INF, -_INF
    return _nan_lo(add_dn(al, bl)), _nan_hi(add_up(ah, bh))


@njit(forceinline=True)
def isub(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """``[a] - [b]``."""
    if nil(al, ah) or nil(bl, bh):
        return _INF, -_INF
    return _nan_lo(add_dn(al, -bh)), _nan_hi(add_up(ah, -bl))


@njit(inline="always")
def _qdn(a: float, b: float) -> float:
    return 0.0 if a == 0.0 else dn(a / b)


@njit(inline="always")
def _qup(a: float, b: float) -> float:
    return 0.0 if a == 0.0 else up(a / b)


@njit
def ixdiv(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """``[a]/[b]``, set-based (IEEE 1788), as :func:`.arith.div`: unbounded when ``0 ∈ [b]``."""
    if nil(al, ah) or nil(bl, bh) or (bl == 0.0 and bh == 0.0):
        return _INF, -_INF
    if bl > 0.0 or bh < 0.0:
        lo, hi = _INF, -_INF
        for x in (al, ah):
            for y in (bl, bh):
                q = _qdn(x, y)
                lo = lo if q != q else min(lo, q)  # inf/inf corners are dominated
                q = _qup(x, y)
                hi = hi if q != q else max(hi, q)
        return lo, hi
    if al == 0.0 and ah == 0.0:
        return 0.0, 0.0
    if bl == 0.0:  # [b] = [0, bh], bh > 0
        if al >= 0.0:
            return _qdn(al, bh), _INF
        if ah <= 0.0:
            return -_INF, _qup(ah, bh)
    elif bh == 0.0:  # [b] = [bl, 0], bl < 0
        if al >= 0.0:
            return -_INF, _qup(al, bl)
        if ah <= 0.0:
            return _qdn(ah, bl), _INF
    return -_INF, _INF


@njit
def iexp(al: float, ah: float) -> tuple[float, float]:
    """``exp([a])``, libm results widened by ``LIBM_ULPS``."""
    if nil(al, ah):
        return _INF, -_INF
    lo = 1.0 if al == 0.0 else max(wdn(math.exp(al)), 0.0)
    hi = 1.0 if ah == 0.0 else wup(math.exp(ah))
    return lo, hi


@njit
def ilog(al: float, ah: float) -> tuple[float, float]:
    """``log([a] ∩ (0, +∞))``; empty when ``[a] <= 0``."""
    if nil(al, ah) or ah <= 0.0:
        return _INF, -_INF
    lo = -_INF if al <= 0.0 else (0.0 if al == 1.0 else wdn(math.log(al)))
    hi = 0.0 if ah == 1.0 else (_INF if ah == _INF else wup(math.log(ah)))
    return lo, hi


@njit
def _pow_pos(x: float, n: int, upward: bool) -> float:
    """Directed ``x**n`` for ``x >= 0``, ``n >= 1`` (square and multiply, monotone steps)."""
    r, b = 1.0, x
    while n:
        if n & 1:
            r = mul_up(r, b) if upward else mul_dn(r, b)
        n >>= 1
        if n:
            b = mul_up(b, b) if upward else mul_dn(b, b)
    return r


@njit
def ipown(al: float, ah: float, n: int) -> tuple[float, float]:
    """``[a]ⁿ`` for an integer ``n``, as :func:`.arith.pown`."""
    if nil(al, ah):
        return _INF, -_INF
    if n == 0:
        return 1.0, 1.0
    if n < 0:
        pl, ph = ipown(al, ah, -n)
        return ixdiv(1.0, 1.0, pl, ph)
    if n % 2 == 0:
        mig = 0.0 if al <= 0.0 <= ah else min(abs(al), abs(ah))
        return _pow_pos(mig, n, False), _pow_pos(max(abs(al), abs(ah)), n, True)
    lo = _pow_pos(al, n, False) if al >= 0.0 else -_pow_pos(-al, n, True)
    hi = _pow_pos(ah, n, True) if ah >= 0.0 else -_pow_pos(-ah, n, False)
    return lo, hi


@njit(forceinline=True)
def iabs(al: float, ah: float) -> tuple[float, float]:
    """``|[a]|``."""
    if nil(al, ah):
        return _INF, -_INF
    if al >= 0.0:
        return al, ah
    return (-ah, -al) if ah <= 0.0 else (0.0, max(-al, ah))
