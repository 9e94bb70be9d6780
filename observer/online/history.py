"""Smoothing at loop closures for the online filter: a bounded history of steps and its backward-forward pass.

:class:`StepHistory` keeps, for the last ``capacity`` steps, the step's record, pose box, heading interval and
displacement box ``[d_k]`` (``x_k ∈ x_{k-1} + [d_k]``, Eq. B.20, from :func:`.step_jit.filter_step_q`).
When the current box has shrunk by more than a share ``threshold`` of its widest since the last pass (an
impact or cone contraction at a loop closure), :meth:`StepHistory.smooth` runs

1. ``C_d/dt`` on the stored gates, backward from the current box and forward again
   (:func:`.smooth_jit.sweep`, outward rounded): only the steps whose box changed are touched after that;
2. when a box changed, digging again (Eq. 6.21, q-relaxed with ``q``) the readings of every stored step from
   its box, so the clear zone and ``M⁻`` grow, and the possibly sensed zone ``Z⁺`` (Eq. B.5) recomputed: the
   marks of the steps that left the history (``frozen``, kept from their final boxes) joined with the marks
   of every stored step from its current box (:func:`.smooth_jit.mark_record`, both in one pass), so that
   dark grows where the shrunk boxes can no longer have sensed.

Every step is a sound contractor of the same constraints, so every box keeps the truth, ``M⁻`` and the clear
zone only grow, and every cell left possibly sensed is one that some step's (sound) box may have sensed.

Memory: ``capacity`` steps of ``O(n_sensors)`` floats each plus one frozen ``(ny, nx)`` bool mask, whatever
the episode's length (when the history is full, its older half is marked into ``frozen`` and dropped: those
boxes stop changing). A pass costs ``O(capacity)`` for the sweep plus the digging and marking of the stored
steps; ``benchmarks/bench_observer.py`` measures the mean and worst update time with it on.
"""

from __future__ import annotations

import numpy as np

from digslam.observer.online.dig_types import CellSets, GridFrame
from digslam.observer.online.smooth_jit import RecordArrays, mark_record, sweep

__all__ = ["StepHistory"]


class StepHistory:
    """The last ``capacity`` steps of an episode and the loop-closure pass (see the module docstring).

    Args:
        shape: the grid's ``(ny, nx)``.
        capacity: steps kept (at least 2).
        threshold: the share of its widest width since the last pass by which the current box must have
            shrunk to start a pass, in ``(0, 1)``.
        q: the filter's q-relaxed mode (digging needs ``q + 1`` readings).
    """

    def __init__(self, shape: tuple[int, int], capacity: int, threshold: float, q: int) -> None:
        self.capacity, self.threshold, self.q = int(capacity), float(threshold), int(q)
        self.frozen = np.zeros(shape, dtype=bool)
        self.n, self.passes, self.widest = 0, 0, 0.0
        c = self.capacity
        self.lo, self.hi, self.psi, self.d = (
            np.zeros((c, 2)),
            np.zeros((c, 2)),
            np.zeros((c, 2)),
            np.zeros((c, 4)),
        )
        # the steps' records as the filter got them (their arrays, not copied), stacked when a pass runs
        self._steps: list[tuple] = []

    def push(self, step: tuple, t: float, lo: np.ndarray, hi: np.ndarray, psi: tuple[float, float],
             d: tuple[float, float, float, float] | None, cells: CellSets, grid: GridFrame
             ) -> None:  # fmt: skip
        """Store one step (``d`` None for the first): its record (the fields of a
        :class:`.dig_types.StepRecord`, ``t`` in place of ``dt``), box, heading and displacement box."""
        if self.n == self.capacity:
            self._drop_half(cells, grid)
        k = self.n
        self._steps.append((t, *step[1:]))
        self.lo[k], self.hi[k], self.psi[k] = lo, hi, psi
        self.d[k] = d if d is not None else (np.nan,) * 4
        self.n += 1
        self.widest = max(self.widest, float(max(hi[0] - lo[0], hi[1] - lo[1])))

    def records(self, k0: int, k1: int) -> RecordArrays:
        """Steps ``k0..k1 - 1`` stacked as the kernels read them."""
        steps = self._steps[k0:k1]
        return RecordArrays(
            *(np.ascontiguousarray(np.stack([s[i] for s in steps])) for i in range(len(steps[0])))
        )

    def _drop_half(self, cells: CellSets, grid: GridFrame) -> None:
        """Freeze the older half: mark its steps into ``frozen`` from their final boxes, shift the rest."""
        h = self.capacity // 2
        into = CellSets(cells.free, cells.sure, self.frozen, cells.count, cells.listed)
        mark_record(into, grid, self.records(0, h), self.lo, self.hi, self.psi, self.q, 0, h - 1)
        for a in (self.lo, self.hi, self.psi, self.d):
            a[: self.n - h] = a[h : self.n].copy()
        del self._steps[:h]
        self.n -= h

    def due(self, lo: np.ndarray, hi: np.ndarray) -> bool:
        """Whether the current box has shrunk enough since the last pass to start one."""
        return self.n > 1 and float(np.max(hi - lo)) <= (1.0 - self.threshold) * self.widest

    def smooth(self, cells: CellSets, grid: GridFrame) -> tuple[bool, int]:
        """The pass (module docstring) over the stored steps; the last stored box is the current one.

        Returns:
            ``(consistent, changed)``: False when a box became empty (the data contradict their bounds),
            and the number of stored boxes that shrank.
        """
        n = self.n
        before_lo, before_hi = self.lo[:n].copy(), self.hi[:n].copy()
        if sweep(self.lo, self.hi, self.d, 0, n - 1) >= 0:
            return False, 0
        changed = int(
            np.count_nonzero(np.any((self.lo[:n] != before_lo) | (self.hi[:n] != before_hi), axis=1))
        )
        if changed:  # dig every stored step from its box again (Eq. 6.21) and mark Z⁺ afresh
            fresh = self.frozen.copy()
            into = CellSets(cells.free, cells.sure, fresh, cells.count, cells.listed)
            mark_record(into, grid, self.records(0, n), self.lo, self.hi, self.psi, self.q, 0, n - 1)
            np.logical_and(cells.maybe, fresh, out=cells.maybe)
            cells.maybe[cells.sure] = True
        self.passes += 1
        self.widest = float(np.max(self.hi[n - 1] - self.lo[n - 1]))
        return True, changed
