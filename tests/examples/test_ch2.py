"""The chapter-2 example scripts (Ex. 2.6, 2.7, 2.8, §2.6.1 path planning, §2.6.2 localization).

Each script in ``examples/`` exposes ``run(eps=..., out=None) -> dict``; it is imported by file path and
run once per module at a coarse ε. The numbers are checked against closed forms or exact point tests
(soundness by sampling: points of inner boxes are in the set, points of outer boxes are not), and every
script must write a non-empty PNG.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from example_loader import load, run_cache

from digslam.observer import Box, pave

pytest.importorskip("matplotlib")


#: coarse precisions: the whole file stays well under the 40 s budget
EPS = {"ex2_6_three_rings": 0.1, "ex2_7_ring": 0.05, "ex2_8_rotated_polygon": 0.05, "path_planning": 0.05,
       "localization_laser": 0.01}  # fmt: skip
PNG = {"ex2_6_three_rings": ["ex2_6_three_rings.png"], "ex2_7_ring": ["ex2_7_ring.png"],
       "ex2_8_rotated_polygon": ["ex2_8_rotated_polygon.png"], "path_planning": ["path_planning.png"],
       "localization_laser": ["localization_laser.png"]}  # fmt: skip


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> dict:
    """Every example run once at its coarse ε, drawing into a temporary folder."""
    return run_cache(tmp_path_factory.mktemp("examples_ch2"), EPS)


def sample_boxes(lo: np.ndarray, hi: np.ndarray, per_box: int, rng: np.random.Generator) -> np.ndarray:
    """Uniform points in the interior of each box (flat boxes skipped)."""
    keep = (hi > lo).all(axis=1)
    lo, hi = lo[keep], hi[keep]
    u = rng.uniform(0.001, 0.999, size=(len(lo), per_box, lo.shape[1]))
    return (lo[:, None] + u * (hi - lo)[:, None]).reshape(-1, lo.shape[1])


def assert_tiles_frame(p, frame) -> None:
    total = p.inner_area + p.outer_area + p.boundary_area
    assert total == pytest.approx(float(np.prod(frame.hi - frame.lo)), rel=1e-9)


# ---- Example 2.6 ------------------------------------------------------------------------------------


def test_ex2_6_single_rings_bracket_closed_form():
    ex = load("ex2_6_three_rings")
    for centre, radius in ex.RINGS:
        p = pave(ex.FRAME, ex.sep_ring(centre, radius), 0.1)
        exact = np.pi * (radius[1] ** 2 - radius[0] ** 2)
        assert p.inner_area <= exact <= p.inner_area + p.boundary_area
        assert p.boundary_area < 0.2 * exact


def test_ex2_6_areas(results):
    r = results("ex2_6_three_rings")
    assert_tiles_frame(r["paving"], load("ex2_6_three_rings").FRAME)
    assert r["ring_areas"] == pytest.approx([27 * np.pi, 24 * np.pi, 7 * np.pi])
    exact, tol = r["exact_area"], 0.02  # midpoint-rule quadrature: converged to ~49.693 within 0.005
    assert exact == pytest.approx(49.693, abs=tol)
    assert r["inner_area"] <= exact + tol
    assert exact - tol <= r["inner_area"] + r["boundary_area"]
    assert r["boundary_area"] < 0.1 * exact  # the accumulation set is 1-d: a thin band at ε = 0.1
    # X ⊂ (X1 ∩ X2) ∪ X3: bounded by the ring areas
    assert r["inner_area"] < r["ring_areas"][1] + r["ring_areas"][2]


def test_ex2_6_sound_by_sampling(results):
    ex = load("ex2_6_three_rings")
    p = results("ex2_6_three_rings")["paving"]
    rng = np.random.default_rng(0)
    assert ex.in_set(sample_boxes(*p.inner, 4, rng)).all()
    assert not ex.in_set(sample_boxes(*p.outer, 4, rng)).any()


# ---- Example 2.7 ------------------------------------------------------------------------------------


def test_ex2_7_contractor_vs_separator(results):
    ex = load("ex2_7_ring")
    r = results("ex2_7_ring")
    c, s, exact = r["contractor"], r["separator"], 1.25 * np.pi
    assert r["exact_area"] == pytest.approx(exact)
    for p in r["pavings"]:
        assert_tiles_frame(p, ex.FRAME)
    # the contractor proves nothing inside: the whole ring is undetermined
    assert c["inner_area"] == 0.0
    assert exact <= c["boundary_area"]
    # the separator brackets the ring area with a thin undetermined band
    assert s["inner_area"] <= exact <= s["inner_area"] + s["boundary_area"]
    assert s["boundary_area"] < c["boundary_area"] / 8
    assert s["bisections"] < c["bisections"] / 4
    # both see the same outside (the contractor is the separator's outer part)
    assert abs(c["outer_area"] - s["outer_area"]) < 0.1


def test_ex2_7_contractor_only_separator_keeps_box():
    ex = load("ex2_7_ring")
    from digslam.observer import CtcFwdBwd, Interval

    s = ex.ContractorOnly(CtcFwdBwd(ex.ring_function(), Interval(1, 2.25)))
    lo, hi = np.array([[3.1, 2.4], [-1.0, -0.5]]), np.array([[3.2, 2.6], [0.0, 0.5]])
    (ilo, ihi), (olo, ohi) = s.separate(lo, hi)
    assert (ilo == lo).all() and (ihi == hi).all()
    assert olo[1, 0] > ohi[1, 0]  # the far box is proved outside
    assert (olo[0] <= ohi[0]).all()  # the box inside the ring is kept


# ---- Example 2.8 ------------------------------------------------------------------------------------


def test_ex2_8_areas(results):
    ex = load("ex2_8_rotated_polygon")
    r = results("ex2_8_rotated_polygon")
    area = ex.polygon_area(ex.M)
    assert area == pytest.approx(14.4)
    for name in ("M", "RM"):  # a rotation keeps the area
        v = r[name]
        assert v["inner_area"] <= area <= v["inner_area"] + v["boundary_area"] + 1e-9
    v, mc, err = r["RM_minus_M"], r["mc_area"], r["mc_stderr"]
    assert v["inner_area"] <= mc + 4 * err
    assert mc - 4 * err <= v["inner_area"] + v["boundary_area"]
    assert v["inner_area"] > 0.8 * mc


def test_ex2_8_sound_by_sampling(results):
    ex = load("ex2_8_rotated_polygon")
    p_m, p_rm, p_diff = results("ex2_8_rotated_polygon")["pavings"]
    rng = np.random.default_rng(1)
    pts = sample_boxes(*p_diff.inner, 3, rng)
    assert len(pts) > 100 and ex.in_rm_minus_m(pts).all()
    out = sample_boxes(*p_diff.outer, 3, rng)
    far = ex.distance_to_boundary(out) > 1e-9
    far &= ex.distance_to_boundary(ex.rotate(out, -ex.ANGLE)) > 1e-9
    assert not ex.in_rm_minus_m(out[far]).any()
    inner_rm = sample_boxes(*p_rm.inner, 3, rng)
    assert ex.point_in_polygon(ex.rotate(inner_rm, -ex.ANGLE)).all()
    assert ex.point_in_polygon(sample_boxes(*p_m.inner, 3, rng)).all()


# ---- §2.6.1 path planning ---------------------------------------------------------------------------


def test_path_planning_path_in_inner_boxes(results):
    ex = load("path_planning")
    r = results("path_planning")
    lo, hi = r["paving"].inner
    boxes, poly = r["path_boxes"], r["path"]
    assert len(boxes) >= 10 and r["goal"][0] - r["start"][0] > 2.0  # crosses a good part of the x1 range
    # consecutive boxes share a face segment of positive length
    for a, b in zip(boxes[:-1], boxes[1:], strict=True):
        ov = np.minimum(hi[a], hi[b]) - np.maximum(lo[a], lo[b])
        assert (ov >= 0).all() and (ov == 0).sum() == 1 and ov.max() > 0
    # polyline: centre_k, face_k,k+1, centre_k+1, ... every segment lies in one (convex) box
    assert len(poly) == 2 * len(boxes) - 1
    for k, b in enumerate(boxes):
        for q in poly[max(0, 2 * k - 1) : 2 * k + 2]:
            assert (lo[b] <= q).all() and (q <= hi[b]).all()
    # every configuration along the path is feasible (exact point test of Eq. 2.80)
    t = np.linspace(0, 1, 20)[:, None]
    dense = np.concatenate([a + t * (b - a) for a, b in zip(poly[:-1], poly[1:], strict=True)])
    assert ex.feasible(dense).all()


def test_path_planning_sound_by_sampling(results):
    ex = load("path_planning")
    p = results("path_planning")["paving"]
    rng = np.random.default_rng(2)
    assert ex.feasible(sample_boxes(*p.inner, 2, rng)).all()
    out = sample_boxes(*p.outer, 2, rng)
    assert not ex.feasible(out).any()
    assert p.inner_area > 0


def test_box_adjacency_small():
    ex = load("path_planning")
    lo = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [2, 0.5]], dtype=float)
    hi = np.array([[1, 1], [2, 1], [1, 2], [2, 2], [3, 1.5]], dtype=float)
    i, j = ex.box_adjacency(lo, hi)
    pairs = set(zip(i.tolist(), j.tolist(), strict=True))
    assert pairs == {(0, 1), (0, 2), (1, 3), (2, 3), (1, 4), (3, 4)}  # (0, 3) touch at a corner only
    assert ex.shortest_box_path(lo, hi, i, j, 0, 4) == [0, 1, 4]
    assert ex._components(len(lo), i, j).tolist() == [0] * 5


def test_box_adjacency_matches_brute_force(results):
    ex = load("path_planning")
    lo, hi = results("path_planning")["paving"].inner
    i, j = ex.box_adjacency(lo, hi)
    ov = np.minimum(hi[:, None], hi[None]) - np.maximum(lo[:, None], lo[None])  # (N, N, 2)
    touch = ((ov[..., 0] == 0) & (ov[..., 1] > 0)) | ((ov[..., 1] == 0) & (ov[..., 0] > 0))
    bi, bj = np.nonzero(np.triu(touch, 1))
    assert sorted(zip(i.tolist(), j.tolist(), strict=True)) == list(
        zip(bi.tolist(), bj.tolist(), strict=True)
    )


def test_path_search_without_scipy(monkeypatch):
    ex = load("path_planning")
    monkeypatch.setitem(sys.modules, "scipy.sparse", None)  # `from scipy.sparse import ...` now fails
    monkeypatch.setitem(sys.modules, "scipy.sparse.csgraph", None)
    lo = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [2, 0.5], [5, 5]], dtype=float)
    hi = np.array([[1, 1], [2, 1], [1, 2], [2, 2], [3, 1.5], [6, 6]], dtype=float)
    i, j = ex.box_adjacency(lo, hi)
    assert ex.shortest_box_path(lo, hi, i, j, 2, 4) in ([2, 0, 1, 4], [2, 3, 1, 4], [2, 3, 4])
    assert ex.shortest_box_path(lo, hi, i, j, 0, 5) == []
    assert ex._components(len(lo), i, j).tolist() == [0, 0, 0, 0, 0, 5]


# ---- §2.6.2 localization ----------------------------------------------------------------------------


def test_localization_contains_truth(results):
    ex = load("localization_laser")
    r = results("localization_laser")
    assert r["truth_in_outer"]
    assert r["n_inner"] > 0 and r["inner_area"] > 0
    assert r["n_inliers"] == 41 and len(r["measurements"]["outliers"]) == 15
    assert r["inliers_consistent_eq_2_84"] == 41
    # the solution set is small (redundant, accurate ranges)
    assert (r["hull_hi"] - r["hull_lo"]).max() < 0.5
    assert (r["hull_lo"] <= ex.TRUTH).all() and (ex.TRUTH <= r["hull_hi"]).all()


def test_localization_inner_sound_by_sampling(results):
    ex = load("localization_laser")
    r = results("localization_laser")
    m = r["measurements"]
    pts = sample_boxes(*r["paving"].inner, 4, np.random.default_rng(3))
    u = np.column_stack([np.cos(m["alpha"]), np.sin(m["alpha"])])
    count = np.zeros(len(pts), dtype=int)
    for k in range(ex.N_MEAS):  # Eq. 2.84 by point tests: a_i ∈ M and b_i ∉ M
        a_ok = ex.point_in_map(pts + m["d_lo"][k] * u[k])
        b_ok = ~ex.point_in_map(pts + m["d_hi"][k] * u[k])
        count += a_ok & b_ok
    assert (count >= ex.N_MEAS - ex.N_OUTLIERS).all()


def test_localization_outer_sound_by_sampling(results):
    """Points proved outside are consistent with fewer than 41 measurements (Eq. 2.84 point tests).

    The widened sets of the sound separator contain those of Eq. 2.84, so a point outside the
    widened q-relaxed intersection is outside the thesis one too.
    """
    ex = load("localization_laser")
    r = results("localization_laser")
    m = r["measurements"]
    pts = sample_boxes(*r["paving"].outer, 200, np.random.default_rng(4))
    u = np.column_stack([np.cos(m["alpha"]), np.sin(m["alpha"])])
    count = np.zeros(len(pts), dtype=int)
    for k in range(ex.N_MEAS):
        count += ex.point_in_map(pts + m["d_lo"][k] * u[k]) & ~ex.point_in_map(pts + m["d_hi"][k] * u[k])
    assert len(pts) > 100 and (count < ex.N_MEAS - ex.N_OUTLIERS).all()


def test_localization_ray_cast():
    ex = load("localization_laser")
    d = ex.ray_cast(np.array([1.0, 1.0]), np.array([0.0, np.pi / 2, np.pi, -np.pi / 2]))
    assert d == pytest.approx([9.0, 7.0, 1.0, 1.0])
    d = ex.ray_cast(np.array([3.0, 3.0]), np.array([0.0]))  # hits the pillar at x = 4
    assert d == pytest.approx([1.0])


def test_localization_grazing_ray_needs_the_sound_widening():
    """A ray clipping the pillar's corner leaves it before b_i: Eq. 2.85 rejects the true position."""
    ex = load("localization_laser")
    truth = ex.TRUTH
    alpha = np.arctan2(3.98 - truth[1], 4.0 - truth[0])  # enters the pillar 2 cm below its corner
    d = float(ex.ray_cast(truth, np.array([alpha]))[0])
    meas = {"alpha": np.array([alpha]), "d_lo": np.array([d - 0.05]), "d_hi": np.array([d + 0.15])}
    box_lo, box_hi = (truth - 1e-6)[None], (truth + 1e-6)[None]
    thesis = ex.measurement_separators(meas, sound=False)[0]
    sound = ex.measurement_separators(meas, sound=True)[0]
    (_, _), (olo, ohi) = thesis.separate(box_lo, box_hi)
    assert (olo > ohi).any()  # Eq. 2.85 proves the truth outside X_i
    (_, _), (olo, ohi) = sound.separate(box_lo, box_hi)
    assert (olo <= ohi).all()  # the widened separator keeps it


