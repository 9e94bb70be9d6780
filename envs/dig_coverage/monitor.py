"""Guarantee monitor: checks every step's claims of the online observer against the privileged ground truth.

Three claims are checked (a debug option of :class:`~.wrapper.GuaranteedObserver`, used by the
tests); the first violation raises :class:`GuaranteeViolation` (a ``RuntimeError``) carrying the step's
record and truth:

1. the true pose lies in the pose box and the true heading in the heading interval;
2. no clear cell contains an obstacle point: each newly clear cell is checked exactly against the world's
   edges (its centre is free and no edge meets the closed cell box, a closed-slab segment test);
3. every truly sensed point lies in clear ∪ penumbra: points drawn in each true sector (below the true range,
   or ``r_max`` without echo) must not fall in a dark cell;
4. (when given the wrapper's ``coverage``) certified coverage never exceeds ground-truth coverage: both are
   counts of cells of the same reachable free area (:func:`.wrapper.reachable_free`), the clear ones
   against those whose centre was truly sensed
   (:meth:`~digslam.envs.explore.coverage.Coverage.on_cells`).

Once the filter reports an inconsistency its claims are withdrawn, so nothing more is checked.

>>> from digslam.envs.sim.world import World
>>> from digslam.observer.record.grid import Grid
>>> sq = np.array([(-2.0, -2.0), (2.0, -2.0), (2.0, 2.0), (-2.0, 2.0)])
>>> m = GuaranteeMonitor(World((-2, -2, 2, 2), [sq]), Grid((-2.0, -2.0), (2.0, 2.0), (4, 4)))
>>> mask = np.zeros((4, 4), bool); mask[1, 1] = True
>>> m.obstacle_cells(mask).tolist()            # an inner cell, free
[]
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from digslam.envs.sim import geometry as geo
from digslam.envs.sim.world import World
from digslam.observer.record.grid import Grid
from digslam.observer.thick.cells import DARK

if TYPE_CHECKING:  # (types only)
    from digslam.envs.explore.coverage import Coverage
    from digslam.envs.explore.truth import GroundTruth
    from digslam.observer.online.observer import OnlineDigSlam
    from digslam.observer.record.mission import MissionRecord

#: Sample points drawn per sensor and step for claim 3.
SENSED_SAMPLES = 32


class GuaranteeViolation(RuntimeError):
    """A false claim of the observer; ``record`` and ``truth`` are the step's data."""

    def __init__(self, msg: str, step: int, record: MissionRecord, truth: GroundTruth) -> None:
        super().__init__(f"step {step}: {msg}\nrecord: {record!r}")
        self.step, self.record, self.truth = step, record, truth


