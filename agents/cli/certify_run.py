"""The observers of ``digslam certify`` on a log's records: the frame, the offline fixpoint, the online one.

:func:`frame_grid` is the map's frame: the hull of the dead-reckoning tube (the odometry integrated from the
start box with the heading tube of the compass and the gyro, forward only, outward rounded) widened by the
longest trusted range plus the farthest mount and the largest reading slack, in cells of ``resolution``
(:func:`digslam.observer.online.frame.frame_of`; a record whose heading or dead reckoning contradicts itself
is framed around its start box, so that the diagnosis can still run the observers on it). :func:`run_offline`
is :func:`digslam.observer.online.smoother.dig_slam` (the fixpoint, thesis §6.4, Eq. 6.18–6.24) and
:func:`run_online` the online filter :class:`~digslam.observer.online.observer.OnlineDigSlam` step by step,
keeping its boxes; :func:`cross_check` compares them (both are sound: the offline sets must be at least as
sharp and its boxes inside the filter's). :func:`is_consistent` is whether a record passes the offline
observer (heading tube and fixpoint), what the diagnosis of :mod:`.certify_diagnose` asks again and again.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from digslam.agents.cli.common import UserError
from digslam.observer.online.frame import FrameError, frame_of
from digslam.observer.online.observer import OnlineConfig, OnlineDigSlam
from digslam.observer.online.smoother import dig_slam
from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord
from digslam.observer.slam.digslam import DigSlamConfig, DigSlamResult
from digslam.observer.thick.cells import CLEAR, DARK
from digslam.observer.tube.tube import Tube, heading_from_compass

#: The most cells a frame may hold (about 20 bytes a cell in the observers: 2.4 GB at this bound).
MAX_CELLS = 120_000_000


def heading_tube(rec: MissionRecord) -> Tube:
    """The heading tube of the compass and the gyro, forward and backward (empty when they contradict)."""
    return heading_from_compass(rec.t, rec.heading[:, 0], rec.heading[:, 1], rec.yaw_rate[1:, 0],
                                rec.yaw_rate[1:, 1])  # fmt: skip


def frame_grid(rec: MissionRecord, x0_lo: Any, x0_hi: Any, max_range: float, resolution: float) -> Grid:
    """The map's frame (see the module docstring); raises :class:`UserError` on an unbounded dead reckoning or
    a frame over :data:`MAX_CELLS` (a one-line message saying its size)."""
    try:
        return frame_of(rec, np.asarray(x0_lo)[:2], np.asarray(x0_hi)[:2], max_range, resolution, MAX_CELLS,
                        contradicted=True)  # fmt: skip
    except FrameError as exc:
        raise UserError(str(exc)) from None


def run_offline(rec: MissionRecord, grid: Grid, x0_lo: Any, x0_hi: Any, q: int) -> DigSlamResult:
    """:func:`~digslam.observer.online.smoother.dig_slam` to its fixpoint (``q`` outliers per record)."""
    return dig_slam(rec, grid, np.asarray(x0_lo)[:2], np.asarray(x0_hi)[:2], DigSlamConfig(q=q))


def is_consistent(rec: MissionRecord, x0_lo: Any, x0_hi: Any, q: int, max_range: float,
                  resolution: float) -> bool:  # fmt: skip
    """Whether the offline observer finds ``rec`` consistent with its bounds (a fresh frame of its own)."""
    if len(rec) < 2:
        return bool(np.all(rec.heading[..., 0] <= rec.heading[..., 1]))
    if heading_tube(rec).is_empty():
        return False
    grid = frame_grid(rec, x0_lo, x0_hi, max_range, resolution)
    return run_offline(rec, grid, x0_lo, x0_hi, q).consistent


@dataclass
class Online:
    """The online filter's run: its boxes at every step it passed, and its sets at the end."""

    lo: np.ndarray
    hi: np.ndarray
    consistent: bool
    failed_at: int | None
    code: np.ndarray
    free: np.ndarray


def run_online(rec: MissionRecord, grid: Grid, x0_lo: Any, x0_hi: Any, q: int, bar: Any = None) -> Online:
    """The online filter over ``rec`` (``bar``: a tqdm-like bar advanced by one per record)."""
    f = OnlineDigSlam(grid, OnlineConfig(q=q))
    n = len(rec)
    lo, hi = np.full((n, 2), np.nan), np.full((n, 2), np.nan)
    f.reset(np.asarray(x0_lo)[:2], np.asarray(x0_hi)[:2], rec[0])
    lo[0], hi[0] = f.pose_lo, f.pose_hi
    for k in range(1, n):
        f.update(rec[k])
        if bar is not None:
            bar.update(1)
        if not f.consistent:
            break
        lo[k], hi[k] = f.pose_lo, f.pose_hi
    return Online(lo, hi, f.consistent, f.inconsistent_step, f.explored(), f.dig.free.copy())


def cross_check(off: DigSlamResult, on: Online, cell_area: float) -> dict[str, Any]:
    """The offline result against the online filter's: areas, the coverage ratio, whether the offline boxes
    lie inside the filter's and its sets are at least as sharp (the observers' contract)."""
    if not on.consistent:
        return {"online_consistent": False, "online_failed_at": on.failed_at}
    assert off.tube is not None and off.dig is not None and off.explored is not None
    c_off = float(np.sum((off.explored == CLEAR) & off.dig.free)) * cell_area
    c_on = float(np.sum((on.code == CLEAR) & on.free)) * cell_area
    inside = bool(np.all(off.tube.gate_lo >= on.lo) and np.all(off.tube.gate_hi <= on.hi))
    sharper = bool(np.all(off.dig.free >= on.free) and np.all((off.explored == CLEAR) >= (on.code == CLEAR))
                   and np.all((off.explored == DARK) >= (on.code == DARK)))  # fmt: skip
    w_on = np.max(on.hi - on.lo, axis=1)
    return {
        "online_consistent": True,
        "online_area_certified_m2": c_on,
        "online_area_free_m2": float(np.sum(on.free)) * cell_area,
        "online_widest_pose_box_m": float(np.max(w_on)),
        "offline_over_online_coverage": c_off / c_on if c_on > 0 else None,
        "offline_boxes_inside_online": inside,
        "offline_at_least_as_sharp": sharper,
    }


__all__ = ["MAX_CELLS", "Online", "cross_check", "frame_grid", "heading_tube", "is_consistent", "run_offline",
           "run_online"]  # fmt: skip
