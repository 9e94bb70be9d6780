"""The compiled forward-backward (observer/expr/tape_jit.py, observer/expr/hc4_jit.py) against sampled solutions and
against the numpy HC4 (tests/ oracle: contractors.hc4_backward), and the compiled paver/algebra against
the figures the numpy implementation produced."""

from __future__ import annotations

import math

import numpy as np
import pytest

from digslam.observer import Box, Function, Interval, SepInverse, pave
from digslam.observer.core.boxes import normalize_empty
from digslam.observer.core.scalar_jit import dn, njit, up
from digslam.observer.expr.hc4_jit import hc4, image, sep_box
from digslam.observer.expr.ops import exp, log, sin, sqrt
from digslam.observer.expr.tape_jit import Tape
from digslam.observer.sets.contractors import CtcFwdBwd, hc4_backward
from digslam.observer.sets.separators import SepBox, SepInter, SepNot, SepUnion, hull_batch, inter_batch
from digslam.observer.sets.testing import assert_separator_sound, random_boxes

EXPRS = {
    "ring": (lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2, (1.0, 2.25)),
    "mul_div": (lambda x: x[0] * x[1] / (1 + x[0] ** 2), (-0.3, 0.2)),
    "sqrt_sub": (lambda x: sqrt(x[0] + 4) - x[1], (0.0, 0.5)),  # defined on the frame
    "exp_log": (lambda x: exp(x[0]) + log(x[1] + 4) * x[0], (0.5, 2.0)),
    "abs_pown": (lambda x: abs(x[0]) - x[1] ** 3 + x[0] ** -2, (0.0, 3.0)),
    "same_arg": (lambda x: x[0] * x[0] - (-x[1]), (-0.5, 0.5)),
}


def _widen(lo: np.ndarray, hi: np.ndarray, tol: float = 1e-12) -> tuple[np.ndarray, np.ndarray]:
    with np.errstate(invalid="ignore"):
        return lo - tol * (1 + np.abs(lo)), hi + tol * (1 + np.abs(hi))


