"""Thick paver: soundness by sampling, no bisection in the penumbra, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from digslam.observer import Box, SepBox, SepUnion
from digslam.observer.thick.paver import thick_pave
from digslam.observer.thick.sep import ThickSep

X0 = ([-3.0, -3.0], [3.0, 3.0])


def ring_like() -> ThickSep:
    """X⁻ = two boxes, X⁺ = a larger box containing them."""
    lower = SepUnion(SepBox(Box([(-1, 0.3), (-1, 1)])), SepBox(Box([(0.5, 1.1), (-0.7, 0.2)])))
    return ThickSep(lower, SepBox(Box([(-2.1, 2.3), (-1.7, 1.9)])))


def test_thick_pave_sound() -> None:
    p = thick_pave(X0, ring_like(), 0.05)
    rng = np.random.default_rng(1)

    def pts(b: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        u = rng.uniform(0, 1, (b[0].shape[0], 16, 2))
        return np.clip(b[0][:, None] + u * (b[1] - b[0])[:, None], b[0][:, None], b[1][:, None]).reshape(
            -1, 2
        )

    def xm(q: np.ndarray) -> np.ndarray:
        a = ((q >= [-1, -1]) & (q <= [0.3, 1])).all(-1)
        return a | ((q >= [0.5, -0.7]) & (q <= [1.1, 0.2])).all(-1)

    def xp(q: np.ndarray) -> np.ndarray:
        return ((q >= [-2.1, -1.7]) & (q <= [2.3, 1.9])).all(-1)

    assert xm(pts(p.clear)).all()
    assert not xp(pts(p.dark)).any()
    q = pts(p.penumbra)
    assert (xp(q) & ~xm(q)).all()
    total = p.clear_area + p.penumbra_area + p.dark_area + p.boundary_area
    assert total == pytest.approx(36.0)
    assert 1.3 * 2 + 0.6 * 0.9 - 0.3 < p.clear_area <= 1.3 * 2 + 0.6 * 0.9 + 1e-12
    assert (np.maximum(p.boundary[1] - p.boundary[0], 0).max(axis=1) <= 0.05).all()


def test_penumbra_not_bisected() -> None:
    ts = ring_like()
    coarse, fine = thick_pave(X0, ts, 0.1), thick_pave(X0, ts, 0.01)
    # bisections grow like the boundary length (× 1/eps), not the penumbra area (× 1/eps²)
    assert fine.bisections < 25 * coarse.bisections  # ×100 if the penumbra were bisected
    assert fine.penumbra_area > 0.9 * (4.4 * 3.6 - 1.3 * 2 - 0.6 * 0.9)


def test_thick_pave_bad_input() -> None:
    ts = ring_like()
    with pytest.raises(ValueError, match="eps"):
        thick_pave(X0, ts, 0.0)
    with pytest.raises(ValueError, match="x0"):
        thick_pave(([0.0, 0.0], [np.inf, 1.0]), ts, 0.1)
    bad = ThickSep(SepBox(Box([(0, 2), (0, 2)])), SepBox(Box([(-1, 1), (-1, 1)])))
    with pytest.raises(ValueError, match="lower bound not inside upper bound"):
        thick_pave(([1.2, 1.2], [1.8, 1.8]), bad, 0.1)


def test_thick_inverse_proj_sound() -> None:
    """x + p ∈ [0, 1], p ∈ [0, 0.5]: X⁻ = [0, 0.5], X⁺ = [-0.5, 1] (Eq. 5.40–5.41)."""
    from digslam.observer.thick.inversion import thick_inverse_classical, thick_inverse_proj

    y, p = Box([(0, 1)]), Box([(0, 0.5)])
    f = lambda z: [z[0] + z[1]]  # noqa: E731
    proj = thick_pave(([-2.0], [2.0]), thick_inverse_proj(f, y, y, p, n=1, eps=0.01), 0.01)
    clas = thick_pave(([-2.0], [2.0]), thick_inverse_classical(f, y, y, p, n=1), 0.01)
    for pav in (proj, clas):
        assert ((pav.clear[0] >= 0) & (pav.clear[1] <= 0.5)).all()
        assert ((pav.dark[1] <= -0.5) | (pav.dark[0] >= 1)).all()
        pen = pav.penumbra
        assert (((pen[0] >= -0.5) & (pen[1] <= 0)) | ((pen[0] >= 0.5) & (pen[1] <= 1))).all()
    assert proj.clear_area > 0.45 and proj.penumbra_area > 0.9
    assert clas.penumbra_area == 0.0  # the classical method cannot prove the penumbra (Fig. 5.7b)
    with pytest.raises(ValueError, match="p_box"):
        thick_inverse_proj(f, y, y, n=1, eps=0.01)


@pytest.mark.expensive
def test_example_5_4_projection_brackets_the_sampled_sets(tmp_path) -> None:  # noqa: ANN001
    """Ex. 5.4 (Fig. 5.7): clear ⊂ X⁻ and clear + penumbra + undetermined ⊃ X⁺ (sampled areas)."""
    from example_loader import load

    r = load("ex5_4_thick_rotation").run(eps=0.3, out=tmp_path)
    p = r["projection"]
    assert p["clear_area"] <= r["sampled_lower_area"] + 0.01
    assert p["clear_area"] + p["penumbra_area"] + p["boundary_area"] >= 0.99 * r["sampled_upper_area"]
    assert any(tmp_path.glob("*.png"))
