"""Compiled passes of Dig-SLAM over a stored stretch of the tube (thesis §6.4, Algorithm 6.3, Eq. 6.21–6.24).

The online filter (:func:`.step_jit.filter_step_q`) sees each reading once, with the box of its own time.
These kernels keep every step's pose box, heading interval and displacement box ``[d_k]``
(``x_k ∈ x_{k-1} + [d_k]``, Eq. B.20: the body-frame velocity and the odometry increment over the slice,
outward rounded by :func:`.pose_jit.predict`) and run the same contractors again over a stretch of them:

* :func:`filter_record`: the filter's steps over a whole stacked record, to the bit those of
  :meth:`.observer.OnlineDigSlam.update` (same kernels, same cone schedule), storing every box;
* :func:`smooth_pass`: one sweep of the constraint network (6.24) over the steps ``k0..k1``:
  ``C_d/dt`` on the gates backward, ``x_j &= x_{j+1} - [d_{j+1}]``, then forward,
  ``x_j &= x_{j-1} + [d_j]`` (outward rounded); the impact contractor (Eq. 6.22) and its directional
  form (:func:`.cones_jit.contract_cones`) on every box against the current ``M⁻``, which holds the cells
  dug at every time, the future included; then digging (Eq. 6.21, q-relaxed with ``q``) again the readings
  of every box that shrank;
* :func:`mark_record`: the possibly sensed zone ``Z⁺`` of the readings of steps ``k0..k1`` from their
  current boxes, into a fresh ``maybe``.

Every step is a sound contractor of the same constraints, so the boxes only shrink, never lose the truth,
and ``M⁻`` only grows. An empty box means the data contradict their bounds (returned as its index).

:class:`RecordArrays` is the stacked record as the kernels read it; :func:`record_arrays` builds it.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from digslam.observer.core.scalar_jit import add_dn, add_up, njit, sub_dn, sub_up
from digslam.observer.online.dig_types import CellSets, GridFrame, PoseBox, StepRecord
from digslam.observer.online.mark_jit import dig_and_mark_q
from digslam.observer.online.step_jit import contract_step, filter_step_q
from digslam.observer.record.mission import MissionRecord

__all__ = [
    "RecordArrays",
    "contract_gates",
    "filter_record",
    "mark_record",
    "record_arrays",
    "redig",
    "smooth_pass",
    "step_at",
    "sweep",
]


class RecordArrays(NamedTuple):
    """A stacked record of ``T + 1`` steps as the kernels read it (C-contiguous float64, ``no_echo`` bool):
    the fields of :class:`.dig_types.StepRecord` with a leading time axis, ``t`` (``(T + 1,)``) in place of
    ``dt`` (the same fields as :class:`~digslam.observer.record.mission.MissionRecord`, ``ranges`` for its
    ``range``)."""

    t: np.ndarray
    speed: np.ndarray  # (T + 1, 2), then yaw_rate, heading and lateral
    lateral: np.ndarray
    yaw_rate: np.ndarray
    heading: np.ndarray
    alpha: np.ndarray  # (T + 1, n), then gamma, r_max and no_echo
    gamma: np.ndarray
    r_max: np.ndarray
    ranges: np.ndarray  # (T + 1, n, 2)
    no_echo: np.ndarray
    mean_velocity: np.ndarray  # (T + 1, 2, 2)
    mount: np.ndarray  # (T + 1, n, 2), then slack
    slack: np.ndarray


def record_arrays(rec: MissionRecord) -> RecordArrays:
    """The :class:`RecordArrays` of a stacked record (C-contiguous copies where needed)."""
    f = np.ascontiguousarray
    return RecordArrays(f(rec.t, np.float64), f(rec.speed), f(rec.lateral), f(rec.yaw_rate), f(rec.heading),
                        f(rec.alpha), f(rec.gamma), f(rec.r_max), f(rec.range), f(rec.no_echo, np.bool_),
                        f(rec.mean_velocity), f(rec.mount), f(rec.slack))  # fmt: skip


@njit
def step_at(rec: RecordArrays, k: int) -> StepRecord:
    """Step ``k`` of a stacked record as a :class:`.dig_types.StepRecord` (``dt = t_k - t_{k-1}``, 0 at
    ``k = 0``, computed as the filter computes it)."""
    dt = rec.t[k] - rec.t[k - 1] if k > 0 else 0.0
    return StepRecord(dt, rec.speed[k], rec.lateral[k], rec.yaw_rate[k], rec.heading[k], rec.alpha[k],
                      rec.gamma[k], rec.r_max[k], rec.ranges[k], rec.no_echo[k],
                      rec.mean_velocity[k], rec.mount[k], rec.slack[k])  # fmt: skip


@njit
def filter_record(cells: CellSets, grid: GridFrame, rec: RecordArrays, lo: np.ndarray, hi: np.ndarray,
                  psi: np.ndarray, d: np.ndarray, impacts: int, q: int, cone_every: int) -> int:  # fmt: skip
    """The online filter over a whole record: step 0 digs and marks from ``lo[0], hi[0], psi[0]``, then each
    step ``k`` is :func:`.step_jit.filter_step_q` from step ``k - 1`` (the cones, ``impacts = 2``, only at
    steps ``k`` multiple of ``cone_every``, as :class:`.observer.OnlineDigSlam`).

    Args:
        cells: the cell sets, updated in place (:class:`.dig_types.CellSets`).
        lo, hi, psi: ``(T + 1, 2)``, row 0 the start box and heading; receive every step's box and heading.
        d: ``(T + 1, 4)`` receives the displacement boxes ``(d_x⁻, d_y⁻, d_x⁺, d_y⁺)`` (row 0: NaN).

    Returns:
        -1, or the first step whose box or heading was empty (the rows from it on are left as they were).
    """
    n = rec.t.shape[0]
    dig_and_mark_q(cells, grid, PoseBox(lo[0, 0], lo[0, 1], hi[0, 0], hi[0, 1], psi[0, 0], psi[0, 1]),
                   step_at(rec, 0), True, q)  # fmt: skip
    d[0, :] = math.nan
    pl, ph, ps = np.empty(2), np.empty(2), np.empty(2)
    for k in range(1, n):
        pl[:], ph[:], ps[:] = lo[k - 1], hi[k - 1], psi[k - 1]
        imp = 1 if impacts == 2 and k % cone_every else impacts
        code, _, _, _, _, dd = filter_step_q(cells, grid, step_at(rec, k), pl, ph, ps, imp, q)
        if code:
            return k
        lo[k], hi[k], psi[k] = pl, ph, ps
        d[k, 0], d[k, 1], d[k, 2], d[k, 3] = dd
    return -1


@njit
def sweep(lo: np.ndarray, hi: np.ndarray, d: np.ndarray, k0: int, k1: int) -> int:
    """``C_d/dt`` on the gates ``k0..k1`` through the displacement boxes: backward,
    ``x_j &= x_{j+1} - [d_{j+1}]``, then forward, ``x_j &= x_{j-1} + [d_j]`` (outward rounded; in place).

    Returns:
        -1, or the first box found empty.
    """
    for j in range(k1 - 1, k0 - 1, -1):
        a0 = max(lo[j, 0], sub_dn(lo[j + 1, 0], d[j + 1, 2]))
        a1 = max(lo[j, 1], sub_dn(lo[j + 1, 1], d[j + 1, 3]))
        b0 = min(hi[j, 0], sub_up(hi[j + 1, 0], d[j + 1, 0]))
        b1 = min(hi[j, 1], sub_up(hi[j + 1, 1], d[j + 1, 1]))
        if not (a0 <= b0 and a1 <= b1):
            return j
        lo[j, 0], lo[j, 1], hi[j, 0], hi[j, 1] = a0, a1, b0, b1
    for j in range(k0 + 1, k1 + 1):
        a0 = max(lo[j, 0], add_dn(lo[j - 1, 0], d[j, 0]))
        a1 = max(lo[j, 1], add_dn(lo[j - 1, 1], d[j, 1]))
        b0 = min(hi[j, 0], add_up(hi[j - 1, 0], d[j, 2]))
        b1 = min(hi[j, 1], add_up(hi[j - 1, 1], d[j, 3]))
        if not (a0 <= b0 and a1 <= b1):
            return j
        lo[j, 0], lo[j, 1], hi[j, 0], hi[j, 1] = a0, a1, b0, b1
    return -1


@njit
def contract_gates(free: np.ndarray, grid: GridFrame, rec: RecordArrays, lo: np.ndarray, hi: np.ndarray,
                   psi: np.ndarray, impacts: int, q: int, k0: int, k1: int) -> int:  # fmt: skip
    """The filter's contractors on the boxes ``k0..k1`` against ``free`` (in place), as in
    :func:`.step_jit.filter_step_q`: ``impacts >= 1`` the impact contractor (Eq. 6.22, q-relaxed radius
    :func:`.pose_jit.impact_bound_q`) on boxes inside the grid's frame, ``impacts = 2`` also the cones
    (:func:`.cones_jit.contract_cones`) on boxes wider than :data:`.step_jit.CONE_MIN_WIDTH`;
    ``impacts = 3`` the cones alone (the impacts done elsewhere, e.g. by
    :meth:`~digslam.observer.slam.digmap.DigMap.contract_impacts` on the whole tube).

    Returns:
        -1, or the first box found empty.
    """
    for j in range(k0, k1 + 1):
        step = step_at(rec, j)
        x0, y0, x1, y1 = contract_step(free, grid, step, lo[j, 0], lo[j, 1], hi[j, 0], hi[j, 1], psi[j, 0],
                                       psi[j, 1], impacts, q)  # fmt: skip
        if not (x0 <= x1 and y0 <= y1):
            return j
        lo[j, 0], lo[j, 1], hi[j, 0], hi[j, 1] = x0, y0, x1, y1
    return -1


@njit
def redig(cells: CellSets, grid: GridFrame, rec: RecordArrays, lo: np.ndarray, hi: np.ndarray,
          psi: np.ndarray, dug_lo: np.ndarray, dug_hi: np.ndarray, q: int, k0: int, k1: int
          ) -> tuple[int, int, int, int, int]:  # fmt: skip
    """Dig again (Eq. 6.21, q-relaxed with ``q``; no marking) the readings of every step ``k0..k1`` whose box
    differs from the one it was dug with (``dug_lo``, ``dug_hi``, updated).

    Returns:
        ``(dug, r0, r1, c0, c1)``: the number of steps dug again and the window of the cells they changed
        (empty: ``r0 >= r1``).
    """
    n_dug, w0, w1, v0, v1 = 0, grid.ys.size, 0, grid.xs.size, 0
    for j in range(k0, k1 + 1):
        if lo[j, 0] == dug_lo[j, 0] and lo[j, 1] == dug_lo[j, 1] and hi[j, 0] == dug_hi[j, 0] and \
                hi[j, 1] == dug_hi[j, 1]:  # fmt: skip
            continue
        box = PoseBox(lo[j, 0], lo[j, 1], hi[j, 0], hi[j, 1], psi[j, 0], psi[j, 1])
        r0, r1, c0, c1 = dig_and_mark_q(cells, grid, box, step_at(rec, j), False, q)
        if r0 < r1 and c0 < c1:
            w0, w1, v0, v1 = min(w0, r0), max(w1, r1), min(v0, c0), max(v1, c1)
        dug_lo[j], dug_hi[j] = lo[j], hi[j]
        n_dug += 1
    return n_dug, w0, w1, v0, v1


@njit
def smooth_pass(cells: CellSets, grid: GridFrame, rec: RecordArrays, lo: np.ndarray, hi: np.ndarray,
                psi: np.ndarray, d: np.ndarray, dug_lo: np.ndarray, dug_hi: np.ndarray, impacts: int, q: int,
                k0: int, k1: int) -> tuple[int, int, int, int, int, int]:  # fmt: skip
    """One sweep over steps ``k0..k1``: :func:`sweep`, :func:`contract_gates` (``impacts`` as there; 0:
    none) and :func:`redig`.

    Returns:
        ``(empty, dug, r0, r1, c0, c1)``: -1 or the first box found empty, then :func:`redig`'s figures.
    """
    empty = sweep(lo, hi, d, k0, k1)
    if empty < 0 and impacts:
        empty = contract_gates(cells.free, grid, rec, lo, hi, psi, impacts, q, k0, k1)
    if empty >= 0:
        return empty, 0, 0, 0, 0, 0
    n_dug, r0, r1, c0, c1 = redig(cells, grid, rec, lo, hi, psi, dug_lo, dug_hi, q, k0, k1)
    return -1, n_dug, r0, r1, c0, c1


@njit
def mark_record(cells: CellSets, grid: GridFrame, rec: RecordArrays, lo: np.ndarray, hi: np.ndarray,
                psi: np.ndarray, q: int, k0: int, k1: int) -> None:  # fmt: skip
    """Grow ``cells.maybe`` (and dig, as :func:`.mark_jit.dig_and_mark_q` does) with the readings of steps
    ``k0..k1`` from their boxes: the possibly sensed zone ``Z⁺`` (Eq. B.5) of those boxes."""
    for j in range(k0, k1 + 1):
        dig_and_mark_q(cells, grid, PoseBox(lo[j, 0], lo[j, 1], hi[j, 0], hi[j, 1], psi[j, 0], psi[j, 1]),
                       step_at(rec, j), True, q)  # fmt: skip
