"""Compiled cell kernels of the online Dig-SLAM filter: digging ``M⁻`` (thesis §6.4, Eq. 6.21).

One step of :class:`~digslam.observer.online.observer.OnlineDigSlam` touches the cells within sensor reach of
the pose box ``[x]``. These kernels loop over those cells in machine code, each bound outward rounded with
:mod:`digslam.observer.core.scalar_jit`.
:func:`dig_cells` digs ``M⁻ := M⁻ ∪ g⁻¹_{[x]}(Z⁻)`` for one reading: a cell is dug when its relative box
``c - [x]`` (outward rounded) lies strictly inside the open disk ``ρ < r`` (farthest corner, squared
distance rounded up) and, for a cone, inside the narrowed cone ``θ ∈ [θ₁, θ₂]`` with ``θ₁ = ψ⁺ + α - γ``,
``θ₂ = ψ⁻ + α + γ`` (rounded inwards): for an aperture at most ``π`` that cone is
``{cross(e₁, p) >= 0} ∩ {cross(p, e₂) >= 0}``, bounded below on the box with interval products and ``e_k``
enclosed by widened ``cos``/``sin``; a wider cone is covered by two cones of aperture ``π⁻``. These are
the proofs of :meth:`.digmap.DigMap.dig_sectors` and :meth:`~.digmap.DigMap.dig_disks`; every dug cell is
also certainly sensed. The possibly sensed zone is in :mod:`.mark_jit`.

In the q-relaxed mode of the filter (at most ``q`` outliers among the readings of one step, thesis §2.6.2,
Eq. 2.54) a reading does not dig: :func:`dig_reading` with a reading stamp ``sid > 0`` counts, per cell, the
readings of the step that prove it free, and :func:`.mark_jit.dig_and_mark_q` digs the cells counted
``q + 1`` times (one of them at least is an inlier).

Skipping a cell never makes a false claim here (it is just not dug), so the windows are float estimates
padded by two cells; every claim is proved cell by cell.

The kernels take their inputs as the named tuples of :mod:`.dig_types` (:class:`~.dig_types.GridFrame`,
:class:`~.dig_types.CellSets`, :class:`~.dig_types.PoseBox`, :class:`~.dig_types.CellAxes`,
:class:`~.dig_types.SectorBatch`).

>>> from digslam.observer.online.window import grid_frame
>>> from digslam.observer.record.grid import Grid
>>> g = Grid((-2.0, -2.0), (2.0, 2.0), (8, 8))
>>> free, sure = np.zeros(g.shape, bool), np.zeros(g.shape, bool)
>>> dig_cells(free, sure, grid_frame(g), PoseBox(0.0, 0.0, 0.0, 0.0, 0.0, 0.0), 0.0, np.pi, 1.2, True)
>>> free.astype(int)[3:5].tolist()            # an omni disk of radius 1.2 around the origin
[[0, 0, 1, 1, 1, 1, 0, 0], [0, 0, 1, 1, 1, 1, 0, 0]]
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.angles_jit import sector_box
from digslam.observer.core.grid_jit import window
from digslam.observer.core.rounding import PI_DOWN
from digslam.observer.core.scalar_jit import (
    add_dn,
    add_up,
    imul_hi,
    imul_lo,
    mul_dn,
    mul_up,
    njit,
    sub_dn,
    sub_up,
    wdn,
    wup,
)
from digslam.observer.online.dig_types import CellAxes, CellSets, GridFrame, PoseBox, SectorBatch

__all__ = [
    "box_ok",
    "cell_size",
    "cone_window",
    "dig_batch",
    "dig_cells",
    "dig_reading",
    "edge_direction",
    "in_frame",
    "reach_axes",
    "union",
]


@njit(forceinline=True)
def cell_size(grid: GridFrame) -> tuple[float, float]:
    """The cell size ``(dx, dy)`` of ``grid``: its frame's sides over the numbers of columns and rows, which
    is ``Grid.cell_size`` to the bit (the same two operations on the same floats)."""
    xs, ys = grid.xs, grid.ys
    return (xs[xs.size - 1] - xs[0]) / (xs.size - 1), (ys[0] - ys[ys.size - 1]) / (ys.size - 1)


@njit(forceinline=True)
def in_frame(grid: GridFrame, x0: float, y0: float, x1: float, y1: float) -> bool:
    """Whether the box ``[x0, x1] × [y0, y1]`` is non-empty and lies in the frame of ``grid``."""
    xs, ys = grid.xs, grid.ys
    return xs[0] <= x0 <= x1 <= xs[xs.size - 1] and ys[ys.size - 1] <= y0 <= y1 <= ys[0]


@njit
def edge_direction(t: float) -> tuple[float, float, float, float]:
    """Enclosures ``(cos⁻, cos⁺, sin⁻, sin⁺)`` of the direction ``e(t) = (cos t, sin t)`` of a cone edge
    (libm's values widened by ``LIBM_ULPS`` ulps)."""
    c, s = math.cos(t), math.sin(t)
    return wdn(c), wup(c), wdn(s), wup(s)


@njit(forceinline=True)
def box_ok(box: PoseBox) -> bool:
    """Whether the position box of ``box`` is non-empty and finite."""
    x0, y0, x1, y1 = box.x_lo, box.y_lo, box.x_hi, box.y_hi
    return x0 <= x1 and y0 <= y1 and math.isfinite(x0 + y0 + x1 + y1)


@njit
def cone_window(grid: GridFrame, box: PoseBox, t1: float, t2: float, r: float, pad: float,
                e1: tuple[float, float, float, float], e2: tuple[float, float, float, float]
                ) -> tuple[int, int, int, int]:  # fmt: skip
    """Cells meeting the bounding box of ``[x] + {ρ <= r, θ ∈ [t1, t2]}`` plus ``pad``: rows and columns
    ``(r0, r1, c0, c1)`` (:func:`~digslam.observer.core.grid_jit.window`).

    The extreme points are the apex, the two edge ends ``r (c_k, s_k)`` (the lower ends of ``e1``, ``e2``,
    :func:`edge_direction` of ``t1``, ``t2``: within ``10⁻¹⁵`` of ``cos``, ``sin``) and the axis points
    ``r·(±1, 0)``, ``r·(0, ±1)`` of the directions inside ``[t1, t2]``
    (:func:`~digslam.observer.core.angles_jit.sector_box`, whose axes never miss one); ``pad`` (two cells)
    covers the rounding of these values.
    """
    ax0, ax1, ay0, ay1 = sector_box(r, t1, t2, e1[0], e1[2], e2[0], e2[2])
    return window(grid.xs, grid.nys, box.x_lo + ax0 - pad, box.y_lo + ay0 - pad, box.x_hi + ax1 + pad,
                  box.y_hi + ay1 + pad)  # fmt: skip


@njit
def _axes(grid: GridFrame, box: PoseBox, r0: int, r1: int, c0: int, c1: int) -> tuple[np.ndarray, np.ndarray]:
    """:attr:`~.dig_types.CellAxes.cols` of the columns ``c0:c1`` and :attr:`~.dig_types.CellAxes.rows` of the
    rows ``r0:r1``."""
    xs, ys = grid.xs, grid.ys
    ax, ay = np.empty((4, c1 - c0)), np.empty((4, r1 - r0))
    for j in range(c0, c1):
        lo, hi = sub_dn(xs[j], box.x_hi), sub_up(xs[j + 1], box.x_lo)
        far, near = max(-lo, hi), max(lo, -hi, 0.0)
        k = j - c0
        ax[0, k], ax[1, k], ax[2, k], ax[3, k] = lo, hi, mul_up(far, far), mul_dn(near, near)
    for i in range(r0, r1):
        lo, hi = sub_dn(ys[i + 1], box.y_hi), sub_up(ys[i], box.y_lo)
        far, near = max(-lo, hi), max(lo, -hi, 0.0)
        k = i - r0
        ay[0, k], ay[1, k], ay[2, k], ay[3, k] = lo, hi, mul_up(far, far), mul_dn(near, near)
    return ax, ay


@njit
def _dig_cone(cells: CellSets, grid: GridFrame, box: PoseBox, t1: float, t2: float, r: float, disk: bool,
              axes: CellAxes, sid: int) -> tuple[int, int, int, int]:  # fmt: skip
    """Dig the cells inside ``[x] + {ρ < r, θ ∈ [t1, t2]}`` (``disk``: the whole disk), ``t2 - t1 <= π``;
    ``axes``: :func:`reach_axes` of a window holding the reading's window. Returns the window
    ``(r0, r1, c0, c1)`` of the cells it dug (empty: ``r0 >= r1``).

    ``sid = 0`` digs (sets ``free`` and ``sure``). ``sid > 0`` (the q-relaxed mode, :func:`dig_reading` of
    reading ``sid - 1``) only counts: each proved cell not yet in ``M⁻`` gets ``count[0] += 1`` once per
    reading (``count[1]`` holds the reading that counted it last, so the two halves of a wide cone count
    once), a cell counted for the first time in the step is appended to ``listed``, and the window returned
    is that of the counted cells (:class:`~.dig_types.CellSets`).

    The bounds that depend on the column only (``p_x`` terms) or on the row only (``p_y`` terms) are
    computed once; each cell then compares them. A comparison ``a ≥ b`` of two bounds is exact, and so is
    ``fl(a + b) < c`` for a float ``c`` (round-to-nearest is monotone): no rounding is lost.
    """
    free, sure, cnt, lst = cells.free, cells.sure, cells.count, cells.listed
    xs, nys = grid.xs, grid.nys
    ax, ay, R0, C0 = axes.cols, axes.rows, axes.row0, axes.col0
    pad = 2.0 * max(xs[1] - xs[0], -nys[1] + nys[0])
    e1, e2 = edge_direction(t1), edge_direction(t2)
    c1l, c1h, s1l, s1h = e1
    c2l, c2h, s2l, s2h = e2
    if disk:
        r0, r1, c0, c1 = window(xs, nys, box.x_lo - r - pad, box.y_lo - r - pad, box.x_hi + r + pad,
                                box.y_hi + r + pad)  # fmt: skip
    else:
        r0, r1, c0, c1 = cone_window(grid, box, t1, t2, r, pad, e1, e2)
    r0, r1 = max(r0, R0), min(r1, R0 + ay.shape[1])
    c0, c1 = max(c0, C0), min(c1, C0 + ax.shape[1])
    if r0 >= r1 or c0 >= c1:
        return 0, 0, 0, 0
    r2 = mul_dn(r, r)
    u0, u1, v0, v1 = r1, r0, c1, c0  # the window of the dug cells
    n = c1 - c0
    sx1, sx2 = np.zeros(n), np.zeros(n)
    xl, xh, fx2 = ax[0, c0 - C0 : c1 - C0], ax[1, c0 - C0 : c1 - C0], ax[2, c0 - C0 : c1 - C0]
    if not disk:
        for k in range(n):
            sx1[k], sx2[k] = imul_hi(s1l, s1h, xl[k], xh[k]), imul_lo(s2l, s2h, xl[k], xh[k])
    for i in range(r0, r1):
        fy2 = ay[2, i - R0]
        if not fy2 < r2:
            continue
        cy1 = cy2 = 0.0
        if not disk:
            dyl, dyh = ay[0, i - R0], ay[1, i - R0]
            cy1, cy2 = imul_lo(c1l, c1h, dyl, dyh), imul_hi(c2l, c2h, dyl, dyh)
        fr, sr = free[i, c0:c1], sure[i, c0:c1]  # row slices indexed from 0 (no wraparound checks)
        if sid:
            cc, cs = cnt[0, i, c0:c1], cnt[1, i, c0:c1]
        else:
            cc = cs = cnt[0, 0, 0:0]
        for k in range(n):
            if fr[k] or not fx2[k] + fy2 < r2:  # strictly inside the open disk, farthest corner
                continue
            # min over the box of cross(e₁, p) = cos θ₁ p_y - sin θ₁ p_x >= 0, and of cross(p, e₂) >= 0
            if disk or (cy1 >= sx1[k] and sx2[k] >= cy2):
                if sid:
                    if cs[k] == sid:  # already counted for this reading (the other half of its cone)
                        continue
                    cs[k] = sid
                    if cc[k] == 0:
                        m = lst[0] + 1
                        lst[0], lst[m] = m, i * free.shape[1] + c0 + k
                    cc[k] += 1
                else:
                    fr[k] = True
                    sr[k] = True
                u0, u1, v0, v1 = min(u0, i), max(u1, i + 1), min(v0, c0 + k), max(v1, c0 + k + 1)
    return u0, u1, v0, v1


@njit
def dig_reading(cells: CellSets, grid: GridFrame, box: PoseBox, alpha: float, gamma: float, r: float,
                disk: bool, axes: CellAxes, sid: int) -> tuple[int, int, int, int]:  # fmt: skip
    """Eq. 6.21 for one reading (direction ``alpha``, half-aperture ``gamma``, free range ``r``; ``disk``:
    the open disk) from ``box``, on shared :func:`reach_axes` (their window must hold the reading's).

    Digs ``cells.free`` and ``cells.sure`` (``sid = 0``), or, in the q-relaxed mode (``sid > 0``, the
    reading's stamp), only counts the proved cells in ``cells.count`` and ``cells.listed``, once for the
    reading. The narrowed cone is ``[θ₁, θ₂] = [ψ⁺ + α - γ, ψ⁻ + α + γ]`` rounded inwards; one wider than
    ``π`` is covered by ``[θ₁, θ₁ + π⁻]`` and ``[θ₂ - π⁻, θ₂]``. Returns the window ``(r0, r1, c0, c1)``
    of the cells it dug or counted (empty: ``r0 >= r1``); ``r`` not finite or ``<= 0`` and empty cones dig
    nothing.
    """
    if not (math.isfinite(r) and r > 0.0):
        return 0, 0, 0, 0
    if disk:
        return _dig_cone(cells, grid, box, 0.0, 0.0, r, True, axes, sid)
    t1, t2 = sub_up(add_up(box.psi_hi, alpha), gamma), add_dn(add_dn(box.psi_lo, alpha), gamma)
    if not (math.isfinite(t1) and math.isfinite(t2) and t1 <= t2):
        return 0, 0, 0, 0
    if sub_up(t2, t1) > PI_DOWN:  # [θ₁, θ₁ + π⁻] and [θ₂ - π⁻, θ₂], both inside [θ₁, θ₂]
        t3, t4 = add_dn(t1, PI_DOWN), sub_up(t2, PI_DOWN)
        a = _dig_cone(cells, grid, box, t1, t3, r, False, axes, sid)
        b = _dig_cone(cells, grid, box, t4, t2, r, False, axes, sid)
        return union(a, b)
    return _dig_cone(cells, grid, box, t1, t2, r, False, axes, sid)


@njit(forceinline=True)
def union(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
    """Smallest window ``(r0, r1, c0, c1)`` holding the windows ``a`` and ``b`` (empty: ``r0 >= r1`` or
    ``c0 >= c1``)."""
    if a[0] >= a[1] or a[2] >= a[3]:
        return b
    if b[0] >= b[1] or b[2] >= b[3]:
        return a
    return min(a[0], b[0]), max(a[1], b[1]), min(a[2], b[2]), max(a[3], b[3])


@njit
def reach_axes(grid: GridFrame, box: PoseBox, r: float) -> CellAxes:
    """:class:`~.dig_types.CellAxes` of the window of the position box grown by ``r`` plus two cells, which
    holds the window of every reading of range ``<= r`` from ``box``."""
    xs, ys = grid.xs, grid.ys
    pad = 2.0 * max(xs[1] - xs[0], ys[0] - ys[1])
    r0, r1, c0, c1 = window(xs, grid.nys, box.x_lo - r - pad, box.y_lo - r - pad, box.x_hi + r + pad,
                            box.y_hi + r + pad)  # fmt: skip
    ax, ay = _axes(grid, box, r0, r1, c0, c1)
    return CellAxes(ax, ay, r0, c0)


@njit
def dig_cells(free: np.ndarray, sure: np.ndarray, grid: GridFrame, box: PoseBox, alpha: float, gamma: float,
              r: float, disk: bool) -> None:  # fmt: skip
    """Eq. 6.21 for one reading (free range ``r``) from the pose box ``box``.

    ``disk``: the omnidirectional sensor (the open disk; the heading, ``alpha``, ``gamma`` unused); empty
    boxes, ``r`` not finite or ``<= 0``, and empty narrowed cones dig nothing. ``free``, ``sure``: updated
    in place.
    """
    if not (box_ok(box) and math.isfinite(r) and r > 0.0):
        return
    cells = CellSets(free, sure, sure, np.zeros((2, 1, 1), np.int32), np.zeros(1, np.int32))
    dig_reading(cells, grid, box, alpha, gamma, r, disk, reach_axes(grid, box, r), 0)


@njit
def dig_batch(free: np.ndarray, sure: np.ndarray, grid: GridFrame, batch: SectorBatch) -> None:
    """:func:`dig_cells` for each reading ``k`` of ``batch``, from its own pose box."""
    b = batch
    for k in range(b.r.size):
        box = PoseBox(b.lo[k, 0], b.lo[k, 1], b.hi[k, 0], b.hi[k, 1], b.psi_lo[k], b.psi_hi[k])
        dig_cells(free, sure, grid, box, b.alpha[k], b.gamma[k], b.r[k], b.disk[k])