def _contains(outer: tuple[np.ndarray, np.ndarray], inner: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """Rows where ``inner`` (empty allowed) lies in ``outer`` widened by a few rounding errors."""
    olo, ohi = _widen(*outer)
    empty = (inner[0] > inner[1]).any(axis=1)
    return empty | ((olo <= inner[0]) & (inner[1] <= ohi)).all(axis=1)


@pytest.mark.parametrize("name", sorted(EXPRS))
def test_compiled_hc4_keeps_solutions_and_lies_in_numpy_hc4(name: str) -> None:
    fn, (a, b) = EXPRS[name]
    f = Function(fn, n=2)
    tape = Tape.of(f)
    assert tape is not None
    lo, hi = random_boxes([-3, -3], [3, 3], 300, 2.0, seed=3)
    rlo, rhi = hc4(tape, lo, hi, np.array([a]), np.array([b]))
    nlo, nhi = hc4_backward(f, f.forward(lo, hi), (np.array([a]), np.array([b])), lo, hi)
    assert _contains((nlo, nhi), (rlo, rhi)).all()
    assert _contains((rlo, rhi), (nlo, nhi)).mean() > 0.95  # same rules: equal up to rounding
    rng = np.random.default_rng(0)
    pts = lo[:, None, :] + rng.random((lo.shape[0], 200, 2)) * (hi - lo)[:, None, :]
    with np.errstate(all="ignore"):
        val = f(pts)
    sol = (val >= a + 1e-9 * (1 + abs(a))) & (val <= b - 1e-9 * (1 + abs(b)))
    inside = ((rlo[:, None, :] <= pts) & (pts <= rhi[:, None, :])).all(axis=2)
    assert not (sol & ~inside).any(), f"{name}: a solution was removed"
    assert (~inside).any()  # the contractor does contract


def test_forward_image_matches_numpy_inclusion() -> None:
    for name, (fn, _) in EXPRS.items():
        f = Function(fn, n=2)
        lo, hi = random_boxes([-3, -3], [3, 3], 200, 1.0, seed=5)
        ilo, ihi = image(Tape.of(f), lo, hi)
        ref = f.eval((lo, hi))
        assert _contains((ref.lo[:, None], ref.hi[:, None]), (ilo, ihi)).all(), name
        assert _contains((ilo, ihi), (ref.lo[:, None], ref.hi[:, None])).all(), name


@pytest.mark.parametrize("name", sorted(EXPRS))
def test_compiled_separator_is_sound_and_matches_numpy_path(name: str) -> None:
    fn, (a, b) = EXPRS[name]
    sep = SepInverse(Function(fn, n=2), Interval(a, b))
    lo, hi = random_boxes([-3, -3], [3, 3], 150, 1.5, seed=7)

    def member(p: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            v = sep.f(p)
        return (v >= a) & (v <= b)

    assert_separator_sound(sep, lo, hi, member, per_box=48)
    (ilo, ihi), (olo, ohi) = sep.separate(lo, hi)
    (nilo, nihi), (nolo, nohi) = (normalize_empty(*p) for p in sep._separate(lo, hi))  # numpy path
    assert _contains((nilo, nihi), (ilo, ihi)).all() and _contains((nolo, nohi), (olo, ohi)).all()


def test_separator_with_image_separator_and_two_outputs() -> None:
    f = Function(lambda x: (x[0] * x[1], x[0] - x[1] ** 2))
    y = Box([(-1, 1), (0, 2)])
    lo, hi = random_boxes([-2, -2], [2, 2], 200, 1.0, seed=11)
    by_box, by_sep = SepInverse(f, y), SepInverse(f, SepBox(y))
    res = sep_box(Tape.of(f), lo, hi, np.stack(by_box.box.box))
    (ilo, ihi), (olo, ohi) = by_sep.separate(lo, hi)
    assert _contains((ilo, ihi), (res[0], res[1])).all() and _contains((olo, ohi), (res[2], res[3])).all()

    def member(p: np.ndarray) -> np.ndarray:
        v = f(p)
        return (np.abs(v[:, 0]) <= 1) & (v[:, 1] >= 0) & (v[:, 1] <= 2)

    assert_separator_sound(by_box, lo, hi, member, per_box=32)
    assert_separator_sound(by_sep, lo, hi, member, per_box=32)


def test_unsupported_op_falls_back_to_numpy() -> None:
    f = Function(lambda x: sin(x[0]) + x[1])
    assert Tape.of(f) is None
    sep = SepInverse(f, Interval(0, 0.5))
    lo, hi = random_boxes([-3, -3], [3, 3], 60, 1.0, seed=2)
    assert_separator_sound(sep, lo, hi, lambda p: (f(p) >= 0) & (f(p) <= 0.5), per_box=32)


def test_ctc_fwd_bwd_compiled_matches_example_2_4() -> None:
    c = CtcFwdBwd(Function(lambda z, x, y: x - y - z), 0.0)
    r = c(Box([(4, 5), (0, 3), (-2, 2)]))
    assert r.lo.tolist() == [4.0, 2.0, -2.0] and r.hi.tolist() == [5.0, 3.0, -1.0]


@njit
def _steps(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    u, d = np.empty_like(x), np.empty_like(x)
    for i in range(x.size):
        u[i], d[i] = up(x[i]), dn(x[i])
    return u, d


def test_fast_ulp_steps_equal_nextafter() -> None:
    rng = np.random.default_rng(4)
    x = rng.standard_normal(200_000) * 10.0 ** rng.integers(-320, 308, 200_000)
    edges = [0.0, -0.0, 5e-324, 2.0**-1022, 2.0**-960, np.nextafter(2.0**-960, 0), 2.0**-959, 1.0,
             np.finfo(float).max, math.inf, -math.inf]  # fmt: skip
    x = np.concatenate([x, edges, -np.asarray(edges)])
    u, d = _steps(x)
    with np.errstate(over="ignore"):
        assert (u == np.nextafter(x, math.inf)).all() and (d == np.nextafter(x, -math.inf)).all()


def _numpy_algebra(seps: list, lo: np.ndarray, hi: np.ndarray, union: bool) -> tuple:
    """Eq. 2.54 as the numpy implementation did it (oracle)."""
    parts = [s.separate(lo, hi) for s in seps]
    if union:
        parts = [(o, i) for i, o in parts]
    xin, xout = (np.full_like(lo, np.inf), np.full_like(hi, -np.inf)), (lo, hi)
    for i, o in parts:
        xin, xout = hull_batch(xin, normalize_empty(*i)), inter_batch(xout, o)
    return (xout, xin) if union else (xin, xout)


def test_compiled_algebra_equals_numpy_algebra() -> None:
    a, b, c = (
        SepBox(Box([(0, 1), (0, 1)])),
        SepBox(Box([(0.5, 2), (0.5, 2)])),
        SepBox(Box([(-1, 0.7), (0.2, 3)])),
    )
    lo, hi = random_boxes([-1, -1], [2.5, 2.5], 400, 1.2, seed=9)
    for sep, ref in ((a & ~b, _numpy_algebra([a, SepNot(b)], lo, hi, False)),
                     (a | b | c, _numpy_algebra([a, b, c], lo, hi, True)),
                     (SepUnion(SepInter(a, b), c), None)):  # fmt: skip
        got = sep.separate(lo, hi)
        if ref is None:
            ref = _numpy_algebra([SepInter(a, b), c], lo, hi, True)
        for g, r in zip(got, ref, strict=True):
            gl, gh = normalize_empty(*g)
            rl, rh = normalize_empty(*r)
            assert np.array_equal(gl, rl) and np.array_equal(gh, rh)


@pytest.mark.parametrize(("problem", "bisections", "inner", "boundary"), [
    ("ring", 167, 3.67525, 0.503935), ("ex26", 857, 48.7244, 1.92975)])  # fmt: skip
def test_paver_reproduces_the_numpy_paver_figures(problem: str, bisections: int, inner: float,
                                                  boundary: float) -> None:  # fmt: skip
    """The numpy paver gave these figures at ε = 0.1 (Ex. 2.7 ring, Eq. 2.60; Ex. 2.6, Eq. 2.56)."""

    def ring(cx: float, cy: float, r0: float, r1: float) -> SepInverse:
        return SepInverse(Function(lambda x: (x[0] - cx) ** 2 + (x[1] - cy) ** 2), Interval(r0**2, r1**2))

    if problem == "ring":
        x0, sep = Box([(-1, 5), (-0.5, 5.5)]), ring(2, 2.5, 1, 1.5)
    else:
        s1, s2, s3 = ring(1, 3, 3, 6), ring(4, 2, 1, 5), ring(-3, -3, 3, 4)
        x0, sep = Box([(-10, 10), (-10, 10)]), (s1 & s2) | (s3 & ~s1)
    p = pave(x0, sep, 0.1)
    assert p.bisections == bisections
    assert p.inner_area == pytest.approx(inner, rel=2e-6) and p.boundary_area == pytest.approx(
        boundary, rel=2e-6
    )
    assert p.tree.size == 2 * bisections + 1
    assert p.inner_area + p.outer_area + p.boundary_area == pytest.approx(float(np.prod(x0.hi - x0.lo)))


def test_blocks_of_a_huge_batch_give_the_same_result(monkeypatch) -> None:
    """Batches above ``jit_hc4.BLOCK`` rows go through in blocks, with the same results as one call."""
    from digslam.observer.expr import hc4_jit as jit_hc4

    f = Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2)
    t = Tape.of(f)
    rng = np.random.default_rng(7)
    c = rng.uniform(-1, 5, (1000, 2))
    w = rng.uniform(0, 0.5, (1000, 2))
    lo, hi = c - w, c + w
    y = np.array([[1.0], [2.25]])
    whole = (jit_hc4.sep_box(t, lo, hi, y), jit_hc4.image(t, lo, hi), jit_hc4.hc4(t, lo, hi, y[0], y[1]))
    monkeypatch.setattr(jit_hc4, "BLOCK", 64)
    blocks = (jit_hc4.sep_box(t, lo, hi, y), jit_hc4.image(t, lo, hi), jit_hc4.hc4(t, lo, hi, y[0], y[1]))
    np.testing.assert_array_equal(whole[0], blocks[0])
    for a, b in zip(whole[1:], blocks[1:]):
        np.testing.assert_array_equal(a[0], b[0])
        np.testing.assert_array_equal(a[1], b[1])
