"""The paver (Algorithm 2.1), regular pavings, and subpavings as data and separators (§2.5.2)."""

from __future__ import annotations

import numpy as np
import pytest

from digslam.observer import (
    Box,
    CtcFwdBwd,
    Function,
    Interval,
    SepInverse,
    SepSubpaving,
    classify_grid,
    load,
    pave,
    save,
    simplify,
)
from digslam.observer.core.boxes import box_difference, volume
from digslam.observer.sets.separators import Sep, check_separation

RING_F = Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2)  # Ex. 2.7, Eq. 2.60
RING_AREA = np.pi * (1.5**2 - 1.0**2)
X0 = Box([(-1, 5), (-0.5, 5.5)])


class SepContractorOnly(Sep):
    """``{identity, C}``: the contractor alone, nothing is ever proved inside (Fig. 2.12, left)."""

    def __init__(self, ctc: CtcFwdBwd) -> None:
        self.ctc, self.n = ctc, ctc.n

    def separate(self, lo: np.ndarray, hi: np.ndarray):  # noqa: ANN201
        return (lo, hi), self.ctc.contract(lo, hi)


def ring_member(p: np.ndarray) -> np.ndarray:
    d = (p[:, 0] - 2) ** 2 + (p[:, 1] - 2.5) ** 2
    return (d >= 1) & (d <= 2.25)


@pytest.mark.parametrize("eps", [0.1, 0.02])
def test_ring_enclosure_and_partition(eps: float) -> None:
    p = pave(X0, SepInverse(RING_F, Interval(1, 2.25)), eps)
    # Eq. 2.58: X⁻ ⊂ X ⊂ X⁺
    assert p.inner_area <= RING_AREA <= p.inner_area + p.boundary_area
    # the three kinds of boxes tile the initial box
    total = p.inner_area + p.outer_area + p.boundary_area
    assert total == pytest.approx(36.0, rel=1e-12)
    assert (np.maximum(p.boundary[1] - p.boundary[0], 0).max(axis=1) < eps).all()
    assert p.bisections == p.tree.size // 2
    rng = np.random.default_rng(0)
    assert ring_member(rng.uniform(*p.inner)).all()
    assert not ring_member(rng.uniform(*p.outer)).any()


def test_ex2_7_separator_beats_contractor() -> None:
    eps = 0.05
    sep = pave(X0, SepInverse(RING_F, Interval(1, 2.25)), eps)
    ctc = pave(X0, SepContractorOnly(CtcFwdBwd(RING_F, Interval(1, 2.25))), eps)
    assert ctc.inner_area == 0.0
    assert ctc.boundary_area > RING_AREA  # the whole ring stays undetermined
    assert sep.boundary_area < 0.2 * ctc.boundary_area
    assert sep.bisections < ctc.bisections


def test_subpaving_roundtrip_and_separator(tmp_path) -> None:  # noqa: ANN001
    p = pave(X0, SepInverse(RING_F, Interval(1, 2.25)), 0.05)
    save(p, tmp_path / "ring.npz")
    q = load(tmp_path / "ring.npz")
    for a, b in ((p.inner, q.inner), (p.outer, q.outer), (p.boundary, q.boundary)):
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    sep = SepSubpaving(q)
    rng = np.random.default_rng(1)
    c = rng.uniform(-3, 7, (4000, 2))
    r = rng.uniform(0, 0.4, (4000, 2))
    lo, hi = c - r, c + r
    xin, xout = sep.separate(lo, hi)
    assert not check_separation(xin, xout, lo, hi).any()
    (plo, phi), _ = box_difference(lo, hi, *xin)
    assert ring_member(rng.uniform(plo, phi)).all()
    (plo, phi), _ = box_difference(lo, hi, *xout)
    assert not ring_member(rng.uniform(plo, phi)).any()
    # paving again through the stored paving keeps the enclosure
    p2 = pave(X0, sep, 0.05)
    assert p2.inner_area <= RING_AREA <= p2.inner_area + p2.boundary_area


def test_load_rejects_foreign_files(tmp_path) -> None:  # noqa: ANN001
    np.savez(tmp_path / "x.npz", a=np.zeros(3))
    with pytest.raises(ValueError, match="missing arrays"):
        load(tmp_path / "x.npz")


def test_simplify_merges_pure_siblings_without_changing_the_sets() -> None:
    # a pessimistic inclusion function (x occurs twice): fathers stay undetermined, sons are proved
    sep = SepInverse(Function(lambda x: x[0] ** 2 + x[0] * x[1] + x[1] ** 2), Interval(-1, 1))
    p = pave(Box([(-3, 3), (-3, 3)]), sep, 0.05)
    s = simplify(p)
    assert len(s.inner[0]) + len(s.outer[0]) < len(p.inner[0]) + len(p.outer[0])
    for a, b in ((p.inner, s.inner), (p.outer, s.outer), (p.boundary, s.boundary)):
        assert volume(*a).sum() == pytest.approx(volume(*b).sum(), rel=1e-12)
    sp = SepSubpaving(s)
    lo, hi = np.array([[-0.1, -0.1], [2.5, 2.5]]), np.array([[0.1, 0.1], [2.9, 2.9]])
    xin, xout = sp.separate(lo, hi)
    assert xin[0][0, 0] > xin[1][0, 0] and xout[0][1, 0] > xout[1][1, 0]


