"""Directed rounding on float64 arrays: the one module that owns outward rounding.

numpy computes in round-to-nearest. Every interval bound that floating point can round goes through
this module, which returns a float that is certainly below (``*_down``) or above (``*_up``) the exact
real result.

* ``+ - * /`` and ``sqrt`` are *tight*: an error-free transformation (TwoSum, Dekker's TwoProduct)
  recovers the exact rounding error, and the bound moves one ulp only when the rounded result is on
  the wrong side of the exact one. Where those transformations can overflow or underflow, the bound
  moves one ulp outward unconditionally, which is sound (round-to-nearest is within half an ulp).
* Transcendental functions come from the platform's libm (numpy may dispatch to SIMD code).
  Their documented error is at most :data:`LIBM_ULPS` ulps, so results are widened by that many ulps
  (:func:`widen_down`, :func:`widen_up`). ``tests/observer/core/test_rounding.py`` measures the real error
  against
  mpmath.

This module does not change the processor's rounding mode, and must not run in a process where
another library did (codac switches the whole process to upward rounding; run it in a subprocess).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core.types import Floats

__all__ = [
    "LIBM_ULPS",
    "PI_DOWN",
    "PI_UP",
    "HALF_PI_DOWN",
    "HALF_PI_UP",
    "TWO_PI_DOWN",
    "TWO_PI_UP",
    "next_down",
    "next_up",
    "step_down",
    "step_up",
    "widen_down",
    "widen_up",
    "add_down",
    "add_up",
    "sub_down",
    "sub_up",
    "mul_down",
    "mul_up",
    "div_down",
    "div_up",
    "sqrt_down",
    "sqrt_up",
]

#: Ulps of slack for results of numpy's transcendental functions (libm or SVML, both documented <= 4).
LIBM_ULPS = 4

_INF = np.inf
_MAX = np.finfo(np.float64).max
#: Below this magnitude a product or quotient may lose bits to gradual underflow.
_TINY = 2.0**-960
#: Above this magnitude Dekker's splitting constant may overflow.
_HUGE = 2.0**995
_SPLIT = 134217729.0  # 2**27 + 1

PI_DOWN = 3.141592653589793  # float(pi) < pi
PI_UP = float(np.nextafter(PI_DOWN, _INF))
HALF_PI_DOWN = PI_DOWN / 2  # exact halving
HALF_PI_UP = PI_UP / 2
TWO_PI_DOWN = PI_DOWN * 2
TWO_PI_UP = PI_UP * 2


_SIGN = np.int64(-(2**63))
_MAG = np.int64(2**63 - 1)
_INF_BITS = np.int64(0x7FF0000000000000)


def next_up(x: Floats, ulps: int = 1) -> np.ndarray:
    """The float ``ulps`` steps above ``x`` (``+inf`` stays ``+inf``, NaN stays NaN).

    Same result as ``ulps`` calls of ``np.nextafter(x, inf)``, several times faster: the bit pattern
    is mapped to an order-preserving signed integer (``±0 -> 0``), stepped, and mapped back.
    """
    y = np.asarray(x, dtype=np.float64)
    bits = y.view(np.int64)
    mag = bits & _MAG
    idx = np.minimum(np.where(bits < 0, -mag, mag) + ulps, _INF_BITS)  # saturate at +inf
    r = np.where(idx >= 0, idx, (-idx) | _SIGN).view(np.float64)
    nan = mag > _INF_BITS
    return np.where(nan, y, r) if nan.any() else r


def next_down(x: Floats, ulps: int = 1) -> np.ndarray:
    """The float ``ulps`` steps below ``x`` (``-inf`` stays ``-inf``)."""
    return -next_up(-np.asarray(x, dtype=np.float64), ulps)


def widen_down(x: Floats, ulps: int = LIBM_ULPS) -> np.ndarray:
    """Move ``x`` down by ``ulps`` ulps: a lower bound for a value computed within ``ulps`` ulps."""
    return next_down(x, ulps)


def widen_up(x: Floats, ulps: int = LIBM_ULPS) -> np.ndarray:
    """Move ``x`` up by ``ulps`` ulps: an upper bound for a value computed within ``ulps`` ulps."""
    return next_up(x, ulps)


def _overflowed(r: Any, a: Any, b: Any) -> np.ndarray:
    return np.isinf(r) & np.isfinite(a) & np.isfinite(b)


def _sum_error(a: Any, b: Any, s: Any) -> np.ndarray:
    """TwoSum (Knuth): exact ``a + b - s``; NaN where an operand is infinite."""
    bb = s - a
    return (a - (s - bb)) + (b - bb)


#: Rump, Zimmermann, Boldo & Melquiond (2009): for finite c, fl(c ± fl(φ|c| + η)) is the successor
#: (predecessor) of c, or the one after it for |c| near the smallest normal; always strictly beyond c.
#: There the exact integer step is used instead.
_PHI = 2.0**-53 * (1.0 + 2.0**-52)
_ETA = 2.0**-1074
_NEAR_SUBNORMAL = 2.0**-1019  # where fl(c ± (φ|c| + η)) can skip a float


def _step(r: Any, mask: Any, up: bool) -> np.ndarray:
    """Exactly one ulp outward where ``mask``: 4 array passes, plus the exact integer step for the rare
    values near the smallest normal where the formula may go two ulps."""
    with np.errstate(over="ignore", invalid="ignore"):
        a = np.abs(r)
        out = np.where(mask, r + (a * _PHI + _ETA) if up else r - (a * _PHI + _ETA), r)
        near = mask & (a < _NEAR_SUBNORMAL)
        if near.any():
            out = np.where(near, next_up(r) if up else next_down(r), out)
        return out


def step_up(r: Floats) -> np.ndarray:
    """An upper bound of the exact value whose round-to-nearest result is ``r``.

    For ``r`` the numpy result of one correctly rounded ``+ - * /`` or ``sqrt`` (within half an ulp of the
    exact value), one ulp up bounds it: cheaper than :func:`add_up` and friends (no error-free
    transformation) and at most one ulp looser. ``+inf`` stays; ``-inf`` (an overflow of a finite exact
    value, or an infinite one) becomes ``-MAX``.
    """
    r = np.asarray(r, dtype=np.float64)
    with np.errstate(over="ignore", invalid="ignore"):
        out = r + (np.abs(r) * _PHI + _ETA)
    near = np.abs(r) < _NEAR_SUBNORMAL
    if near.any():
        out[near] = next_up(r[near])
    inf = np.isinf(r)
    if inf.any():
        out[inf] = np.where(r[inf] > 0, _INF, -_MAX)
    return out


def step_down(r: Floats) -> np.ndarray:
    """A lower bound of the exact value whose round-to-nearest result is ``r`` (see :func:`step_up`)."""
    return -step_up(-np.asarray(r, dtype=np.float64))


def _direct(r: Any, err: Any, up: bool) -> np.ndarray:
    """Rounded result ``r`` of an exact value ``r + err``: step one ulp when ``err`` is on that side."""
    with np.errstate(invalid="ignore"):
        return _step(r, (err > 0) if up else (err < 0), up)


def _add(a: Any, b: Any, up: bool) -> np.ndarray:
    with np.errstate(invalid="ignore", over="ignore"):
        s = np.add(a, b)
        r = _direct(s, _sum_error(a, b, s), up)
        if np.isinf(s).any():  # rare: overflow of finite operands rounds to ±MAX on one side
            r = np.where(_overflowed(s, a, b) & ((s < 0) if up else (s > 0)), -_MAX if up else _MAX, r)
        return r


def add_down(a: Floats, b: Floats) -> np.ndarray:
    """Largest float <= the exact ``a + b`` (``inf - inf`` gives NaN; callers mask it)."""
    return _add(a, b, up=False)


def add_up(a: Floats, b: Floats) -> np.ndarray:
    """Smallest float >= the exact ``a + b``."""
    return _add(a, b, up=True)


def sub_down(a: Floats, b: Floats) -> np.ndarray:
    """Largest float <= the exact ``a - b``."""
    return add_down(a, np.negative(b))


def sub_up(a: Floats, b: Floats) -> np.ndarray:
    """Smallest float >= the exact ``a - b``."""
    return add_up(a, np.negative(b))


def _split(a: Any) -> tuple[np.ndarray, np.ndarray]:
    c = _SPLIT * a
    hi = c - (c - a)
    return hi, a - hi


def _product_error(a: Any, b: Any, p: Any) -> np.ndarray:
    """Dekker's TwoProduct: exact ``a * b - p`` where no operand or result is huge or tiny."""
    ah, al = _split(a)
    bh, bl = _split(b)
    return ((ah * bh - p) + ah * bl + al * bh) + al * bl


