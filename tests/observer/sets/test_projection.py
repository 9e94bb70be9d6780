"""Projection of separators (thesis §4.2.1, Def. 4.2, Theorem 4.1): :class:`SepProj` and :class:`SepOnDims`.

Checked: the separation invariant (``check_separation``), soundness by sampling against sets whose
projection is known in closed form (points proved inside are in the projection, points proved outside
are not), tightness of the paving, the batching (one separator call per generation), bad input.
"""

from __future__ import annotations

import numpy as np
import pytest

from digslam.observer import Box, Function, Interval, SepBox, SepInverse, pave
from digslam.observer.core.boxes import empty_rows
from digslam.observer.sets.projection import SepOnDims, SepProj
from digslam.observer.sets.testing import assert_separator_sound as assert_sound
from digslam.observer.sets.testing import random_boxes


def disk():
    return SepInverse(Function(lambda z: z[0] ** 2 + z[1] ** 2), Interval(-np.inf, 1.0))


def stadium_z():
    """``Z = {(x₁, x₂, y) | x₁² + (x₂ - y)² <= 1}``: with ``y ∈ [0, 2]`` its projection is a stadium."""
    return SepInverse(Function(lambda z: z[0] ** 2 + (z[1] - z[2]) ** 2), Interval(-np.inf, 1.0))


def in_stadium(pts: np.ndarray) -> np.ndarray:
    """Distance to the segment ``{0} × [0, 2]`` at most 1."""
    q = np.stack([np.zeros(len(pts)), np.clip(pts[:, 1], 0.0, 2.0)], axis=1)
    return np.linalg.norm(pts - q, axis=1) <= 1.0


def test_shadow_of_disk_is_an_interval() -> None:
    shadow = SepProj(disk(), [0], Box([(-2, 2)]), eps=1e-3)
    p = pave(Box([(-3, 3)]), shadow, 1e-3)
    assert p.inner[0].min() >= -1.0 and p.inner[1].max() <= 1.0
    assert p.inner_area > 2 - 4e-3
    olo, ohi = p.outer
    assert not ((olo < 1.0) & (ohi > -1.0)).any()  # no outer box meets (-1, 1)


def test_projection_onto_second_coordinate() -> None:
    shadow = SepProj(disk(), [1], Box([(-0.5, 0.5)]), eps=1e-3)  # x₂ with |x₁| <= 0.5: |x₂| <= 1
    p = pave(Box([(-2, 2)]), shadow, 1e-3)
    assert p.inner[0].min() >= -1.0 and p.inner[1].max() <= 1.0 and p.inner_area > 1.99


def test_stadium_soundness_and_separation() -> None:
    sep = SepProj(stadium_z(), [0, 1], Box([(0, 2)]), eps=0.02)
    lo, hi = random_boxes([-2, -2], [2, 4], 300, 0.6)
    assert_sound(sep, lo, hi, in_stadium)
    p = pave(Box([(-2, 2), (-2, 4)]), sep, 0.05)
    exact = np.pi + 4.0
    assert p.inner_area <= exact <= p.inner_area + p.boundary_area
    assert p.boundary_area < 0.1 * exact


def test_three_dims_kept_order() -> None:
    """Kept coordinates may come in any order: ``[1, 0]`` swaps the stadium's axes."""
    sep = SepProj(stadium_z(), [1, 0], Box([(0, 2)]), eps=0.02)
    lo, hi = random_boxes([-2, -2], [4, 2], 200, 0.6)
    assert_sound(sep, lo, hi, lambda pts: in_stadium(pts[:, ::-1]))


def test_one_call_per_generation_and_limits_sound() -> None:
    for kw in ({}, {"max_splits": 2}, {"max_pairs": 4}, {"presplit": 3}):
        sep = SepProj(stadium_z(), [0, 1], Box([(0, 2)]), eps=1e-3, **kw)
        lo, hi = random_boxes([-2, -2], [2, 4], 100, 0.4, seed=3)
        assert_sound(sep, lo, hi, in_stadium, seed=4)
        assert sep.calls >= 1 and sep.pairs >= 2 * 100
    lo, hi = random_boxes([-2, -2], [2, 4], 50, 0.4, seed=5)
    sep = SepProj(stadium_z(), [0, 1], Box([(0, 2)]), eps=0.5)
    sep.separate(lo, hi)
    assert sep.calls <= 4  # generations, not boxes: the batch goes in one call each


def test_empty_rows_and_single_box_call() -> None:
    sep = SepProj(stadium_z(), [0, 1], Box([(0, 2)]), eps=0.05)
    lo = np.array([[np.inf, np.inf], [-0.1, 0.9]])
    hi = np.array([[-np.inf, -np.inf], [0.1, 1.1]])
    (ilo, ihi), (olo, ohi) = sep.separate(lo, hi)
    assert empty_rows(ilo, ihi)[0] and empty_rows(olo, ohi)[0]
    assert empty_rows(ilo, ihi)[1] and not empty_rows(olo, ohi)[1]  # deep inside the stadium
    xin, xout = sep(Box([(3, 4), (0, 1)]))
    assert bool(xout.is_empty().any()) and not bool(xin.is_empty().any())


def test_sep_on_dims() -> None:
    cyl = SepOnDims(SepBox(Box([(0, 1)])), [1], 3)  # {z | z₂ ∈ [0, 1]}
    lo, hi = random_boxes([-1, -1, -1], [2, 2, 2], 200, 1.0)
    assert_sound(cyl, lo, hi, lambda p: (p[:, 1] >= 0) & (p[:, 1] <= 1))
    (ilo, ihi), (olo, ohi) = cyl.separate(np.array([[5.0, 0.2, -3.0]]), np.array([[6.0, 0.8, 3.0]]))
    assert empty_rows(ilo, ihi)[0] and (olo[0] == [5.0, 0.2, -3.0]).all()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"dims_kept": [0, 5], "y_box": Box([(0, 2)]), "eps": 0.1}, "dims_kept"),
        ({"dims_kept": [0, 0], "y_box": Box([(0, 2)]), "eps": 0.1}, "repeated"),
        ({"dims_kept": [0, 1], "y_box": Box([(0, 2), (0, 1)]), "eps": 0.1}, "y_box"),
        ({"dims_kept": [0, 1], "y_box": Box([(0, np.inf)]), "eps": 0.1}, "bounded"),
        ({"dims_kept": [0, 1], "y_box": [[0, 1, 2]], "eps": 0.1}, "y_box"),
        ({"dims_kept": [0, 1], "y_box": Box([(0, 2)]), "eps": 0.0}, "eps"),
        ({"dims_kept": [0, 1], "y_box": Box([(0, 2)]), "eps": 0.1, "max_splits": 0}, "max_splits"),
        ({"dims_kept": [], "y_box": Box([(0, 2)]), "eps": 0.1}, "dims_kept"),
        ({"dims_kept": [0, 1], "y_box": Box([(0, 2)]), "eps": 0.1, "presplit": 17}, "presplit"),
    ],
)
def test_bad_input(kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        SepProj(stadium_z(), **kwargs)


def test_sep_on_dims_bad_input() -> None:
    with pytest.raises(ValueError, match="dims"):
        SepOnDims(SepBox(Box([(0, 1), (0, 1)])), [0], 3)
    with pytest.raises(ValueError, match="dims"):
        SepOnDims(SepBox(Box([(0, 1)])), [3], 3)
    with pytest.raises(ValueError, match="dimension"):
        SepProj(stadium_z(), [0, 1], Box([(0, 2)]), 0.1).separate(np.zeros((1, 3)), np.ones((1, 3)))
