"""Ground-truth checks shared by the observer tests: claims of freedom against the exact world."""

from __future__ import annotations

import numpy as np

from digslam.observer.record.grid import Grid


def assert_free(mask: np.ndarray, world: object, grid: Grid, rng: np.random.Generator, n: int = 3000) -> None:
    """No cell of ``mask`` meets an obstacle: the exact raster, plus sampled points and corners of the cells.

    ``grid`` must be square-celled over the world's frame (the raster's cells are then the grid's cells).
    """
    raster = np.flipud(world.raster(grid.cell_size[0]))  # type: ignore[attr-defined]
    assert raster.shape == mask.shape
    assert not np.any(mask & (raster != 0)), "a claimed-free cell is occupied or crossed by an edge"
    rows, cols = np.nonzero(mask)
    pick = rng.choice(rows.size, min(rows.size, n), replace=False)
    lo, hi = grid.cell_boxes(rows[pick], cols[pick])
    pts = np.concatenate([lo, hi, np.c_[lo[:, 0], hi[:, 1]], lo + (hi - lo) * rng.random(lo.shape)])
    assert np.all(world.clearance(pts) > 0), "a point of a claimed-free cell is not free"  # type: ignore[attr-defined]
