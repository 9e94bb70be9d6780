"""Ground-truth coverage: the free area truly sensed so far.

A cell counts once its centre has lain inside some sensor's sector closer than the true range (or ``r_max``
without echo): such points are certainly free. Only the cells of a given set of free cells count, so the
covered area never includes obstacle area. Each update is one compiled pass over the cells within reach
that are still to cover (:func:`.coverage_jit.cover_step`: blocks of cells already covered are skipped).

Two areas are in use, and each figure says which:

* :class:`Coverage` on a world (the reward of ``digslam/Explore-v0``, ``info["coverage"]`` of the raw env):
  cells of ``coverage_resolution`` entirely free in the exact raster, *all* of the world's free area,
  reachable or not;
* :meth:`Coverage.on_cells` over the **reachable free area** of the certified-coverage environments
  (:func:`~digslam.envs.dig_coverage.wrapper.reachable_free`: the observer grid's cells entirely free in
  the exact raster and connected to the start), kept by the wrapper itself. ``info["true_coverage"]`` of
  :class:`~digslam.envs.dig_coverage.wrapper.GuaranteedObserver` is this one: the share of those cells
  whose centre was truly sensed, over the same cells as the certified coverage (clear cells among them over
  their number). A clear cell is proved free and certainly sensed, so its centre was truly sensed:
  *certified coverage <= ground-truth coverage* is an invariant (checked by ``monitor=True``,
  :mod:`digslam.envs.dig_coverage.monitor`).
"""

from __future__ import annotations

import numpy as np

from digslam.envs.explore.coverage_jit import cone_table, cover_step, todo_blocks
from digslam.envs.sim.raster import FREE
from digslam.envs.sim.sensors import SensorSuite
from digslam.envs.sim.world import World


class Coverage:
    """Seen-cell bookkeeping on the exact raster of a world (all of its free area; see the module).

    Args:
        world: Ground-truth world.
        resolution: Cell size (m).
        reach: Largest sensor range (m), sizes the per-step window.
    """

    def __init__(self, world: World, resolution: float, reach: float) -> None:
        self._setup(world.raster(float(resolution)) == FREE, (world.frame[0], world.frame[1]),
                    (float(resolution), float(resolution)), reach)  # fmt: skip

    @classmethod
    def on_cells(cls, free: np.ndarray, origin: tuple[float, float], cell: tuple[float, float],
                 reach: float) -> Coverage:  # fmt: skip
        """Coverage of the cells of ``free`` ``(ny, nx)`` (row 0 at the BOTTOM) of a regular grid whose
        lower-left corner is ``origin`` and whose cells are ``cell = (dx, dy)``: e.g. the reachable free
        area of the observer grid (``reachable[::-1]``), for the ground truth that the certified coverage is
        compared with. :attr:`fraction` is the share of those cells whose centre was truly sensed."""
        cov = cls.__new__(cls)
        cov._setup(np.ascontiguousarray(free, dtype=bool), (float(origin[0]), float(origin[1])),
                   (float(cell[0]), float(cell[1])), reach)  # fmt: skip
        return cov

    def _setup(self, free: np.ndarray, origin: tuple[float, float], cell: tuple[float, float],
               reach: float) -> None:  # fmt: skip
        self.resx, self.resy = cell
        self.res = self.resx  # the cell side (square cells), kept for the callers
        self.x0, self.y0 = origin
        self.free = free
        self.seen = np.zeros_like(self.free)
        self.n_seen = 0  # count of seen cells, kept by update() (the only writer of seen)
        self.total_free = int(np.count_nonzero(self.free))
        self.kx = int(np.ceil(reach / self.resx)) + 1
        self.ky = int(np.ceil(reach / self.resy)) + 1
        self.k = max(self.kx, self.ky)
        ny, nx = self.free.shape
        self.xs = self.x0 + (np.arange(nx) + 0.5) * self.resx
        self.ys = self.y0 + (np.arange(ny) + 0.5) * self.resy
        self._win = np.array([self.x0, self.y0, self.resx, self.resy, self.kx, self.ky], dtype=np.float64)
        self._geo = np.concatenate([self._win, self.xs, self.ys])  # what cover_step reads of the grid
        self._todo = self.free.copy()  # free and not yet seen: update() keeps it with seen
        self._blocks = todo_blocks(self._todo)
        self._cell_area = self.resx * self.resy
        self._cones_for: SensorSuite | None = None

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
        return self.resx * self.resy

    @property
    def fraction(self) -> float:
        """Covered share of the cells counted (:attr:`free`)."""
        return float(self.n_seen) / max(self.total_free, 1)

    def update(self, pose: np.ndarray, suite: SensorSuite, ranges: np.ndarray) -> float:
        """Mark the cells sensed from ``pose`` and return the newly covered area (m^2).

        The only writer of :attr:`seen`: it keeps the cells still to cover beside it."""
        p, rng = pose, ranges
        if not (type(p) is np.ndarray and p.dtype == np.float64 and p.shape == (3,)):
            p = np.array([float(pose[0]), float(pose[1]), float(pose[2])])
        if not (type(rng) is np.ndarray and rng.dtype == np.float64 and rng.flags.c_contiguous):
            rng = np.ascontiguousarray(ranges, dtype=np.float64)
        if self._cones_for is not suite:
            self._cones = cone_table(*self._angular_cover(suite), suite.r_max)
            self._cones_for = suite
        hits = cover_step(self._todo, self._blocks, self.seen, self._geo, p, self._cones, rng)
        self.n_seen += hits
        return hits * self._cell_area


__all__ = [
    "Coverage",
]
