"""Inter-temporal shape SLAM (thesis §6.2.3.1, §6.3, Algorithm 6.2, Eq. 6.14, Table 6.1)."""

from __future__ import annotations

import numpy as np
import pytest
from example_loader import load
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.observer.slam.shape_registration import (
    SepTranslationInclusion,
    ThickImage,
    level_thick_image,
    register_translation,
)
from digslam.observer.slam.shape_slam import ShapeSlamConfig, ctc_minus, overlap_pretest, shape_slam
from digslam.observer.thick.cells import CLEAR, DARK
from digslam.observer.tube.tube import Tube

GRAD = 1 / 3 + 1 / 2.5 + 0.5 * np.sqrt(2) / 4  # bound of |∇z|₂ for the field below


def field(m: np.ndarray) -> np.ndarray:
    return np.sin(m[..., 0] / 3) + np.cos(m[..., 1] / 2.5) + 0.5 * np.sin((m[..., 0] + m[..., 1]) / 4)


def shape_at(x: np.ndarray, rng: np.random.Generator, cell: float = 0.5, half: int = 20, delta: float = 0.05,
             bounds: bool = False, level: float = 0.3) -> ThickImage:  # fmt: skip
    """``[Z] = M - x`` seen on a disk of radius ``0.9·half·cell`` around ``x``; noise ±delta."""
    n = 2 * half
    cx = (np.arange(-half, half) + 0.5) * cell
    gx, gy = np.meshgrid(cx, cx[::-1])
    c = np.stack([gx, gy], -1)
    scope = np.hypot(gx, gy) <= 0.9 * half * cell
    noise = delta * (rng.choice([-1.0, 1.0], (n, n)) if bounds else rng.uniform(-1, 1, (n, n)))
    z = np.where(scope, field(c + x) + noise, np.nan)
    err = delta + GRAD * cell / np.sqrt(2) + 1e-9
    return level_thick_image(z, err, level, cell, (-half, half), scope)


