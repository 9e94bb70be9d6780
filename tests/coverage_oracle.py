"""The oracle of :func:`digslam.envs.explore.coverage_jit.cover_step`, the ground-truth coverage kernel
without block skipping: the same decisions cell by cell over the whole window, with no block skipping
(``tests/envs/explore/test_coverage.py`` checks the two mark the same cells, bit for bit; the numpy
brute force of that file checks this one).

:func:`cover_kernel` turns the cone-edge bearings into world bearings, orders them by
:func:`~digslam.envs.explore.coverage_jit.pseudo_angle` and marks every free, not yet seen cell of the
window whose centre lies strictly closer than the radius of its bearing's interval: the cells nearer than
the smallest radius first, then each interval of a larger radius over the bounding box of its sector.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from digslam.envs.explore.coverage_jit import NB, pseudo_angle
from digslam.observer.core.angles_jit import axes_in
from digslam.observer.core.scalar_jit import njit


class CoverGrid(NamedTuple):
    """The raster :func:`cover_kernel` marks.

    Attributes:
        free, seen: Boolean rasters ``(ny, nx)``; ``seen`` is updated in place.
        xs, ys: Cell-centre coordinates ``(nx,)``, ``(ny,)``, increasing.
    """

    free: np.ndarray
    seen: np.ndarray
    xs: np.ndarray
    ys: np.ndarray


class ConeReach(NamedTuple):
    """How far the sensors see on each angular interval between cone edges (robot frame).

    Attributes:
        breaks: Cone-edge bearings in the robot frame, in ``[0, 2 pi)``, sorted, starting at 0, ``(B,)``.
        cover: ``(B, n)``: which sensors cover the interval that starts at each break.
        ranges: True range per sensor ``(n,)`` (``inf`` without echo).
        r_max: Maximum ranges ``(n,)``; a sensor senses up to ``min(range, r_max)``.
    """

    breaks: np.ndarray
    cover: np.ndarray
    ranges: np.ndarray
    r_max: np.ndarray


class _Scan(NamedTuple):
    """What :func:`_scan` reads: the raster, the window of rows ``i0:i1`` and columns ``j0:j1``, the sensor
    position, the cell sides (``inf`` for a single row or column) and the bearing intervals (their starts
    ``ws`` in pseudo-angle order and the lookup table ``tab`` over ``NB`` bins)."""

    grid: CoverGrid
    i0: int
    i1: int
    j0: int
    j1: int
    x: float
    y: float
    resx: float
    resy: float
    ws: np.ndarray
    tab: np.ndarray


@njit
def cover_kernel(grid: CoverGrid, i0: int, i1: int, j0: int, j1: int, x: float, y: float, th: float,
                 cones: ConeReach) -> int:  # fmt: skip
    """Mark the cells ``[i0:i1, j0:j1]`` of ``grid`` sensed from ``(x, y, th)`` in ``grid.seen``; return
    how many are new. ``cones``: the sensed radius per bearing interval (:class:`ConeReach`).
    """
    breaks, cover, ranges, r_max = cones.breaks, cones.cover, cones.ranges, cones.r_max
    xs, ys = grid.xs, grid.ys
    B, n = cover.shape
    two_pi = 2 * np.pi
    world, rad, wrad = np.empty(B), np.zeros(B), np.empty(B)
    for b in range(B):
        wrad[b] = np.mod(breaks[b] + th, two_pi)
        world[b] = pseudo_angle(math.cos(wrad[b]), math.sin(wrad[b]))
        r = 0.0
        for s in range(n):
            if cover[b, s]:
                r = max(r, ranges[s] if ranges[s] < r_max[s] else r_max[s])
        rad[b] = r
    order = np.arange(B)  # stable insertion sort by pseudo-angle (B is small)
    for b in range(1, B):
        o, q = order[b], b
        while q > 0 and world[order[q - 1]] > world[o]:
            order[q] = order[q - 1]
            q -= 1
        order[q] = o
    ws, r2, wr = world[order], rad[order] * rad[order], wrad[order]
    r2min = r2.min()
    # Lookup table of the interval index over NB bins of pseudo-angle [q / 64, (q + 1) / 64]: exact where
    # no bound lies in a bin (the interval is the same for every bearing in it), -2 (search) where one does.
    tab = np.empty(NB, dtype=np.int64)
    c = 0
    while c < B and ws[c] <= 0.0:
        c += 1
    c_lo = c
    for q in range(NB):
        hi = (q + 1) / 64.0
        while c < B and ws[c] <= hi:
            c += 1
        tab[q] = (c_lo - 1 if c_lo > 0 else B - 1) if c == c_lo else -2  # c_lo = #(ws <= q / 64)
        c_lo = c
    resx = (xs[xs.shape[0] - 1] - xs[0]) / (xs.shape[0] - 1) if xs.shape[0] > 1 else math.inf  # one column:
    resy = (ys[ys.shape[0] - 1] - ys[0]) / (ys.shape[0] - 1) if ys.shape[0] > 1 else math.inf  # no cut needed
    w = _Scan(grid, i0, i1, j0, j1, x, y, resx, resy, ws, tab)
    # Cells nearer than the smallest radius are sensed whatever their bearing.
    rm = math.sqrt(r2min)
    count = _scan(w, -rm, rm, -rm, rm, r2min, -1, r2min)
    # Then each interval of a larger radius, over the bounding box of its sector (cells of other intervals
    # in the box are left to their own interval).
    for b in range(B):
        if r2[b] <= r2min:
            continue
        R = math.sqrt(r2[b])
        a0, a1 = wr[b], (wr[b + 1] if b + 1 < B else wr[0] + two_pi)
        xlo, xhi = min(0.0, R * math.cos(a0), R * math.cos(a1)), max(0.0, R * math.cos(a0), R * math.cos(a1))
        ylo, yhi = min(0.0, R * math.sin(a0), R * math.sin(a1)), max(0.0, R * math.sin(a0), R * math.sin(a1))
        east, north, west, south = axes_in(a0, a1)  # the axis directions inside the sector
        if east:
            xhi = max(xhi, R)
        if north:
            yhi = max(yhi, R)
        if west:
            xlo = min(xlo, -R)
        if south:
            ylo = min(ylo, -R)
        count += _scan(w, xlo, xhi, ylo, yhi, r2[b], b, r2min)
    return count


@njit
def _scan(w: _Scan, xlo: float, xhi: float, ylo: float, yhi: float, r2b: float, b: int, r2min: float) -> int:
    """Mark the free, unseen cells of the box ``[xlo, xhi] x [ylo, yhi]`` (relative to the pose, widened by
    two cells) closer than ``sqrt(r2b)``: all of them if ``b < 0``, else those of bearing interval ``b``
    beyond ``sqrt(r2min)``."""
    free, seen, xs, ys = w.grid.free, w.grid.seen, w.grid.xs, w.grid.ys
    x, y, resx, resy, ws, tab = w.x, w.y, w.resx, w.resy, w.ws, w.tab
    B = ws.size
    ia = max(w.i0, int(math.floor((y + ylo - ys[0]) / resy)) - 2)
    ib = min(w.i1, int(math.floor((y + yhi - ys[0]) / resy)) + 3)
    ja = max(w.j0, int(math.floor((x + xlo - xs[0]) / resx)) - 2)
    jb = min(w.j1, int(math.floor((x + xhi - xs[0]) / resx)) + 3)
    count = 0
    for i in range(ia, ib):
        vy = ys[i] - y
        for j in range(ja, jb):
            if not free[i, j] or seen[i, j]:
                continue
            vx = xs[j] - x
            d2 = vx * vx + vy * vy
            if not d2 < r2b:
                continue
            if b >= 0:
                if d2 < r2min:
                    continue
                p = pseudo_angle(vx, vy)
                k = tab[min(int(p * 64.0), NB - 1)]
                if k == -2:  # k = #(ws <= p) - 1 (np.searchsorted side="right" counts the ws <= p)
                    k = np.searchsorted(ws, p, side="right") - 1
                    if k < 0:  # before the first bound: the last interval
                        k = B - 1
                if k != b:
                    continue
            seen[i, j] = True
            count += 1
    return count


@njit
def cover_update(free: np.ndarray, seen: np.ndarray, xs: np.ndarray, ys: np.ndarray, win: np.ndarray,
                 pose: np.ndarray, breaks: np.ndarray, cover: np.ndarray, ranges: np.ndarray,
                 r_max: np.ndarray) -> int:  # fmt: skip
    """:func:`cover_kernel` on the window of cells within reach of ``pose`` ``(x, y, theta)``: ``win`` is
    ``(x0, y0, dx, dy, kx, ky)``, the grid's lower-left corner, its cell sides and the reach in cells; the
    window is the ``(2 ky + 1) x (2 kx + 1)`` cells around the pose's cell (one call per step, no Python
    arithmetic), narrowed to this step's farthest reading: no cell centre beyond ``max_s min(range_s,
    r_max_s)`` can be marked."""
    x, y, th = pose[0], pose[1], pose[2]
    ny, nx = free.shape
    far = 0.0
    for s in range(ranges.shape[0]):
        far = max(far, min(ranges[s], r_max[s]))
    kx = min(int(win[4]), int(math.ceil(far / win[2])) + 1)
    ky = min(int(win[5]), int(math.ceil(far / win[3])) + 1)
    ic, jc = int(math.floor((y - win[1]) / win[3])), int(math.floor((x - win[0]) / win[2]))
    i0, i1, j0, j1 = max(ic - ky, 0), min(ic + ky + 1, ny), max(jc - kx, 0), min(jc + kx + 1, nx)
    return cover_kernel(CoverGrid(free, seen, xs, ys), i0, i1, j0, j1, x, y, th,
                        ConeReach(breaks, cover, ranges, r_max))  # fmt: skip


__all__ = ["ConeReach", "CoverGrid", "cover_kernel", "cover_update"]
