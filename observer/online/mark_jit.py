"""Compiled kernels of the online filter's possibly sensed zone ``Z⁺`` (App. B, Eq. B.5) and of one step's
readings (§6.4, Eq. 6.21 then B.5), outward rounded with :mod:`digslam.observer.core.scalar_jit`.

:func:`mark_cells` grows the outer explored zone: a cell stays unmarked only when it is *proved* to miss
the widened sector ``x + {ρ <= r⁺, θ ∈ [ψ⁻ + α - γ, ψ⁺ + α + γ]}`` (angles rounded outwards) for every
pose ``x ∈ [x]``: the nearest distance of its relative box ``c - [x]`` (rounded down) exceeds ``r⁺``
(rounded up), or, for an aperture at most ``π/2``, the box lies strictly outside one cone edge (upper bound
of the cross product ``< 0``) or strictly beyond an axis that bounds both edges (``cos``/``sin`` enclosures
of one sign). Only the cells of the window of the sector's bounding box are tested: the sector lies in the
box of its apex, its arc ends and the axis points of its arc (shifted by the pose box), and the two cells
of padding dwarf the float error of that box, so a cell outside the window misses the sector. Not proved
out means marked: a doubt never makes a cell dark.

:func:`dig_and_mark` runs one step: :func:`.dig_jit.dig_reading` for each reading's free range, then
:func:`mark_cells` for its upper range, sharing the per-row / per-column bounds of the pose box.
:func:`dig_and_mark_q` is the same step robust to at most ``q`` outliers among the step's readings
(§2.6.2): a cell is dug where ``q + 1`` readings prove it free, ``Z⁺`` grows with the maximum ranges.
The readings come as a :class:`.dig_types.StepRecord` (only its readings are read here).

>>> from digslam.observer.online.window import grid_frame
>>> from digslam.observer.record.grid import Grid
>>> g = Grid((-2.0, -2.0), (2.0, 2.0), (8, 8))
>>> maybe = np.zeros(g.shape, bool)
>>> mark_cells(maybe, grid_frame(g), PoseBox(0.0, 0.0, 0.0, 0.0, 0.0, 0.0), 0.0, np.pi / 8, 1.2)
>>> maybe.astype(int)[3:5].tolist()          # a cone towards +x from the origin
[[0, 0, 0, 1, 1, 1, 1, 0], [0, 0, 0, 1, 1, 1, 1, 0]]
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.grid_jit import window
from digslam.observer.core.rounding import HALF_PI_DOWN, PI_DOWN
from digslam.observer.core.scalar_jit import add_dn, add_up, imul_hi, imul_lo, mul_up, njit, sub_dn, sub_up
from digslam.observer.online.dig_jit import (
    box_ok,
    cone_window,
    dig_reading,
    edge_direction,
    reach_axes,
    union,
)
from digslam.observer.online.dig_types import CellAxes, CellSets, GridFrame, PoseBox, StepRecord
from digslam.observer.online.mount_jit import apex, mount_kind

__all__ = ["mark_cells", "mark_batch", "dig_and_mark", "dig_and_mark_q"]


@njit
def _mark(maybe: np.ndarray, grid: GridFrame, box: PoseBox, alpha: float, gamma: float, r: float,
          axes: CellAxes) -> tuple[int, int, int, int]:  # fmt: skip
    """:func:`mark_cells` on shared :func:`.dig_jit.reach_axes` (their window must hold the reading's
    window); returns the window ``(r0, r1, c0, c1)`` of the cells it marked (empty: ``r0 >= r1``)."""
    if not (math.isfinite(r) and r > 0.0):
        return 0, 0, 0, 0
    xs, nys = grid.xs, grid.nys
    ax, ay, R0, C0 = axes.cols, axes.rows, axes.row0, axes.col0
    t1, t2 = sub_dn(add_dn(box.psi_lo, alpha), gamma), add_up(add_up(box.psi_hi, alpha), gamma)
    narrow = math.isfinite(t1) and math.isfinite(t2) and sub_up(t2, t1) <= HALF_PI_DOWN
    pad = 2.0 * max(xs[1] - xs[0], -nys[1] + nys[0])
    e1, e2 = edge_direction(t1), edge_direction(t2)
    c1l, c1h, s1l, s1h = e1
    c2l, c2h, s2l, s2h = e2
    if narrow:
        r0, r1, c0, c1 = cone_window(grid, box, t1, t2, r, pad, e1, e2)
    else:
        r0, r1, c0, c1 = window(xs, nys, box.x_lo - r - pad, box.y_lo - r - pad, box.x_hi + r + pad,
                                box.y_hi + r + pad)  # fmt: skip
    r0, r1 = max(r0, R0), min(r1, R0 + ay.shape[1])
    c0, c1 = max(c0, C0), min(c1, C0 + ax.shape[1])
    if r0 >= r1 or c0 >= c1:
        return 0, 0, 0, 0
    r2 = mul_up(r, r)
    u0, u1, v0, v1 = r1, r0, c1, c0  # the window of the marked cells
    # a cone of aperture < π whose two edges lie in a closed half-plane lies in it
    right, left = c1l >= 0.0 and c2l >= 0.0, c1h <= 0.0 and c2h <= 0.0
    top, bottom = s1l >= 0.0 and s2l >= 0.0, s1h <= 0.0 and s2h <= 0.0
    n = c1 - c0
    sx1, sx2, out_col = np.zeros(n), np.zeros(n), np.zeros(n, dtype=np.bool_)
    xl, xh, mx2 = ax[0, c0 - C0 : c1 - C0], ax[1, c0 - C0 : c1 - C0], ax[3, c0 - C0 : c1 - C0]
    if narrow:
        for k in range(n):
            sx1[k], sx2[k] = imul_lo(s1l, s1h, xl[k], xh[k]), imul_hi(s2l, s2h, xl[k], xh[k])
            out_col[k] = (right and xh[k] < 0.0) or (left and xl[k] > 0.0)
    for i in range(r0, r1):
        dyl, dyh, my2 = ay[0, i - R0], ay[1, i - R0], ay[3, i - R0]
        if my2 > r2 or (narrow and ((top and dyh < 0.0) or (bottom and dyl > 0.0))):
            continue
        cy1 = cy2 = 0.0
        if narrow:
            cy1, cy2 = imul_hi(c1l, c1h, dyl, dyh), imul_lo(c2l, c2h, dyl, dyh)
        mr = maybe[i, c0:c1]  # a row slice indexed from 0 (no wraparound checks)
        for k in range(n):
            if mr[k] or mx2[k] + my2 > r2:  # nearest point beyond r⁺ (exact: monotone rounding)
                continue
            # max over the box of cross(e₁, p) < 0, or of cross(p, e₂) < 0: strictly outside an edge
            if narrow and (cy1 < sx1[k] or sx2[k] < cy2 or out_col[k]):
                continue
            mr[k] = True
            u0, u1, v0, v1 = min(u0, i), max(u1, i + 1), min(v0, c0 + k), max(v1, c0 + k + 1)
    return u0, u1, v0, v1


@njit
def mark_cells(
    maybe: np.ndarray, grid: GridFrame, box: PoseBox, alpha: float, gamma: float, r: float
) -> None:
    """Mark in ``maybe`` every cell not proved outside the sensed sector of one reading (direction
    ``alpha``, half-aperture ``gamma``, range ``<= r``) from ``box``."""
    if not (box_ok(box) and math.isfinite(r) and r > 0.0):
        return
    _mark(maybe, grid, box, alpha, gamma, r, reach_axes(grid, box, r))


@njit
def mark_batch(maybe: np.ndarray, grid: GridFrame, box: PoseBox, alpha: np.ndarray, gamma: np.ndarray,
               r: np.ndarray) -> None:  # fmt: skip
    """:func:`mark_cells` for each reading ``k`` of one pose box."""
    for k in range(r.size):
        mark_cells(maybe, grid, box, alpha[k], gamma[k], r[k])


@njit
def dig_and_mark(cells: CellSets, grid: GridFrame, box: PoseBox, step: StepRecord, mark: bool
                 ) -> tuple[int, int, int, int]:  # fmt: skip
    """One step's readings from one pose box: dig each free range ``min(y⁻, r_max)`` (``gamma >= π⁻`` is
    the omnidirectional disk); with ``mark``, grow ``Z⁺`` with ``min(y⁺, r_max)``. ``step``: a
    :class:`.dig_types.StepRecord` (its ``alpha``, ``gamma``, ``r_max`` and ``ranges``). The per-row and
    per-column bounds (:func:`.dig_jit.reach_axes`) are computed once for all the readings; returns the
    smallest window ``(r0, r1, c0, c1)`` holding every cell changed (``(0, 0, 0, 0)`` when none).
    :func:`dig_and_mark_q` with ``q = 0``."""
    return dig_and_mark_q(cells, grid, box, step, mark, 0)


@njit
def _settle(cells: CellSets, need: int) -> tuple[int, int, int, int]:
    """Dig (``free``, ``sure``) the cells of ``cells.listed`` (every cell counted in the step) counted at
    least ``need`` times, then clear their counts and stamps and the list; returns the window of the dug
    cells."""
    free, sure, cnt, lst = cells.free, cells.sure, cells.count, cells.listed
    nx = free.shape[1]
    u0, u1, v0, v1 = free.shape[0], 0, nx, 0
    for m in range(1, lst[0] + 1):
        i, j = lst[m] // nx, lst[m] % nx
        if cnt[0, i, j] >= need:
            free[i, j] = True
            sure[i, j] = True
            u0, u1, v0, v1 = min(u0, i), max(u1, i + 1), min(v0, j), max(v1, j + 1)
        cnt[0, i, j] = 0
        cnt[1, i, j] = 0
    lst[0] = 0
    return u0, u1, v0, v1


@njit
def _dig_and_mark_each(cells: CellSets, grid: GridFrame, box: PoseBox, step: StepRecord, mark: bool, q: int
                       ) -> tuple[int, int, int, int]:  # fmt: skip
    """:func:`dig_and_mark_q` for readings of different mounts or slacks: each reading digs (counts, with
    ``q > 0``) and marks from its own apex box (:func:`.mount_jit.apex`), on its own row and column bounds."""
    alpha, gamma, r_max, rng = step.alpha, step.gamma, step.r_max, step.ranges
    w = (0, 0, 0, 0)
    dug = (0, 0, 0, 0)
    n = alpha.size
    for k in range(n):
        b = apex(box, step.mount[k, 0], step.mount[k, 1], step.slack[k, 0], step.slack[k, 1])
        r_dig = min(rng[k, 0], r_max[k])
        rm = min(rng[k, 1], r_max[k]) if q == 0 else r_max[k]
        reach = 0.0
        for r in (r_dig, rm):
            if math.isfinite(r):
                reach = max(reach, r)
        axes = reach_axes(grid, b, reach)
        if q == 0:
            w = union(w, dig_reading(cells, grid, b, alpha[k], gamma[k], r_dig, gamma[k] >= PI_DOWN, axes, 0))
        elif n > q:
            dug = union(dug, dig_reading(cells, grid, b, alpha[k], gamma[k], r_dig, gamma[k] >= PI_DOWN, axes,
                                         k + 1))  # fmt: skip
        if mark:
            w = union(w, _mark(cells.maybe, grid, b, alpha[k], gamma[k], rm, axes))
    if q > 0 and dug[0] < dug[1] and dug[2] < dug[3]:
        w = union(w, _settle(cells, q + 1))
    return w


@njit
def dig_and_mark_q(cells: CellSets, grid: GridFrame, box: PoseBox, step: StepRecord, mark: bool, q: int
                   ) -> tuple[int, int, int, int]:  # fmt: skip
    """:func:`dig_and_mark` robust to at most ``q`` outliers among the ``n`` readings of this step.

    ``q = 0``: every reading digs its free range (Eq. 6.21) and marks ``Z⁺`` with ``min(y⁺, r_max)``
    (``cells.count`` and ``cells.listed`` unused).

    ``q > 0`` (thesis §2.6.2, the q-relaxed intersection, Eq. 2.54, applied to the readings of ONE step):
    each reading's free-range proof only counts, in ``cells.count`` (the counted cells listed in
    ``cells.listed``, :class:`.dig_types.CellSets`), and a cell is dug (``M⁻`` and certainly sensed ``Z⁻``)
    only where ``q + 1`` readings of the step prove it free: one of them at least is an inlier, so the cell
    is free and was sensed. With ``q >= n`` nothing is dug. An outlier's upper range can be below the truth,
    so ``Z⁺`` is grown with ``r_max`` for every reading: the union over all the choices of at most
    ``q >= 1`` outliers (a true echo is within ``r_max``).

    Mounted cones and readings with a slack (:mod:`.mount_jit`) dig and mark from their apex box: one for
    the step when they share a mount and slack, else each its own (:func:`_dig_and_mark_each`).
    """
    if not box_ok(box):
        return 0, 0, 0, 0
    kind = mount_kind(step.mount, step.slack)
    if kind == 2:
        return _dig_and_mark_each(cells, grid, box, step, mark, q)
    if kind == 1:  # one apex box for every reading (:mod:`.mount_jit`)
        box = apex(box, step.mount[0, 0], step.mount[0, 1], step.slack[0, 0], step.slack[0, 1])
    alpha, gamma, r_max, rng = step.alpha, step.gamma, step.r_max, step.ranges
    reach = 0.0
    for k in range(alpha.size):
        rm = min(rng[k, 1], r_max[k]) if q == 0 else r_max[k]
        for r in (min(rng[k, 0], r_max[k]), rm):
            if math.isfinite(r):
                reach = max(reach, r)
    axes = reach_axes(grid, box, reach)
    w = (0, 0, 0, 0)
    if q == 0:
        for k in range(alpha.size):
            w = union(w, dig_reading(cells, grid, box, alpha[k], gamma[k], min(rng[k, 0], r_max[k]),
                                     gamma[k] >= PI_DOWN, axes, 0))  # fmt: skip
    elif alpha.size > q:  # with q >= n no cell can be proved by q + 1 readings
        c = (0, 0, 0, 0)
        for k in range(alpha.size):
            c = union(c, dig_reading(cells, grid, box, alpha[k], gamma[k], min(rng[k, 0], r_max[k]),
                                     gamma[k] >= PI_DOWN, axes, k + 1))  # fmt: skip
        if c[0] < c[1] and c[2] < c[3]:
            w = union(w, _settle(cells, q + 1))
    if mark:
        for k in range(alpha.size):
            rm = min(rng[k, 1], r_max[k]) if q == 0 else r_max[k]
            w = union(w, _mark(cells.maybe, grid, box, alpha[k], gamma[k], rm, axes))
    return w
