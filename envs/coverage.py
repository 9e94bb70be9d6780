"""Ground-truth coverage: the free area truly sensed so far, the reward of ``digslam/Explore-v0``.

A cell counts once its centre has lain inside some sensor's sector closer than the true range (or ``r_max``
without echo): such points are certainly free. Only cells that are entirely free (exact raster) count, so
the covered area never includes obstacle area. Each update is one compiled pass over the cells within reach
(:func:`.coverage_jit.cover_kernel`).
"""

from __future__ import annotations

import numpy as np

from .coverage_jit import cover_kernel
from .raster import FREE
from .sensors import SensorSuite
from .world import World


class Coverage:
    """Seen-cell bookkeeping on the exact raster of a world.

    Args:
        world: Ground-truth world.
        resolution: Cell size (m).
        reach: Largest sensor range (m), sizes the per-step window.
    """

    def __init__(self, world: World, resolution: float, reach: float) -> None:
        self.res = float(resolution)
        self.x0, self.y0 = world.frame[0], world.frame[1]
        self.free = world.raster(self.res) == FREE
        self.seen = np.zeros_like(self.free)
        self.n_seen = 0  # count of seen cells, kept by update() (the only writer of seen)
        self.total_free = int(np.count_nonzero(self.free))
        self.k = int(np.ceil(reach / self.res)) + 1
        ny, nx = self.free.shape
        self.xs = self.x0 + (np.arange(nx) + 0.5) * self.res
        self.ys = self.y0 + (np.arange(ny) + 0.5) * self.res

    def _angular_cover(self, suite: SensorSuite) -> tuple[np.ndarray, np.ndarray]:
        """Cone-edge bearings in ``[0, 2 pi)`` (sorted, from 0) and which sensors cover each interval."""
        if getattr(self, "_cover_for", None) is not suite:
            edges = np.mod(np.concatenate([suite.alpha - suite.gamma, suite.alpha + suite.gamma]), 2 * np.pi)
            breaks = np.unique(np.concatenate([[0.0], edges]))
            mids = 0.5 * (breaks + np.append(breaks[1:], 2 * np.pi))
            off = np.mod(mids[:, None] - suite.alpha[None, :] + np.pi, 2 * np.pi) - np.pi
            self._cover = (breaks, np.abs(off) <= suite.gamma[None, :])
            self._cover_for = suite
        return self._cover

    @property
    def cell_area(self) -> float:
        """Area of one cell (m^2)."""
        return self.res * self.res

    @property
    def fraction(self) -> float:
        """Covered share of the free cells."""
        return float(self.n_seen) / max(self.total_free, 1)

    def update(self, pose: np.ndarray, suite: SensorSuite, ranges: np.ndarray) -> float:
        """Mark the cells sensed from ``pose`` and return the newly covered area (m^2)."""
        x, y, th = float(pose[0]), float(pose[1]), float(pose[2])
        ny, nx = self.free.shape
        ic, jc, k = int((y - self.y0) // self.res), int((x - self.x0) // self.res), self.k
        i0, i1, j0, j1 = max(ic - k, 0), min(ic + k + 1, ny), max(jc - k, 0), min(jc + k + 1, nx)
        breaks, cover = self._angular_cover(suite)
        rng = np.ascontiguousarray(ranges, dtype=np.float64)
        hits = cover_kernel(self.free, self.seen, self.xs, self.ys, i0, i1, j0, j1, x, y, th, breaks, cover,
                            rng, suite._k_r_max)  # fmt: skip
        self.n_seen += hits
        return float(hits) * self.cell_area