def _segments_meet_boxes(e: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Whether segment ``e[i]`` (x1, y1, x2, y2) meets the closed box ``[lo[i], hi[i]]`` (Liang–Barsky)."""
    p = e[:, :2]
    d = e[:, 2:] - p
    t0, t1 = np.zeros(len(e)), np.ones(len(e))
    ok = np.ones(len(e), dtype=bool)
    for k in (0, 1):
        flat = d[:, k] == 0
        ok &= ~flat | ((lo[:, k] <= p[:, k]) & (p[:, k] <= hi[:, k]))
        with np.errstate(divide="ignore", invalid="ignore"):
            a, b = (lo[:, k] - p[:, k]) / d[:, k], (hi[:, k] - p[:, k]) / d[:, k]
        t0 = np.where(flat, t0, np.maximum(t0, np.minimum(a, b)))
        t1 = np.where(flat, t1, np.minimum(t1, np.maximum(a, b)))
    return ok & (t0 <= t1)


class GuaranteeMonitor:
    """Checker of one episode's claims.

    Args:
        world: the ground truth.
        grid: the observer's grid.
        coverage: ``(reachable, truth)``: the reachable free cells ``(ny, nx)`` (row 0 at the top) and the
            ground-truth :class:`~digslam.envs.explore.coverage.Coverage` over them, updated before each
            :meth:`check`; then claim 4 is checked too.
    """

    def __init__(self, world: World, grid: Grid, coverage: tuple[np.ndarray, Coverage] | None = None) -> None:
        self.world, self.grid, self.coverage = world, grid, coverage
        self.checked = np.zeros(grid.shape, dtype=bool)
        self.rng = np.random.default_rng(0)
        self.violations = 0

    def obstacle_cells(self, mask: np.ndarray) -> np.ndarray:
        """``(k, 2)`` row, column of the cells of ``mask`` that contain an obstacle point."""
        rows, cols = np.nonzero(mask)
        if not rows.size:
            return np.zeros((0, 2), dtype=np.int64)
        lo, hi = self.grid.cell_boxes(rows, cols)
        ctr = 0.5 * (lo + hi)
        edges = self.world.edges
        bad = ~self.world.is_free(ctr)
        if len(edges):
            half = 0.5 * np.hypot(*(hi - lo).T) * (1 + 1e-9) + 1e-12
            near = np.nonzero(~bad & (geo.point_edge_distance(ctr, edges) <= half))[0]
            bb = self.world.bbox
            for s in range(0, near.size, 512):  # chunks of cells x all edges (memory bound)
                c = near[s : s + 512]
                ov = (
                    (bb[None, :, 0] <= hi[c, None, 0])
                    & (bb[None, :, 2] >= lo[c, None, 0])
                    & (bb[None, :, 1] <= hi[c, None, 1])
                    & (bb[None, :, 3] >= lo[c, None, 1])
                )
                ci, ei = np.nonzero(ov)
                hit = _segments_meet_boxes(edges[ei], lo[c[ci]], hi[c[ci]])
                bad[c[ci[hit]]] = True
        return np.stack([rows[bad], cols[bad]], axis=1)

    def check(self, filt: OnlineDigSlam, truth: GroundTruth, record: MissionRecord, step: int) -> None:
        """Check the filter's current claims; raise :class:`GuaranteeViolation` on the first false one."""
        if not filt.consistent:
            return

        def fail(msg: str) -> None:
            self.violations += 1
            raise GuaranteeViolation(msg, step, record, truth)

        x, y, th = (float(v) for v in truth.pose)
        lo, hi = filt.pose_lo, filt.pose_hi
        # the true position is within truth.pose_error of the simulator's float one (its heading is exact):
        # a float position farther than that from the box proves the true one outside it
        e = float(getattr(truth, "pose_error", 0.0))
        e = e if e >= 0.0 else 0.0  # NaN: an episode saved before the bound was recorded
        if not (lo[0] - e <= x <= hi[0] + e and lo[1] - e <= y <= hi[1] + e):
            fail(f"true position {(x, y)} (within {e:.1e}) outside the pose box {lo.tolist()}..{hi.tolist()}")
        if not (filt.heading_lo <= th <= filt.heading_hi):
            fail(f"true heading {th} outside [{filt.heading_lo}, {filt.heading_hi}]")
        clear = filt.clear_mask()
        new = clear & ~self.checked
        bad = self.obstacle_cells(new)
        if len(bad):
            fail(f"clear cells {bad[:5].tolist()} contain an obstacle")
        self.checked |= new
        if self.coverage is not None:
            reach, cov = self.coverage
            n_cert, n_true = int(np.count_nonzero(clear & reach)), int(cov.n_seen)
            if n_cert > n_true:
                fail(f"certified coverage ({n_cert} clear reachable cells) exceeds the ground truth "
                     f"({n_true} reachable cells truly sensed) over the same area")  # fmt: skip
            unseen = np.argwhere(clear & reach & ~cov.seen[::-1])
            if len(unseen):
                fail(f"clear cells {unseen[:5].tolist()}: their centres were never truly sensed")
        explored = filt.explored()
        pts = self.sensed_points(truth.pose, record, truth.ranges)
        g = self.grid
        col = Grid.count_below(g.xs, pts[:, 0]) - 1
        row = Grid.count_below(-g.ys, -pts[:, 1]) - 1
        ny, nx = g.shape
        inside = (col >= 0) & (col < nx) & (row >= 0) & (row < ny)
        dark = explored[row[inside], col[inside]] == DARK
        if dark.any():
            p = pts[inside][dark][0]
            fail(f"truly sensed point {p.tolist()} lies in a dark cell")

    def sensed_points(self, pose: np.ndarray, record: MissionRecord, ranges: np.ndarray) -> np.ndarray:
        """Random points of the true sensed sectors (below the true range, or ``r_max`` without echo)."""
        reach = np.where(np.isfinite(ranges), ranges, record.r_max)
        n, k = reach.size, SENSED_SAMPLES
        u = self.rng.uniform(size=(2, n, k))
        r = reach[:, None] * np.sqrt(u[0]) * (1 - 1e-9)
        a = pose[2] + record.alpha[:, None] + record.gamma[:, None] * (2 * u[1] - 1) * (1 - 1e-9)
        return np.stack([pose[0] + r * np.cos(a), pose[1] + r * np.sin(a)], axis=-1).reshape(-1, 2)


__all__ = [
    "GuaranteeMonitor",
    "GuaranteeViolation",
    "SENSED_SAMPLES",
]
