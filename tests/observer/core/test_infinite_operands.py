"""Infinite scalar operands (issue 24, item 1): a float ``±inf`` is no real number (IEEE 1788-2015 §7.2),
so wherever it meets an interval the result is the empty interval, never a NaN bound nor ``[inf, inf]``:
scalar and batch paths, numpy (:mod:`digslam.observer.core.arith`, :mod:`~digslam.observer.core.trig`) and
compiled (:mod:`digslam.observer.core.scalar_jit`), constants in expressions and
``[±inf, ±inf]`` rows of a batch.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from digslam.observer import Box, CtcFwdBwd, Function, Interval, IntervalArray, SepInverse
from digslam.observer.core import arith, trig
from digslam.observer.core import scalar_jit as jit
from digslam.observer.core.boxes import validate_batch
from digslam.observer.expr.ops import atan2, maximum, minimum, sqr

INF = math.inf
MAX = 1.7976931348623157e308


def _empty(x: IntervalArray) -> bool:
    return bool(np.all(x.lo == INF) and np.all(x.hi == -INF))


@pytest.mark.parametrize(
    "expr",
    [
        lambda: Interval(MAX, INF) + (-INF),
        lambda: Interval(0, 1) + INF,
        lambda: INF + Interval(0, 1),
        lambda: Interval(0, 1) - INF,
        lambda: -INF - Interval(0, 1),
        lambda: Interval(1, 2) * INF,
        lambda: Interval(-1, 2) * -INF,
        lambda: Interval(0, 0) * INF,
        lambda: Interval(1, 2) / INF,
        lambda: INF / Interval(1, 2),
        lambda: Interval.entire() + INF,
        lambda: Interval(0, 1) & INF,
        lambda: atan2(Interval(0, 1), INF),
        lambda: minimum(Interval(0, 1), -INF),
        lambda: maximum(INF, Interval(0, 1)),
    ],
)
def test_scalar_operand_inf_is_empty(expr) -> None:
    r = expr()
    assert _empty(r), r


def test_batch_operand_elementwise() -> None:
    x = IntervalArray([0.0, 1.0, 2.0], [1.0, 2.0, 3.0])
    r = x + np.array([INF, 1.0, -INF])
    assert r.lo.tolist() == [INF, 2.0, INF] and r.hi.tolist() == [-INF, 3.0, -INF]
    r = x * np.array([1.0, INF, 2.0])
    assert r.lo.tolist() == [0.0, INF, 4.0] and r.hi.tolist() == [1.0, -INF, 6.0]


def test_no_nan_bound_ever() -> None:
    vals = [-INF, -MAX, -1.0, 0.0, 1.0, MAX, INF]
    ivs = [Interval(MAX, INF), Interval(-INF, -MAX), Interval(0, INF), Interval.entire(), Interval(-1, 1)]
    for v in vals:
        for x in ivs:
            for r in (x + v, x - v, v - x, x * v, v * x, x / v, v / x):
                assert not (np.isnan(r.lo) or np.isnan(r.hi))
                if math.isinf(v):
                    assert _empty(r)


def test_finite_operands_unchanged() -> None:
    """The rule touches infinite points only: unbounded intervals and finite floats work as before."""
    assert Interval(0, INF) + 1.0 == Interval(1, INF)
    assert (Interval(1, 2) * Interval(0, INF)) == Interval(0, INF)
    r = Interval(1, 2) / 3.0
    assert Fraction(r.lo) <= Fraction(1, 3) <= Fraction(r.hi) and Fraction(r.hi) <= Fraction(2, 3) + Fraction(
        1, 2**52
    )


def test_membership_of_infinity() -> None:
    assert not bool(Interval(0, INF).contains(INF))
    assert not bool(Interval.entire().contains(-INF))
    assert bool(Interval(0, INF).contains(1e308))
    with pytest.raises(ValueError, match="NaN"):
        Interval(0, 1).contains(float("nan"))


@pytest.mark.parametrize("pt", [(INF, INF), (-INF, -INF)])
def test_numpy_kernels_read_infinite_points_as_empty(pt: tuple[float, float]) -> None:
    a, b = (np.array([0.0]), np.array([1.0])), (np.array([pt[0]]), np.array([pt[1]]))
    for k in (arith.add, arith.sub, arith.mul, arith.div, arith.minimum, arith.maximum, trig.atan2):
        lo, hi = k(a, b)
        assert lo[0] == INF and hi[0] == -INF, k.__name__
    for k in (arith.sqr, arith.sqrt, arith.exp, arith.log, arith.abs_, trig.sin, trig.atan, trig.tan):
        lo, hi = k(b)
        assert lo[0] == INF and hi[0] == -INF, k.__name__


@pytest.mark.parametrize("pt", [(INF, INF), (-INF, -INF)])
def test_compiled_kernels_read_infinite_points_as_empty(pt: tuple[float, float]) -> None:
    for k in (jit.imul, jit.idiv, jit.iadd, jit.isub, jit.ixdiv, jit.meet):
        assert k(0.0, 1.0, *pt) == (INF, -INF), k
        assert k(*pt, 0.0, 1.0) == (INF, -INF), k
    for k in (jit.isqr, jit.isqrt, jit.iexp, jit.ilog, jit.iabs):
        assert k(*pt) == (INF, -INF), k
    assert jit.ipown(*pt, 3) == (INF, -INF)


def test_batch_rows_with_infinite_points() -> None:
    lo, hi = np.array([[INF, 0.0], [0.0, 0.0]]), np.array([[INF, 1.0], [1.0, 1.0]])
    vlo, vhi = validate_batch(lo, hi)
    assert vlo[0, 0] == INF and vhi[0, 0] == -INF and lo[0, 0] == INF and hi[0, 0] == INF  # input kept
    f = Function(lambda x: x[0] + x[1])  # compiled path
    r = f.eval((lo, hi))
    assert r.lo[0] == INF and r.hi[0] == -INF and r.lo[1] == 0.0 and r.hi[1] == 2.0
    clo, chi = CtcFwdBwd(f, Interval(-10, 10))((np.array([[-INF, 0.0]]), np.array([[-INF, 1.0]])))
    assert (clo == INF).all() and (chi == -INF).all()
    with pytest.raises(ValueError, match="infinite point"):  # the constructor still refuses it
        Box([(-INF, -INF), (0, 1)])
    g = Function(lambda x: sqr(x[0]) + x[1] * 0.0 + atan2(x[1], 1.0))  # numpy path (atan2)
    r = g.eval((lo, hi))
    assert r.lo[0] == INF and r.hi[0] == -INF


def test_infinite_constant_is_the_empty_constant() -> None:
    f = Function(lambda x: x[0] + INF, n=1)
    assert _empty(f.eval(Box([(0, 1)])))
    xin, xout = SepInverse(f, Interval(0, 1))(Box([(0, 1)]))
    assert _empty(xout) and bool((xin == Box([(0, 1)])).all())
    with pytest.raises(ValueError, match="not a number"):
        f(np.array([0.5]))
    with pytest.raises(ValueError, match="cannot use"):
        Function(lambda x: x[0] + float("nan"), n=1)


def test_image_set_inf_is_empty() -> None:
    """``Y = {inf}`` holds no real: the inverse image is empty."""
    r = CtcFwdBwd(Function(lambda x: x[0], n=1), INF)(Box([(0, 1)]))
    assert _empty(r)
