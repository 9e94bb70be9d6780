"""One step of the online Dig-SLAM filter (thesis §6.4, Algorithm 6.3, Eq. 6.21–6.23) in one compiled call.

:func:`filter_step` chains the kernels of one step of the filter
(:meth:`~digslam.observer.online.observer.OnlineDigSlam.update`):

1. :func:`.pose_jit.predict`: the tube step (``x' = R(ψ) v``, Eq. 3.59, 6.12, B.20, heading fused with
   the compass);
2. with ``impacts``, :func:`.pose_jit.impact_bound` then :func:`.pose_jit.contract` (Eq. 6.22), skipped
   (box unchanged) when the box leaves the grid's frame or no sensor echoed, as
   :meth:`.window.WindowDigMap.contract_box` does; with ``impacts = 2`` also the directional form, each
   echo's cone meeting ``comp M⁻`` (:func:`.cones_jit.contract_cones`), on a box wider than
   :data:`CONE_MIN_WIDTH`;
3. :func:`.mark_jit.dig_and_mark`: digs ``M⁻`` (Eq. 6.21) and grows the explored zone (Eq. B.5).

:func:`filter_step_q` takes ``q``, the number of outliers allowed among the step's range readings (thesis
§2.6.2): step 2 then uses the q-relaxed impact radius and step 3 digs a cell only where ``q + 1`` readings
prove it free; :func:`filter_step` is ``q = 0``.

The inputs are the named tuples the caller builds, the filter's :class:`.dig_types.CellSets` and
:class:`.dig_types.GridFrame` (once per episode) and the step's :class:`.dig_types.StepRecord`, and the state:
three ``(2,)`` arrays holding the pose box and the heading interval of the previous step, which receive
the new ones; the step's displacement box is returned. Nothing is rounded here: every bound comes from
those kernels (outward rounded with :mod:`digslam.observer.core.scalar_jit`). (The state is not a named
tuple on purpose: each named tuple costs about a microsecond at every call from Python, and this call runs
at every step.)

:func:`filter_step_flat` is :func:`filter_step_q` called from Python at every step
(:meth:`~digslam.observer.online.observer.OnlineDigSlam.update`): it takes the three named tuples as plain
tuples of their fields and builds them inside, which numba's dispatcher types several times faster (a named
tuple argument is typed field by field in Python, a plain tuple in C).

>>> from digslam.observer.online.window import grid_frame
>>> from digslam.observer.record.grid import Grid
>>> g = Grid((-3.0, -3.0), (3.0, 3.0), (60, 60))
>>> free, sure, maybe = (np.zeros(g.shape, bool) for _ in range(3))
>>> cells = CellSets(free, sure, maybe, np.zeros((2, 1, 1), np.int32), np.zeros(1, np.int32))
>>> lo, hi, psi = np.zeros(2), np.zeros(2), np.array([-1e-3, 1e-3])
>>> step = StepRecord(0.1, np.array([0.99, 1.01]), np.zeros(2), np.array([-0.01, 0.01]),
...     np.array([-1e-3, 1e-3]), np.zeros(1), np.array([np.pi]), np.array([5.0]), np.array([[1.9, 2.0]]),
...     np.zeros(1, bool))
>>> code, *win, shift = filter_step(cells, grid_frame(g), step, lo, hi, psi, False)
>>> code, bool(lo[0] <= 0.1 <= hi[0]), bool(free[30, 30]), bool(free[30, 55])
(0, True, True, False)
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.scalar_jit import njit
from digslam.observer.online.cones_jit import contract_cones
from digslam.observer.online.dig_jit import in_frame
from digslam.observer.online.dig_types import CellSets, GridFrame, PoseBox, StepRecord
from digslam.observer.online.mark_jit import dig_and_mark_q
from digslam.observer.online.mount_jit import apex, centre_of, centre_ranges, mount_kind
from digslam.observer.online.pose_jit import contract, impact_bound_q, predict

__all__ = ["CONE_MIN_WIDTH", "contract_step", "filter_step", "filter_step_flat", "filter_step_q"]

#: Pose boxes at most this wide (m) skip the cone contractor (it seldom cuts them: ``M⁻`` is set back from
#: the walls by about a cell); skipping a contractor never makes a claim false.
CONE_MIN_WIDTH = 0.15


@njit
def _contract_centred(free: np.ndarray, grid: GridFrame, step: StepRecord, ranges: np.ndarray, x0: float,
                      y0: float, x1: float, y1: float, psi_lo: float, psi_hi: float, impacts: int, q: int,
                      cones: bool) -> tuple[float, float, float, float]:  # fmt: skip
    """The impact contractor (``impacts`` 1 or 2, Eq. 6.22, q-relaxed radius from ``ranges``) then, with
    ``cones`` and ``impacts >= 2``, the cones on a box wider than :data:`CONE_MIN_WIDTH`, for cones whose
    apex is the box ``[x0, x1] × [y0, y1]`` (``impacts = 3``: the cones alone)."""
    r_hi = impact_bound_q(step.no_echo, ranges, q)
    if math.isfinite(r_hi) and in_frame(grid, x0, y0, x1, y1):
        if impacts <= 2:
            x0, y0, x1, y1 = contract(free, grid, x0, y0, x1, y1, r_hi)
        if cones and impacts >= 2 and x0 <= x1 and y0 <= y1 and max(x1 - x0, y1 - y0) > CONE_MIN_WIDTH:
            x0, y0, x1, y1 = contract_cones(free, grid, x0, y0, x1, y1, psi_lo, psi_hi, step.alpha,
                                            step.gamma, ranges, step.no_echo, q)  # fmt: skip
    return x0, y0, x1, y1


@njit
def contract_step(free: np.ndarray, grid: GridFrame, step: StepRecord, x0: float, y0: float, x1: float,
                  y1: float, psi_lo: float, psi_hi: float, impacts: int, q: int
                  ) -> tuple[float, float, float, float]:  # fmt: skip
    """The contractors of one step's readings on the position box ``[x0, x1] × [y0, y1]`` (heading
    ``[psi_lo, psi_hi]``) against ``free`` (``M⁻``): ``impacts`` 1, the impact contractor (Eq. 6.22,
    q-relaxed radius :func:`.pose_jit.impact_bound_q`), skipped when the box leaves the grid's frame or no
    sensor echoed; 2, also each echo's cone meeting ``comp M⁻`` (:func:`.cones_jit.contract_cones`) on a box
    wider than :data:`CONE_MIN_WIDTH`; 3, the cones alone.

    Mounted cones (:mod:`.mount_jit`): sharing one mount and slack, both act on the apex box and the position
    is cut to what the contracted apex box allows (:func:`.mount_jit.centre_of`); mixed, the impact radius
    of each reading is widened to the position (:func:`.mount_jit.centre_ranges`) and the cones are
    skipped (skipping a contractor never makes a claim false).

    Returns:
        The contracted box; empty (``x0 > x1`` or ``y0 > y1``) when no position meets the readings.
    """
    kind = mount_kind(step.mount, step.slack)
    if kind == 0:
        return _contract_centred(free, grid, step, step.ranges, x0, y0, x1, y1, psi_lo, psi_hi, impacts, q,
                                 True)  # fmt: skip
    if kind == 2:
        if impacts == 3:
            return x0, y0, x1, y1
        wide = centre_ranges(step.ranges, step.mount, step.slack)
        return _contract_centred(free, grid, step, wide, x0, y0, x1, y1, psi_lo, psi_hi, impacts, q, False)
    m1, m2, sp = step.mount[0, 0], step.mount[0, 1], step.slack[0, 0]
    a = apex(PoseBox(x0, y0, x1, y1, psi_lo, psi_hi), m1, m2, sp, step.slack[0, 1])
    a0, b0, a1, b1 = _contract_centred(free, grid, step, step.ranges, a.x_lo, a.y_lo, a.x_hi, a.y_hi,
                                       a.psi_lo, a.psi_hi, impacts, q, True)  # fmt: skip
    if not (a0 <= a1 and b0 <= b1):
        return a0, b0, a1, b1
    return centre_of(x0, y0, x1, y1, PoseBox(a0, b0, a1, b1, a.psi_lo, a.psi_hi), m1, m2, sp)


@njit
def filter_step_q(cells: CellSets, grid: GridFrame, step: StepRecord, pose_lo: np.ndarray,
                  pose_hi: np.ndarray, heading: np.ndarray, impacts: int, q: int
                  ) -> tuple[int, int, int, int, int, tuple[float, float, float, float]]:  # fmt: skip
    """Predict, contract and measure one step (see the module docstring), robust to ``q`` outliers.

    Args:
        cells: the filter's cell sets ``M⁻``, certainly and possibly sensed (updated in place), and the
            per-cell counts of the q-relaxed mode (:class:`.dig_types.CellSets`; unused when ``q = 0``).
        grid: the grid's cell bounds and the clearance bound's constants (:class:`.dig_types.GridFrame`).
        step: the step's record (:class:`.dig_types.StepRecord`): odometry and readings.
        pose_lo, pose_hi, heading: ``(2,)`` the pose box ``[x⁻, y⁻]``, ``[x⁺, y⁺]`` and the heading interval
            ``[ψ⁻, ψ⁺]`` at the previous step, overwritten with the new ones when ``code`` is 0 (left as
            they are otherwise).
        impacts: 0: no impact contractor; 1 (or True): Eq. 6.22; 2: Eq. 6.22 then each echo's cone
            (:func:`.cones_jit.contract_cones`).
        q: at most ``q`` of this step's range readings are outliers (0: none): the impact radius is the
            q-relaxed :func:`.pose_jit.impact_bound_q` and a cell is dug where ``q + 1`` readings prove it
            free (:func:`.mark_jit.dig_and_mark_q`).

    Returns:
        ``(code, r0, r1, c0, c1, shift)``: ``code`` 0, the window holding every changed cell and the
        step's displacement box ``shift = (d_x⁻, d_y⁻, d_x⁺, d_y⁺)``, ``x_k ∈ x_{k-1} + [d]`` (Eq. B.20, for
        the backward smoothing); or ``code`` 1 when the data contradict their bounds (empty heading or box;
        nothing dug; ``shift`` NaN).
    """
    nan = (math.nan, math.nan, math.nan, math.nan)
    lo, hi, psi = pose_lo, pose_hi, heading
    ok, box, d = predict(PoseBox(lo[0], lo[1], hi[0], hi[1], psi[0], psi[1]), step)
    if not ok:
        return 1, 0, 0, 0, 0, nan
    x0, y0, x1, y1 = box.x_lo, box.y_lo, box.x_hi, box.y_hi
    if impacts:
        x0, y0, x1, y1 = contract_step(cells.free, grid, step, x0, y0, x1, y1, box.psi_lo, box.psi_hi,
                                       impacts, q)  # fmt: skip
    if not (x0 <= x1 and y0 <= y1):
        return 1, 0, 0, 0, 0, nan
    lo[0], lo[1], hi[0], hi[1] = x0, y0, x1, y1
    psi[0], psi[1] = box.psi_lo, box.psi_hi
    box = PoseBox(x0, y0, x1, y1, box.psi_lo, box.psi_hi)
    r0, r1, c0, c1 = dig_and_mark_q(cells, grid, box, step, True, q)
    return 0, r0, r1, c0, c1, d


@njit
def filter_step_flat(cells: tuple, grid: tuple, step: tuple, pose_lo: np.ndarray, pose_hi: np.ndarray,
                     heading: np.ndarray, impacts: int, q: int
                     ) -> tuple[int, int, int, int, int, tuple[float, float, float, float]]:  # fmt: skip
    """:func:`filter_step_q` with ``cells``, ``grid`` and ``step`` the plain tuples of the fields of a
    :class:`.dig_types.CellSets`, a :class:`.dig_types.GridFrame` and a :class:`.dig_types.StepRecord` (all 11
    fields: ``tuple(StepRecord(...))``); same arguments otherwise, same results to the bit."""
    return filter_step_q(CellSets(*cells), GridFrame(*grid), StepRecord(*step), pose_lo, pose_hi, heading,
                         impacts, q)  # fmt: skip


@njit
def filter_step(cells: CellSets, grid: GridFrame, step: StepRecord, pose_lo: np.ndarray, pose_hi: np.ndarray,
                heading: np.ndarray, impacts: int
                ) -> tuple[int, int, int, int, int, tuple[float, float, float, float]]:  # fmt: skip
    """:func:`filter_step_q` with ``q = 0`` (no outlier: every reading's interval contains the truth)."""
    return filter_step_q(cells, grid, step, pose_lo, pose_hi, heading, impacts, 0)
