"""Polygons of a boolean raster (:mod:`digslam.observer.thick.polygons`): exact areas, point-in-polygon
agreement with the raster, holes inside their exteriors, diagonal contacts."""

from __future__ import annotations

import numpy as np
import pytest

from digslam.observer.record.grid import Grid
from digslam.observer.thick.polygons import contains, mask_polygons, polygon_area, ring_area


def _grid(ny: int, nx: int) -> Grid:
    return Grid((-1.3, 2.0), (-1.3 + 0.1 * nx, 2.0 + 0.1 * ny), (ny, nx))


@pytest.mark.parametrize("seed", range(40))
def test_areas_and_points_agree_with_the_raster(seed: int) -> None:
    rng = np.random.default_rng(seed)
    ny, nx = (int(v) for v in rng.integers(1, 20, 2))
    mask = rng.random((ny, nx)) < rng.random()
    g = _grid(ny, nx)
    polys = mask_polygons(mask, g)
    dx, dy = g.cell_size
    assert sum(polygon_area(p) for p in polys) == pytest.approx(mask.sum() * dx * dy, abs=1e-9)
    for p in polys:
        assert ring_area(p[0]) > 0 and all(ring_area(h) < 0 for h in p[1:])
        for h in p[1:]:  # a hole lies inside its own exterior (a point just inside the hole's first edge)
            mid = 0.5 * (h[0] + h[1])
            step = (h[1] - h[0]) / np.linalg.norm(h[1] - h[0]) * 1e-3
            inside = mid + np.array([step[1], -step[0]])  # right of the edge: the hole's side
            assert contains([[p[0]]], inside[:1], inside[1:])[0]
    cx, cy = g.centers()
    jx, jy = cx + rng.uniform(-0.049, 0.049, cx.shape), cy + rng.uniform(-0.049, 0.049, cy.shape)
    assert np.array_equal(contains(polys, jx, jy), mask)


def test_a_ring_with_a_hole_and_diagonal_cells() -> None:
    m = np.ones((3, 3), bool)
    m[1, 1] = False
    polys = mask_polygons(m, Grid((0.0, 0.0), (3.0, 3.0), (3, 3)))
    assert len(polys) == 1 and len(polys[0]) == 2 and polygon_area(polys[0]) == 8.0
    assert polys[0][0].tolist() == [[0.0, 0.0], [3.0, 0.0], [3.0, 3.0], [0.0, 3.0], [0.0, 0.0]]
    diag = np.array([[True, False], [False, True]])  # touching at a corner: two polygons
    polys = mask_polygons(diag, Grid((0.0, 0.0), (2.0, 2.0), (2, 2)))
    assert len(polys) == 2 and all(polygon_area(p) == 1.0 for p in polys)
    assert mask_polygons(np.zeros((2, 2), bool), Grid((0.0, 0.0), (2.0, 2.0), (2, 2))) == []


def test_a_wrong_shape_is_refused() -> None:
    with pytest.raises(ValueError, match="mask: expected shape"):
        mask_polygons(np.zeros((2, 3), bool), Grid((0.0, 0.0), (2.0, 2.0), (2, 2)))
