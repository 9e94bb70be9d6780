"""ThickSivia (thesis App. A, Algorithm A.2) and the test-cases 1-4 of §A.5.

Soundness is checked on sampled points of the proved boxes against the exact point bounds
``f⁻(x)``, ``f⁺(x)`` and against random members ``f ∈ [f]`` (random parameters per point). The point
checks run in round-to-nearest with the same monotone formulas as the enclosures, so they stay within
the outward-rounded bounds; test-case 1 is also checked in exact rational arithmetic.
"""

from __future__ import annotations

from collections.abc import Callable
from fractions import Fraction

import numpy as np
import pytest
from example_loader import load

from digslam.observer import Box, Function
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA, UNKNOWN
from digslam.observer.thick.function import ThickFunction
from digslam.observer.thick.paver import ThickPaving
from digslam.observer.thick.sivia import ThickInverse, thick_sivia

Bounds = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
TC1 = load("a5_test_case1_translation")
TC2 = load("a5_test_case2_linear_system")
TC3 = load("a5_test_case3_parameter_estimation")
TC4 = load("a5_test_case4_communication")


def points(
    b: tuple[np.ndarray, np.ndarray], rng: np.random.Generator, k: int = 8, cap: int = 4000
) -> np.ndarray:
    """``k`` points per box (corners first), at most ``cap`` boxes."""
    lo, hi = b
    if lo.shape[0] > cap:
        idx = rng.choice(lo.shape[0], cap, replace=False)
        lo, hi = lo[idx], hi[idx]
    u = rng.uniform(0, 1, (lo.shape[0], k, lo.shape[1]))
    u[:, :4] = np.array([[0, 0], [0, 1], [1, 0], [1, 1]])[:, : lo.shape[1]]
    return np.clip(lo[:, None] + u * (hi - lo)[:, None], lo[:, None], hi[:, None]).reshape(-1, lo.shape[1])


def check_sound(p: ThickPaving, bounds: Bounds, member: Callable, ym: np.ndarray, yp: np.ndarray,
                seed: int = 0) -> None:  # fmt: skip
    """Theorem A.2 on samples: clear ⊂ X⁻, penumbra ⊂ X⁺ \\ X⁻, dark ∩ X⁺ = ∅."""
    rng = np.random.default_rng(seed)
    ym, yp = np.asarray(ym, float), np.asarray(yp, float)
    q = points(p.clear, rng)
    lo, hi = bounds(q)
    assert ((lo >= ym[:, 0]) & (hi <= ym[:, 1])).all(), "a clear point has [f](x) ⊄ Y⁻"
    v = member(q, rng)
    assert ((v >= ym[:, 0]) & (v <= ym[:, 1])).all(), "a member f of [f] sends a clear point outside Y⁻"
    q = points(p.dark, rng)
    lo, hi = bounds(q)
    assert ((hi < yp[:, 0]) | (lo > yp[:, 1])).any(axis=1).all(), "a dark point has [f](x) ∩ Y⁺ ≠ ∅"
    v = member(q, rng)
    assert ((v < yp[:, 0]) | (v > yp[:, 1])).any(axis=1).all(), "a member f sends a dark point into Y⁺"
    q = points(p.penumbra, rng)
    lo, hi = bounds(q)
    assert ((lo <= yp[:, 1]) & (hi >= yp[:, 0])).all(axis=1).all(), "a penumbra point outside X⁺"
    assert ((lo < ym[:, 0]) | (hi > ym[:, 1])).any(axis=1).all(), "a penumbra point inside X⁻"


# ---------------------------------------------------------------- test-case 1 (thick translation)
V_LO, V_HI = np.array(TC1.V_LO), np.array(TC1.V_HI)


