"""Tests of digslam.observer.thick.interval: worked numbers of §A.3 and Example A.2."""

import numpy as np
import pytest

from digslam.observer.thick.interval import FALSE, TRUE, UNKNOWN, ThickIntervalArray, thin


def _ab():
    return ThickIntervalArray([1.0], [2.0], [4.0], [5.0]), ThickIntervalArray([3.0], [7.0], [6.0], [8.0])


def test_sum_a3():
    a, b = _ab()
    assert (a + b).as_tuple() == ((4.0, 9.0), (10.0, 13.0))


def test_intersection_a3():
    a, b = _ab()
    assert (a & b).as_tuple() == ((3.0, 7.0), (4.0, 5.0))


def test_union_a3():
    a, b = _ab()
    assert (a | b).as_tuple() == ((1.0, 2.0), (6.0, 8.0))


def test_example_a2_overlap():
    a = thin([1.0], [5.0])
    b = ThickIntervalArray([2.0], [4.0], [3.0], [6.0])
    assert a.overlaps(b)[0] == TRUE
    assert a.disjoint(b)[0] == FALSE


def test_subset_tristate_batch():
    a = ThickIntervalArray([2.0, 0.0, 1.0], [2.5, 0.5, 3.0], [3.0, 9.0, 4.0], [3.5, 9.5, 6.0])
    b = ThickIntervalArray([0.0, 1.0, 2.0], [1.0, 2.0, 2.5], [4.0, 3.0, 4.5], [5.0, 4.0, 5.0])
    assert a.subset_of(b).tolist() == [TRUE, FALSE, UNKNOWN]
    assert a.not_subset_of(b).tolist() == [FALSE, TRUE, UNKNOWN]


def test_outward_rounding_sub():
    a = thin([0.1], [0.2])
    d = a - a
    assert d.lo_lo[0] <= 0.1 - 0.2 and d.hi_hi[0] >= 0.2 - 0.1


def test_bad_input():
    with pytest.raises(ValueError, match="every member"):
        ThickIntervalArray([5.0], [6.0], [1.0], [2.0])
    with pytest.raises(ValueError, match="shape"):
        ThickIntervalArray(np.zeros(2), np.zeros(3), np.zeros(2), np.zeros(2))


def test_thick_function_and_parametric():
    from digslam.observer import Function
    from digslam.observer.thick.function import ThickFunction

    tf = ThickFunction(Function(lambda x: x[0] - 1), Function(lambda x: x[0] + 1))
    r = tf.eval(np.array([[0.0], [2.0]]), np.array([[1.0], [2.0]]))
    assert r.lo_lo.ravel().tolist() == [-1.0, 1.0] and r.hi_hi.ravel().tolist() == [2.0, 3.0]
    pf = ThickFunction.from_parametric(Function(lambda x, p: x * p), [1.0], [2.0])
    rng = np.random.default_rng(0)
    xs = rng.uniform(0, 3, 50)
    r = pf.eval(xs[:, None], xs[:, None])
    lo_true, hi_true = xs * 1.0, xs * 2.0  # f⁻, f⁺ for x ≥ 0
    assert np.all(r.lo_lo.ravel() <= lo_true) and np.all(lo_true <= r.lo_hi.ravel())
    assert np.all(r.hi_lo.ravel() <= hi_true) and np.all(hi_true <= r.hi_hi.ravel())
