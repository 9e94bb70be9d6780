"""Minkowski difference and sum separators (thesis §4.3, Prop. 4.1–4.2, Ex. 4.1–4.2).

Soundness by sampling against the closed forms: ``B ⊖ A`` for a disk and a rectangle is the
intersection of the disks centred at minus the corners; the sum of two convex polygons is the hull of
the vertex sums; for intervals ``[a, b] ⊖ [c, d] = [a - c, b - d]`` and ``[a, b] ⊕ [c, d] = [a + c, b + d]``.
"""

from __future__ import annotations

import numpy as np
import pytest

from digslam.observer import Box, Function, Interval, SepBox, SepInverse, SepPolygon, pave
from digslam.observer.sets.minkowski import SepMinkowskiDiff, SepMinkowskiSum, sep_negate
from digslam.observer.sets.separators import check_separation
from digslam.observer.sets.testing import assert_separator_sound as assert_sound
from digslam.observer.sets.testing import random_boxes

RECT = np.array([(-2.0, -1.0), (2.0, -1.0), (2.0, 1.0), (-2.0, 1.0)])
TRIANGLE = np.array([(0.0, 0.0), (3.0, 0.0), (1.0, 2.0)])


def disk(r: float = 5.0):
    return SepInverse(Function(lambda x: x[0] ** 2 + x[1] ** 2), Interval(-np.inf, r * r))


def in_disk_diff(p: np.ndarray) -> np.ndarray:
    return (np.linalg.norm(p[:, None, :] + RECT[None], axis=2) <= 5.0).all(axis=1)


def test_interval_difference_and_sum() -> None:
    b, a = SepBox(Box([(0, 3)])), SepBox(Box([(-0.5, 1.0)]))
    diff = SepMinkowskiDiff(b, a, [(-0.5, 1.0)], 1e-3)  # [0.5, 2]
    lo, hi = random_boxes([-2], [5], 300, 0.6)
    assert_sound(diff, lo, hi, lambda p: (p[:, 0] >= 0.5) & (p[:, 0] <= 2.0))
    p = pave(Box([(-2, 5)]), diff, 1e-3)
    assert 0.5 <= p.inner[0].min() and p.inner[1].max() <= 2.0 and p.inner_area > 1.5 - 5e-3
    summ = SepMinkowskiSum(a, b, [(-0.5, 1.0)], 1e-3)  # [-0.5, 4]
    assert_sound(summ, lo, hi, lambda p: (p[:, 0] >= -0.5) & (p[:, 0] <= 4.0))
    p = pave(Box([(-2, 5)]), summ, 1e-3)
    assert p.inner_area > 4.5 - 5e-3


def test_ex4_1_disk_minus_rectangle() -> None:
    sep = SepMinkowskiDiff(disk(), SepBox(Box([(-2, 2), (-1, 1)])), [(-2, 2), (-1, 1)], 0.05)
    lo, hi = random_boxes([-6, -6], [6, 6], 300, 1.0)
    assert_sound(sep, lo, hi, in_disk_diff)
    p = pave(Box([(-6, 6), (-6, 6)]), sep, 0.1)
    assert p.inner_area > 26.5 and p.boundary_area < 2.0  # exact area 27.7678


def sum_hull() -> np.ndarray:
    """Counter-clockwise hull of the vertex sums of TRIANGLE and the square [-1, 1]² (monotone chain)."""
    sq = np.array([(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)])
    pts = np.unique((TRIANGLE[:, None, :] + sq[None]).reshape(-1, 2), axis=0)

    def half(points: np.ndarray) -> list:
        h: list = []
        for q in points:
            while (
                len(h) >= 2
                and (h[-1][0] - h[-2][0]) * (q[1] - h[-2][1]) - (h[-1][1] - h[-2][1]) * (q[0] - h[-2][0]) <= 0
            ):
                h.pop()
            h.append(q)
        return h

    return np.array(half(pts)[:-1] + half(pts[::-1])[:-1])


def hull_margin(p: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Largest outward offset of ``p`` over the edges of a ccw convex polygon: ``<= 0`` inside."""
    e = np.roll(poly, -1, axis=0) - poly
    nrm = np.stack([e[:, 1], -e[:, 0]], axis=1) / np.linalg.norm(e, axis=1)[:, None]
    return ((p[:, None, :] - poly[None]) * nrm[None]).sum(axis=2).max(axis=1)


def test_ex4_2_triangle_plus_square() -> None:
    a_box = [(0, 3), (0, 2)]
    sep = SepMinkowskiSum(SepPolygon(TRIANGLE), SepBox(Box([(-1, 1), (-1, 1)])), a_box, 0.05)

    hull = sum_hull()

    def member(p: np.ndarray) -> np.ndarray:
        return hull_margin(p, hull) <= 1e-9

    def strict(p: np.ndarray) -> np.ndarray:
        return hull_margin(p, hull) <= -1e-9

    lo, hi = random_boxes([-3, -3], [6, 5], 200, 0.8)
    (ilo, ihi), (olo, ohi) = sep.separate(lo, hi)
    assert not check_separation((ilo, ihi), (olo, ohi), lo, hi).any()
    rng = np.random.default_rng(0)
    pts = lo[:, None] + rng.random((200, 48, 2)) * (hi - lo)[:, None]
    in_in = ((ilo[:, None] <= pts) & (pts <= ihi[:, None])).all(axis=2)
    in_out = ((olo[:, None] <= pts) & (pts <= ohi[:, None])).all(axis=2)
    assert member(pts[~in_in]).all()
    assert not strict(pts[~in_out]).any()
    assert (~in_in).sum() > 500 and (~in_out).sum() > 500  # both sides decide many points
    x, y = hull[:, 0], hull[:, 1]
    assert abs(abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2 - 17.0) < 1e-12


def test_sep_negate() -> None:
    s = sep_negate(SepBox(Box([(1, 2), (0, 3)])))
    lo, hi = random_boxes([-3, -4], [0, 1], 200, 0.8)
    assert_sound(s, lo, hi, lambda p: (p[:, 0] >= -2) & (p[:, 0] <= -1) & (p[:, 1] >= -3) & (p[:, 1] <= 0))


def test_bad_input() -> None:
    with pytest.raises(ValueError, match="sep_b"):
        SepMinkowskiDiff(disk(), SepBox(Box([(0, 1)])), [(0, 1)], 0.1)
    with pytest.raises(ValueError, match="sep_a"):
        SepMinkowskiDiff(SepBox(Box([(0, 1)])), disk(), [(0, 1)], 0.1)
    with pytest.raises(ValueError, match="sep_a"):
        SepMinkowskiSum(disk(), SepBox(Box([(0, 1)])), [(0, 1)], 0.1)
    with pytest.raises(ValueError, match="a_box"):
        SepMinkowskiDiff(disk(), disk(), [(0, np.inf), (0, 1)], 0.1)
    with pytest.raises(ValueError, match="eps"):
        SepMinkowskiDiff(disk(), disk(), [(0, 1), (0, 1)], -1.0)
