"""Compiled kernel of the ground-truth coverage (:mod:`.coverage`: the reward of ``digslam/Explore-v0``, and
the ground truth the certified coverage is compared with, over the reachable free area).

The sensed radius is a step function of the world bearing: on each angular interval between cone edges,
the largest reach of the cones covering it. :func:`cover_step` turns the interval bounds into world
bearings, orders them by :func:`pseudo_angle` (a monotone stand-in for ``atan2``) and marks every free,
not yet seen cell of the window around the pose whose centre lies strictly closer than the radius of its
bearing's interval (bearings before the first bound fall in the last interval, which wraps around). Cells
nearer than the smallest radius are marked first; then each interval of a larger radius scans the bounding
box of its sector only, and decides each cell there through a lookup table of pseudo-angle bins (a binary
search in the bins that hold a bound), keeping the cells whose interval it is. It visits only the cells
still to cover: it keeps them in a raster beside ``seen`` with their counts per block of ``BLOCK x BLOCK``
cells, and skips the blocks with none left or none within reach, and the whole step when no cell left lies
within reach. Same decisions, bit for bit, as the kernel without block skipping (the oracle
``tests/coverage_oracle.py``), and as the numpy brute force of ``tests/envs/explore/test_coverage.py``
except for cell centres within rounding of a cone edge.

Example (one omnidirectional sensor of reach 0.12 at the centre of a 3 x 3 grid of 0.1 m cells; a second
update from the same pose finds nothing new)::

    >>> todo, seen = np.ones((3, 3), dtype=bool), np.zeros((3, 3), dtype=bool)
    >>> xs = ys = np.array([0.05, 0.15, 0.25])
    >>> geo = np.concatenate([[0.0, 0.0, 0.1, 0.1, 2, 2], xs, ys])   # corner, cell sides, reach in cells
    >>> cones = cone_table(np.array([0.0]), np.ones((1, 1), dtype=bool), np.array([0.12]))
    >>> pose, ranges, blocks = np.array([0.15, 0.15, 0.0]), np.array([np.inf]), todo_blocks(todo)
    >>> cover_step(todo, blocks, seen, geo, pose, cones, ranges), seen.astype(int).tolist()
    (5, [[0, 1, 0], [1, 1, 1], [0, 1, 0]])
    >>> cover_step(todo, blocks, seen, geo, pose, cones, ranges)
    0
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.angles_jit import sector_box
from digslam.observer.core.scalar_jit import njit

#: Bins of the per-step radius lookup table over pseudo-angles ``[0, 4)``.
NB = 256


@njit(forceinline=True)
def pseudo_angle(x: float, y: float) -> float:
    """A strictly increasing function of the bearing of ``(x, y)`` in ``[0, 2 pi)``, with values in ``[0, 4)``
    (the "diamond angle": one division, no libm call; 0 at the origin)."""
    if x == 0.0 and y == 0.0:
        return 0.0
    if y >= 0.0:
        return y / (x + y) if x >= 0.0 else 1.0 - x / (y - x)
    return 2.0 - y / (-x - y) if x < 0.0 else 3.0 + x / (x - y)


#: Side (cells) of the square blocks whose counts of cells still to cover let :func:`cover_step` skip them.
BLOCK = 8


def cone_table(breaks: np.ndarray, cover: np.ndarray, r_max: np.ndarray) -> np.ndarray:
    """The per-suite table :func:`cover_step` reads, ``(B + 1, n + 1)`` float64: in row ``b < B``, column 0
    the start ``breaks[b]`` of interval ``b`` (a cone-edge bearing in ``[0, 2 pi)`` relative to the heading,
    sorted, from 0; :meth:`.coverage.Coverage._angular_cover`) and column ``1 + s`` the maximum range of
    sensor ``s`` if it covers the interval (``cover[b, s]``), else 0 (maximum ranges are ``> 0``); row ``B``
    holds the maximum ranges ``r_max`` in columns ``1:``."""
    B, n = cover.shape
    r = np.asarray(r_max, dtype=np.float64)
    tab = np.zeros((B + 1, n + 1))
    tab[:B, 0] = breaks
    tab[:B, 1:] = np.where(cover, r[None, :], 0.0)
    tab[B, 1:] = r
    return tab


def todo_blocks(todo: np.ndarray) -> np.ndarray:
    """Counts ``(ceil(ny / BLOCK), ceil(nx / BLOCK))`` int64 of the True cells of ``todo`` per block."""
    ny, nx = todo.shape
    nby, nbx = -(-ny // BLOCK), -(-nx // BLOCK)
    pad = np.zeros((nby * BLOCK, nbx * BLOCK), dtype=np.int64)
    pad[:ny, :nx] = todo
    return np.ascontiguousarray(pad.reshape(nby, BLOCK, nbx, BLOCK).sum(axis=(1, 3)))


@njit(forceinline=True)
def _block_d2(blocks: np.ndarray, bi: int, bj: int, ra: int, rb: int, ca: int, cb: int, xs: np.ndarray,
              ys: np.ndarray, x: float, y: float) -> float:  # fmt: skip
    """``inf`` if block ``(bi, bj)`` has no cell left to cover, else a lower bound of the computed squared
    distance ``vx * vx + vy * vy`` of its cells ``[ra:rb, ca:cb]`` (rounded subtraction, squaring and
    addition are monotone, and ``fl(a - b) = -fl(b - a)``)."""
    if blocks[bi, bj] == 0:
        return math.inf
    mx = max(xs[ca] - x, 0.0, x - xs[cb - 1])
    my = max(ys[ra] - y, 0.0, y - ys[rb - 1])
    return mx * mx + my * my


@njit(forceinline=True)
def _box(i0: int, i1: int, j0: int, j1: int, x: float, y: float, xs: np.ndarray, ys: np.ndarray,
         resx: float, resy: float, xlo: float, xhi: float, ylo: float, yhi: float
         ) -> tuple[int, int, int, int]:  # fmt: skip
    """The cells ``[ia:ib, ja:jb]`` :func:`_scan_todo` visits for the box ``[xlo, xhi] x [ylo, yhi]``
    (relative to ``(x, y)``, widened by two cells, within the window ``[i0:i1, j0:j1]``)."""
    ia = max(i0, int(math.floor((y + ylo - ys[0]) / resy)) - 2)
    ib = min(i1, int(math.floor((y + yhi - ys[0]) / resy)) + 3)
    ja = max(j0, int(math.floor((x + xlo - xs[0]) / resx)) - 2)
    jb = min(j1, int(math.floor((x + xhi - xs[0]) / resx)) + 3)
    return ia, ib, ja, jb


@njit(forceinline=True)
def _any_todo(todo: np.ndarray, blocks: np.ndarray, ia: int, ib: int, ja: int, jb: int, xs: np.ndarray,
              ys: np.ndarray, x: float, y: float, r2b: float) -> bool:  # fmt: skip
    """Whether some cell of ``[ia:ib, ja:jb]`` still to cover lies nearer than ``sqrt(r2b)`` (the computed
    squared distance of :func:`_scan_todo`), visiting only the blocks :func:`_block_d2` does not rule out."""
    for bi in range(ia // BLOCK, (ib - 1) // BLOCK + 1):
        ra, rb = max(bi * BLOCK, ia), min(bi * BLOCK + BLOCK, ib)
        for bj in range(ja // BLOCK, (jb - 1) // BLOCK + 1):
            ca, cb = max(bj * BLOCK, ja), min(bj * BLOCK + BLOCK, jb)
            if not _block_d2(blocks, bi, bj, ra, rb, ca, cb, xs, ys, x, y) < r2b:
                continue
            for i in range(ra, rb):
                vy = ys[i] - y
                for j in range(ca, cb):
                    if todo[i, j]:
                        vx = xs[j] - x
                        if vx * vx + vy * vy < r2b:
                            return True
    return False


@njit
def _scan_todo(todo: np.ndarray, blocks: np.ndarray, seen: np.ndarray, xs: np.ndarray, ys: np.ndarray,
               ia: int, ib: int, ja: int, jb: int, x: float, y: float, r2b: float, b: int, r2min: float,
               ws: np.ndarray, tab: np.ndarray) -> int:  # fmt: skip
    """Mark the cells of ``[ia:ib, ja:jb]`` still to cover (``todo``) whose centre lies nearer than
    ``sqrt(r2b)``: all of them if ``b < 0``, else those of bearing interval ``b`` beyond ``sqrt(r2min)``;
    block by block, skipping the blocks with none left or none nearer than ``sqrt(r2b)`` (:func:`_block_d2`);
    ``seen``, ``todo`` and the counts ``blocks`` are updated. Returns the count."""
    B = ws.size
    count = 0
    for bi in range(ia // BLOCK, (ib - 1) // BLOCK + 1):
        ra, rb = max(bi * BLOCK, ia), min(bi * BLOCK + BLOCK, ib)
        for bj in range(ja // BLOCK, (jb - 1) // BLOCK + 1):
            ca, cb = max(bj * BLOCK, ja), min(bj * BLOCK + BLOCK, jb)
            if not _block_d2(blocks, bi, bj, ra, rb, ca, cb, xs, ys, x, y) < r2b:
                continue
            for i in range(ra, rb):
                vy = ys[i] - y
                for j in range(ca, cb):
                    if not todo[i, j]:
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
                    todo[i, j] = False
                    blocks[bi, bj] -= 1
                    count += 1
    return count


@njit(forceinline=True)
def _lookup(ws: np.ndarray, tab: np.ndarray) -> None:
    """The lookup table of the scans over ``NB`` pseudo-angle bins, from the sorted interval starts ``ws``:
    the interval of the whole bin, or -2 when a bound lies in it (then a binary search decides)."""
    B = ws.size
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


@njit
def cover_step(todo: np.ndarray, blocks: np.ndarray, seen: np.ndarray, geo: np.ndarray, pose: np.ndarray,
               cones: np.ndarray, ranges: np.ndarray) -> int:  # fmt: skip
    """Mark the cells sensed from ``pose`` ``(x, y, theta)`` (see the module) and return how many are new.

    ``todo`` (bool ``(ny, nx)``) holds the free cells not yet seen and ``blocks`` their counts per block of
    ``BLOCK x BLOCK`` cells (:func:`todo_blocks`); both are updated in place with ``seen``. ``geo`` is
    ``(x0, y0, dx, dy, kx, ky)`` (the grid's lower-left corner, its cell sides and the reach in cells: the
    window is the ``(2 ky + 1) x (2 kx + 1)`` cells around the pose's cell, narrowed to the step's farthest
    reading) followed by the cell centres ``xs``
    ``(nx,)`` and ``ys`` ``(ny,)``; ``cones`` the per-suite :func:`cone_table` (the ``breaks``, ``cover``
    and ``r_max`` of the suite in one array); ``ranges`` the true ranges ``(n,)``.

    The scans visit only the cells still to cover (a free, unseen cell is one of ``todo``) and skip whole
    blocks with none left or none nearer than the radius, and the lookup table is built only when a scan may
    need it (the same floating-point operations as the oracle, ``tests/coverage_oracle.py``).
    """
    x, y, th = pose[0], pose[1], pose[2]
    ny, nx = todo.shape
    B, n = cones.shape[0] - 1, cones.shape[1] - 1
    work = np.empty((9, B))  # radii, world bearings, their cosines, sines and pseudo-angles; then sorted
    rad, wrad, wcos, wsin, world = work[0], work[1], work[2], work[3], work[4]
    ws, wr, cs, sn = work[5], work[6], work[7], work[8]
    far, radmax = 0.0, 0.0
    for s in range(n):
        far = max(far, min(ranges[s], cones[B, 1 + s]))
    for b in range(B):
        r = 0.0
        for s in range(n):
            if cones[b, 1 + s] > 0.0:
                r = max(r, ranges[s] if ranges[s] < cones[b, 1 + s] else cones[b, 1 + s])
        rad[b] = r
        radmax = max(radmax, r)
    kx = min(int(geo[4]), int(math.ceil(far / geo[2])) + 1)
    ky = min(int(geo[5]), int(math.ceil(far / geo[3])) + 1)
    ic, jc = int(math.floor((y - geo[1]) / geo[3])), int(math.floor((x - geo[0]) / geo[2]))
    i0, i1, j0, j1 = max(ic - ky, 0), min(ic + ky + 1, ny), max(jc - kx, 0), min(jc + kx + 1, nx)
    xs, ys = geo[6 : 6 + nx], geo[6 + nx : 6 + nx + ny]
    # Every cell marked lies in the window, is still to cover and is nearer than the largest radius: most
    # steps, once the surroundings are covered, end here.
    if i0 >= i1 or j0 >= j1 or not _any_todo(todo, blocks, i0, i1, j0, j1, xs, ys, x, y, radmax * radmax):
        return 0
    two_pi = 2 * np.pi
    for b in range(B):
        wrad[b] = np.mod(cones[b, 0] + th, two_pi)
        wcos[b], wsin[b] = math.cos(wrad[b]), math.sin(wrad[b])
        world[b] = pseudo_angle(wcos[b], wsin[b])
    order = np.arange(B)  # stable insertion sort by pseudo-angle (B is small)
    for b in range(1, B):
        o, q = order[b], b
        while q > 0 and world[order[q - 1]] > world[o]:
            order[q] = order[q - 1]
            q -= 1
        order[q] = o
    r2 = np.empty(B)
    for b in range(B):
        o = order[b]
        ws[b], wr[b], cs[b], sn[b], r2[b] = world[o], wrad[o], wcos[o], wsin[o], rad[o] * rad[o]
    r2min = r2.min()
    resx = (xs[xs.shape[0] - 1] - xs[0]) / (xs.shape[0] - 1) if xs.shape[0] > 1 else math.inf
    resy = (ys[ys.shape[0] - 1] - ys[0]) / (ys.shape[0] - 1) if ys.shape[0] > 1 else math.inf
    tab = np.empty(NB, dtype=np.int64)
    ready = False
    rm = math.sqrt(r2min)
    ia, ib, ja, jb = _box(i0, i1, j0, j1, x, y, xs, ys, resx, resy, -rm, rm, -rm, rm)
    count = 0
    if ia < ib and ja < jb:
        count = _scan_todo(todo, blocks, seen, xs, ys, ia, ib, ja, jb, x, y, r2min, -1, r2min, ws, tab)
    for b in range(B):
        if r2[b] <= r2min:
            continue
        R = math.sqrt(r2[b])
        a0, a1 = wr[b], (wr[b + 1] if b + 1 < B else wr[0] + two_pi)
        c0, s0 = cs[b], sn[b]  # cos and sin of a0 and a1, computed once per bearing
        c1, s1 = (cs[b + 1], sn[b + 1]) if b + 1 < B else (math.cos(a1), math.sin(a1))
        xlo, xhi, ylo, yhi = sector_box(R, a0, a1, c0, s0, c1, s1)
        ia, ib, ja, jb = _box(i0, i1, j0, j1, x, y, xs, ys, resx, resy, xlo, xhi, ylo, yhi)
        if ia >= ib or ja >= jb or not _any_todo(todo, blocks, ia, ib, ja, jb, xs, ys, x, y, r2[b]):
            continue
        if not ready:  # the lookup table, built once a scan may read it
            _lookup(ws, tab)
            ready = True
        count += _scan_todo(todo, blocks, seen, xs, ys, ia, ib, ja, jb, x, y, r2[b], b, r2min, ws, tab)
    return count


__all__ = [
    "BLOCK",
    "NB",
    "cone_table",
    "cover_step",
    "pseudo_angle",
    "todo_blocks",
]