def tc1_bounds(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = np.maximum(np.maximum(V_LO - x, x - V_HI), 0.0)
    far = np.maximum(x - V_LO, V_HI - x)
    return (d * d).sum(axis=1, keepdims=True), (far * far).sum(axis=1, keepdims=True)


def tc1_member(x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    v = rng.uniform(V_LO, V_HI, x.shape)
    v[::3] = np.where(rng.integers(0, 2, v[::3].shape) == 1, V_LO, V_HI)  # corners of [v] too
    d = x - v
    return (d * d).sum(axis=1, keepdims=True)


def test_tc1_bisections_below_thesis_and_codac() -> None:
    """Table of test-case 1: ours ≤ thesis' "our method" and ≤ codac 1.5.6 (76,521 at ε = 0.001)."""
    r = TC1.run(eps=0.1, table=(0.5, 0.1, 0.05, 0.01, 0.005, 0.001), classical_min_eps=0.05)
    got = {row["eps"]: row for row in r["table"]}
    assert [got[e]["ours"] for e in TC1.EPS_TABLE] == [119, 565, 1161, 9539, 19109, 76517]
    for e, row in got.items():
        assert row["ours"] <= TC1.THESIS[e][1]
    assert got[0.001]["ours"] <= 76521 and got[0.01]["ours"] <= 9543
    # classical Sivia (no penumbra test): also below the thesis' classical counts, and far above ours
    assert [got[e]["classical"] for e in (0.5, 0.1, 0.05)] == [155, 1785, 6579]
    assert got[0.05]["classical"] > 5 * got[0.05]["ours"]
    assert r["classical_bisections"] == 1785 and r["bisections"] == 565


def test_tc1_sound_and_areas() -> None:
    p, _ = TC1.solve(0.01)
    check_sound(p, tc1_bounds, tc1_member, [[0, 1]], [[0, 4]])
    # exact areas: X⁻ = D(0,1) ⊖ [v] (lens of 4 disks), X⁺ ∩ frame = (D(0,2) ⊕ [v]) ∩ frame
    g = np.linspace(-2, 4, 1501)[:-1] + 0.002
    lo, hi = tc1_bounds(np.stack(np.meshgrid(g, g), -1).reshape(-1, 2))
    lower, upper = float((hi <= 1).mean() * 36), float((lo <= 4).mean() * 36)
    assert p.clear_area <= lower + 0.01 and p.clear_area > lower - 0.05
    assert p.clear_area + p.penumbra_area + p.boundary_area >= upper - 0.01
    assert p.boundary_area < 0.15


def test_tc1_exact_rational_check() -> None:
    """Clear / dark / penumbra sample points checked in exact rational arithmetic (floats are rationals)."""
    p, _ = TC1.solve(0.05)
    rng = np.random.default_rng(3)
    vl, vh = [Fraction(float(a)) for a in V_LO], [Fraction(float(a)) for a in V_HI]

    def exact(x: np.ndarray) -> tuple[Fraction, Fraction]:
        xs = [Fraction(float(c)) for c in x]
        d = [max(vl[j] - xs[j], xs[j] - vh[j], Fraction(0)) for j in range(2)]
        far = [max(xs[j] - vl[j], vh[j] - xs[j]) for j in range(2)]
        return d[0] ** 2 + d[1] ** 2, far[0] ** 2 + far[1] ** 2

    for batch, ok in ((p.clear, lambda a, b: b <= 1), (p.dark, lambda a, b: a > 4),
                      (p.penumbra, lambda a, b: a <= 4 and b > 1)):  # fmt: skip
        pts = points(batch, rng, k=4, cap=60)  # corners: where the exact bounds are reached
        assert all(ok(*exact(x)) for x in pts)


def test_tc1_fast_path_agrees_with_outward_rounding() -> None:
    """The error-bounded round-to-nearest path classifies like the outward-rounded one."""
    fast = ThickInverse(TC1.thick_disk(), [0, 1], [0, 4])
    slow_f = TC1.thick_disk()
    slow_f.approx = None
    slow = ThickInverse(slow_f, [0, 1], [0, 4])
    rng = np.random.default_rng(5)
    c = rng.uniform(-2, 4, (3000, 2))
    w = rng.uniform(0, 0.3, (3000, 2))
    # dyadic boxes too, where bounds such as ‖x − v‖² = 4 are exact
    c[:1000] = np.round(c[:1000] * 64) / 64
    w[:1000] = np.round(w[:1000] * 64) / 64
    lo, hi = c - w, c + w
    assert (fast.classify(lo, hi) == slow.classify(lo, hi)).all()
    p_slow = thick_sivia(TC1.FRAME, slow_f, [0, 1], [0, 4], eps=0.05)
    assert p_slow.bisections == 1161


def test_tc1_classify_hand_boxes() -> None:
    t = ThickInverse(TC1.thick_disk(), [0, 1], [0, 4])
    lo = np.array([[0.9, -0.1], [3.4, 3.4], [2.4, -0.05], [1.6, 0.0], [1.0, -0.1]])
    hi = np.array([[1.1, 0.1], [3.6, 3.6], [2.6, 0.05], [2.4, 0.1], [1.0, -0.2]])  # last row empty
    assert t.classify(lo, hi).tolist() == [CLEAR, DARK, PENUMBRA, UNKNOWN, UNKNOWN]
    assert ThickInverse(TC1.thick_disk(), [0, 1], [0, 4], penumbra=False).classify(lo, hi)[2] == UNKNOWN


def test_tc1_figure(tmp_path) -> None:  # noqa: ANN001
    r = TC1.run(eps=0.5, out=tmp_path, table=(0.5,))
    assert (tmp_path / "a5_test_case1_translation.png").exists() and r["figure"]


# ---------------------------------------------------------------- test-case 2 (interval linear system)
def tc2_bounds(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    t = np.stack([TC2.A_LO[None] * x[:, None], TC2.A_HI[None] * x[:, None]])  # (2, P, m, n)
    return t.min(axis=0).sum(axis=-1), t.max(axis=0).sum(axis=-1)


def tc2_member(x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    a = rng.uniform(TC2.A_LO, TC2.A_HI, (x.shape[0], 2, 2))
    return (a * x[:, None]).sum(axis=-1)


def test_tc2_tolerable_united() -> None:
    r = TC2.run(eps=0.01)
    assert r["tolerable_area"] == pytest.approx(0.1515625, abs=1e-9)  # exact polygon areas
    assert r["united_area"] == pytest.approx(2.875, abs=1e-9)
    lo, hi = r["united_bbox"]
    assert lo[0] >= TC2.FRAME[0][0] and lo[1] >= TC2.FRAME[0][1] and hi[0] <= TC2.FRAME[1][0]
    assert 0.9 * r["tolerable_area"] < r["clear_area"] <= r["tolerable_area"]
    assert r["clear_area"] + r["penumbra_area"] + r["boundary_area"] >= r["united_area"]
    assert r["boundary_area"] < 0.15 and r["bisections"] < r["classical_bisections"] / 5
    p = thick_sivia(TC2.FRAME, TC2.thick_linear(), TC2.B, eps=0.02)
    check_sound(p, tc2_bounds, tc2_member, TC2.B, TC2.B)


def test_linear_thick_function_ranges() -> None:
    """``ThickFunction.linear`` encloses the exact ranges of f⁻, f⁺ on boxes (sampled)."""
    f = TC2.thick_linear()
    rng = np.random.default_rng(2)
    c, w = rng.uniform(-2, 2, (200, 2)), rng.uniform(0, 1, (200, 2))
    e = f.eval(c - w, c + w)
    q = np.clip(c[:, None] + rng.uniform(-1, 1, (200, 50, 2)) * w[:, None], c[:, None] - w[:, None],
                c[:, None] + w[:, None])  # fmt: skip
    lo, hi = tc2_bounds(q.reshape(-1, 2))
    lo, hi = lo.reshape(200, 50, 2), hi.reshape(200, 50, 2)
    assert (e.lo_lo[:, None] <= lo).all() and (lo <= e.lo_hi[:, None]).all()
    assert (e.hi_lo[:, None] <= hi).all() and (hi <= e.hi_hi[:, None]).all()
    with pytest.raises(ValueError, match="a_lo"):
        ThickFunction.linear([[1.0, 2.0]], [[0.0, 3.0]])


# ---------------------------------------------------------------- test-case 3 (parameter estimation)
def tc3_bounds(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    e = x[:, :1, None] * np.exp(-x[:, 1:2, None] * TC3.T[None])  # (P, 5, 2)
    return e.min(axis=-1), e.max(axis=-1)


def tc3_member(x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    t = rng.uniform(TC3.T[:, 0], TC3.T[:, 1], (x.shape[0], 5))
    return x[:, :1] * np.exp(-x[:, 1:2] * t)


def test_tc3_parameter_estimation() -> None:
    r = TC3.run(eps=0.1)
    # thesis (Fig. A.10): 2744 boxes with thick intervals, 10337 with classical ones
    assert r["boxes"] == 2551 and r["classical_boxes"] == 8891
    assert r["boxes"] <= TC3.THESIS["thick_boxes"] and r["classical_boxes"] <= TC3.THESIS["classical_boxes"]
    assert r["clear_area"] > 10.0 and r["penumbra_area"] > 30.0
    p = thick_sivia(TC3.FRAME, TC3.thick_model(), TC3.Y, eps=0.2)
    check_sound(p, tc3_bounds, tc3_member, TC3.Y, TC3.Y)
    # the frame contains X⁺: no box touching the frame's border is anything but dark
    for b in (p.clear, p.penumbra, p.boundary):
        assert (b[0] > np.array(TC3.FRAME[0])).all() and (b[1] < np.array(TC3.FRAME[1])).all()


# ---------------------------------------------------------------- test-case 4 (communication area)
def tc4_member(x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    m = rng.uniform(TC4.M_LO, TC4.M_HI, (x.shape[0], 4, 2))
    return ((x[:, None] - m) ** 2).sum(axis=-1)


def test_tc4_communication_area() -> None:
    r = TC4.run(eps=0.1, grid=800)
    assert r["bisections"] == 4488 and r["classical_bisections"] == 105238
    assert r["clear_area"] <= r["grid_lower_area"] + 0.3  # grid estimate: ±0.3 at 800²
    assert r["clear_area"] + r["penumbra_area"] + r["boundary_area"] >= r["grid_upper_area"] - 0.5
    p = thick_sivia(TC4.FRAME, ThickFunction.sqdist(TC4.M_LO, TC4.M_HI), TC4.Y_MINUS, TC4.Y_PLUS, eps=0.3)
    check_sound(p, TC4.point_bounds, tc4_member, TC4.Y_MINUS, TC4.Y_PLUS)


def test_sqdist_ranges_both_paths() -> None:
    """Both evaluations of ``sqdist`` enclose the sampled ranges of ``f⁻`` and ``f⁺``."""
    f = ThickFunction.sqdist(TC4.M_LO, TC4.M_HI)
    rng = np.random.default_rng(4)
    c, w = rng.uniform(-15, 15, (300, 2)), rng.uniform(0, 3, (300, 2))
    e = f.eval(c - w, c + w)
    (all_, lh, hl, hh), k = f.approx(c - w, c + w)
    assert k == 5
    q = np.clip(c[:, None] + rng.uniform(-1, 1, (300, 40, 2)) * w[:, None], c[:, None] - w[:, None],
                c[:, None] + w[:, None])  # fmt: skip
    lo, hi = TC4.point_bounds(q.reshape(-1, 2))
    lo, hi = lo.reshape(300, 40, 4), hi.reshape(300, 40, 4)
    assert (e.lo_lo[:, None] <= lo).all() and (lo <= e.lo_hi[:, None]).all()
    assert (e.hi_lo[:, None] <= hi).all() and (hi <= e.hi_hi[:, None]).all()
    assert np.allclose(all_, e.lo_lo) and np.allclose(hh, e.hi_hi) and np.allclose(lh, e.lo_hi)
    with pytest.raises(ValueError, match="m_lo"):
        ThickFunction.sqdist([[1.0, 0.0]], [[0.0, 1.0]])


# ---------------------------------------------------------------- generic ThickSivia
def test_generic_function_pair_and_example_a1() -> None:
    """Example A.1 with f⁻, f⁺ given as Functions (natural inclusion) vs the closed form."""
    from digslam.observer import maximum

    def dist(t: object, a: float, b: float) -> object:
        return maximum(maximum(a - t, t - b), 0.0)

    fm = Function(lambda x: dist(x[0], 0, 1) ** 2 + dist(x[1], 0, 1) ** 2)
    fp = Function(lambda x: maximum(x[0] ** 2, (x[0] - 1) ** 2) + maximum(x[1] ** 2, (x[1] - 1) ** 2))
    frame = ([-2.0, -2.0], [4.0, 4.0])
    p_gen = thick_sivia(frame, ThickFunction(fm, fp), [0.0, 4.0], eps=0.1)
    p_cf = thick_sivia(frame, ThickFunction.sqdist([[0.0, 0.0]], [[1.0, 1.0]]), [0.0, 4.0], eps=0.1)
    assert p_cf.bisections <= p_gen.bisections and p_gen.penumbra_area > 0.8 * p_cf.penumbra_area

    def bounds(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return fm(x)[:, None], fp(x)[:, None]

    def member(x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        a = rng.uniform(0, 1, x.shape)
        return ((x - a) ** 2).sum(axis=1, keepdims=True)

    check_sound(p_gen, bounds, member, [[0, 4]], [[0, 4]])
    check_sound(p_cf, bounds, member, [[0, 4]], [[0, 4]])


def test_thin_and_empty_bounds() -> None:
    """``y_upper=None`` is the thin set Y⁺ = Y⁻; ``y_lower=None`` is Y⁻ = ∅ (no clear box)."""
    f = ThickFunction.sqdist([[0.0, 0.0]], [[1.0, 1.0]])
    frame = ([-2.0, -2.0], [4.0, 4.0])
    p = thick_sivia(frame, f, None, [0.0, 4.0], eps=0.1)
    assert p.clear_area == 0.0 and p.penumbra_area > 14.0
    q = thick_sivia(frame, f, Box([(0, 4)]), eps=0.1)
    assert q.clear_area > 4.0


def test_bad_input() -> None:
    f = ThickFunction.sqdist([[0.0, 0.0]], [[1.0, 1.0]])
    with pytest.raises(ValueError, match="Y⁻ must be inside Y⁺"):
        ThickInverse(f, [0.0, 5.0], [0.0, 4.0])
    with pytest.raises(ValueError, match="y_upper"):
        ThickInverse(f, None, [3.0, 1.0])
    with pytest.raises(ValueError, match="at least one"):
        ThickInverse(f, None, None)
    with pytest.raises(ValueError, match="f:"):
        ThickInverse(object(), [0.0, 1.0])  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="intervals but"):
        ThickInverse(f, [[0.0, 1.0], [0.0, 1.0]], [0.0, 4.0])
    with pytest.raises(ValueError, match="eps"):
        thick_sivia(([-1.0, -1.0], [1.0, 1.0]), f, [0.0, 1.0], eps=0.0)
    bad = ThickFunction(Function(lambda x: x[0] + 10), Function(lambda x: x[0]))
    with pytest.raises(ValueError, match="f- > f"):
        ThickInverse(bad, [0.0, 1.0]).classify(np.array([[0.0]]), np.array([[1.0]]))
