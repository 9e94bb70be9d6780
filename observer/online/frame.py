"""The map's frame from the data: where a log's robot can have been, widened by how far it can have sensed.

A robot's log has no fixed frame: its odometry frame starts at the start box and its ranges reach tens of
metres. :func:`frame_of` takes the frame from the record itself, before any map is made:

1. the heading tube of the compass and the gyro (:func:`~digslam.observer.tube.tube.heading_from_compass`;
   without a compass, the integrated yaw rate from the start heading);
2. the dead-reckoning tube ``x' = R(ψ) v`` forward from the start box with the odometry increments
   (:func:`~digslam.observer.tube.tube.ctc_deriv`, Eq. 3.59, 6.12, B.20): it holds every position the robot
   can have had, so every later box of any observer lies inside it;
3. its hull, widened by the longest trusted range plus the farthest mount and slack (every dug, sensed or
   contracted cell is within that of a position), plus a margin of ``pad`` cells, snapped outward to whole
   cells of ``resolution``.

The frame is fixed before the observers start (no map that grows): the observers' sets then cost
``area / resolution²`` cells, one byte each for ``M⁻`` and the sensed sets and 4 for the smoother's counts
with ``q > 0``. On an hour's mission at 1 m/s whose odometry drifts 1 %, the dead-reckoning hull is about the
path's extent plus 36 m each side: a 200 m × 200 m building seen with a 20 m range at 0.1 m per cell is
(200 + 2·56)² / 0.01 ≈ 9.7 M cells, about 110 MB for the filter's three boolean maps and the clearance map.
:func:`frame_cost` states it for a given frame.

>>> import numpy as np
>>> from digslam.observer.record.mission import MissionRecord
>>> one = np.ones((11, 1))
>>> rec = MissionRecord(t=0.1 * np.arange(11), speed=one * [0.99, 1.01], yaw_rate=one * [-0.01, 0.01],
...     heading=one * [-1e-3, 1e-3], alpha=0 * one, gamma=np.pi * one, r_max=5 * one,
...     range=np.tile([[1.0, 1.1]], (11, 1, 1)), no_echo=one < 0, outlier=one < 0)
>>> g = frame_of(rec, [0.0, 0.0], [0.0, 0.0], max_range=5.0, resolution=0.1)
>>> bool(g.lo[0] <= -5.0 and g.hi[0] >= 6.0), [round(c, 12) for c in g.cell_size]
(True, [0.1, 0.1])
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord
from digslam.observer.slam.digslam import odometry_increment, odometry_velocity
from digslam.observer.tube.tube import Tube, ctc_deriv, heading_from_compass

__all__ = ["FrameError", "frame_cost", "frame_of"]

#: Cells of margin around the widened hull.
PAD_CELLS = 4


class FrameError(ValueError):
    """The record cannot be framed: its heading or dead reckoning is empty (the data contradict their
    bounds) or unbounded, or the frame would exceed ``max_cells``."""


def frame_of(record: MissionRecord, x0_lo: Any, x0_hi: Any, max_range: float, resolution: float,
             max_cells: int = 400_000_000, contradicted: bool = False) -> Grid:  # fmt: skip
    """The grid the observers map ``record`` on (see the module docstring).

    Args:
        record: a stacked mission of at least two samples.
        x0_lo, x0_hi: the start position box.
        max_range: the longest range any reading is trusted to (m); no-echo readings reach their ``r_max``.
        resolution: cell side (m).
        max_cells: refuse a frame of more cells than this (:class:`FrameError`, saying the size).
        contradicted: a record whose heading or odometry contradicts itself (an empty tube) is framed around
            its start box instead of refused: the frame a diagnosis runs the observers in to find where the
            data break their bounds.

    Raises:
        FrameError: on an empty (unless ``contradicted``) or unbounded dead-reckoning tube, or a frame over
            ``max_cells``.
    """
    if not (resolution > 0 and math.isfinite(resolution)):
        raise FrameError(f"resolution: expected a finite cell size > 0 (m), got {resolution}")
    lo0, hi0 = np.asarray(x0_lo, np.float64)[:2], np.asarray(x0_hi, np.float64)[:2]
    lo, hi = _hull(record, lo0, hi0, contradicted)
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise FrameError(
            "the dead reckoning is unbounded: give every record a finite speed interval (a log: "
            "finite [odometry] speed and lateral bounds)"
        )
    reach = max(float(max_range), float(np.max(record.r_max, initial=0.0)))
    mount = float(np.max(np.hypot(record.mount[..., 0], record.mount[..., 1]), initial=0.0))
    slack = float(np.max(record.slack[..., 0], initial=0.0)) * math.sqrt(2.0)
    wide = reach + mount + slack + PAD_CELLS * resolution
    f_lo = np.floor((lo - wide) / resolution) * resolution
    f_hi = np.ceil((hi + wide) / resolution) * resolution
    shape = tuple(int(v) for v in np.round((f_hi - f_lo) / resolution))
    cells = shape[0] * shape[1]
    if cells > max_cells:
        raise FrameError(
            f"the frame is {f_hi[0] - f_lo[0]:.0f} m x {f_hi[1] - f_lo[1]:.0f} m, {cells:,} cells "
            f"at {resolution} m: coarsen the map's resolution or trust shorter ranges"
        )
    return Grid((float(f_lo[0]), float(f_lo[1])), (float(f_hi[0]), float(f_hi[1])), (shape[1], shape[0]))


def _hull(record: MissionRecord, lo0: np.ndarray, hi0: np.ndarray, contradicted: bool
          ) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """The hull of the dead-reckoning tube's gates (the start box's when the tube is empty and
    ``contradicted``)."""
    t = record.t
    heading = heading_from_compass(t, record.heading[:, 0], record.heading[:, 1], record.yaw_rate[1:, 0],
                                   record.yaw_rate[1:, 1])  # fmt: skip
    if heading.is_empty():
        if contradicted:
            return lo0, hi0
        at = heading.inconsistent_at if heading.inconsistent_at is not None else heading.first_empty()
        raise FrameError(f"record {at}: the heading and the yaw rate contradict each other")
    u, inc = odometry_velocity(record, heading), odometry_increment(record, heading)
    n = t.shape[0]
    g_lo, g_hi = np.full((n, 2), -np.inf), np.full((n, 2), np.inf)
    g_lo[0], g_hi[0] = lo0, hi0
    tube = ctc_deriv(Tube(t, g_lo, g_hi), *u, backward=False, increment=inc)
    if tube.is_empty():
        if contradicted:
            return lo0, hi0
        raise FrameError(f"record {tube.first_empty()}: the odometry contradicts itself")
    return tube.gate_lo.min(axis=0), tube.gate_hi.max(axis=0)


def frame_cost(grid: Grid, q: int = 0) -> int:
    """Bytes the observers' cell sets take on ``grid``: ``M⁻``, certainly and possibly sensed (1 byte a cell
    each), the clearance map (8), and with ``q > 0`` the two counts (4 each) and the list (4)."""
    cells = grid.shape[0] * grid.shape[1]
    return cells * (3 + 8 + (12 if q else 0))
