"""The chapter-3 example scripts (§3.4.1.1 one landmark, §3.4.1.2 three landmarks, §3.4.2 transit).

Each script in ``examples/`` exposes ``run(eps=..., out=None) -> dict``; it is imported by file path and
run once at a coarse ε. Checked: the exact pie area is enclosed, the minimal polar separator's first
outer box is never larger than the forward-backward one, points of inner / outer boxes are in / out of
the set, the simulated truth is kept, and each script writes a non-empty PNG.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from example_loader import load

pytest.importorskip("matplotlib")


def box_inside(outer, inner) -> bool:
    (a, b), (c, d) = outer, inner
    return bool(np.all(np.asarray(c) >= np.asarray(a)) and np.all(np.asarray(d) <= np.asarray(b)))


def in_pies(pts: np.ndarray, table) -> np.ndarray:
    ok = np.ones(len(pts), dtype=bool)
    for m, (r0, r1), (t0, t1) in table:
        d = np.asarray(m) - pts
        r, t = np.hypot(d[:, 0], d[:, 1]), np.arctan2(d[:, 1], d[:, 0])
        t = t0 + np.mod(t - t0, 2 * np.pi)
        ok &= (r >= r0) & (r <= r1) & (t <= t1)
    return ok


def check_paving(p, table, rng) -> None:
    for boxes, expect in ((p.inner, True), (p.outer, False)):
        lo, hi = boxes
        if len(lo):
            pts = rng.uniform(lo, hi)
            assert (in_pies(pts, table) == expect).all()


def test_one_landmark(tmp_path: Path) -> None:
    mod = load("ex3_4_one_landmark")
    r = mod.run(eps=0.01, out=tmp_path)  # the chapter's claim at the default ε, with the grid policy
    for k in ("polar", "fwdbwd"):
        assert r[k]["inner_area"] <= r["exact_area"] <= r[k]["inner_area"] + r[k]["boundary_area"]
    assert box_inside(r["fwdbwd"]["first_outer_box"], r["polar"]["first_outer_box"])
    assert r["polar"]["first_outer_area"] < 0.5 * r["fwdbwd"]["first_outer_area"]
    assert r["polar"]["bisections"] < r["fwdbwd"]["bisections"]  # cut="grid", max_volume=ε²/2
    d = r["default_cut"]
    assert d["polar"] > d["fwdbwd"]  # the default midpoint cut reverses it (stated in the output)
    check_paving(r["pavings"]["polar"], [(mod.LANDMARK, mod.RANGE, mod.BEARING)], np.random.default_rng(0))
    assert Path(r["png"]).stat().st_size > 0


def test_three_landmarks(tmp_path: Path) -> None:
    mod = load("ex3_4_three_landmarks")
    r = mod.run(eps=0.1, out=tmp_path)
    assert box_inside(r["fwdbwd"]["first_outer_box"], r["polar"]["first_outer_box"])
    assert r["polar"]["first_outer_area"] < r["fwdbwd"]["first_outer_area"]
    table = [(m, rr, np.deg2rad(b)) for m, rr, b in mod.TABLE]
    check_paving(r["pavings"]["polar"], table, np.random.default_rng(1))
    check_paving(r["pavings"]["fwdbwd"], table, np.random.default_rng(2))
    assert r["polar"]["inner_area"] > 2.0
    assert Path(r["png"]).stat().st_size > 0


def test_transit(tmp_path: Path) -> None:
    mod = load("ex3_10_transit")
    r = mod.run(out=tmp_path, fix_period=5.0)  # one fix every 5 s, as VAMA
    assert r["polar"]["contains_truth"] and r["fwdbwd"]["contains_truth"]
    assert (r["ratio_i0"] >= 1 - 1e-9).all() and (r["ratio_dr"] >= 1 - 1e-9).all()
    assert r["ratio_i0"].mean() > 2
    assert Path(r["png"]).stat().st_size > 0
