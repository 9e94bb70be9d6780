"""The interval API: batch/scalar agreement, empty sets, special intervals, bad input, contractor algebra.

* A batch of N intervals (or N boxes through ``Function.eval``) gives, bit for bit, what each gives alone.
* The empty interval goes in, the empty interval ``[+inf, -inf]`` comes out, for every primitive.
* Over a grid of special intervals (empty, entire, ``[0,0]``, half-lines, huge, subnormal) × the same grid
  for binary operations, no bound is ever NaN, every result is a valid interval, and it holds the
  exact image of sample points.
* Bad input raises ``ValueError`` naming the culprit.
* ``CtcFixPoint`` reaches a fixpoint; ``&`` / ``|`` / ``@`` obey the set laws on an example.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from fractions import Fraction

import mpmath
import numpy as np
import pytest

from digslam.observer import (
    Box,
    CtcFixPoint,
    CtcFwdBwd,
    Function,
    Interval,
    IntervalArray,
    abs_,
    acos,
    asin,
    atan,
    atan2,
    cos,
    exp,
    log,
    maximum,
    minimum,
    pown,
    sin,
    sqr,
    sqrt,
    tan,
)
from digslam.observer.core import boxes

INF = math.inf
MAX = float(np.finfo(np.float64).max)
mp = mpmath.mpf

# ---- operations and exact references -------------------------------------------------------------


def F(x: float) -> Fraction:
    return Fraction(float(x))


def _mp(fn: Callable[..., mpmath.mpf]) -> Callable[..., mpmath.mpf]:
    """``fn`` at 50 digits, at 2600 bits when 50 digits cannot tell the value from a float."""

    def ex(*a: float) -> mpmath.mpf:
        with mpmath.workdps(50):
            v = fn(*(mp(x) for x in a))
            f = float(v)
            near = math.isfinite(f) and abs(v - mp(f)) <= abs(v) * mp(2) ** -150
        if near:
            with mpmath.workprec(2600):
                v = fn(*(mp(x) for x in a))
        return v

    return ex


def _when(pred: Callable[..., bool], fn: Callable[..., object]) -> Callable[..., object]:
    return lambda *a: fn(*a) if pred(*a) else None


UNARY: dict[str, tuple[Callable[[IntervalArray], IntervalArray], Callable[[float], object]]] = {
    "neg": (lambda x: -x, lambda a: -F(a)),
    "sqr": (sqr, lambda a: F(a) ** 2),
    "sqrt": (sqrt, _when(lambda a: a >= 0, _mp(mpmath.sqrt))),
    "exp": (exp, _mp(mpmath.exp)),
    "log": (log, _when(lambda a: a > 0, _mp(mpmath.log))),
    "sin": (sin, _mp(mpmath.sin)),
    "cos": (cos, _mp(mpmath.cos)),
    "tan": (tan, _mp(mpmath.tan)),
    "asin": (asin, _when(lambda a: -1 <= a <= 1, _mp(mpmath.asin))),
    "acos": (acos, _when(lambda a: -1 <= a <= 1, _mp(mpmath.acos))),
    "atan": (atan, _mp(mpmath.atan)),
    "abs": (abs_, lambda a: abs(F(a))),
    **{
        f"pown{n}": (
            lambda x, n=n: pown(x, n),
            _when(lambda a, n=n: n >= 0 or a != 0, lambda a, n=n: F(a) ** n),
        )
        for n in range(-3, 6)
    },
}
BINARY: dict[str, tuple[Callable[..., IntervalArray], Callable[[float, float], object]]] = {
    "add": (lambda x, y: x + y, lambda a, b: F(a) + F(b)),
    "sub": (lambda x, y: x - y, lambda a, b: F(a) - F(b)),
    "mul": (lambda x, y: x * y, lambda a, b: F(a) * F(b)),
    "div": (lambda x, y: x / y, _when(lambda a, b: b != 0, lambda a, b: F(a) / F(b))),
    "atan2": (atan2, _when(lambda a, b: a != 0 or b != 0, _mp(mpmath.atan2))),
    "min": (minimum, lambda a, b: min(F(a), F(b))),
    "max": (maximum, lambda a, b: max(F(a), F(b))),
}


def inside(lo: float, hi: float, v: object) -> bool:
    if isinstance(v, Fraction):
        return (lo == -INF or (lo != INF and Fraction(lo) <= v)) and (
            hi == INF or (hi != -INF and v <= Fraction(hi))
        )
    return mp(lo) <= v <= mp(hi)


def bits(x: IntervalArray) -> tuple[list[float], list[float]]:
    return np.asarray(x.lo).tolist(), np.asarray(x.hi).tolist()


# ---- special intervals ---------------------------------------------------------------------------

PI_UP = math.nextafter(math.pi, INF)
SPECIAL: list[tuple[float, float]] = [
    (INF, -INF),  # empty
    (-INF, INF),
    (0.0, 0.0),
    (1.0, 1.0),
    (-1.0, 1.0),
    (0.0, 1.0),
    (-1.0, 0.0),
    (1.0, 2.0),
    (-2.0, -1.0),
    (-INF, 0.0),
    (0.0, INF),
    (-INF, -1.0),
    (1.0, INF),
    (-INF, 5.0),
    (-3.0, INF),
    (MAX, INF),
    (-INF, -MAX),
    (-MAX, MAX),
    (MAX, MAX),
    (5e-324, 5e-324),
    (-5e-324, 5e-324),
    (3.0, 1e300),
    (math.pi, PI_UP),
    (-PI_UP, -math.pi),
    (2.0**60, 2.0**61),
]


def sample_points(lo: float, hi: float) -> list[float]:
    """A few finite points of ``[lo, hi]``: finite bounds, 0, ±1, and points far along half-lines."""
    if lo > hi:
        return []
    pts = {p for p in (lo, hi) if math.isfinite(p)}
    pts |= {
        p for p in (0.0, 1.0, -1.0, 1e300, -1e300, 0.5 * lo + 0.5 * hi) if lo <= p <= hi and math.isfinite(p)
    }
    return sorted(pts)


def arrays(pairs):
    return IntervalArray._raw(np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs]))


def check_valid(res: IntervalArray, what: str) -> None:
    lo, hi = np.asarray(res.lo), np.asarray(res.hi)
    assert not (np.isnan(lo).any() or np.isnan(hi).any()), f"{what}: NaN bound in {bits(res)}"
    empty = lo > hi
    assert np.all(~empty | ((lo == INF) & (hi == -INF))), f"{what}: non-normalised empty {bits(res)}"
    assert not np.any(~empty & ((lo == INF) | (hi == -INF))), f"{what}: infinite member {bits(res)}"


# ---- batch vs scalar -----------------------------------------------------------------------------


def _random_intervals(n: int, seed: int) -> list[tuple[float, float]]:
    rng = np.random.default_rng(seed)
    v = np.sort(np.concatenate([rng.uniform(-5, 5, (n, 2)), rng.standard_cauchy((n, 2)) * 100]), axis=1)
    return [tuple(p) for p in v.tolist()] + SPECIAL


@pytest.mark.parametrize("name", list(UNARY))
def test_unary_batch_equals_scalar(name):
    op = UNARY[name][0]
    pairs = _random_intervals(40, 1)
    batch = op(arrays(pairs))
    for i, p in enumerate(pairs):
        alone = op(IntervalArray._raw(np.asarray(p[0]), np.asarray(p[1])))
        assert bits(alone) == (batch.lo[i].item(), batch.hi[i].item()), (name, p)


@pytest.mark.parametrize("name", list(BINARY))
def test_binary_batch_equals_scalar(name):
    op = BINARY[name][0]
    a, b = _random_intervals(30, 2), _random_intervals(30, 3)[::-1]
    batch = op(arrays(a), arrays(b))
    for i, (p, q) in enumerate(zip(a, b)):
        alone = op(
            IntervalArray._raw(np.asarray(p[0]), np.asarray(p[1])), IntervalArray._raw(*map(np.asarray, q))
        )
        assert bits(alone) == (batch.lo[i].item(), batch.hi[i].item()), (name, p, q)


FUNCTIONS = {
    "ring": Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2),
    "x1cosx2": Function(lambda x: x[0] * cos(x[1])),
    "atan2_minus_prod": Function(lambda x: atan2(x[1], x[0]) - x[0] * x[1]),
    "gauss_sin": Function(lambda x: exp(-(x[0] ** 2)) * sin(3 * x[0]), n=2),
    "vector": Function(lambda x: (sqrt(x[0]) + log(x[1]), x[0] / x[1], abs_(x[0]) - pown(x[1], 3))),
    "all_unary": Function(
        lambda x: tan(x[0]) + asin(x[1]) * acos(x[1]) + atan(minimum(x[0], maximum(x[1], 0.5)))
    ),
}


@pytest.mark.parametrize("name", list(FUNCTIONS))
def test_function_eval_batch_equals_single_box(name):
    f = FUNCTIONS[name]
    a, b = _random_intervals(30, 4), _random_intervals(30, 5)[::-1]
    lo = np.array([[p[0], q[0]] for p, q in zip(a, b)])
    hi = np.array([[p[1], q[1]] for p, q in zip(a, b)])
    batch = f.eval(IntervalArray._raw(lo, hi))
    check_valid(batch, name)
    for i in range(len(lo)):
        alone = f.eval(IntervalArray._raw(lo[i], hi[i]))
        assert bits(alone) == (batch.lo[i].tolist(), batch.hi[i].tolist()), (name, lo[i], hi[i])
    # raw (lo, hi) pairs give the same as an IntervalArray
    assert bits(f.eval((lo, hi))) == bits(batch)


def test_contractor_batch_equals_single_box():
    ctc = CtcFwdBwd(FUNCTIONS["ring"], (1.0, 2.0)) & CtcFwdBwd(FUNCTIONS["x1cosx2"], (0.5, 1.0))
    a, b = _random_intervals(30, 6), _random_intervals(30, 7)[::-1]
    lo = np.array([[p[0], q[0]] for p, q in zip(a, b)])
    hi = np.array([[p[1], q[1]] for p, q in zip(a, b)])
    rlo, rhi = ctc((lo, hi))
    for i in range(len(lo)):
        alone = ctc(IntervalArray._raw(lo[i], hi[i]))
        assert bits(alone) == (rlo[i].tolist(), rhi[i].tolist()), (lo[i], hi[i])


# ---- empty sets and special intervals ------------------------------------------------------------


@pytest.mark.parametrize("name", list(UNARY))
def test_unary_empty_in_empty_out(name):
    res = UNARY[name][0](Interval.empty())
    assert bits(res) == (INF, -INF)
    res = UNARY[name][0](IntervalArray.empty((3, 2)))
    assert np.all(res.lo == INF) and np.all(res.hi == -INF)


@pytest.mark.parametrize("name", list(BINARY))
def test_binary_empty_in_empty_out(name):
    op = BINARY[name][0]
    for other in SPECIAL:
        x = Interval.empty()
        y = IntervalArray._raw(np.asarray(other[0]), np.asarray(other[1]))
        assert bits(op(x, y)) == (INF, -INF), (name, other)
        assert bits(op(y, x)) == (INF, -INF), (name, other)


def test_set_operations_with_empty():
    e, x = Interval.empty(), Interval(1, 2)
    assert bits(e & x) == (INF, -INF)
    assert bits(e | x) == (1.0, 2.0)
    assert bits(Interval(1, 2) & Interval(3, 4)) == (INF, -INF)
    assert bool(Interval.empty().is_empty()) and float(Interval.empty().width()) == 0.0


def test_function_and_contractor_on_empty_boxes():
    lo = np.array([[INF, 0.0], [0.0, 0.0], [1.0, INF]])
    hi = np.array([[-INF, 1.0], [1.0, 1.0], [2.0, -INF]])
    for name, f in FUNCTIONS.items():
        r = f.eval((lo, hi))
        rlo, rhi = np.asarray(r.lo).reshape(3, -1), np.asarray(r.hi).reshape(3, -1)
        assert np.all(rlo[[0, 2]] == INF) and np.all(rhi[[0, 2]] == -INF), name
        assert np.all(rlo[1] <= rhi[1]), name
    rlo, rhi = CtcFwdBwd(FUNCTIONS["ring"], (0.0, 10.0))((lo, hi))
    assert np.all(rlo[[0, 2]] == INF) and np.all(rhi[[0, 2]] == -INF)


@pytest.mark.parametrize("name", list(UNARY))
def test_unary_special_intervals(name):
    op, exact = UNARY[name]
    res = op(arrays(SPECIAL))
    check_valid(res, name)
    for i, (lo, hi) in enumerate(SPECIAL):
        for p in sample_points(lo, hi):
            v = exact(p)
            if v is not None:
                assert inside(res.lo[i].item(), res.hi[i].item(), v), (name, (lo, hi), p, bits(res[i]))


@pytest.mark.parametrize("name", list(BINARY))
def test_binary_special_intervals_exhaustive(name):
    op, exact = BINARY[name]
    a = [p for p in SPECIAL for _ in SPECIAL]
    b = [q for _ in SPECIAL for q in SPECIAL]
    res = op(arrays(a), arrays(b))
    check_valid(res, name)
    for i, (p, q) in enumerate(zip(a, b)):
        rlo, rhi = res.lo[i].item(), res.hi[i].item()
        for x in sample_points(*p)[:3]:
            for y in sample_points(*q)[:3]:
                v = exact(x, y)
                if v is not None:
                    assert inside(rlo, rhi, v), (name, p, q, (x, y), (rlo, rhi))


def test_contractors_never_nan_on_special_boxes():
    ctc = CtcFixPoint(
        CtcFwdBwd(FUNCTIONS["atan2_minus_prod"], (-1.0, 1.0)) & CtcFwdBwd(FUNCTIONS["ring"], (0, 4))
    )
    a = [p for p in SPECIAL for _ in SPECIAL]
    b = [q for _ in SPECIAL for q in SPECIAL]
    lo = np.array([[p[0], q[0]] for p, q in zip(a, b)])
    hi = np.array([[p[1], q[1]] for p, q in zip(a, b)])
    rlo, rhi = ctc((lo, hi))
    assert not (np.isnan(rlo).any() or np.isnan(rhi).any())
    assert np.all((rlo <= rhi) | ((rlo == INF) & (rhi == -INF)))
    assert np.all((rlo >= lo) | (lo > hi).any(axis=1, keepdims=True)) and np.all(
        (rhi <= hi) | (lo > hi).any(axis=1, keepdims=True)
    )


# ---- bad input -----------------------------------------------------------------------------------


def test_interval_lower_above_upper():
    with pytest.raises(ValueError, match="lower bound"):
        IntervalArray(2, 1)
    with pytest.raises(ValueError, match="lower bound"):
        Interval(2, 1)


def test_interval_nan_bounds():
    with pytest.raises(ValueError, match="NaN"):
        IntervalArray(np.nan, 1)
    with pytest.raises(ValueError, match="NaN"):
        IntervalArray([0.0, 1.0], [1.0, np.nan])


def test_interval_infinite_member():
    with pytest.raises(ValueError, match="infinite"):
        IntervalArray(INF, INF)


def test_interval_mismatched_shapes():
    with pytest.raises(ValueError, match="hi"):
        IntervalArray([0.0, 1.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="bounds"):
        Box([(0, 1, 2)])


def test_validate_batch_wrong_dimension():
    with pytest.raises(ValueError, match="boxes.*dimension 3.*expected 2"):
        boxes.validate_batch(np.zeros((4, 3)), np.ones((4, 3)), "boxes", 2)
    with pytest.raises(ValueError, match="mybatch"):
        boxes.validate_batch(np.zeros((4, 2)), np.ones((4, 3)), "mybatch")
    with pytest.raises(ValueError, match="NaN"):
        boxes.validate_batch(np.full((1, 2), np.nan), np.ones((1, 2)))
    with pytest.raises(ValueError, match="lower bound"):
        boxes.validate_batch(np.full((1, 2), 2.0), np.ones((1, 2)))


def test_function_wrong_point_dimension():
    f = FUNCTIONS["ring"]
    with pytest.raises(ValueError, match="x: expected points of dimension 2"):
        f([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="boxes"):
        f.eval(Box([(0, 1), (0, 1), (0, 1)]))


def test_ctc_fwdbwd_y_of_wrong_dimension():
    f = Function(lambda x: (x[0] + x[1], x[0] - x[1]))  # m = 2
    with pytest.raises(ValueError, match="y: expected an interval or a box of dimension 2"):
        CtcFwdBwd(f, IntervalArray([0.0], [1.0]))


@pytest.mark.parametrize("m, ydim", [(2, 3), (1, 2)])
def test_ctc_fwdbwd_y_longer_than_output(m, ydim):
    f = Function(lambda x: (x[0] + x[1], x[0] - x[1])) if m == 2 else FUNCTIONS["ring"]
    with pytest.raises(ValueError, match="y: expected"):
        CtcFwdBwd(f, IntervalArray(np.zeros(ydim), np.ones(ydim)))


def test_ctc_wrong_box_dimension():
    with pytest.raises(ValueError, match="boxes"):
        CtcFwdBwd(FUNCTIONS["ring"], (0.0, 1.0))(Box([(0, 1)] * 3))


def test_ctc_fixpoint_bad_arguments():
    ctc = CtcFwdBwd(FUNCTIONS["ring"], (0.0, 1.0))
    with pytest.raises(ValueError, match="ratio"):
        CtcFixPoint(ctc, ratio=1.5)
    with pytest.raises(ValueError, match="ratio"):
        CtcFixPoint(ctc, ratio=-0.1)
    with pytest.raises(ValueError, match="max_iter"):
        CtcFixPoint(ctc, max_iter=0)


def test_composition_of_mismatched_dimensions():
    c2 = CtcFwdBwd(FUNCTIONS["ring"], (0.0, 1.0))
    c3 = CtcFwdBwd(Function(lambda x: x[0] + x[1] + x[2]), 0.0)
    for combine in (lambda a, b: a & b, lambda a, b: a | b, lambda a, b: a @ b):
        with pytest.raises(ValueError, match="dimension"):
            combine(c2, c3)


def test_pown_non_integer_exponent():
    with pytest.raises(ValueError, match="n"):
        pown(Interval(1, 2), 1.5)


# ---- fixpoint and algebra ------------------------------------------------------------------------

C_RING = CtcFwdBwd(FUNCTIONS["ring"], (1.0, 4.0))
C_COS = CtcFwdBwd(FUNCTIONS["x1cosx2"], (0.5, 1.5))
C_LINE = CtcFwdBwd(Function(lambda x: x[1] - 0.5 * x[0]), (-0.25, 0.25))
X0 = (
    np.array([[-10.0, -10.0], [0.0, 0.0], [1.0, 1.0], [-1.0, 2.0]]),
    np.array([[10.0, 10.0], [4.0, 5.0], [3.0, 1.5], [1.0, 2.5]]),
)


def test_fixpoint_reached():
    """``ratio=0`` iterates to an exact fixpoint: applying it again changes nothing. A ratio > 0 stops
    the same decreasing sequence earlier (one round shrinking by <= ratio does not bound the next
    round, so only this is guaranteed): its result lies between the exact fixpoint and one round."""
    inner = C_RING & C_COS & C_LINE
    lo0, hi0 = CtcFixPoint(inner, ratio=0.0, max_iter=1000)(X0)
    again = CtcFixPoint(inner, ratio=0.0, max_iter=1000)((lo0, hi0))
    assert _same(again, (lo0, hi0))
    assert _same(inner((lo0, hi0)), (lo0, hi0))
    one = inner(X0)
    prev = X0
    for ratio in (0.5, 0.1, 0.01, 0.001):
        r = CtcFixPoint(inner, ratio=ratio, max_iter=1000)(X0)
        assert _subset(r, one).all() and _subset((lo0, hi0), r).all(), ratio
        assert _subset(r, prev).all(), ratio  # a smaller ratio goes at least as far
        prev = r
    # max_iter=1 is one application
    assert _same(CtcFixPoint(inner, max_iter=1)(X0), one)


def _subset(a, b) -> np.ndarray:
    """Row-wise ``a ⊂ b`` (an empty row is a subset of anything)."""
    alo, ahi = a
    blo, bhi = b
    return (alo > ahi).any(axis=1) | ((blo <= alo) & (ahi <= bhi)).all(axis=1)


def _same(a, b) -> bool:
    return a[0].tolist() == b[0].tolist() and a[1].tolist() == b[1].tolist()


def test_algebra_laws():
    c1, c2 = C_RING, C_COS
    r1, r2 = c1(X0), c2(X0)
    inter, union, comp = (c1 & c2)(X0), (c1 | c2)(X0), (c1 @ c2)(X0)
    # contractance
    for r in (r1, r2, inter, union, comp):
        assert _subset(r, X0).all()
    # C1 & C2 ⊂ each, and is exactly their intersection
    assert _subset(inter, r1).all() and _subset(inter, r2).all()
    ilo, ihi = np.maximum(r1[0], r2[0]), np.minimum(r1[1], r2[1])
    assert _subset(inter, (ilo, ihi)).all() and _subset((ilo, ihi), inter).all()
    # C1 | C2 ⊃ each, and is exactly their hull
    assert _subset(r1, union).all() and _subset(r2, union).all()
    # C1 @ C2 runs C2 first: ⊂ C2(X), and equals C1(C2(X))
    assert _subset(comp, r2).all()
    assert _same(comp, c1(r2))
    # commutativity and idempotence of & and |
    assert _same(inter, (c2 & c1)(X0)) and _same(union, (c2 | c1)(X0))
    assert _same((c1 & c1)(X0), r1) and _same((c1 | c1)(X0), r1)
    # associativity of the n-ary forms
    c3 = C_LINE
    assert _same(((c1 & c2) & c3)(X0), (c1 & (c2 & c3))(X0))
    assert _same(((c1 | c2) | c3)(X0), (c1 | (c2 | c3))(X0))
    assert _same(((c1 @ c2) @ c3)(X0), (c1 @ (c2 @ c3))(X0))
    # a contractor that empties everything is neutral for | and absorbing for &
    none = CtcFwdBwd(FUNCTIONS["ring"], (-2.0, -1.0))
    assert (none(X0)[0] == INF).all()
    assert _same((c1 | none)(X0), r1)
    assert ((c1 & none)(X0)[0] == INF).all() and ((c1 @ none)(X0)[0] == INF).all()


def test_contractor_leaves_input_untouched_and_keeps_intervalarray_type():
    lo, hi = X0[0].copy(), X0[1].copy()
    CtcFixPoint(C_RING @ C_COS)((lo, hi))
    assert _same((lo, hi), X0)
    box = Box([(0, 4), (0, 5)])
    r = (C_RING & C_COS)(box)
    assert isinstance(r, IntervalArray) and r.shape == (2,)
    assert bool(r.issubset(box).all())
