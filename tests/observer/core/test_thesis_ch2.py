"""The worked examples of thesis chapter 2 (§2.3.1 Ex. 2.1, 2.2; §2.3.2 Ex. 2.3; §2.4.1 Ex. 2.4), exactly."""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np

from digslam.observer import Box, CtcFwdBwd, Function, Interval, IntervalArray, cos, dot
from digslam.observer.core import boxes


def bounds(x: IntervalArray) -> tuple[list[float], list[float]] | tuple[float, float]:
    if x.ndim == 0:
        return float(x.lo), float(x.hi)
    return x.lo.tolist(), x.hi.tolist()


# ---- Example 2.1 (Eq. 2.11-2.14) -----------------------------------------------------------------


def test_ex_2_1_intersection():
    assert bounds(Interval(-1, 5) & Interval(-3, 2)) == (-1.0, 2.0)


def test_ex_2_1_union_hull():
    assert bounds(Interval(-3, 3) | Interval(4, 10)) == (-3.0, 10.0)


def test_ex_2_1_difference():
    assert bounds(Interval(-3, 3) - Interval(4, 10)) == (-13.0, -1.0)


def test_ex_2_1_width():
    assert float(Interval(-2, 9).width()) == 11.0


# ---- Example 2.2 (Eq. 2.19-2.22) -----------------------------------------------------------------

X = Box([(1, 2), (2, 9)])
Y = Box([(-1, 2), (-5, 5)])


def test_ex_2_2_box_sum():
    assert bounds(X + Y) == ([0.0, -3.0], [4.0, 14.0])


def test_ex_2_2_scalar_product():
    assert bounds(dot(X, Y)) == (-47.0, 49.0)


def test_ex_2_2_euclidean_width_is_sqrt50_rounded_up():
    w = float(boxes.width_euclid(X.lo[None, :], X.hi[None, :])[0])
    assert w in (math.sqrt(50), math.nextafter(math.sqrt(50), math.inf))
    assert Fraction(w) ** 2 >= 50  # an upper bound of √50 ...
    assert Fraction(math.nextafter(w, 0)) ** 2 < 50  # ... and the smallest float that is one


def test_ex_2_2_infinity_width():
    assert float(boxes.width_inf(X.lo[None, :], X.hi[None, :])[0]) == 7.0


# ---- Example 2.3 (Eq. 2.27-2.28) -----------------------------------------------------------------


def test_ex_2_3_natural_inclusion_of_x1_cos_x2():
    # [π/6, π/3] rounded outward so that it certainly contains the real interval
    x2 = (math.nextafter(math.pi / 6, 0), math.nextafter(math.pi / 3, math.inf))
    with mpmath.workdps(50):
        assert mpmath.mpf(x2[0]) < mpmath.pi / 6 and mpmath.pi / 3 < mpmath.mpf(x2[1])
        expected = (-mpmath.sqrt(3), mpmath.sqrt(3) / 2)
        f = Function(lambda x1, x2: x1 * cos(x2))
        got = f.eval(Box([(-2, 1), x2]))
        lo, hi = mpmath.mpf(float(got.lo)), mpmath.mpf(float(got.hi))
        assert lo <= expected[0] and expected[1] <= hi, (got, expected)
        assert expected[0] - lo < 1e-12 and hi - expected[1] < 1e-12, (got, expected)
        # the same through interval arithmetic directly (Eq. 2.27)
        direct = Interval(-2, 1) * cos(Interval(*x2))
        assert mpmath.mpf(float(direct.lo)) <= expected[0] and expected[1] <= mpmath.mpf(float(direct.hi))


# ---- Example 2.4 (Eq. 2.31) ----------------------------------------------------------------------


def test_ex_2_4_forward_backward_contractor():
    ctc = CtcFwdBwd(Function(lambda z, x, y: x - y - z), 0)
    got = ctc(Box([(4, 5), (0, 3), (-2, 2)]))
    assert bounds(got) == ([4.0, 2.0, -2.0], [5.0, 3.0, -1.0])


def test_ex_2_4_batch_and_raw_pair():
    ctc = CtcFwdBwd(Function(lambda z, x, y: x - y - z), 0)
    lo = np.array([[4.0, 0.0, -2.0]] * 3)
    hi = np.array([[5.0, 3.0, 2.0]] * 3)
    rlo, rhi = ctc((lo, hi))
    assert rlo.tolist() == [[4.0, 2.0, -2.0]] * 3
    assert rhi.tolist() == [[5.0, 3.0, -1.0]] * 3