def _safe(*vals: Any) -> np.ndarray:
    """Where the error-free transformations are exact: every operand and the result are finite with
    magnitude in ``[2⁻⁹⁶⁰, 2⁹⁹⁵]`` (no overflow in Dekker's split, no bits lost to underflow)."""
    ok = np.ones(np.shape(vals[0]), dtype=bool)
    for v in vals:
        m = np.abs(v)
        ok &= (m >= _TINY) & (m <= _HUGE)
    return ok


def _finish(r: Any, err: Any, ok: Any, exact: Any, up: bool) -> np.ndarray:
    """Directed result: tight where ``ok``, exact where ``exact``, else one ulp outward."""
    with np.errstate(invalid="ignore"):
        return _step(r, np.where(ok, (err > 0) if up else (err < 0), ~exact), up)


def _mul(a: Any, b: Any, up: bool) -> np.ndarray:
    with np.errstate(invalid="ignore", over="ignore", under="ignore"):
        p = np.multiply(a, b)
        ok = _safe(p, a, b)
        err = _product_error(np.where(ok, a, 0.0), np.where(ok, b, 0.0), np.where(ok, p, 0.0))
        # exact: a zero operand, an infinite operand (no rounding in extended reals)
        exact = (a == 0) | (b == 0) | np.isinf(a) | np.isinf(b)
        r = _finish(p, err, ok, exact, up)
        # an underflow to 0 keeps the sign of the exact product: 0 bounds it on the other side
        sign = np.sign(a) * np.sign(b)
        r = np.where((p == 0) & (sign < 0 if up else sign > 0), 0.0, r)
        if np.isinf(p).any():
            ovf = _overflowed(p, a, b)
            r = np.where(ovf & ((p > 0) if not up else (p < 0)), _MAX if not up else -_MAX, r)
        return r


