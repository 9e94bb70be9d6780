"""The offline Dig-SLAM observer (thesis §6.4, Algorithm 6.3, Eq. 6.18–6.24): the fixpoint of every
contractor of the online filter over a whole record.

From a recorded mission (bounded body-frame velocity, yaw rate, odometry increment, compass heading and
range intervals) :func:`dig_slam` encloses the robot's positions in a tube, proves which cells are free (the
dig zone ``M⁻``) and which were explored, and iterates the contractors of the constraint network (6.24):

1. the online filter over the record (:func:`.smooth_jit.filter_record`: prediction ``x' = R(ψ) v`` with the
   ``mean_velocity`` increment, Eq. 3.59, 6.12, B.20; the impact contractor, Eq. 6.22, and its directional
   cone form; digging, Eq. 6.21, q-relaxed with ``q``; the possibly sensed zone, Eq. B.5); each box, heading
   and displacement box ``[d_k]`` is kept;
2. the heading tube of the compass and the gyro forward and backward
   (:func:`~digslam.observer.tube.tube.heading_from_compass`) intersected with the filter's headings;
3. to a fixpoint, over the whole tube: ``C_d/dt`` on the gates through the ``[d_k]`` backward and forward
   (:func:`.smooth_jit.sweep`); the impact contractor on every box against the current ``M⁻``, which holds
   the cells dug at every time, the future included (one clearance map for all the boxes,
   :meth:`~digslam.observer.slam.digmap.DigMap.contract_impacts`), and the cone contractor on every box
   wider than :data:`.step_jit.CONE_MIN_WIDTH` (:func:`.smooth_jit.contract_gates`); digging again every box
   that shrank (:func:`.smooth_jit.redig`); then ``C_d/dt`` of the tube
   (:func:`~digslam.observer.tube.tube.ctc_deriv`, the body-frame velocity and the increment over each
   slice), which also encloses the slices;
4. the possibly sensed zone of the final boxes (:func:`.smooth_jit.mark_record`) intersected with the
   filter's, and, with ``explored``, the explored-zone proofs of App. B on the final tube
   (:func:`~digslam.observer.slam.digslam.explored_zone`).

Every step is a sound contractor of the same constraints, started from the filter's own sets, so on any
record the offline boxes lie inside the online filter's at every step, its ``M⁻`` and clear cells contain
the filter's and its dark cells contain the filter's (same ``impacts``, ``cones``, ``cone_every`` and
``q``; ``tests/observer/online/test_smoother.py``). An empty box means the data contradict their bounds:
the result then says so (``consistent`` is False) and carries no sets.

Cost per step of record: one filter step (about 50 µs on the §6.4.2 loop; its impact contraction decides
the cells of a wide box a row at a time, :func:`.pose_jit.contract`), then per iteration one impact
contraction per box, one cone contraction per box wider than :data:`.step_jit.CONE_MIN_WIDTH` and the
digging of the boxes that shrank; 3000 steps of the coverage environment take about 0.3–1 s, and the §6.4.2
loop (12,001 samples) less than Algorithm 6.3 as written,
:func:`~digslam.observer.slam.digslam.thesis_dig_slam` (about 0.3–0.5 of its time;
``benchmarks/bench_digslam.py`` prints ``dig_slam_over_thesis``).

The data contract is :mod:`digslam.observer.record.mission`'s: ``speed[k]``, ``lateral[k]`` and
``yaw_rate[k]`` bound the truth over the slice ``[t_{k-1}, t_k]`` that ends at ``t_k``; ``heading[k]`` bounds
the heading at ``t_k``; ``range[k]`` bounds the ranges from the pose at ``t_k``; ``mean_velocity[k]`` bounds
the velocity averaged over the slice in the body frame at its start. A mounted sensor's ranges are from its
cone's apex, and a reading with a slack was taken within it of the record's pose (``mount``, ``slack``): the
kernels then dig, mark and contract from the apex box (:mod:`.mount_jit`), and step 3's impact contractor runs
box by box (:func:`.smooth_jit.contract_gates`) instead of on one clearance map.

>>> from digslam.observer.record.mission import MissionRecord
>>> k, one = np.arange(21), np.ones((21, 1))
>>> rec = MissionRecord(t=0.1 * k, speed=one * [0.49, 0.51], yaw_rate=one * [-0.01, 0.01],
...     heading=one * [-1e-3, 1e-3], alpha=0 * one, gamma=np.pi * one, r_max=5 * one,
...     range=(3.0 - 0.05 * k[:, None, None]) + [[-0.01, 0.01]], no_echo=one < 0, outlier=one < 0)
>>> res = dig_slam(rec, Grid((-4.0, -4.0), (4.0, 4.0), (80, 80)), [0.0, 0.0], [0.0, 0.0])  # a wall at x = 3
>>> res.consistent, bool(np.all(res.tube.widths() <= res.online_widths)), bool(res.dig.free[40, 70])
(True, True, False)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core.boxes import width_inf
from digslam.observer.online.dig_types import CellSets
from digslam.observer.online.smooth_jit import (
    contract_gates,
    filter_record,
    mark_record,
    record_arrays,
    redig,
    sweep,
)
from digslam.observer.online.window import WindowDigMap
from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord
from digslam.observer.slam.digslam import (
    DigSlamConfig,
    DigSlamResult,
    explored_zone,
    odometry_increment,
    odometry_velocity,
)
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA
from digslam.observer.tube.tube import Tube, ctc_deriv, heading_from_compass

__all__ = ["dig_slam", "impact_radius"]


def impact_radius(record: MissionRecord, q: int) -> np.ndarray:
    """Per step, the radius of the q-relaxed impact constraint (Eq. 6.22 under thesis §2.6.2): the
    ``(q + 1)``-th smallest upper range bound over the echoing sensors (``inf`` when fewer echoed), as
    :func:`.pose_jit.impact_bound_q`."""
    hi = np.sort(np.where(record.no_echo, np.inf, record.range[..., 1]), axis=1)
    return hi[:, q] if q < hi.shape[1] else np.full(hi.shape[0], np.inf)


def _check_start(grid: Grid, x0_lo: Any, x0_hi: Any) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = np.asarray(x0_lo, dtype=np.float64).ravel(), np.asarray(x0_hi, dtype=np.float64).ravel()
    if lo.shape != (2,) or hi.shape != (2,) or not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise ValueError(f"x0_lo, x0_hi: expected a finite 2-d box, got {x0_lo} and {x0_hi}")
    if np.any(lo > hi) or np.any(lo < grid.lo) or np.any(hi > grid.hi):
        raise ValueError(f"x0_lo, x0_hi: expected lo <= hi inside the grid's frame, got {lo} and {hi}")
    return lo, hi


def _dead_reckoning(t: np.ndarray, x0: tuple[np.ndarray, np.ndarray], u: tuple[np.ndarray, np.ndarray],
                    inc: Any) -> np.ndarray:  # fmt: skip
    n = t.shape[0]
    g_lo, g_hi = np.full((n, 2), -np.inf), np.full((n, 2), np.inf)
    g_lo[0], g_hi[0] = x0
    return ctc_deriv(Tube(t, g_lo, g_hi), *u, backward=False, increment=inc).widths()


def dig_slam(
    record: MissionRecord, grid: Grid, x0_lo: Any, x0_hi: Any, config: DigSlamConfig | None = None
) -> DigSlamResult:
    """Run Dig-SLAM (Algorithm 6.3) on a recorded mission to its fixpoint (see the module docstring).

    Args:
        record: a stacked mission of ``T + 1`` samples.
        grid: the cells of ``M⁻`` (they must cover the region the robot senses).
        x0_lo, x0_hi: the initial position box ``X₀`` (Eq. 6.15), finite, inside the grid's frame.
        config: :class:`~digslam.observer.slam.digslam.DigSlamConfig` (defaults when None).

    Returns:
        A :class:`~digslam.observer.slam.digslam.DigSlamResult`; check ``consistent`` before using the sets.

    Raises:
        ValueError: on a single-step record, a grid that is not a Grid, a bad initial box, or
            ``explored=True`` with ``q > 0``.
    """
    cfg = config or DigSlamConfig()
    if not isinstance(record, MissionRecord) or record.t.ndim != 1 or len(record) < 2:
        raise ValueError("record: expected a stacked mission of at least two samples")
    if not isinstance(grid, Grid):
        raise ValueError(f"grid: expected a Grid, got {type(grid).__name__}")
    x0 = _check_start(grid, x0_lo, x0_hi)
    t, n, q = record.t, len(record), int(cfg.q)
    if cfg.explored and q:
        raise ValueError("config: explored=True (the App. B proofs) trusts every reading; it needs q = 0")
    centred = record.centred
    if cfg.explored and not centred:
        raise ValueError(
            "config: explored=True (the App. B proofs) takes centred cones read at the record's "
            "instant; this record has mounts or slacks: leave explored unset"
        )
    heading = heading_from_compass(t, record.heading[:, 0], record.heading[:, 1],
                                   record.yaw_rate[1:, 0], record.yaw_rate[1:, 1])  # fmt: skip
    if heading.is_empty():  # compass and gyro contradict each other
        at = heading.inconsistent_at if heading.inconsistent_at is not None else heading.first_empty()
        return DigSlamResult(False, at, None, None, heading, 0)
    u, inc = odometry_velocity(record, heading), odometry_increment(record, heading)
    res = DigSlamResult(False, None, None, None, heading, 0, dead_reckoning=_dead_reckoning(t, x0, u, inc))
    # the filter's state (as OnlineDigSlam keeps it), then every box, heading and displacement box
    dig = WindowDigMap(grid)
    sure, maybe = np.zeros(grid.shape, dtype=bool), np.zeros(grid.shape, dtype=bool)
    cnt = np.zeros((2, *grid.shape) if q else (2, 1, 1), dtype=np.int32)
    lst = np.zeros(grid.shape[0] * grid.shape[1] + 1 if q else 1, dtype=np.int32)
    cells = CellSets(dig.free, sure, maybe, cnt, lst)
    rec = record_arrays(record)
    lo, hi, psi, d = np.empty((n, 2)), np.empty((n, 2)), np.empty((n, 2)), np.empty((n, 4))
    lo[0], hi[0], psi[0] = x0[0], x0[1], record.heading[0]
    impacts = (2 if cfg.cones else 1) if cfg.impacts else 0
    at = filter_record(cells, dig.frame, rec, lo, hi, psi, d, impacts, q, int(cfg.cone_every))
    if at >= 0:
        return _failed(res, at)
    res.online_widths = width_inf(lo, hi)
    np.maximum(psi[:, 0], heading.gate_lo[:, 0], out=psi[:, 0])
    np.minimum(psi[:, 1], heading.gate_hi[:, 0], out=psi[:, 1])
    if not np.all(psi[:, 0] <= psi[:, 1]):
        return _failed(res, int(np.argmax(psi[:, 0] > psi[:, 1])))
    s_lo, s_hi = np.full((n - 1, 2), -np.inf), np.full((n - 1, 2), np.inf)
    dug_lo, dug_hi = lo.copy(), hi.copy()
    r_hi = impact_radius(record, q)
    total = float(np.sum(width_inf(lo, hi)))
    for it in range(cfg.max_iter):
        before = width_inf(lo, hi)
        res.iterations = it + 1
        empty = sweep(lo, hi, d, 0, n - 1)
        if empty < 0 and impacts and not centred:  # mounted cones: each box by the step's kernels
            empty = contract_gates(cells.free, dig.frame, rec, lo, hi, psi, impacts, q, 0, n - 1)
        elif empty < 0 and impacts:
            lo[:], hi[:] = dig.contract_impacts(lo, hi, r_hi)  # Eq. 6.22 on every box, one clearance map
            bad = ~np.all(lo <= hi, axis=1)
            empty = int(np.argmax(bad)) if bad.any() else -1
            if empty < 0 and cfg.cones:
                empty = contract_gates(cells.free, dig.frame, rec, lo, hi, psi, 3, q, 0, n - 1)
        if empty >= 0:
            return _failed(res, int(empty))
        redig(cells, dig.frame, rec, lo, hi, psi, dug_lo, dug_hi, q, 0, n - 1)
        after = width_inf(lo, hi)
        tube = ctc_deriv(Tube(t, lo, hi, s_lo, s_hi), *u, increment=inc)
        if tube.is_empty():
            at = tube.inconsistent_at if tube.inconsistent_at is not None else tube.first_empty()
            return _failed(res, at)
        lo[:], hi[:], s_lo, s_hi = tube.gate_lo, tube.gate_hi, tube.slice_lo, tube.slice_hi
        res.widths.append({"before": before, "impacts": after, "deriv": tube.widths()})
        new_total = float(np.sum(tube.widths()))
        if total - new_total <= cfg.tol * total:
            break
        total = new_total
    redig(cells, dig.frame, rec, lo, hi, psi, dug_lo, dug_hi, q, 0, n - 1)  # the boxes C_d/dt shrank last
    fresh = np.zeros(grid.shape, dtype=bool)
    mark_record(CellSets(dig.free, sure, fresh, cnt, lst), dig.frame, rec, lo, hi, psi, q, 0, n - 1)
    maybe &= fresh  # both are sound: a cell possibly sensed from the final boxes and from the filter's
    res.heading = Tube(t, psi[:, :1], psi[:, 1:])
    res.tube = Tube(t, lo, hi, s_lo, s_hi)
    code = np.full(grid.shape, DARK, dtype=np.int8)
    code[maybe] = PENUMBRA
    if cfg.explored:
        ez = explored_zone(grid, record, res.tube, res.heading)
        code[ez == DARK] = DARK
        sure |= ez == CLEAR
    code[sure] = CLEAR
    res.consistent, res.dig, res.explored = True, dig, code
    return res


def _failed(res: DigSlamResult, at: int | None) -> DigSlamResult:
    """The result of an inconsistent record: no tube, no sets."""
    res.consistent, res.first_empty, res.tube, res.dig, res.explored = False, at, None, None, None
    return res
