"""Property tests of the interval core: inclusion and contractor soundness, against exact values.

* Inclusion: for random boxes ``[x]`` and points ``x ∈ [x]``, the exact ``f(x)`` (``Fraction`` for
  rational operations, mpmath at 50 digits otherwise) lies in ``[f]([x])``, for every primitive and
  a few composite functions.
* Contractor soundness: for a point ``x`` and ``y = f(x)`` computed exactly, ``CtcFwdBwd(f, [y])``
  with ``[y]`` the two floats around ``y`` (a point interval when ``y`` is a float) never removes
  ``x`` from any box that holds it; the same for ``&``, ``|``, ``@`` and :class:`CtcFixPoint`.

Each hypothesis example draws a seed and a few floats of its own choice (injected as points and
bounds), then evaluates a batch of 64 boxes built by numpy from that seed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.observer import (
    CtcFixPoint,
    CtcFwdBwd,
    Function,
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
    sqrt,
    tan,
)
from digslam.observer.core import rounding as rnd

N_BOXES = 64
MAX = float(np.finfo(np.float64).max)
SETTINGS = settings(max_examples=200, deadline=None)
#: contractor runs cost ~5 ms a call in the library: fewer examples keep the file under ~40 s on 2 cores
CTC_SETTINGS = settings(max_examples=100, deadline=None)
mp = mpmath.mpf
Exact = Fraction | mpmath.mpf | None

# ---- reference values ----------------------------------------------------------------------------


def F(x: float) -> Fraction:
    return Fraction(float(x))


def _div(a: float, b: float) -> Exact:
    return None if b == 0 else F(a) / F(b)


def _pown(n: int) -> Callable[[float], Exact]:
    def ex(a: float) -> Exact:
        if n < 0 and a == 0:
            return None
        return F(a) ** n

    return ex


def _near_float(v: mpmath.mpf) -> bool:
    """Whether 50 digits cannot tell ``v`` from a float (``exp(1e-300)``, ``cos(1e-100)``, or a float)."""
    f = float(v)
    return math.isfinite(f) and abs(v - mp(f)) <= abs(v) * mp(2) ** -150


def _mp(fn: Callable[..., mpmath.mpf]) -> Callable[..., mpmath.mpf]:
    """``fn`` on mpf arguments at 50 digits, again at 2600 bits when the result is that close to a
    float (the distance from a transcendental value to a float is at least ~2⁻²²⁰⁰ relative)."""

    def ex(*a: float) -> mpmath.mpf:
        with mpmath.workdps(50):
            v = fn(*(mp(x) for x in a))
            near = _near_float(v)
        if near:
            with mpmath.workprec(2600):
                v = fn(*(mp(x) for x in a))
        return v

    return ex


def _dom(pred: Callable[..., bool], fn: Callable[..., mpmath.mpf]) -> Callable[..., Exact]:
    f = _mp(fn)
    return lambda *a: f(*a) if pred(*a) else None


_atan2 = _mp(mpmath.atan2)
_mixed = _mp(lambda x1, x2: mpmath.atan2(x2, x1) - x1 * x2)


def _atan2_exact(y: float, x: float) -> Exact:
    return None if (y == 0 and x == 0) else _atan2(y, x)


def _mixed_exact(x1: float, x2: float) -> Exact:
    return None if (x1 == 0 and x2 == 0) else _mixed(x1, x2)


# name -> (Function, exact reference on python floats)
PRIMITIVES: dict[str, tuple[Function, Callable[..., Exact]]] = {
    "add": (Function(lambda x: x[0] + x[1]), lambda a, b: F(a) + F(b)),
    "sub": (Function(lambda x: x[0] - x[1]), lambda a, b: F(a) - F(b)),
    "mul": (Function(lambda x: x[0] * x[1]), lambda a, b: F(a) * F(b)),
    "div": (Function(lambda x: x[0] / x[1]), _div),
    "neg": (Function(lambda x: -x[0]), lambda a: -F(a)),
    "sqr": (Function(lambda x: x[0] ** 2), lambda a: F(a) ** 2),
    "sqrt": (Function(lambda x: sqrt(x[0])), _dom(lambda a: a >= 0, mpmath.sqrt)),
    "exp": (Function(lambda x: exp(x[0])), _dom(lambda a: True, mpmath.exp)),
    "log": (Function(lambda x: log(x[0])), _dom(lambda a: a > 0, mpmath.log)),
    "sin": (Function(lambda x: sin(x[0])), _dom(lambda a: True, mpmath.sin)),
    "cos": (Function(lambda x: cos(x[0])), _dom(lambda a: True, mpmath.cos)),
    "tan": (Function(lambda x: tan(x[0])), _dom(lambda a: True, mpmath.tan)),
    "asin": (Function(lambda x: asin(x[0])), _dom(lambda a: -1 <= a <= 1, mpmath.asin)),
    "acos": (Function(lambda x: acos(x[0])), _dom(lambda a: -1 <= a <= 1, mpmath.acos)),
    "atan": (Function(lambda x: atan(x[0])), _dom(lambda a: True, mpmath.atan)),
    "atan2": (Function(lambda x: atan2(x[0], x[1])), _atan2_exact),
    "abs": (Function(lambda x: abs_(x[0])), lambda a: abs(F(a))),
    "min": (Function(lambda x: minimum(x[0], x[1])), lambda a, b: min(F(a), F(b))),
    "max": (Function(lambda x: maximum(x[0], x[1])), lambda a, b: max(F(a), F(b))),
}
POWN = {n: (Function(lambda x, n=n: pown(x[0], n)), _pown(n)) for n in range(-3, 6)}
COMPOSITES: dict[str, tuple[Function, Callable[..., Exact]]] = {
    "ring": (Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2), lambda a, b: (F(a) - 2) ** 2 + (F(b) - Fraction(5, 2)) ** 2),
    "x1cosx2": (Function(lambda x: x[0] * cos(x[1])), _mp(lambda a, b: a * mpmath.cos(b))),
    "atan2_minus_prod": (Function(lambda x: atan2(x[1], x[0]) - x[0] * x[1]), _mixed_exact),
    "gauss_sin": (Function(lambda x: exp(-x[0] ** 2) * sin(3 * x[0])), _mp(lambda a: mpmath.exp(-a**2) * mpmath.sin(3 * a))),
}  # fmt: skip
ALL = {**PRIMITIVES, **{f"pown{n}": v for n, v in POWN.items()}, **COMPOSITES}


def inside(lo: float, hi: float, v: Fraction | mpmath.mpf) -> bool:
    """``lo <= v <= hi`` exactly (``v`` a Fraction or an mpf)."""
    if isinstance(v, Fraction):
        return (lo == -math.inf or (lo != math.inf and Fraction(lo) <= v)) and (
            hi == math.inf or (hi != -math.inf and v <= Fraction(hi))
        )
    return mp(lo) <= v <= mp(hi)


def float_down(v: Fraction | mpmath.mpf) -> float:
    """Largest float <= v (``MAX`` above the range, ``-inf`` below it); comparisons only, no rounding."""
    if isinstance(v, Fraction) and abs(v) > MAX:
        f = math.inf if v > 0 else -math.inf
    else:
        f = float(v)
    if math.isinf(f):
        return MAX if f > 0 else -math.inf
    if (F(f) > v) if isinstance(v, Fraction) else (mp(f) > v):
        f = math.nextafter(f, -math.inf)
    return f


def float_up(v: Fraction | mpmath.mpf) -> float:
    """Smallest float >= v."""
    if isinstance(v, Fraction) and abs(v) > MAX:
        f = math.inf if v > 0 else -math.inf
    else:
        f = float(v)
    if math.isinf(f):
        return -MAX if f < 0 else math.inf
    if (F(f) < v) if isinstance(v, Fraction) else (mp(f) < v):
        f = math.nextafter(f, math.inf)
    return f


# ---- batches of boxes ------------------------------------------------------------------------------

HALF_PI = math.pi / 2


def _values(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    """A mixture: moderate, unit, small integers, log-uniform magnitudes, huge, near multiples of π/2."""
    size = int(np.prod(shape))
    sign = rng.choice([-1.0, 1.0], size)
    comps = [
        rng.uniform(-4, 4, size),
        rng.uniform(-1.1, 1.1, size),
        rng.integers(-3, 4, size).astype(float),
        sign * np.exp2(rng.uniform(-60, 60, size)),
        sign * np.exp2(rng.uniform(-1074, 1023, size)),
        HALF_PI * rng.integers(-8, 9, size) * (1 + rng.integers(-4, 5, size) * 2.0**-52),
        sign * 0.0,
    ]
    k = rng.choice(len(comps), size, p=[0.25, 0.15, 0.12, 0.18, 0.05, 0.15, 0.10])
    return np.choose(k, comps).reshape(shape)


def make_boxes(seed: int, specials: list[float], n: int, m: int = N_BOXES):
    """``(lo, pt, hi)`` arrays ``(m, n)`` with ``lo <= pt <= hi``, ``pt`` finite, some infinite bounds."""
    rng = np.random.default_rng(seed)
    # half: three sorted values; half: a centre and two widths (narrow boxes)
    tri = np.sort(_values(rng, (m, n, 3)), axis=-1)
    lo, pt, hi = tri[..., 0], tri[..., 1], tri[..., 2]
    c = _values(rng, (m, n))
    w1, w2 = np.exp2(rng.uniform(-50, 3, (2, m, n))) * (rng.random((2, m, n)) < 0.9)
    with np.errstate(over="ignore", invalid="ignore"):
        nlo, nhi = c - w1 * np.maximum(1, abs(c)), c + w2 * np.maximum(1, abs(c))
        npt = np.clip(nlo + rng.random((m, n)) * (nhi - nlo), nlo, nhi)
    npt = np.where(rng.random((m, n)) < 0.3, c, npt)
    narrow = (rng.random((m, 1)) < 0.5) & np.isfinite(nlo) & np.isfinite(nhi) & np.isfinite(npt)
    lo, pt, hi = np.where(narrow, nlo, lo), np.where(narrow, npt, pt), np.where(narrow, nhi, hi)
    # points drawn by hypothesis replace some points (the box grows to hold them)
    for s in specials:
        i, j = rng.integers(m), rng.integers(n)
        pt[i, j] = s
        lo[i, j], hi[i, j] = min(lo[i, j], s), max(hi[i, j], s)
        if rng.random() < 0.5:  # and sometimes sit on a bound
            (lo if rng.random() < 0.5 else hi)[i, j] = s
    # a point on a bound, and half-lines
    on = rng.random((m, n))
    pt = np.where(on < 0.05, lo, np.where(on < 0.1, hi, pt))
    lo = np.where(rng.random((m, n)) < 0.05, -np.inf, lo)
    hi = np.where(rng.random((m, n)) < 0.05, np.inf, hi)
    return lo + 0.0, pt + 0.0, hi + 0.0


specials_st = st.lists(
    st.one_of(
        st.floats(allow_nan=False, allow_infinity=False),
        st.floats(-10, 10),
        st.sampled_from([0.0, -0.0, 1.0, -1.0, 2.0, 2.5, math.pi, -math.pi, HALF_PI, -HALF_PI, 1e-300]),
    ),
    max_size=6,
)
seed_st = st.integers(0, 2**32 - 1)


# ---- inclusion -------------------------------------------------------------------------------------


def check_inclusion(
    f: Function, exact: Callable[..., Exact], seed: int, specials: list[float], prefilter: bool = True
) -> None:
    """Exact ``f(pt)`` in ``[f](box)``. With ``prefilter`` (single primitives only, whose numpy value is
    within 4 ulps: see test_rounding.py) points whose numpy value is 16 ulps inside the enclosure are
    accepted without the exact evaluation; the others (near a bound, non-finite) are checked exactly."""
    lo, pt, hi = make_boxes(seed, specials, f.n)
    res = f.eval(IntervalArray(lo, hi))
    rlo, rhi = res.lo, res.hi
    assert not (np.isnan(rlo).any() or np.isnan(rhi).any()), "NaN bound"
    todo = np.arange(len(pt))
    if prefilter:
        fp = f(pt)
        clear = np.isfinite(fp) & (rnd.widen_down(fp, 16) > rlo) & (rnd.widen_up(fp, 16) < rhi)
        todo = todo[~clear]
    bad = []
    for i in todo.tolist():
        v = exact(*pt[i].tolist())
        if v is None:
            continue
        if not inside(float(rlo[i]), float(rhi[i]), v):
            bad.append((lo[i].tolist(), hi[i].tolist(), pt[i].tolist(), float(rlo[i]), float(rhi[i]), str(v)))
    assert not bad, (
        f"{len(bad)} points outside [f](box): (box lo, box hi, point, [f] lo, [f] hi, f(point)) {bad[:3]}"
    )


@pytest.mark.parametrize("name", list(PRIMITIVES) + list(COMPOSITES))
@SETTINGS
@given(seed=seed_st, specials=specials_st)
def test_inclusion(name, seed, specials):
    check_inclusion(*ALL[name], seed, specials, prefilter=name in PRIMITIVES)


@SETTINGS
@given(n=st.integers(-3, 5), seed=seed_st, specials=specials_st)
def test_inclusion_pown(n, seed, specials):
    check_inclusion(*POWN[n], seed, specials)


def test_inclusion_atan2_cut_and_origin():
    """Boxes that hold the origin, touch it, or straddle the cut ``{x < 0, y = 0}``."""
    f, exact = PRIMITIVES["atan2"]
    ys = [(-1.0, 1.0), (0.0, 1.0), (-1.0, 0.0), (0.0, 0.0), (-1e-300, 1e-300), (-5e-324, 0.0), (2.0, 3.0)]
    xs = [(-2.0, -1.0), (-1.0, 0.0), (-1.0, 1.0), (0.0, 0.0), (0.0, 2.0), (-math.inf, -1.0), (-3.0, math.inf)]
    lo, hi, pts = [], [], []
    for y in ys:
        for x in xs:
            for py in {y[0], y[1], 0.5 * (y[0] + y[1])}:
                for px in {x[0], x[1], -1.0, 0.0}:
                    if x[0] <= px <= x[1] and math.isfinite(px):
                        lo.append((y[0], x[0]))
                        hi.append((y[1], x[1]))
                        pts.append((py, px))
    res = f.eval(IntervalArray(np.array(lo), np.array(hi)))
    with mpmath.workdps(50):
        for i, p in enumerate(pts):
            v = exact(*p)
            if v is not None:
                assert inside(float(res.lo[i]), float(res.hi[i]), v), (lo[i], hi[i], p, res[i])


# ---- contractor soundness --------------------------------------------------------------------------


def anchored(seed: int, specials: list[float], exact_fns, n: int, halves: int = 1):
    """Batches of boxes around anchor points ``x0``, with ``f(x0)`` exact for each ``f``.

    Yields ``(x0, lo, hi, [exact f(x0) for f])`` for up to ``halves`` anchors of ``N_BOXES // halves``
    boxes each, skipping anchors where some ``f`` is undefined.
    """
    lo, pt, hi = make_boxes(seed, specials, n)
    k = N_BOXES // halves
    for h in range(halves):
        rows = slice(h * k, (h + 1) * k)
        for cand in range(h * k, (h + 1) * k):
            x0 = pt[cand]
            ys = [fn(*x0.tolist()) for fn in exact_fns]
            if all(y is not None for y in ys):
                break
        else:
            continue
        yield x0, np.minimum(lo[rows], x0), np.maximum(hi[rows], x0), ys


def y_interval(v, widen: bool) -> tuple[float, float]:
    """The floats around the exact ``v`` (a point interval when ``v`` is a float)."""
    ylo, yhi = float_down(v), float_up(v)
    if widen:
        d = 1e-9 * max(1.0, abs(ylo), abs(yhi))
        ylo, yhi = ylo - d, yhi + d
    return ylo, yhi


def assert_keeps(ctc, x0: np.ndarray, lo: np.ndarray, hi: np.ndarray, what: str) -> None:
    rlo, rhi = ctc((lo, hi))
    assert not (np.isnan(rlo).any() or np.isnan(rhi).any()), f"{what}: NaN bound"
    kept = ((rlo <= x0) & (x0 <= rhi)).all(axis=1)
    if not kept.all():
        i = int(np.flatnonzero(~kept)[0])
        raise AssertionError(
            f"{what}: removed x0={x0.tolist()} from box lo={lo[i].tolist()} hi={hi[i].tolist()} "
            f"-> lo={rlo[i].tolist()} hi={rhi[i].tolist()} ({int((~kept).sum())}/{len(kept)} boxes)"
        )


def check_contractor(f: Function, exact, seed: int, specials: list[float], widen: bool) -> None:
    with mpmath.workdps(50):
        for x0, lo, hi, (v,) in anchored(seed, specials, [exact], f.n):
            y = y_interval(v, widen)
            assert_keeps(CtcFwdBwd(f, y), x0, lo, hi, f"CtcFwdBwd(f, {y}) at f(x0) = {v}")


@pytest.mark.parametrize("name", list(PRIMITIVES) + list(COMPOSITES))
@CTC_SETTINGS
@given(seed=seed_st, specials=specials_st, widen=st.booleans())
def test_contractor_sound(name, seed, specials, widen):
    check_contractor(*ALL[name], seed, specials, widen)


@SETTINGS
@given(n=st.integers(-3, 5), seed=seed_st, specials=specials_st, widen=st.booleans())
def test_contractor_sound_pown(n, seed, specials, widen):
    check_contractor(*POWN[n], seed, specials, widen)


VEC = Function(lambda x: ((x[0] - 2) ** 2 + (x[1] - 2.5) ** 2, x[0] * cos(x[1])))
G4 = Function(lambda x: exp(-(x[0] ** 2)) * sin(3 * x[0]), n=2)


def _algebra_cases(seed: int, specials: list[float], widen: bool, fixpoints: bool):
    fns = [COMPOSITES[k] for k in ("ring", "x1cosx2", "atan2_minus_prod")] + [
        (G4, COMPOSITES["gauss_sin"][1])
    ]
    exacts = [fns[0][1], fns[1][1], fns[2][1], lambda a, b: fns[3][1](a)]
    for x0, lo, hi, ys in anchored(seed, specials, exacts, 2):
        c1, c2, c3, c4 = (CtcFwdBwd(f, y_interval(v, widen)) for (f, _), v in zip(fns, ys))
        bad = CtcFwdBwd(fns[0][0], (-2.0, -1.0))  # the ring is never negative: no solution at all
        if not fixpoints:
            cases = {  # every operator, each operand of | both kept and empty, nested compositions
                "C1 & C2": c1 & c2,
                "C2 | bad": c2 | bad,
                "C3 @ C1": c3 @ c1,
                "(bad | C4) @ (C3 & C2)": (bad | c4) @ (c3 & c2),
            }
        else:
            vec_y = IntervalArray([float_down(ys[0]), float_down(ys[1])], [float_up(ys[0]), float_up(ys[1])])
            cases = {
                "fixpoint(C1 & C3)": CtcFixPoint(c1 & c3, max_iter=6),
                "fixpoint(C2 @ C4, ratio=0)": CtcFixPoint(c2 @ c4, ratio=0.0, max_iter=6),
                "fixpoint(vector f, ratio=0)": CtcFixPoint(CtcFwdBwd(VEC, vec_y), ratio=0.0, max_iter=6),
            }
        for what, ctc in cases.items():
            assert_keeps(ctc, x0, lo, hi, what)


@settings(max_examples=60, deadline=None)  # 10 contractor calls an example
@given(seed=seed_st, specials=specials_st, widen=st.booleans())
def test_contractor_algebra_sound(seed, specials, widen):
    _algebra_cases(seed, specials, widen, fixpoints=False)


@settings(max_examples=15, deadline=None)  # a fixpoint costs up to 6 rounds of 2 contractors
@given(seed=seed_st, specials=specials_st, widen=st.booleans())
def test_contractor_fixpoint_sound(seed, specials, widen):
    _algebra_cases(seed, specials, widen, fixpoints=True)
