"""Directed rounding (observer/core/rounding.py) against exact rational arithmetic, and the libm error bound.

* ``+ - * /`` and ``sqrt``: ``*_down(a, b) <= exact <= *_up(a, b)`` with the exact value computed by
  :class:`fractions.Fraction`, on random floats over the whole binary64 range (huge, tiny, subnormal,
  signed zeros, infinities). In the range where the error-free transformations are exact the bounds
  are *tight* (equal when the exact value is a float, one ulp apart otherwise); outside it the module
  steps one ulp outward unconditionally (documented), so only a two-ulp bracket is required there.
* numpy's transcendental functions are within :data:`LIBM_ULPS` ulps of mpmath at 50 digits.
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.observer.core import rounding as rnd

MAX = float(np.finfo(np.float64).max)
TINY_SUB = 5e-324
SAFE_LO, SAFE_HI = 2.0**-900, 2.0**900  # operands and results where the tight path is certain

SPECIALS = [
    0.0, -0.0, 1.0, -1.0, 0.5, 3.0, 0.1, -0.1, MAX, -MAX, TINY_SUB, -TINY_SUB, 2.2250738585072014e-308,
    -2.2250738585072014e-308, 2.225073858507201e-308, 1e308, -1e308, 1e-308, 2.0**-1022, 2.0**-1074 * 3,
    2.0**995, 2.0**996, 2.0**-960, 2.0**-961, 2.0**53, 2.0**53 + 2, 1 + 2.0**-52, 1 - 2.0**-53, math.pi,
    math.inf, -math.inf,
]  # fmt: skip


def random_floats(rng: np.random.Generator, size: int) -> np.ndarray:
    """Floats spread over every binade (random sign, exponent and mantissa bits), plus specials."""
    bits = rng.integers(0, 2**63, size=size, dtype=np.uint64) | (
        rng.integers(0, 2, size=size, dtype=np.uint64) << np.uint64(63)
    )
    x = bits.view(np.float64)
    x = np.where(np.isnan(x), 1.0, x)  # the all-ones exponent: NaN or inf; keep a plain number
    # a third of the values at moderate magnitudes, where cancellation and exact results are common
    mod = rng.choice([-1.0, 1.0], size) * np.ldexp(rng.integers(1, 2**12, size), rng.integers(-20, 20, size))
    x = np.where(rng.random(size) < 0.33, mod, x)
    spec = np.array(SPECIALS)[rng.integers(0, len(SPECIALS), size)]
    return np.where(rng.random(size) < 0.1, spec, x)


def fr(x: float) -> Fraction:
    return Fraction(float(x))


def directed(v: Fraction, up: bool) -> float:
    """The float nearest ``v`` in the given direction (±inf beyond the range)."""
    try:
        f = float(v)
    except OverflowError:
        f = math.inf if v > 0 else -math.inf
    if math.isinf(f):
        if up:
            return f if f > 0 else -MAX
        return -math.inf if f < 0 else MAX
    if up and Fraction(f) < v:
        f = math.nextafter(f, math.inf)
    if not up and Fraction(f) > v:
        f = math.nextafter(f, -math.inf)
    return f


def exact_op(op: str, a: float, b: float) -> Fraction | float | None:
    """Exact result, or a float ±inf for defined infinite results, or None where undefined."""
    if math.isinf(a) or math.isinf(b):
        with np.errstate(all="ignore"):
            r = {"add": np.add, "sub": np.subtract, "mul": np.multiply, "div": np.divide}[op](a, b)
        if op == "div" and b == 0:
            return None
        return None if math.isnan(r) else float(r)
    A, B = fr(a), fr(b)
    if op == "add":
        return A + B
    if op == "sub":
        return A - B
    if op == "mul":
        return A * B
    if b == 0:
        return None
    return A / B


def in_safe_range(op: str, a: float, b: float, exact: Fraction) -> bool:
    mags = [abs(a), abs(b)]
    if op == "add" or op == "sub":  # TwoSum is exact everywhere the sum does not overflow
        return abs(exact) <= MAX
    if any(m != 0 and not (SAFE_LO <= m <= SAFE_HI) for m in mags):
        return False
    return exact == 0 or SAFE_LO <= abs(exact) <= SAFE_HI


OPS = {
    "add": (rnd.add_down, rnd.add_up),
    "sub": (rnd.sub_down, rnd.sub_up),
    "mul": (rnd.mul_down, rnd.mul_up),
    "div": (rnd.div_down, rnd.div_up),
}


def check_binary(op: str, a: np.ndarray, b: np.ndarray) -> None:
    down_f, up_f = OPS[op]
    down, up = down_f(a, b), up_f(a, b)
    failures = []
    for x, y, d, u in zip(a.tolist(), b.tolist(), down.tolist(), up.tolist()):
        ex = exact_op(op, x, y)
        if ex is None:
            continue
        if isinstance(ex, float):  # infinite operand, defined result: exact in the extended reals
            if not (d == ex == u):
                failures.append((x, y, d, u, ex))
            continue
        if (
            math.isnan(d)
            or math.isnan(u)
            or not ((d == -math.inf or Fraction(d) <= ex) and (u == math.inf or ex <= Fraction(u)))
        ):
            failures.append((x, y, d, u, "unsound"))
            continue
        lo_t, hi_t = directed(ex, up=False), directed(ex, up=True)
        if in_safe_range(op, x, y, ex):
            if (d, u) != (lo_t, hi_t):
                failures.append((x, y, d, u, f"not tight: expected [{lo_t!r}, {hi_t!r}]"))
        elif not (d >= math.nextafter(lo_t, -math.inf) and u <= math.nextafter(hi_t, math.inf)):
            failures.append((x, y, d, u, f"more than one ulp outward of [{lo_t!r}, {hi_t!r}]"))
    assert not failures, f"{op}: {len(failures)} failures, first: {failures[:5]}"


@pytest.mark.parametrize("op", list(OPS))
def test_binary_random_all_binades(op):
    rng = np.random.default_rng(1788 + len(op) + ord(op[0]))
    a, b = random_floats(rng, 6000), random_floats(rng, 6000)
    check_binary(op, a, b)


@pytest.mark.parametrize("op", list(OPS))
def test_binary_specials_exhaustive(op):
    s = np.array(SPECIALS)
    a, b = np.meshgrid(s, s)
    check_binary(op, a.ravel(), b.ravel())


@pytest.mark.parametrize("op", ["add", "sub"])
def test_cancellation_and_near_ties(op):
    """Sums that cancel or land exactly half-way between floats (the TwoSum corner cases)."""
    rng = np.random.default_rng(7)
    a = np.ldexp(rng.integers(2**52, 2**53, 3000).astype(np.float64), rng.integers(-60, 60, 3000))
    shift = rng.integers(50, 56, 3000)
    b = np.ldexp(rng.integers(1, 8, 3000).astype(np.float64), np.frexp(a)[1] - shift)
    b = np.where(rng.random(3000) < 0.5, -b, b)
    check_binary(op, a, b)
    check_binary(op, a, -np.nextafter(a, 0))


finite_floats = st.floats(allow_nan=False, allow_infinity=True, allow_subnormal=True)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(finite_floats, finite_floats), min_size=1, max_size=16))
def test_binary_hypothesis(pairs):
    a = np.array([p[0] for p in pairs])
    b = np.array([p[1] for p in pairs])
    for op in OPS:
        check_binary(op, a, b)


def check_sqrt(a: np.ndarray) -> None:
    down, up = rnd.sqrt_down(a), rnd.sqrt_up(a)
    failures = []
    for x, d, u in zip(a.tolist(), down.tolist(), up.tolist()):
        if x < 0:
            continue
        if x == math.inf:
            if not d == u == math.inf:
                failures.append((x, d, u))
            continue
        X = fr(x)
        if math.isnan(d) or math.isnan(u) or not (d >= 0 and fr(d) ** 2 <= X <= fr(u) ** 2):
            failures.append((x, d, u, "unsound"))
            continue
        s = math.sqrt(x)  # correctly rounded (IEEE 754)
        s2 = fr(s) ** 2
        lo_t = s if s2 <= X else math.nextafter(s, -math.inf)
        hi_t = s if s2 >= X else math.nextafter(s, math.inf)
        if x == 0 or SAFE_LO <= x <= SAFE_HI:
            if (d, u) != (lo_t, hi_t):
                failures.append((x, d, u, f"not tight: expected [{lo_t!r}, {hi_t!r}]"))
        elif not (d >= math.nextafter(lo_t, -math.inf) and u <= math.nextafter(hi_t, math.inf)):
            failures.append((x, d, u, f"more than one ulp outward of [{lo_t!r}, {hi_t!r}]"))
    assert not failures, f"sqrt: {len(failures)} failures, first: {failures[:5]}"


def test_sqrt_random_all_binades():
    rng = np.random.default_rng(42)
    a = np.abs(random_floats(rng, 8000))
    squares = np.ldexp(
        rng.integers(1, 2**26, 2000).astype(np.float64) ** 2, 2 * rng.integers(-520, 485, 2000)
    )
    check_sqrt(np.concatenate([a, squares, np.abs(np.array(SPECIALS))]))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(min_value=0.0, allow_nan=False), min_size=1, max_size=32))
def test_sqrt_hypothesis(xs):
    check_sqrt(np.array(xs))


def test_next_and_widen():
    x = np.array([0.0, 1.0, -1.0, MAX, -MAX, math.inf, -math.inf, TINY_SUB])
    assert np.all(rnd.next_down(x[:-3]) < x[:-3]) and np.all(rnd.next_up(x[:-3]) > x[:-3])
    assert rnd.next_up(np.array(-math.inf))[()] == -MAX
    assert rnd.next_down(np.array(-math.inf))[()] == -math.inf
    assert rnd.next_up(np.array(math.inf))[()] == math.inf
    assert rnd.widen_up(np.array(1.0), 3)[()] == 1 + 3 * 2.0**-52
    assert rnd.widen_down(np.array(1.0), 2)[()] == 1 - 2 * 2.0**-53
    assert rnd.PI_UP == math.nextafter(rnd.PI_DOWN, math.inf)
    with mpmath.workdps(50):
        pi = +mpmath.pi
        for lo, hi, k in (
            (rnd.PI_DOWN, rnd.PI_UP, 1),
            (rnd.HALF_PI_DOWN, rnd.HALF_PI_UP, 0.5),
            (rnd.TWO_PI_DOWN, rnd.TWO_PI_UP, 2),
        ):
            assert mpmath.mpf(lo) < k * pi < mpmath.mpf(hi)


# ---- libm accuracy -------------------------------------------------------------------------------

N_LIBM = 20_000


def _log_uniform(rng: np.random.Generator, lo_exp: float, hi_exp: float, n: int, signed: bool = True):
    x = np.exp2(rng.uniform(lo_exp, hi_exp, n))
    return x * rng.choice([-1.0, 1.0], n) if signed else x


def _args(name: str, rng: np.random.Generator) -> tuple[np.ndarray, ...]:
    n = N_LIBM
    q = n // 4
    if name == "exp":
        return (
            np.concatenate(
                [rng.uniform(-745, 709.7, q), rng.uniform(-5, 5, q), _log_uniform(rng, -60, 3, 2 * q)]
            ),
        )
    if name == "log":
        return (np.concatenate([
            _log_uniform(rng, -1074, 1024, q, signed=False), rng.uniform(0.5, 2, q),
            1 + rng.uniform(-1e-6, 1e-6, q), _log_uniform(rng, -20, 20, q, signed=False),
        ]),)  # fmt: skip
    if name in ("sin", "cos", "tan"):
        return (np.concatenate([
            rng.uniform(-7, 7, q), rng.uniform(-1000, 1000, q), _log_uniform(rng, -40, 50, q),
            np.pi / 2 * rng.integers(-1000, 1000, q) + rng.uniform(-1e-9, 1e-9, q),
        ]),)  # fmt: skip
    if name == "atan":
        return (np.concatenate([rng.uniform(-4, 4, 2 * q), _log_uniform(rng, -100, 100, 2 * q)]),)
    if name in ("asin", "acos"):
        return (np.concatenate([
            rng.uniform(-1, 1, 2 * q), rng.choice([-1.0, 1.0], q) * (1 - _log_uniform(rng, -53, -3, q, signed=False)),
            _log_uniform(rng, -60, -1, q),
        ]),)  # fmt: skip
    assert name == "atan2"
    y = np.concatenate([rng.uniform(-10, 10, 2 * q), _log_uniform(rng, -300, 300, 2 * q)])
    x = np.concatenate([rng.uniform(-10, 10, 2 * q), _log_uniform(rng, -300, 300, 2 * q)])
    return y, x


LIBM = {
    "exp": (np.exp, mpmath.exp),
    "log": (np.log, mpmath.log),
    "sin": (np.sin, mpmath.sin),
    "cos": (np.cos, mpmath.cos),
    "tan": (np.tan, mpmath.tan),
    "atan": (np.arctan, mpmath.atan),
    "asin": (np.arcsin, mpmath.asin),
    "acos": (np.arccos, mpmath.acos),
    "atan2": (np.arctan2, mpmath.atan2),
}


@pytest.mark.parametrize("name", list(LIBM))
def test_libm_within_libm_ulps(name):
    """numpy's result widened by LIBM_ULPS ulps must bracket the exact value (mpmath, 50 digits)."""
    np_fn, mp_fn = LIBM[name]
    rng = np.random.default_rng(sum(map(ord, name)))
    args = _args(name, rng)
    with np.errstate(all="ignore"):
        got = np_fn(*args)
    lo, hi = rnd.widen_down(got), rnd.widen_up(got)
    worst, worst_at, bad = 0.0, None, []
    with mpmath.workdps(50):
        for i in range(len(got)):
            g = float(got[i])
            ex = mp_fn(*(mpmath.mpf(float(a[i])) for a in args))
            if not math.isfinite(g):
                continue  # overflow to inf: the kernels treat it separately
            spacing = math.ulp(abs(g)) if g != 0 else TINY_SUB
            err = float(abs(mpmath.mpf(g) - ex) / spacing)
            if err > worst:
                worst, worst_at = err, tuple(float(a[i]) for a in args)
            if not (mpmath.mpf(float(lo[i])) <= ex <= mpmath.mpf(float(hi[i]))):
                bad.append(tuple(float(a[i]) for a in args))
    msg = f"{name}: max observed error {worst:.3f} ulps at {worst_at} (LIBM_ULPS = {rnd.LIBM_ULPS})"
    assert not bad, f"{msg}; {len(bad)} arguments outside the widened result, e.g. {bad[:3]}"
    assert worst <= rnd.LIBM_ULPS, msg