def test_classify_grid_matches_paver_classes() -> None:
    sep = SepInverse(RING_F, Interval(1, 2.25))
    status = classify_grid(X0, sep, (60, 60))
    assert status.shape == (60, 60) and set(np.unique(status)) <= {-1, 0, 1}
    # image convention: row 0 is the top; the ring centre (2, 2.5) is outside and lies in row 30
    ys = np.linspace(5.5, -0.5, 61)
    xs = np.linspace(-1, 5, 61)
    cy, cx = 30, 30
    assert ys[cy] >= 2.5 >= ys[cy + 1] and xs[cx] <= 2 <= xs[cx + 1]
    assert status[cy, cx] == -1
    inside = np.argwhere(status == 1)
    centres = np.stack(
        [(xs[inside[:, 1]] + xs[inside[:, 1] + 1]) / 2, (ys[inside[:, 0]] + ys[inside[:, 0] + 1]) / 2], 1
    )
    assert ring_member(centres).all()


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"eps": 0.0}, "eps"),
        ({"eps": -1.0}, "eps"),
        ({"x0": Box([(0, 1)])}, "dimension"),
        ({"x0": Box([(0, np.inf), (0, 1)])}, "bounded"),
        ({"x0": (np.array([1.0, 0.0]), np.array([0.0, 1.0]))}, "above"),
    ],
)
def test_pave_bad_input(kwargs: dict, message: str) -> None:
    args = {"x0": X0, "sep": SepInverse(RING_F, Interval(1, 2.25)), "eps": 0.1} | kwargs
    with pytest.raises(ValueError, match=message):
        pave(**args)


@pytest.mark.parametrize("eps", [0.05, 0.01])
def test_grid_cut_and_max_volume_keep_the_enclosure(eps: float) -> None:
    """``cut="grid"`` and ``max_volume`` move cuts, never claims: same partition and enclosure, and the
    boundary boxes keep ``w∞ < ε`` and respect the volume bound."""
    sep = SepInverse(RING_F, Interval(1, 2.25))
    mid = pave(X0, sep, eps)
    for kw in ({"cut": "grid"}, {"cut": "grid", "max_volume": eps**2 / 2}, {"max_volume": eps**2 / 4}):
        p = pave(X0, sep, eps, **kw)
        assert p.inner_area <= RING_AREA <= p.inner_area + p.boundary_area
        assert p.inner_area + p.outer_area + p.boundary_area == pytest.approx(36.0, rel=1e-12)
        w = np.maximum(p.boundary[1] - p.boundary[0], 0)
        assert (w.max(axis=1) < eps).all()
        if "max_volume" in kw:
            assert (w.prod(axis=1) < kw["max_volume"]).all()
        assert p.bisections == p.tree.size // 2
        rng = np.random.default_rng(2)
        assert ring_member(rng.uniform(*p.inner)).all()
        assert not ring_member(rng.uniform(*p.outer)).any()
    grid = pave(X0, sep, eps, cut="grid")
    assert grid.bisections < mid.bisections  # boxes just under ε instead of ε/2 … ε
    vol = pave(X0, sep, eps, cut="grid", max_volume=eps**2 / 2)
    assert vol.boundary_area < grid.boundary_area


def test_grid_cut_on_a_side_too_narrow_to_split_terminates() -> None:
    """ε below the float resolution of the coordinates: the box that cannot be split stays undetermined
    (with ``cut="ratio"`` too) instead of being bisected into itself forever."""
    sep = SepInverse(Function(lambda x: 3 * x[0], n=2), Interval(3e8 + 1, 6e8))  # x₁ ≥ 1e8 + 1/3, rounded
    x0 = Box([(1e8 + 1 / 3 - 1e-7, 1e8 + 1 / 3 + 1e-7), (0.0, 1e-10)])
    for kw in ({}, {"cut": "grid"}):
        p = pave(x0, sep, 1e-12, **kw)
        w = p.boundary[1] - p.boundary[0]
        assert len(w) and (w[:, 0] <= np.spacing(1e8)).all()  # one ulp: the side that cannot be cut


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [({"cut": "middle"}, "cut"), ({"max_volume": 0.0}, "max_volume"), ({"max_volume": np.inf}, "max_volume")],
)
def test_pave_bad_policy(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        pave(X0, SepInverse(RING_F, Interval(1, 2.25)), 0.1, **kwargs)
