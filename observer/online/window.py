"""Windowed kernels of the online Dig-SLAM filter (thesis §6.4, Eq. 6.21–6.22; explored zone of App. B).

Each step of the online filter only touches the cells within sensor reach of the current pose box.
:class:`WindowDigMap` is a :class:`~.digmap.DigMap` whose digging runs the compiled cell kernels of
:mod:`.dig_jit` on the window of each reading (the same proofs as :meth:`DigMap.dig_disks` and
:meth:`DigMap.dig_sectors`, outward rounded), with a clearance lower bound computed on a window
(:meth:`WindowDigMap.clearance_window`: cells outside the window count as *not* free, which only lowers
distances, so the bound stays a lower bound; for the few cells of a pose box,
:meth:`WindowDigMap.clearance_cells` takes the same minimum directly, compiled) and the impact contractor of
Eq. 6.22 for one pose box (:meth:`WindowDigMap.contract_box`, :func:`.pose_jit.contract`).

:func:`mark_possibly_sensed` grows the outer explored zone ``Z⁺`` (Eq. B.5): a cell is marked unless it is
*proved* to miss every sensed sector ``x + R(ψ)·{ρ <= r⁺, |θ - α| <= γ}`` for ``x ∈ [x]``, ``ψ ∈ [ψ]``:
either its relative box ``c - [x]`` (outward rounded) misses the closed disk ``ρ <= r⁺``, or, for a cone of
aperture at most ``π/2``, it lies strictly on the outer side of one of the cone's edges, or of an axis
that bounds the cone (:func:`.mark_jit.mark_cells`). The certainly sensed cells (``Z⁻``) are exactly the
dug cells: a cell is dug when it lies in ``x + Z⁻`` for every pose.

Rounding: every bound goes through the outward-rounded scalar kernels of
:mod:`digslam.observer.core.scalar_jit` (one-ulp steps of each correctly rounded operation, libm
``cos``/``sin`` widened by ``LIBM_ULPS`` ulps).

>>> g = Grid((-2.0, -2.0), (2.0, 2.0), (8, 8))
>>> maybe = np.zeros(g.shape, bool)
>>> mark_possibly_sensed(g, maybe, np.zeros(2), np.zeros(2), 0.0, 0.0, np.array([0.0]),
...                      np.array([np.pi / 8]), np.array([1.2]))
>>> maybe.astype(int)[3:5].tolist()          # a cone towards +x from the origin
[[0, 0, 0, 1, 1, 1, 1, 0], [0, 0, 0, 1, 1, 1, 1, 0]]
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right

import numpy as np
from scipy.ndimage import distance_transform_edt

from digslam.observer.core import rounding as rnd
from digslam.observer.online import pose_jit
from digslam.observer.online.dig_jit import dig_batch
from digslam.observer.online.dig_types import GridFrame, PoseBox, SectorBatch
from digslam.observer.online.mark_jit import mark_batch
from digslam.observer.record.grid import Grid
from digslam.observer.slam.digmap import EDT_SLACK, DigMap

__all__ = ["WindowDigMap", "grid_frame", "mark_possibly_sensed"]


def _slack(grid: Grid) -> tuple[float, float]:
    """``keep = 1 - EDT_SLACK`` and ``off = diag + EDT_SLACK·span`` of the clearance bound."""
    dx, dy = grid.cell_size
    diag = float(np.hypot(dx, dy)) * (1 + EDT_SLACK)
    span = max(grid.hi[0] - grid.lo[0], grid.hi[1] - grid.lo[1])
    return 1 - EDT_SLACK, diag + EDT_SLACK * span


def grid_frame(grid: Grid) -> GridFrame:
    """The :class:`.dig_types.GridFrame` of ``grid`` for the online kernels: writeable float64 copies of its
    exact cell bounds (``xs``, ``ys``, ``nys = -ys``) and the constants ``keep = 1 - EDT_SLACK``,
    ``off = diag + EDT_SLACK·span`` of the clearance bound."""
    xs, ys = (np.array(v, dtype=np.float64) for v in (grid.xs, grid.ys))
    keep, off = _slack(grid)
    return GridFrame(xs, ys, -ys, float(keep), float(off))


class WindowDigMap(DigMap):
    """A :class:`DigMap` whose per-step operations stay inside a window of the grid.

    Digging tests only the cells of each reading's window not already dug, with the compiled kernels of
    :mod:`.dig_jit` (the same claims as :meth:`DigMap.dig_sectors`: every point of the cell lies in the
    cone, strictly inside the open disk, for every pose of the box).
    """

    def __init__(self, grid: Grid) -> None:
        super().__init__(grid)
        self._xs, self._nys = grid.xs.tolist(), (-grid.ys).tolist()
        #: The grid as the online kernels read it (:func:`grid_frame`, :class:`.dig_types.GridFrame`).
        self.frame = grid_frame(grid)
        self.xs, self.ys, self.nys = self.frame.xs, self.frame.ys, self.frame.nys
        self.keep, self.off = self.frame.keep, self.frame.off

    def win(self, lo: np.ndarray, hi: np.ndarray) -> tuple[int, int, int, int]:
        """:meth:`Grid.window` of one box ``(2,)``, as Python ints (bisection on the exact cell bounds)."""
        ny, nx = self.grid.shape
        c0 = min(max(bisect_left(self._xs, float(lo[0])) - 1, 0), nx)
        c1 = min(max(bisect_right(self._xs, float(hi[0])), c0), nx)
        r0 = min(max(bisect_left(self._nys, -float(hi[1])) - 1, 0), ny)
        r1 = min(max(bisect_right(self._nys, -float(lo[1])), r0), ny)
        return r0, r1, c0, c1

    def dig_disks(self, pos_lo: np.ndarray, pos_hi: np.ndarray, r: np.ndarray) -> None:
        """:meth:`DigMap.dig_disks` on each disk's window: a cell is dug when its farthest point from the
        box (outward rounded) is strictly closer than ``r`` (:func:`.dig_jit.dig_cells`)."""
        lo, hi, r = self._check(pos_lo, pos_hi, r)
        z = np.zeros(r.size)
        batch = SectorBatch(np.ascontiguousarray(lo), np.ascontiguousarray(hi), z, z, z, z, r,
                            np.ones(r.size, dtype=bool))  # fmt: skip
        dig_batch(self.free, self.free, self.frame, batch)

    def dig_sectors(self, pos_lo: np.ndarray, pos_hi: np.ndarray, psi_lo: np.ndarray, psi_hi: np.ndarray,
                    alpha: np.ndarray, gamma: np.ndarray, r: np.ndarray) -> None:  # fmt: skip
        """:meth:`DigMap.dig_sectors` (same narrowed cones ``θ₁ = ψ⁺ + α - γ``, ``θ₂ = ψ⁻ + α + γ``, rounded
        inwards; a cone wider than ``π`` split in two) on the cells of each cone's window not yet dug."""
        lo, hi, r = self._check(pos_lo, pos_hi, r)
        psi_lo, psi_hi, alpha, gamma = (np.asarray(v, dtype=np.float64).ravel() for v in
                                        (psi_lo, psi_hi, alpha, gamma))  # fmt: skip
        if not (psi_lo.shape == psi_hi.shape == alpha.shape == gamma.shape == r.shape):
            raise ValueError("psi_lo, psi_hi, alpha, gamma: expected one value per pose box")
        batch = SectorBatch(np.ascontiguousarray(lo), np.ascontiguousarray(hi), psi_lo, psi_hi, alpha, gamma,
                            r, np.zeros(r.size, dtype=bool))  # fmt: skip
        dig_batch(self.free, self.free, self.frame, batch)

    def clearance_window(self, r0: int, r1: int, c0: int, c1: int) -> np.ndarray:
        """Lower bound on ``dist(p, comp M⁻)`` for the cells ``[r0:r1, c0:c1]`` (see :meth:`clearance_lower`).

        The cells around the window are taken as not free: for a cell of the window, clamping the index of
        any cell outside it onto that ring moves it no farther, so the distance transform only decreases.
        """
        dx, dy = self.grid.cell_size
        pad = np.zeros((r1 - r0 + 2, c1 - c0 + 2), dtype=bool)
        sub = self.free[r0:r1, c0:c1]
        pad[1:-1, 1:-1] = sub
        d = distance_transform_edt(pad, sampling=(dy, dx))[1:-1, 1:-1]
        low = rnd.step_down(d * self.keep - self.off)
        return np.where(sub, np.maximum(low, 0.0), 0.0)

    def clearance_cells(self, b0: int, b1: int, a0: int, a1: int, window: tuple[int, int, int, int]
                        ) -> np.ndarray:  # fmt: skip
        """:meth:`clearance_window` of ``window`` restricted to the cells ``[b0:b1, a0:a1]`` (inside it).

        The centre distance ``D`` to the nearest not-free cell of the window (or of the ring around it,
        straight across) is a direct minimum over those cells (compiled,
        :func:`.pose_jit.clearance_cells`), with the same bound ``D(1 - EDT_SLACK) - diag``.
        """
        w0, w1, v0, v1 = window
        return pose_jit.clearance_cells(self.free, self.frame, (b0, b1, a0, a1), (w0, w1, v0, v1))

    def contract_box(self, lo: np.ndarray, hi: np.ndarray, r_hi: float) -> tuple[np.ndarray, np.ndarray]:
        """Eq. 6.22 for one pose box: keep the hull of the cells with ``clearance <= r⁺`` (exact cell bounds).

        Returns the box unchanged when it leaves the frame or ``r⁺`` is infinite, and ``[+inf, -inf]``
        when no cell of the box is feasible.
        """
        (gx0, gy0), (gx1, gy1) = self.grid.lo, self.grid.hi
        x0, y0, x1, y1, r_hi = float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]), float(r_hi)
        if not (math.isfinite(r_hi) and gx0 <= x0 <= x1 <= gx1 and gy0 <= y0 <= y1 <= gy1):
            return lo, hi
        c = pose_jit.contract(self.free, self.frame, x0, y0, x1, y1, r_hi)
        return np.array(c[:2]), np.array(c[2:])


