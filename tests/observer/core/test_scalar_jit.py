"""The compiled scalar kernels of observer/core/scalar_jit.py enclose the exact rational results."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.observer.core import scalar_jit as jit

finite = st.floats(min_value=-1e300, max_value=1e300, allow_nan=False, allow_infinity=False)
small = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(finite, finite)
def test_add_sub_mul_enclose_exact(a: float, b: float) -> None:
    fa, fb = Fraction(a), Fraction(b)
    assert Fraction(jit.add_dn(a, b)) <= fa + fb <= Fraction(jit.add_up(a, b))
    assert Fraction(jit.sub_dn(a, b)) <= fa - fb <= Fraction(jit.sub_up(a, b))
    if math.isfinite(a * b):
        assert Fraction(jit.mul_dn(a, b)) <= fa * fb <= Fraction(jit.mul_up(a, b))
    if b != 0 and math.isfinite(a / b):
        assert Fraction(jit.div_dn(a, b)) <= fa / fb <= Fraction(jit.div_up(a, b))


@settings(max_examples=200, deadline=None)
@given(st.floats(min_value=0, max_value=1e300))
def test_sqrt_encloses_exact(a: float) -> None:
    lo, hi = jit.sqrt_dn(a), jit.sqrt_up(a)
    assert 0 <= lo <= hi
    assert Fraction(lo) ** 2 <= Fraction(a) <= Fraction(hi) ** 2


@settings(max_examples=300, deadline=None)
@given(small, small, small, small, st.floats(0, 1), st.floats(0, 1))
def test_interval_kernels_contain_point_images(
    a1: float, a2: float, b1: float, b2: float, s: float, t: float
) -> None:
    al, ah = min(a1, a2), max(a1, a2)
    bl, bh = min(b1, b2), max(b1, b2)
    x, y = (
        Fraction(al) + Fraction(s) * (Fraction(ah) - Fraction(al)),
        Fraction(bl) + Fraction(t) * (Fraction(bh) - Fraction(bl)),
    )
    lo, hi = jit.imul(al, ah, bl, bh)
    assert Fraction(lo) <= x * y <= Fraction(hi)
    one_lo, one_hi = jit.imul_lo(al, ah, bl, bh), jit.imul_hi(al, ah, bl, bh)  # one rounding step
    assert Fraction(one_lo) <= x * y <= Fraction(one_hi)
    assert one_lo <= lo and hi <= one_hi
    lo, hi = jit.isqr(al, ah)
    assert 0 <= hi and Fraction(lo) <= x * x <= Fraction(hi)
    lo, hi = jit.idiv(al, ah, bl, bh)
    if y != 0:
        assert lo == -math.inf or Fraction(lo) <= x / y
        assert hi == math.inf or x / y <= Fraction(hi)
    lo, hi = jit.isqrt(al, ah)
    if x >= 0:
        assert Fraction(lo) ** 2 <= x <= Fraction(hi) ** 2


def test_empty_in_empty_out_and_libm_widening() -> None:
    e = (math.inf, -math.inf)
    for res in (
        jit.imul(*e, 1.0, 2.0),
        jit.isqr(*e),
        jit.idiv(1.0, 2.0, *e),
        jit.isqrt(-2.0, -1.0),
        jit.idiv(1.0, 2.0, 0.0, 0.0),
    ):
        assert res[0] > res[1]
    assert jit.idiv(1.0, 2.0, -1.0, 1.0) == (-math.inf, math.inf)
    x = 1.0
    lo, hi = x, x
    for _ in range(jit.LIBM_ULPS):
        lo, hi = np.nextafter(lo, -math.inf), np.nextafter(hi, math.inf)
    assert jit.wdn(x) == lo and jit.wup(x) == hi
    assert jit.mul_dn(0.0, math.inf) == 0.0 == jit.mul_up(-math.inf, 0.0)