def point_in(img: ThickImage, m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Whether points (N, 2) of the robot frame fall in a ``Z⁻`` pixel / outside ``Z⁺`` (not on edges)."""
    (c0, r0), e = img.corner, img.cell
    j, i = np.floor(m[:, 0] / e).astype(int) - c0, r0 - 1 - np.floor(m[:, 1] / e).astype(int)
    ok = (i >= 0) & (i < img.shape[0]) & (j >= 0) & (j < img.shape[1])
    i, j = np.clip(i, 0, img.shape[0] - 1), np.clip(j, 0, img.shape[1] - 1)
    return ok & img.lower[i, j], ok & ~img.upper[i, j]


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("bounds", [False, True])
def test_thick_shape_encloses_level_set(seed: int, bounds: bool) -> None:
    rng = np.random.default_rng(seed)
    x = rng.uniform(-50, 50, 2)
    img = shape_at(x, rng, bounds=bounds)
    assert img.lower.any() and (~img.upper).any() and (img.upper & ~img.lower & img.scope).any()
    assert (img.upper[~img.scope]).all() and not img.lower[~img.scope].any()  # unobserved: penumbra
    m = rng.uniform(-12, 12, (20000, 2))  # the image spans [-10, 10]²
    inside = field(m + x) <= 0.3
    lower, dark = point_in(img, m)
    assert inside[lower].all() and not inside[dark].any()
    st_ = img.sep.classify(m, m)  # the thick separator agrees on degenerate boxes
    assert inside[st_ == CLEAR].all() and not inside[st_ == DARK].any()
    assert (st_[np.abs(m).max(axis=1) > 10.0] != DARK).all()  # outside the image: penumbra


def brute_feasible(a: ThickImage, b: ThickImage, p: np.ndarray) -> bool:
    """``A⁻ + p ⊂ B⁺``: no ``A⁻`` pixel shifted by ``p`` overlaps (with area) a pixel outside ``B⁺``."""
    e = a.cell
    ra, ca = np.nonzero(a.lower)
    rb, cb = np.nonzero(~b.upper)
    ax, ay = (a.corner[0] + ca) * e + p[0], (a.corner[1] - ra - 1) * e + p[1]
    bx, by = (b.corner[0] + cb) * e, (b.corner[1] - rb - 1) * e
    ox = np.abs(ax[:, None] - bx[None]) < e
    oy = np.abs(ay[:, None] - by[None]) < e
    return not (ox & oy).any()


@pytest.mark.parametrize("seed", range(3))
def test_translation_separator_sound(seed: int) -> None:
    rng = np.random.default_rng(seed)
    xi = rng.uniform(-30, 30, 2)
    xj = xi + rng.uniform(-4, 4, 2)
    a, b = shape_at(xj, rng), shape_at(xi, rng)
    sep = SepTranslationInclusion(a, b, 1, samples=2)
    c = (xj - xi) + rng.uniform(-6, 6, (300, 2))
    w = rng.uniform(0.01, 2.0, (300, 2))
    (ilo, _), (olo, _) = sep.separate(c - w, c + w)
    proved_out, proved_in = np.isinf(olo[:, 0]), np.isinf(ilo[:, 0])
    assert proved_out.sum() >= 5 and not (proved_out & proved_in).any()
    for k in np.flatnonzero(proved_out | proved_in)[:60]:
        for p in c[k] + w[k] * rng.uniform(-1, 1, (5, 2)):
            assert brute_feasible(a, b, p) == bool(proved_in[k])


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("bounds", [False, True])
def test_registration_keeps_true_translation(seed: int, bounds: bool) -> None:
    rng = np.random.default_rng(100 + seed)
    xi = rng.uniform(-40, 40, 2)
    xj = xi + rng.uniform(-5, 5, 2)
    a, b = shape_at(xj, rng, bounds=bounds), shape_at(xi, rng, bounds=bounds)
    p = xj - xi
    box = [(p[d] - rng.uniform(0, 6), p[d] + rng.uniform(0, 6)) for d in range(2)]
    lo, hi = register_translation(a, b, box, eps_p=0.25)
    assert ((lo <= p) & (p <= hi)).all()
    assert (hi - lo).sum() < sum(h - lo_ for lo_, h in box)  # it contracts


def test_registration_image_vs_projection() -> None:
    rng = np.random.default_rng(7)
    xi = np.array([3.3, -1.7])
    xj = xi + [1.4, -0.6]
    a, b = shape_at(xj, rng, half=12), shape_at(xi, rng, half=12)
    p, box = xj - xi, [(-2.0, 4.0), (-3.0, 2.0)]
    r1 = register_translation(a, b, box, eps_p=0.1)
    r2 = register_translation(a, b, box, eps_p=0.1, method="projection", eps=0.25)
    for lo, hi in (r1, r2):  # both sound, both contract [p] (widths 6 + 5)
        assert ((lo <= p) & (p <= hi)).all() and (hi - lo).sum() < 10.0
    assert (r1[1] - r1[0]).sum() <= (r2[1] - r2[0]).sum() + 0.5  # the lattice separators are as sharp


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(-3200, 3200), min_size=4, max_size=4),
       st.lists(st.floats(0, 5), min_size=6, max_size=6))  # fmt: skip
def test_ctc_minus_sound(v: list[int], w: list[float]) -> None:
    xi, xj = np.array([v[:2]]) / 64, np.array([v[2:]]) / 64  # dyadic: p = x_j - x_i is exact
    p = xj - xi
    boxes = [(xi - w[0], xi + w[1]), (xj - w[2], xj + w[3]), (p - w[4], p + w[5])]
    for (lo, hi), true in zip(ctc_minus(*boxes), (xi, xj, p)):
        assert ((lo <= true) & (true <= hi)).all()


def test_overlap_pretest() -> None:
    rng = np.random.default_rng(3)
    n = 4000
    ci, cj = rng.uniform(-50, 50, (n, 2)), rng.uniform(-50, 50, (n, 2))
    hi_, hj = rng.uniform(1, 20, (n, 2)), rng.uniform(1, 20, (n, 2))
    vi, vj = (ci - hi_, ci + hi_), (cj - hj, cj + hj)
    p = rng.uniform(-60, 60, (n, 2))
    w = rng.uniform(0, 15, (n, 2))
    pb = (p - w, p + rng.uniform(0, 15, (n, 2)))
    truly = (np.maximum(vi[0], vj[0] + p) <= np.minimum(vi[1], vj[1] + p)).all(axis=1)
    res = overlap_pretest(vi, vj, pb, inner_i=vi, inner_j=vj)
    assert (res[truly] >= 0).all() and (res == -1).any() and (res == 1).any()
    # X⁻ ≠ ∅ claimed: every sampled p of the box gives overlapping boxes
    for k in np.flatnonzero(res == 1)[:200]:
        q = pb[0][k] + (pb[1][k] - pb[0][k]) * rng.uniform(0, 1, (20, 2))
        assert (np.maximum(vi[0][k], vj[0][k] + q) <= np.minimum(vi[1][k], vj[1][k] + q)).all()


@pytest.fixture(scope="module")
def small_run(tmp_path_factory: pytest.TempPathFactory) -> dict:
    ex = load("ex6_3_bathymetric_slam")
    out = tmp_path_factory.mktemp("ex6_3")
    return ex.run(seed=1, bounds=True, out=out, legs=4, leg=200.0, max_passes=4)  # a 11-minute survey


def test_small_mission_truth_in_tube(small_run: dict) -> None:
    r, sim = small_run["result"], small_run["sim"]
    assert r.consistent and small_run["inside"]
    t, x = sim["t"], sim["x"]
    rng = np.random.default_rng(0)
    k = rng.integers(0, t.size - 1, 3000)  # sampled slice points: the truth is linear on each slice
    a = rng.uniform(0, 1, k.size)
    tau, xs = t[k] + a * (t[k + 1] - t[k]), x[k] + a[:, None] * (x[k + 1] - x[k])
    tau = np.where((tau > t[k]) & (tau < t[k + 1]), tau, t[k])
    xs = np.where((tau > t[k])[:, None], xs, x[k])
    assert r.tube.contains(tau, xs).all()
    assert small_run["p_contains_truth"]


def test_small_mission_width_bounded(small_run: dict) -> None:
    dr, sl = small_run["dr_width"], small_run["slam_width"]
    assert dr[-1] == pytest.approx(dr.max()) and dr[-1] > 20.0  # dead reckoning grows
    assert sl.max() < 0.75 * dr.max() and sl[-1] < 0.75 * dr[-1]
    assert (sl <= dr + 1e-9).all()
    assert small_run["w_after"] < small_run["w_before"]  # Table 6.1 in spirit
    assert small_run["registrations"] > 0 and 0 < small_run["tested"] < small_run["pairs"]
    assert small_run["figure"].endswith(".png")


def test_pretest_keeps_truly_overlapping_pairs(small_run: dict) -> None:
    sim, r = small_run["sim"], small_run["result"]
    g, xs = sim["gates"], sim["x"][sim["gates"]]
    i, j = r.pairs.T
    boxes = [s.scope_box() for s in sim["shapes"]]
    lo, hi = np.array([b[0] for b in boxes]), np.array([b[1] for b in boxes])
    p = xs[j] - xs[i]
    truly = (np.maximum(lo[i], lo[j] + p) < np.minimum(hi[i], hi[j] + p)).all(axis=1)
    assert truly.any() and r.tested[truly].all()
    assert ((r.p[0] <= p) & (p <= r.p[1])).all()  # every [p_ij] holds the true displacement
    assert np.all(g == sim["gates"])


def test_bad_input() -> None:
    z = np.zeros((4, 4))
    with pytest.raises(ValueError, match="elevation"):
        level_thick_image(np.zeros(4), 0.1, 0.0, 1.0, (0, 0))
    with pytest.raises(ValueError, match="error"):
        level_thick_image(z, -0.1, 0.0, 1.0, (0, 0))
    with pytest.raises(ValueError, match="level"):
        level_thick_image(z, 0.1, (1.0, 0.0), 1.0, (0, 0))
    with pytest.raises(ValueError, match="corner"):
        level_thick_image(z, 0.1, 0.0, 0.1, (3, 3))
    with pytest.raises(ValueError, match="cell"):
        level_thick_image(z, 0.1, 0.0, -1.0, (0, 0))
    with pytest.raises(ValueError, match="lower"):
        ThickImage(np.ones((2, 2)), np.zeros((2, 2)), np.ones((2, 2)), 1.0, (0, 0))
    a = level_thick_image(z, 0.1, 0.0, 1.0, (0, 0))
    b = level_thick_image(z, 0.1, 0.0, 2.0, (0, 0))
    with pytest.raises(ValueError, match="b: cell"):
        SepTranslationInclusion(a, b)
    with pytest.raises(ValueError, match="method"):
        register_translation(a, a, [(0, 1), (0, 1)], 0.1, method="nope")
    with pytest.raises(ValueError, match="p_box"):
        register_translation(a, a, [(0, 1)] * 3 + [(5, 4)], 0.1)
    with pytest.raises(ValueError, match="max_passes"):
        ShapeSlamConfig(max_passes=0)
    with pytest.raises(ValueError, match="eps_p"):
        ShapeSlamConfig(eps_p=0.0)
    t = np.arange(5.0)
    x0 = Tube.entire(t, 2)
    u = np.zeros((4, 2))
    with pytest.raises(ValueError, match="gates"):
        shape_slam(x0, u, u, np.array([1, 9]), [a, a])
    with pytest.raises(ValueError, match="shapes"):
        shape_slam(x0, u, u, np.array([1, 2]), [a])
    with pytest.raises(ValueError, match="tube"):
        shape_slam(Tube.entire(t, 1), u, u, np.array([1, 2]), [a, a])
    with pytest.raises(ValueError, match="v_j"):
        overlap_pretest((np.zeros((2, 2)),) * 2, (np.zeros((3, 2)),) * 2, (np.zeros((2, 2)),) * 2)


@pytest.mark.expensive
def test_full_mission_width_bounded(tmp_path) -> None:  # noqa: ANN001
    """The default 39-minute survey (about 30 s): bounded tube, growing dead reckoning, Table 6.1."""
    r = load("ex6_3_bathymetric_slam").run(out=tmp_path)
    dr, sl = r["dr_width"], r["slam_width"]
    assert r["inside"] and r["p_contains_truth"] and r["w_after"] < 0.5 * r["w_before"]
    assert dr[-1] > 90.0 and sl.max() < 0.4 * dr.max() and sl[-1] < 0.2 * dr[-1]
    half = sl.size // 2
    assert sl[half:].max() <= sl[:half].max() + 1.0  # no growth over the second half
