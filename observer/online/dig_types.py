"""The named tuples that the online filter's kernels take (kernel rule 4 of :mod:`digslam.observer.core`).

:class:`GridFrame` (the grid, built once per grid by :func:`.window.grid_frame`), :class:`CellSets` (the
filter's cell sets), :class:`PoseBox` (one pose box and heading interval), :class:`CellAxes` (the per-row
and per-column bounds shared by the readings of one pose box, :func:`.dig_jit.reach_axes`),
:class:`SectorBatch` (a batch of readings, one pose box each) and :class:`StepRecord` (one step's record):
the kernels of :mod:`.dig_jit`, :mod:`.mark_jit`, :mod:`.pose_jit`, :mod:`.step_jit` and
:mod:`.smooth_jit` share them; numba passes them as records.

>>> box = PoseBox(0.0, 0.0, 1.0, 1.0, -0.1, 0.1)
>>> box.x_hi - box.x_lo, StepRecord._fields[-3:]
(1.0, ('mean_velocity', 'mount', 'slack'))
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

__all__ = ["NO_MEAN", "NO_MOUNT", "CellAxes", "CellSets", "GridFrame", "PoseBox", "SectorBatch", "StepRecord"]


class GridFrame(NamedTuple):
    """The online filter's grid as its kernels read it (:func:`.window.grid_frame` builds it once per grid).

    The frame is ``[xs[0], xs[-1]] × [ys[-1], ys[0]]`` and the cell size :func:`.dig_jit.cell_size`, both
    exactly those of the :class:`~digslam.observer.record.grid.Grid` (whose bounds are a ``linspace`` of its
    frame): they are not stored, so that the tuple stays small (each field costs at every call from Python).

    Attributes:
        xs: ``(nx + 1,)`` exact column bounds, increasing.
        ys: ``(ny + 1,)`` exact row bounds, decreasing (row 0 at the top).
        nys: ``-ys`` (increasing), for :func:`~digslam.observer.core.grid_jit.window`.
        keep, off: the constants of the clearance lower bound ``D·keep - off`` (``keep = 1 - EDT_SLACK``,
            ``off = diag + EDT_SLACK·span``, as in :meth:`.digmap.DigMap.clearance_lower`).
    """

    xs: np.ndarray
    ys: np.ndarray
    nys: np.ndarray
    keep: float
    off: float


class CellSets(NamedTuple):
    """The online filter's cell sets, updated in place by the kernels (all C-contiguous).

    Attributes:
        free: ``(ny, nx)`` bool, ``M⁻``: the cells proved free (dug, Eq. 6.21).
        sure: ``(ny, nx)`` bool, the certainly sensed cells ``Z⁻`` (the dug cells).
        maybe: ``(ny, nx)`` bool, the possibly sensed cells ``Z⁺`` (Eq. B.5).
        count: ``(2, ny, nx)`` int32, zero between steps: per cell, the readings of the step that prove it
            free and the last reading that counted it (the q-relaxed mode; ``(2, 1, 1)`` when unused).
        listed: ``(ny·nx + 1,)`` int32, ``listed[0] = 0`` between steps: the number of cells counted in the
            step, then their flat indices ``i·nx + j`` (q-relaxed mode; ``(1,)`` when unused).
    """

    free: np.ndarray
    sure: np.ndarray
    maybe: np.ndarray
    count: np.ndarray  # type: ignore[assignment]  # a field, shadowing tuple.count
    listed: np.ndarray


class PoseBox(NamedTuple):
    """One pose box: the position box ``[x]`` and the heading interval ``[ψ]`` (scalars).

    Attributes:
        x_lo, y_lo, x_hi, y_hi: the position box ``[x⁻, x⁺] × [y⁻, y⁺]``.
        psi_lo, psi_hi: the heading interval ``[ψ⁻, ψ⁺]``.
    """

    x_lo: float
    y_lo: float
    x_hi: float
    y_hi: float
    psi_lo: float
    psi_hi: float


class CellAxes(NamedTuple):
    """Bounds of the relative boxes ``c - [x]`` of the cells of a window, per column and per row
    (:func:`.dig_jit.reach_axes`): shared by every reading of one pose box, each cell test then only compares
    them.

    Attributes:
        cols: ``(4, nc)``: per column from ``col0``, the lower and upper bound of ``x_c - [x]`` (outward
            rounded), the farthest squared distance (rounded up) and the nearest (rounded down).
        rows: ``(4, nr)``: the same per row from ``row0``, for ``y``.
        row0, col0: the window's first row and column.
    """

    cols: np.ndarray
    rows: np.ndarray
    row0: int
    col0: int


class SectorBatch(NamedTuple):
    """A batch of readings, each from its own pose box (:func:`.dig_jit.dig_batch`).

    Attributes:
        lo, hi: ``(N, 2)`` the pose boxes.
        psi_lo, psi_hi: ``(N,)`` the heading intervals.
        alpha, gamma: ``(N,)`` the cone directions (relative to the heading) and half-apertures.
        r: ``(N,)`` the free ranges.
        disk: ``(N,)`` bool: the omnidirectional sensor (the open disk; ``psi``, ``alpha``, ``gamma`` unused).
    """

    lo: np.ndarray
    hi: np.ndarray
    psi_lo: np.ndarray
    psi_hi: np.ndarray
    alpha: np.ndarray
    gamma: np.ndarray
    r: np.ndarray
    disk: np.ndarray


#: The mean velocity of a record that does not measure it (``MissionRecord``'s default): never written.
NO_MEAN = np.array([[-math.inf, math.inf], [-math.inf, math.inf]])
NO_MEAN.flags.writeable = False
#: :attr:`StepRecord.mount` and :attr:`StepRecord.slack` of a step whose cones are all centred: no rows.
NO_MOUNT = np.zeros((0, 2))
NO_MOUNT.flags.writeable = False


class StepRecord(NamedTuple):
    """One single-step record as the filter's kernels read it: the fields of a single-step
    :class:`~digslam.observer.record.mission.MissionRecord` and the duration of the step that ends at it.

    Attributes:
        dt: ``t_k - t_{k-1}``, the duration of the step (0 for the first record of an episode).
        speed, lateral: ``(2,)`` the body-frame velocity ``v = (v_1, v_2)`` (forward, leftward), bounding the
            truth over the step (``x' = R(ψ) v``, Eq. 3.59, 6.12, B.20; ``lateral = [0, 0]``: a unicycle).
        yaw_rate: ``(2,)`` the yaw-rate interval, bounding the truth over the step.
        heading: ``(2,)`` the compass interval at ``t_k``.
        alpha, gamma, r_max: ``(n,)`` the cones' directions (relative to the heading), half-apertures and
            maximum ranges.
        ranges: ``(n, 2)`` the range intervals (``[r_max, inf]`` where ``no_echo``).
        no_echo: ``(n,)`` bool, True where nothing lies in the cone up to ``r_max``.
        mean_velocity: ``(2, 2)`` the body-frame velocity averaged over the step (rows ``v̄_1``, ``v̄_2``;
            ``[-inf, inf]`` twice when not measured, the default).
        mount, slack: ``(n, 2)`` each cone's place on the robot and its reading's slack
            (:mod:`.mount_jit`); the default, no rows (:data:`NO_MOUNT`), is every cone centred.
    """

    dt: float
    speed: np.ndarray
    lateral: np.ndarray
    yaw_rate: np.ndarray
    heading: np.ndarray
    alpha: np.ndarray
    gamma: np.ndarray
    r_max: np.ndarray
    ranges: np.ndarray
    no_echo: np.ndarray
    mean_velocity: np.ndarray = NO_MEAN
    mount: np.ndarray = NO_MOUNT
    slack: np.ndarray = NO_MOUNT
