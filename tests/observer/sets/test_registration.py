"""Shape registration separators (thesis §4.2.2, Eq. 4.13–4.20) and the cone separator.

Soundness by sampling against closed forms: for convex ``A`` (the hull of its corners) and convex
``B``, ``f(A, p) ⊂ B`` iff every transformed corner lies in ``B``; for intervals everything is explicit.
The §4.2.3 published interval is checked in ``test_examples_ch4.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

from digslam.observer import Box, Function, Interval, SepBox, pave
from digslam.observer.sets.registration import (
    SepRegistration,
    rigid2d,
    scaling,
    sep_cone,
    sep_inclusion,
    sep_intersection,
    transform_function,
    translation,
)  # fmt: skip
from digslam.observer.sets.testing import assert_separator_sound as assert_sound
from digslam.observer.sets.testing import random_boxes

SQUARE = np.array([(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)])


def test_translation_inclusion_1d() -> None:
    """``[0, 1] + p ⊂ [0, 3]`` iff ``p ∈ [0, 2]``."""
    sep = sep_inclusion(SepBox(Box([(0, 1)])), SepBox(Box([(0, 3)])), translation(1), [(0, 1)], 1e-3)
    p = pave(Box([(-2, 4)]), sep, 1e-3)
    assert p.inner[0].min() >= 0.0 and p.inner[1].max() <= 2.0 and p.inner_area > 2 - 5e-3
    lo, hi = random_boxes([-2], [4], 300, 0.5)
    assert_sound(sep, lo, hi, lambda q: (q[:, 0] >= 0) & (q[:, 0] <= 2))


def test_translation_intersection_1d() -> None:
    """``([0, 1] + p) ∩ [2, 3] ≠ ∅`` iff ``p ∈ [1, 3]``."""
    sep = sep_intersection(SepBox(Box([(0, 1)])), SepBox(Box([(2, 3)])), translation(1), [(0, 1)], 1e-3)
    lo, hi = random_boxes([-1], [5], 300, 0.5)
    assert_sound(sep, lo, hi, lambda q: (q[:, 0] >= 1) & (q[:, 0] <= 3))
    p = pave(Box([(-1, 5)]), sep, 1e-3)
    assert p.inner_area > 2 - 5e-3


def in_rigid(q: np.ndarray, half: float = 2.0) -> np.ndarray:
    """``R(θ) SQUARE + (x, y) ⊂ [-half, half]²`` (both convex: test the corners)."""
    c, s = np.cos(q[:, 2]), np.sin(q[:, 2])
    cx = c[:, None] * SQUARE[None, :, 0] - s[:, None] * SQUARE[None, :, 1] + q[:, 0, None]
    cy = s[:, None] * SQUARE[None, :, 0] + c[:, None] * SQUARE[None, :, 1] + q[:, 1, None]
    return ((np.abs(cx) <= half) & (np.abs(cy) <= half)).all(axis=1)


def test_rigid2d_inclusion_soundness() -> None:
    sep = sep_inclusion(SepBox(Box([(-0.5, 0.5), (-0.5, 0.5)])), SepBox(Box([(-2, 2), (-2, 2)])), rigid2d(),
                        [(-0.5, 0.5), (-0.5, 0.5)], 0.05)  # fmt: skip
    lo, hi = random_boxes([-2.5, -2.5, -np.pi], [2.5, 2.5, np.pi], 200, 0.5)
    assert_sound(sep, lo, hi, in_rigid)
    (ilo, ihi), _ = sep.separate(np.array([[-0.1, -0.1, -0.1]]), np.array([[0.1, 0.1, 0.1]]))
    assert ilo[0, 0] > ihi[0, 0]  # small motions keep the square inside: proved


def test_rigid2d_intersection_soundness() -> None:
    """``(R(θ) SQUARE + t) ∩ [1.5, 3]² ≠ ∅``: tested by sampling the moved square densely (inner side)."""
    sep = sep_intersection(SepBox(Box([(-0.5, 0.5), (-0.5, 0.5)])), SepBox(Box([(1.5, 3), (1.5, 3)])), rigid2d(),
                           [(-0.5, 0.5), (-0.5, 0.5)], 0.02)  # fmt: skip
    g = np.linspace(-0.5, 0.5, 41)
    pts = np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)

    def meets(q: np.ndarray, tol: float) -> np.ndarray:
        c, s = np.cos(q[:, 2]), np.sin(q[:, 2])
        x = c[:, None] * pts[None, :, 0] - s[:, None] * pts[None, :, 1] + q[:, 0, None]
        y = s[:, None] * pts[None, :, 0] + c[:, None] * pts[None, :, 1] + q[:, 1, None]
        return ((x >= 1.5 - tol) & (x <= 3 + tol) & (y >= 1.5 - tol) & (y <= 3 + tol)).any(axis=1)

    lo, hi = random_boxes([0, 0, -1], [3.5, 3.5, 1], 150, 0.4)
    (ilo, ihi), (olo, ohi) = sep.separate(lo, hi)
    rng = np.random.default_rng(2)
    q = lo[:, None] + rng.random((150, 32, 3)) * (hi - lo)[:, None]
    in_in = ((ilo[:, None] <= q) & (q <= ihi[:, None])).all(axis=2)
    in_out = ((olo[:, None] <= q) & (q <= ohi[:, None])).all(axis=2)
    # proved inside: the grid with a tolerance of its spacing (0.025·√2) must see a meeting point
    assert meets(q[~in_in], 0.04).all()
    # proved outside: not even the exact square meets B (grid points included)
    assert not meets(q[~in_out], 0.0).any()


def test_scaling_sonar_value() -> None:
    """§4.2.3 at a coarse ε: the enclosure of ``sup D`` contains ``5 / cos(5π/24)``."""
    s1 = sep_cone((0.0, 1.0), Interval.pi() * 0.25, Interval.pi() / 24)
    s_m = ~SepBox(Box([(5, 1e300), (3, 1e300)]))
    p = pave(Box([(0, 10)]), sep_inclusion(s1, s_m, scaling(), [(0, 1), (0, 1)], 1e-3), 1e-3)
    d = 5 / np.cos(5 * np.pi / 24)
    assert p.inner[1].max() <= d <= p.boundary[1].max()


def in_pie(pts: np.ndarray, rlo: float, rhi: float, alpha: float, gamma: float) -> np.ndarray:
    r = np.linalg.norm(pts, axis=1)
    ang = np.angle(np.exp(1j * (np.arctan2(pts[:, 1], pts[:, 0]) - alpha)))
    return (r >= rlo) & (r <= rhi) & (np.abs(ang) <= gamma)


@pytest.mark.parametrize(("r", "alpha", "gamma"), [((0.0, 1.0), np.pi / 4, np.pi / 24), ((2.0, 3.0), 2.5, 0.4),
                                                    ((1.0, 4.0), -np.pi, 1.2), ((0.5, 0.5), 0.0, 0.3)])  # fmt: skip
def test_sep_cone_soundness(r, alpha, gamma) -> None:
    sep = sep_cone(r, alpha, gamma)
    lo, hi = random_boxes([-4, -4], [4, 4], 400, 1.0)
    # angles/radii within 1e-9 of the border are not decided by the float reference: shrink/grow it
    (ilo, ihi), (olo, ohi) = sep.separate(lo, hi)
    rng = np.random.default_rng(0)
    pts = lo[:, None] + rng.random((400, 32, 2)) * (hi - lo)[:, None]
    in_in = ((ilo[:, None] <= pts) & (pts <= ihi[:, None])).all(axis=2)
    in_out = ((olo[:, None] <= pts) & (pts <= ohi[:, None])).all(axis=2)
    assert in_pie(pts[~in_in], r[0] - 1e-9, r[1] + 1e-9, alpha, gamma + 1e-9).all()
    assert not in_pie(pts[~in_out], r[0] + 1e-9, r[1] - 1e-9, alpha, gamma - 1e-9).any()


def test_sep_cone_area() -> None:
    p = pave(Box([(-3, 3), (-3, 3)]), sep_cone((2, 3), 1.0, 0.3), 0.01)
    assert p.inner_area <= 0.3 * 5 <= p.inner_area + p.boundary_area


@pytest.mark.parametrize(
    ("r", "gamma", "match"),
    [((-1.0, 1.0), 0.2, "r"), ((2.0, 1.0), 0.2, "r"), ((0.0, np.inf), 0.2, "r"), ((0.0, 1.0), 0.0, "aperture"),
     ((0.0, 1.0), -0.1, "aperture"), ((0.0, 1.0), np.pi / 2, "aperture"), ((0.0, 1.0), np.pi, "aperture")],
)  # fmt: skip
def test_sep_cone_bad_input(r, gamma, match) -> None:
    with pytest.raises(ValueError, match=match):
        sep_cone(r, 0.0, gamma)


def test_bad_transform_dimension() -> None:
    a, b = SepBox(Box([(0, 1), (0, 1)])), SepBox(Box([(0, 3), (0, 3)]))
    with pytest.raises(ValueError, match="cannot trace the transform"):
        sep_inclusion(a, b, translation(3), [(0, 1), (0, 1)], 0.1)  # R³ translation for 2-d shapes
    with pytest.raises(ValueError, match="3 outputs but B has dimension 2"):
        sep_inclusion(a, b, lambda a_, p: (a_[0] + p[0], a_[1] + p[1], p[0]), [(0, 1), (0, 1)], 0.1, q=2)
    with pytest.raises(ValueError, match="1 outputs but B has dimension 2"):
        sep_inclusion(a, b, lambda a_, p: (a_[0] + p[0],), [(0, 1), (0, 1)], 0.1, q=1)  # 1 output for 2-d B
    with pytest.raises(ValueError, match="variables"):
        sep_inclusion(a, b, Function(lambda z: (z[0] + z[2], z[1] + z[3]), n=5), [(0, 1), (0, 1)], 0.1, q=2)
    with pytest.raises(ValueError, match="a_box"):
        sep_inclusion(a, b, translation(2), [(0, 1)], 0.1)
    with pytest.raises(ValueError, match="q"):
        sep_inclusion(a, b, lambda a_, p: (a_[0] + p[0], a_[1]), [(0, 1), (0, 1)], 0.1)
    with pytest.raises(ValueError, match="mode"):
        SepRegistration(a, b, translation(2), [(0, 1), (0, 1)], 0.1, mode="subset")
    with pytest.raises(ValueError, match="n"):
        translation(0)
    with pytest.raises(ValueError, match="f"):
        transform_function(42, 2, 2, 2)  # type: ignore[arg-type]


def test_function_transform_and_q_attribute() -> None:
    f = Function(lambda z: (z[0] + z[2], z[1] + z[3]), n=4)
    sep = SepRegistration(
        SepBox(Box([(0, 1), (0, 1)])), SepBox(Box([(0, 3), (0, 3)])), f, [(0, 1), (0, 1)], 0.05
    )
    assert sep.n == 2
    lo, hi = random_boxes([-1, -1], [4, 4], 200, 0.5)
    assert_sound(sep, lo, hi, lambda q: ((q >= 0) & (q <= 2)).all(axis=1))
