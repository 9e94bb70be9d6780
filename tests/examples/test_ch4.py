"""The chapter-4 example scripts (§4.2.3 sonar registration, Ex. 4.1–4.2 Minkowski, §4.4 localization).

Each script in ``examples/`` exposes ``run(eps=..., out=None) -> dict``; it is imported by file path and
run once at a coarse ε. Checked: the published §4.2.3 interval (our enclosure contains the exact
distance ``5 / cos(5π/24)`` and lies inside ``[6.2988, 6.3085]``), the Minkowski pavings against their
closed forms (points and areas), the true pose inside the §4.4 result and the soundness of its inner
boxes against the exact sonar model, and that every script writes its PNGs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from example_loader import load, run_cache

pytest.importorskip("matplotlib")


#: coarse precisions: the whole file stays well under its share of the 40 s budget
EPS = {"ex4_sonar_registration": 1e-4, "ex4_minkowski": 0.1, "ex4_4_sonar_localization": 0.5}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    return run_cache(tmp_path_factory.mktemp("examples_ch4"), EPS)


def test_exact_distance_enclosure() -> None:
    mod = load("ex4_sonar_registration")
    lo, hi = mod.exact_distance()
    assert lo <= 5 / np.cos(5 * np.pi / 24) <= hi and hi - lo < 1e-13
    assert abs(float(mod.exact_distance_str()) - 5 / np.cos(5 * np.pi / 24)) < 1e-12


def test_sonar_registration_published_interval(results) -> None:
    r = results("ex4_sonar_registration")
    lo, hi = r["d"]
    elo, ehi = r["exact"]
    assert lo <= elo and ehi <= hi, "the enclosure must contain 5 / cos(5π/24)"
    assert 6.2988 <= lo and hi <= 6.3085, "at least as tight as the thesis's [6.2988, 6.3085]"
    assert hi - lo < 1e-3
    assert r["contains_exact"] and r["tighter_than_published"]
    assert Path(r["png"]).stat().st_size > 0


def test_minkowski_closed_forms(results) -> None:
    r = results("ex4_minkowski")
    for key in ("diff", "sum"):
        v = r[key]
        assert v["inner_area"] <= v["exact_area"] <= v["inner_area"] + v["boundary_area"]
        assert v["inner_violations"] == 0 and v["outer_violations"] == 0
        assert v["inner_points"] > 100 and v["outer_points"] > 100
        assert v["boundary_area"] < 0.1 * v["exact_area"]
    assert abs(r["sum"]["exact_area"] - 17.0) < 1e-12
    assert [Path(p).name for p in r["png"]] == ["ex4_minkowski_diff.png", "ex4_minkowski_sum.png"]
    assert all(Path(p).stat().st_size > 0 for p in r["png"])


def test_localization_contains_true_pose(results) -> None:
    mod = load("ex4_4_sonar_localization")
    r = results("ex4_4_sonar_localization")
    assert r["true_pose_in_result"]
    d, true_d = r["ranges"], r["true_distances"]
    assert ((d[:, 0] <= true_d) & (true_d <= d[:, 1])).all()
    assert 0 < r["n_boxes"] and r["inner_area"] > 0
    hlo, hhi = r["hull"]
    assert (hhi - hlo).max() < 3.0  # the six cones localise the robot to a small region
    # soundness of the inner boxes against the exact sensor model: every cone distance in [d_i]
    rng = np.random.default_rng(0)
    ilo, ihi = r["paving"].inner
    pts = ilo[:, None] + rng.random((len(ilo), 3, 2)) * (ihi - ilo)[:, None]
    for q in pts.reshape(-1, 2):
        dist = np.array([mod.cone_distance(q, a, mod.GAMMA) for a in mod.ALPHAS])
        assert ((d[:, 0] - 1e-9 <= dist) & (dist <= d[:, 1] + 1e-9)).all()
    assert Path(r["png"]).stat().st_size > 0


def test_cone_distance_closed_form() -> None:
    mod = load("ex4_4_sonar_localization")
    square = np.array([(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)])
    assert (
        abs(mod.cone_distance(np.zeros(2), 0.0, 0.3, square) - 1.0) < 1e-15
    )  # the wall x = 1, straight ahead
    assert (
        abs(mod.cone_distance(np.zeros(2), 0.6, 0.1, square) - 1 / np.cos(0.5)) < 1e-12
    )  # nearest ray at 0.5 rad
