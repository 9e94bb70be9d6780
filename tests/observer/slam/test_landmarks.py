"""Initial localization among indistinguishable landmarks (thesis §3.4.3, Eq. 3.66–3.70, Table 3.3).

The landmark contractor is compared with a brute-force reference; the fixpoint is checked against the
simulated truth (examples/ex3_12_initial_localization.py) over several seeds, with errors drawn
uniformly and exactly on their bounds: the truth stays in the tubes and no unique association is
ever wrong. The full run (full association) is marked expensive.
"""

from __future__ import annotations

import numpy as np
import pytest
from example_loader import load
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.observer.slam.landmarks import CtcLandmarks, contract_detections, contract_disjunctive, localize

EX = load("ex3_12_initial_localization")


def brute_hull(pts: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    out_lo, out_hi = np.full(lo.shape, np.inf), np.full(hi.shape, -np.inf)
    for i in range(lo.shape[0]):
        inside = ((pts >= lo[i]) & (pts <= hi[i])).all(axis=1)
        if inside.any():
            out_lo[i], out_hi[i] = pts[inside].min(axis=0), pts[inside].max(axis=0)
    return out_lo, out_hi


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(1, 60), st.integers(1, 50))
def test_landmark_contractor_matches_brute_force(seed: int, n_lm: int, n_box: int) -> None:
    rng = np.random.default_rng(seed)
    pts = np.round(rng.uniform(-10, 10, (n_lm, 2)), 1)  # ties and points on box faces
    a, b = np.round(rng.uniform(-12, 12, (n_box, 2)), 1), np.round(rng.uniform(-12, 12, (n_box, 2)), 1)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    lo[0], hi[0] = -np.inf, np.inf
    lm = CtcLandmarks(pts)
    got = lm.contract(lo, hi)
    ref = brute_hull(pts, lo, hi)
    np.testing.assert_array_equal(got[0], ref[0])
    np.testing.assert_array_equal(got[1], ref[1])
    cnt = np.array([((pts >= lo[i]) & (pts <= hi[i])).all(axis=1).sum() for i in range(n_box)])
    np.testing.assert_array_equal(lm.count(lo, hi), cnt)
    uniq = lm.unique(lo, hi)
    for i in range(n_box):
        inside = np.flatnonzero(((pts >= lo[i]) & (pts <= hi[i])).all(axis=1))
        assert uniq[i] == (inside[0] if inside.size == 1 else -1)


def test_landmark_contractor_chunks_and_empty_boxes(monkeypatch: pytest.MonkeyPatch) -> None:
    import digslam.observer.slam.landmarks as L

    monkeypatch.setattr(L, "_CHUNK", 7)  # many chunks
    rng = np.random.default_rng(3)
    pts = rng.uniform(0, 10, (40, 2))
    lo = np.vstack([rng.uniform(0, 5, (30, 2)), [[np.inf, np.inf]]])
    hi = np.vstack([lo[:30] + rng.uniform(0, 6, (30, 2)), [[-np.inf, -np.inf]]])
    got = L.CtcLandmarks(pts).contract(lo, hi)
    ref = brute_hull(pts, lo, hi)
    np.testing.assert_array_equal(got[0], ref[0])
    np.testing.assert_array_equal(got[1], ref[1])


def test_detection_contractors_keep_the_truth() -> None:
    rng = np.random.default_rng(0)
    pts = rng.uniform(-50, 50, (100, 2))
    lm = CtcLandmarks(pts)
    p_true, psi_true = np.array([[1.0, 2.0]]), np.array([0.3])
    d = pts[7] - p_true[0]
    rho_t, phi_t = np.hypot(*d), np.arctan2(d[1], d[0]) - psi_true[0]
    rho = (np.array([rho_t * 0.99]), np.array([rho_t * 1.01]))
    phi = (np.array([phi_t - 0.02]), np.array([phi_t + 0.02]))
    p = (np.array([[-5.0, -5.0]]), np.array([[5.0, 5.0]]))
    psi = (np.array([0.2]), np.array([0.4]))
    m = (np.full((1, 2), -np.inf), np.full((1, 2), np.inf))
    for fn in (lambda *a: contract_detections(lm, *a), lambda *a: contract_disjunctive(lm, *a)):
        (plo, phi_), (slo, shi), (mlo, mhi) = fn(p, psi, m, rho, phi)
        assert ((plo <= p_true) & (p_true <= phi_)).all() and slo[0] <= psi_true[0] <= shi[0]
        assert ((mlo[0] <= pts[7]) & (pts[7] <= mhi[0])).all()


@pytest.mark.parametrize("noise", ["uniform", "bounds"])
@pytest.mark.parametrize("seed", [0, 2, 5])
def test_guarantee_over_seeds(seed: int, noise: str) -> None:
    r = EX.run(seed=seed, noise=noise, max_iter=3)
    assert r["truth_inside"] and r["heading_inside"] and r["result"].consistent
    assert r["wrong"] == 0
    d = r["data"]
    m = r["result"]
    true_m = d["landmarks"][d["true_landmark"]]
    assert ((m.m_lo <= true_m) & (true_m <= m.m_hi)).all()


def test_hull_only_mode_is_sound() -> None:
    r = EX.run(seed=EX.SEED, noise="bounds", max_iter=4, disjunctive=False)
    assert r["truth_inside"] and r["heading_inside"] and r["wrong"] == 0


def test_table_3_3_columns_are_monotone() -> None:
    r = EX.run(seed=EX.SEED, max_iter=6)
    h = r["result"].history
    assert h[0].min_candidates == h[0].max_candidates == 280  # [p] = R²: every landmark is a candidate
    assert all(a.max_candidates >= b.max_candidates for a, b in zip(h, h[1:]))
    assert all(a.max_width >= b.max_width for a, b in zip(h, h[1:]))
    assert len(r["data"]["k"]) == 90


@pytest.mark.expensive
@pytest.mark.parametrize("noise", ["uniform", "bounds"])
def test_full_association(noise: str) -> None:
    r = EX.run(seed=EX.SEED, noise=noise)
    assert r["truth_inside"] and r["heading_inside"] and r["wrong"] == 0
    if noise == "uniform":
        assert r["full_association_at"] is not None and r["full_association_at"] <= 25
        assert r["unique"] == 90


def test_bad_input_names_the_argument() -> None:
    d = EX.simulate(0)
    args = [d["t"], d["v"], d["omega"], d["psi0"], d["k"], d["rho"], d["phi"], d["landmarks"]]
    with pytest.raises(ValueError, match="landmarks"):
        CtcLandmarks(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="landmarks"):
        CtcLandmarks([[0.0, np.nan]])
    bad = {1: (np.zeros((3, 2)), np.zeros((3, 2))), 2: (np.zeros(3), np.zeros(3)), 3: (1.0, 0.0),
           4: np.array([0.5]), 5: (d["rho"][1], d["rho"][0]), 6: (np.zeros(2), np.zeros(2))}  # fmt: skip
    names = {1: "v", 2: "omega", 3: "psi0", 4: "k", 5: "rho", 6: "phi"}
    for i, val in bad.items():
        a = list(args)
        a[i] = val
        with pytest.raises(ValueError, match=names[i]):
            localize(*a)
    with pytest.raises(ValueError, match="tol"):
        localize(*args, tol=-1.0)
    with pytest.raises(ValueError, match="t"):
        localize(np.array([0.0]), *args[1:])