@pytest.mark.parametrize("op", ["add", "sub", "mul", "div", "sqrt"])
def test_step_bounds_round_to_nearest_results(op):
    """step_down(fl(a op b)) <= a op b <= step_up(fl(a op b)), at most one ulp beyond the directed result."""
    rng = np.random.default_rng(7)
    a, b = random_floats(rng, 4000), random_floats(rng, 4000)
    if op == "sqrt":
        a = np.abs(a)
    fn = {"add": np.add, "sub": np.subtract, "mul": np.multiply, "div": np.divide}.get(op)
    with np.errstate(all="ignore"):
        r = np.sqrt(a) if op == "sqrt" else fn(a, b)
    lo, hi = rnd.step_down(r), rnd.step_up(r)
    bad = []
    for i in range(a.size):
        x, y = float(a[i]), float(b[i])
        if op == "sqrt":
            if math.isinf(x):
                continue
            ex = mpmath.sqrt(mpmath.mpf(x))
            ok = mpmath.mpf(float(lo[i])) <= ex <= mpmath.mpf(float(hi[i]))
        else:
            ex = exact_op(op, x, y)
            if ex is None or isinstance(ex, float):
                continue
            ok = (lo[i] == -math.inf or Fraction(float(lo[i])) <= ex) and (
                hi[i] == math.inf or ex <= Fraction(float(hi[i]))
            )
            if ok and abs(ex) <= MAX:
                ok = lo[i] >= math.nextafter(directed(ex, False), -math.inf) and hi[i] <= math.nextafter(
                    directed(ex, True), math.inf
                )
        if not ok:
            bad.append((x, y, float(r[i]), float(lo[i]), float(hi[i])))
    assert not bad, f"{op}: {len(bad)} failures, first {bad[:3]}"
    assert rnd.step_up(np.array([np.inf, -np.inf])).tolist() == [np.inf, -MAX]
    assert rnd.step_down(np.array([np.inf, -np.inf])).tolist() == [MAX, -np.inf]