# ---- rendering ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(EPS))
def test_each_script_writes_png(results, name):
    r = results(name)
    for f in PNG[name]:
        png = Path(r["png"])
        assert png.name == f and png.exists() and png.stat().st_size > 10_000
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("name", ["ex2_6_three_rings", "ex2_7_ring", "ex2_8_rotated_polygon"])
def test_command_line(tmp_path, capsys, name):
    load(name).main(["--out", str(tmp_path), "--eps", "0.2"])
    printed = capsys.readouterr().out
    assert "eps=0.2" in printed and "wrote" in printed
    assert (tmp_path / PNG[name][0]).stat().st_size > 10_000


def test_draw_module_headless(tmp_path):
    from digslam.observer import Function, Interval, SepInverse, classify_grid
    from digslam.observer.paving.draw import draw_boxes, draw_grid, draw_paving, new_figure, save_figure

    ring = SepInverse(Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2), Interval(1, 2.25))
    frame = Box([(-1, 5), (-0.5, 5.5)])
    fig, axes = new_figure(ncols=3)
    draw_paving(pave(frame, ring, 0.2), axes[0], edgecolor="none")
    status = classify_grid(frame, ring, (40, 40))
    draw_grid(status, frame, axes[1])
    draw_grid(np.where(status == 0, 2, status), (-1, 5, -0.5, 5.5), axes[2], thick=True, penumbra=2)
    draw_boxes(np.zeros((0, 2)), np.zeros((0, 2)), axes[2])  # an empty batch draws nothing
    path = save_figure(fig, tmp_path / "a" / "b" / "draw.png")
    assert path.exists() and path.stat().st_size > 5_000
    assert len(axes[0].collections) == 3 and len(axes[1].images) == 1