def mark_possibly_sensed(
    grid: Grid,
    maybe: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    psi_lo: float,
    psi_hi: float,
    alpha: np.ndarray,
    gamma: np.ndarray,
    r_hi: np.ndarray,
) -> None:
    """Mark in ``maybe`` (in place) every cell not proved outside all the sensed sectors of one pose box.

    Args:
        grid: the cells of ``maybe``.
        maybe: ``(ny, nx)`` bool, the cells possibly sensed so far (only cells still False are tested).
        lo, hi: ``(2,)`` the pose box.
        psi_lo, psi_hi: the heading interval.
        alpha, gamma, r_hi: ``(n,)`` cone directions, half-apertures and sensed ranges ``r⁺``.
    """
    if maybe.shape != grid.shape or maybe.dtype != np.bool_ or not maybe.flags.c_contiguous:
        raise ValueError(f"maybe: expected a C-contiguous bool array of shape {grid.shape}")
    alpha, gamma, r_hi = (np.ascontiguousarray(v, dtype=np.float64).ravel() for v in (alpha, gamma, r_hi))
    if not (alpha.shape == gamma.shape == r_hi.shape):
        raise ValueError("alpha, gamma, r_hi: expected one value per sensor")
    lo, hi = np.asarray(lo, dtype=np.float64).ravel(), np.asarray(hi, dtype=np.float64).ravel()
    box = PoseBox(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]), float(psi_lo), float(psi_hi))
    mark_batch(maybe, grid_frame(grid), box, alpha, gamma, r_hi)