def mul_down(a: Floats, b: Floats) -> np.ndarray:
    """Largest float <= the exact ``a * b`` (``0 * inf`` gives NaN; callers mask it)."""
    return _mul(a, b, up=False)


def mul_up(a: Floats, b: Floats) -> np.ndarray:
    """Smallest float >= the exact ``a * b``."""
    return _mul(a, b, up=True)


def _div(a: Any, b: Any, up: bool) -> np.ndarray:
    with np.errstate(invalid="ignore", over="ignore", under="ignore", divide="ignore"):
        q = np.divide(a, b)
        ok = _safe(q, a, b)
        q0, b0 = np.where(ok, q, 0.0), np.where(ok, b, 0.0)
        p = q0 * b0
        # a - q*b is exact and representable for the rounded quotient q (Markstein)
        rem = (np.where(ok, a, 0.0) - p) - _product_error(q0, b0, p)
        err = rem * np.sign(b)  # sign of (a/b - q)
        exact = (a == 0) | np.isinf(b) | (np.isinf(a) & np.isfinite(b))
        r = _finish(q, err, ok, exact, up)
        if np.isinf(q).any():
            ovf = _overflowed(q, a, b) & (b != 0)
            r = np.where(ovf & ((q > 0) if not up else (q < 0)), _MAX if not up else -_MAX, r)
        return r


def div_down(a: Floats, b: Floats) -> np.ndarray:
    """Largest float <= the exact ``a / b`` for ``b != 0``."""
    return _div(a, b, up=False)


def div_up(a: Floats, b: Floats) -> np.ndarray:
    """Smallest float >= the exact ``a / b`` for ``b != 0``."""
    return _div(a, b, up=True)


def _sqrt(a: Any, up: bool) -> np.ndarray:
    with np.errstate(invalid="ignore", under="ignore"):
        s = np.sqrt(a)
        ok = _safe(s, a)
        s0 = np.where(ok, s, 0.0)
        p = s0 * s0
        err = (np.where(ok, a, 0.0) - p) - _product_error(s0, s0, p)  # sign of sqrt(a) - s
        exact = (a == 0) | np.isinf(a)
        return _finish(s, err, ok, exact, up)


def sqrt_down(a: Floats) -> np.ndarray:
    """Largest float <= the exact square root of ``a >= 0``."""
    return _sqrt(a, up=False)


def sqrt_up(a: Floats) -> np.ndarray:
    """Smallest float >= the exact square root of ``a >= 0``."""
    return _sqrt(a, up=True)
