"""Conservative downsampling of the observer's cell sets into the policy's ``"map"`` image.

Each map pixel stands for a block of grid cells: pixel ``p`` of a side of ``n`` cells drawn on ``m`` pixels
covers cells ``starts[p] <= c < starts[p + 1]`` with ``starts[p] = floor(p n / m)`` (a partition when
``n >= m``; when ``n < m`` each pixel lies inside one cell, repeated). The rule never upgrades a claim:

* a pixel is CLEAR only if all its cells are clear (proved free and certainly explored);
* it is DARK only if all its cells are dark (certainly not explored);
* otherwise it is PENUMBRA (mixed or possibly explored: nothing is claimed).

The per-cell work is compiled (``digslam.observer.core.scalar_jit.njit``): :func:`observer_sets` turns the
filter's
certainly / possibly sensed and dug cells into the explored codes, the clear and dark masks and the
certified count in one pass, and :func:`sets_and_map` keeps them and the image up to date on the window
of cells a step changed; :func:`observe` does that, then the pose-box channel, the ``"state"`` vector and
the copies ``info`` hands out, all in one compiled call per step (the wrapper's fast path).

**The observation holds no ground truth.** The image and the state are drawn from the filter's sets, the
pose and heading boxes, the grid and the step count only. The ``reach`` plane (the true reachable free
cells) feeds nothing but the count these kernels return, which the wrapper puts in ``info`` and the reward;
the state's certified value is the share of the *grid's* cells that are clear, not of the reachable ones
(the grid is the observer's own, fixed by its configuration; the reachable area is what a real robot does
not know, and a share of it would tell the agent how much is left to find).

>>> clear = np.zeros((4, 4), bool); clear[:2, :2] = True; clear[0, 2] = True
>>> dark = np.zeros((4, 4), bool); dark[2:, 2:] = True
>>> c, p, d = three_state(clear, dark, 2)
>>> c.tolist(), d.tolist(), p.tolist()
([[True, False], [False, False]], [[False, False], [False, True]], [[False, True], [True, False]])
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from digslam.observer.core.grid_jit import window
from digslam.observer.core.scalar_jit import njit
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA

_CLEAR, _PENUMBRA, _DARK = int(CLEAR), int(PENUMBRA), int(DARK)


def block_starts(n: int, m: int) -> np.ndarray:
    """First cell of each of the ``m`` pixel blocks over ``n`` cells."""
    return (np.arange(m, dtype=np.int64) * n) // m


@lru_cache(maxsize=64)
def _bounds(n: int, m: int) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    """Block ``[start, end)`` of each pixel (a pixel inside one cell when ``n < m``), and the starts."""
    s = block_starts(n, m)
    e = np.maximum(np.append(s[1:], n), s + 1)
    return s, e, tuple(s.tolist())


class PixelBlocks(NamedTuple):
    """The cell blocks of the map's pixels (:func:`pixel_blocks`): pixel ``(p, q)`` covers the rows
    ``row_start[p] : row_end[p]`` and the columns ``col_start[q] : col_end[q]``; each field ``(m,)`` int64.
    """

    row_start: np.ndarray
    row_end: np.ndarray
    col_start: np.ndarray
    col_end: np.ndarray


class MapPlanes(NamedTuple):
    """The per-cell sets the map is drawn from, each ``(ny, nx)`` with one byte per cell (kept up to date on
    the cells a step changed).

    Attributes:
        explored: the explored codes (int8 ``CLEAR``, ``PENUMBRA``, ``DARK``, or their uint8 bytes).
        clear: the clear mask (certainly sensed and proved free; bool or uint8 0 / 1).
        dark: the dark mask (certainly not sensed).
        reach: the reachable free cells, ground truth: only the count returned to the wrapper (``info``,
            reward) is taken over them, never the observation.
    """

    explored: np.ndarray
    clear: np.ndarray
    dark: np.ndarray
    reach: np.ndarray


class MapContext(NamedTuple):
    """What :func:`observe` reads and keeps between steps, built once per episode by :func:`map_context`
    (flat on purpose: each field, and each nested tuple more, costs at every call from Python).

    Attributes:
        sure, maybe, free: ``(ny, nx)`` bool, the filter's certainly and possibly sensed cells and ``M⁻``
            (read: the filter's own arrays).
        explored, clear, dark, reach: the map's cell sets, ``(ny, nx)`` uint8 planes (:class:`MapPlanes`),
            kept up to date on the cells a step changed.
        base: ``(3, m, m)`` uint8, the clear / penumbra / dark channels of the map, kept between steps.
        row_start, row_end, col_start, col_end: the pixel blocks (:class:`PixelBlocks`).
        xs, nys: the grid's exact cell bounds (``nys = -ys``), for the pose-box channel; the state is
            normalised over the grid's frame ``[xs[0], xs[-1]] × [-nys[-1], -nys[0]]``.
        horizon: the episode's step horizon (the state's elapsed-steps value is ``steps / horizon``).
    """

    sure: np.ndarray
    maybe: np.ndarray
    free: np.ndarray
    explored: np.ndarray
    clear: np.ndarray
    dark: np.ndarray
    reach: np.ndarray
    base: np.ndarray
    row_start: np.ndarray
    row_end: np.ndarray
    col_start: np.ndarray
    col_end: np.ndarray
    xs: np.ndarray
    nys: np.ndarray
    horizon: float


@njit
def _fill(clear: np.ndarray, dark: np.ndarray, img: np.ndarray, ch: int, blocks: PixelBlocks,
          pix: tuple[int, int, int, int]) -> None:  # fmt: skip
    """Pixels ``pix = (p0, p1, q0, q1)`` (rows ``p0:p1``, columns ``q0:q1``) of channels ``ch, ch + 1,
    ch + 2`` of ``img`` (255 / 0): all clear, mixed, all dark per pixel block. The masks come as ``uint8``
    views; each block row is first AND-reduced over its cells' rows."""
    p0, p1, q0, q1 = pix
    if p0 >= p1 or q0 >= q1:
        return
    rs, re, cs, ce = blocks.row_start, blocks.row_end, blocks.col_start, blocks.col_end
    j0, j1 = cs[q0], ce[q1 - 1]
    w = j1 - j0
    ac, ad = np.empty(w, np.uint8), np.empty(w, np.uint8)
    one, full = np.uint8(1), np.uint8(255)
    for p in range(p0, p1):  # slices indexed from 0: no wraparound checks, the row loops vectorize
        cr, dr = clear[rs[p], j0:j1], dark[rs[p], j0:j1]
        for j in range(w):
            ac[j] = cr[j]
            ad[j] = dr[j]
        for i in range(rs[p] + 1, re[p]):
            cr, dr = clear[i, j0:j1], dark[i, j0:j1]
            for j in range(w):
                ac[j] &= cr[j]
                ad[j] &= dr[j]
        o0, o1, o2 = img[ch, p, q0:q1], img[ch + 1, p, q0:q1], img[ch + 2, p, q0:q1]
        for q in range(q1 - q0):
            k0, k1 = cs[q0 + q] - j0, ce[q0 + q] - j0
            c, d = ac[k0], ad[k0]
            for k in range(k0 + 1, k1):
                c &= ac[k]
                d &= ad[k]
            d &= one ^ c
            o0[q] = full * c
            o1[q] = full * (one ^ (c | d))
            o2[q] = full * d


def fill_map(clear: np.ndarray, dark: np.ndarray, img: np.ndarray, ch: int = 0) -> None:
    """Write the clear / penumbra / dark pixel masks of the cell masks into ``img[ch : ch + 3]`` (0 / 255)."""
    blocks = pixel_blocks(clear.shape, img.shape[-1])
    u8 = [np.ascontiguousarray(v).view(np.uint8) for v in (clear, dark)]
    _fill(u8[0], u8[1], img, ch, blocks, (0, blocks.row_start.size, 0, blocks.col_start.size))


def three_state(clear: np.ndarray, dark: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(clear, penumbra, dark)`` pixel masks of side ``m`` (mutually exclusive, covering every pixel)."""
    img = np.empty((3, m, m), dtype=np.uint8)
    fill_map(np.asarray(clear, dtype=bool), np.asarray(dark, dtype=bool), img)
    return img[0] > 0, img[1] > 0, img[2] > 0


def all_blocks(mask: np.ndarray, m: int) -> np.ndarray:
    """``(m, m)``: True where every cell of the pixel's block is True."""
    return three_state(mask, np.zeros_like(mask, dtype=bool), m)[0]


@njit
def _sets(sure: np.ndarray, maybe: np.ndarray, free: np.ndarray, planes: MapPlanes,
          win: tuple[int, int, int, int]) -> int:  # fmt: skip
    """The cells ``win = (r0, r1, c0, c1)`` of ``planes``; returns the change of the clear cells inside
    ``planes.reach``."""
    r0, r1, c0, c1 = win
    n = 0
    s8, m8, f8, r8 = (
        sure.view(np.uint8),
        maybe.view(np.uint8),
        free.view(np.uint8),
        planes.reach.view(np.uint8),
    )
    e8, c8, d8 = planes.explored.view(np.uint8), planes.clear.view(np.uint8), planes.dark.view(np.uint8)
    one, code_dark = np.uint8(1), np.uint8(_DARK & 0xFF)
    for i in range(r0, r1):  # row slices: indices from 0, so no wraparound checks (the loops vectorize)
        s_, m_, f_, r_ = s8[i, c0:c1], m8[i, c0:c1], f8[i, c0:c1], r8[i, c0:c1]
        e_, c_, d_ = e8[i, c0:c1], c8[i, c0:c1], d8[i, c0:c1]
        for j in range(c_.size):
            n -= np.int64(c_[j] & r_[j])
        for j in range(c_.size):
            s, mb = s_[j], m_[j]
            c = s & f_[j]
            e_[j] = (np.uint8(_CLEAR) if s else np.uint8(_PENUMBRA)) if (s | mb) else code_dark
            c_[j] = c
            d_[j] = one ^ (s | mb)
            n += np.int64(c & r_[j])
    return n


@njit
def _sets_and_map(sure: np.ndarray, maybe: np.ndarray, free: np.ndarray, planes: MapPlanes, img: np.ndarray,
                  blocks: PixelBlocks, win: tuple[int, int, int, int]) -> int:  # fmt: skip
    """:func:`sets_and_map` (compiled): :func:`_sets` of ``win``, then :func:`_fill` of its pixels."""
    r0, r1, c0, c1 = win
    ny, nx = sure.shape
    n = _sets(sure, maybe, free, planes, win)
    pix = (*_pixels(blocks.row_start, r0, r1, ny), *_pixels(blocks.col_start, c0, c1, nx))
    _fill(planes.clear.view(np.uint8), planes.dark.view(np.uint8), img, 0, blocks, pix)
    return n


@njit
def _pixels(s: np.ndarray, r0: int, r1: int, n: int) -> tuple[int, int]:
    """:func:`pixel_range` on the block starts ``s`` (compiled twin, same result): ``np.searchsorted`` with
    ``side="right"`` is ``bisect_right`` and ``side="left"`` is ``bisect_left``."""
    if r0 >= r1:
        return 0, 0
    m = s.size
    p0 = np.searchsorted(s, r0, side="right") - 1
    p1 = np.searchsorted(s, r1 - 1, side="right")
    if n < m:  # several pixels share a cell: take them all (bisect_left(s, s[p0]))
        p0 = np.searchsorted(s, s[p0], side="left")
    return max(p0, 0), min(p1, m)


@njit
def observe(maps: MapContext, pose_lo: np.ndarray, pose_hi: np.ndarray, heading: tuple[float, float],
            win: tuple[int, int, int, int], steps: int, n_prev: int, img: np.ndarray, state: np.ndarray,
            snap: np.ndarray) -> int:  # fmt: skip
    """One step of the wrapper's observation in one compiled call: :func:`sets_and_map` of the window
    ``win`` of cells the step changed into the planes and ``base`` of ``maps`` (the clear / penumbra / dark
    channels), then ``img[:3] = base``, ``img[3]`` the pose-box footprint (the pixels whose blocks meet the
    cells of the position box ``pose_lo``, ``pose_hi``, :func:`~digslam.observer.core.grid_jit.window`)
    and the 11 values of ``state`` (the wrapper's ``"state"``, with the heading interval ``heading``; its
    ``state[9]`` is the share of the grid's cells that are clear, from the observer alone);
    ``snap`` ``(3, ny, nx)`` uint8 receives copies of the explored codes, the clear mask and ``maps.free``
    (an empty ``snap``, ``(3, 0, 0)``: no copies).

    ``steps`` is the number of elapsed steps and ``n_prev`` the certified count before the step (clear cells
    in ``maps.reach``, ground truth); returns the new count, which enters neither ``img`` nor ``state``. No
    argument checks: the wrapper's own arrays (:class:`MapContext`, or the plain tuple of its fields).
    :func:`observe_step` is the same step with both counts kept by the caller (what the wrapper calls).
    """
    counts = np.array([n_prev, -1], np.int64)
    _observe(MapContext(*maps), pose_lo, pose_hi, heading, win, steps, counts, img, state, snap)
    return counts[0]


@njit
def observe_step(maps: tuple, pose_lo: np.ndarray, pose_hi: np.ndarray, heading: tuple[float, float],
                 win: tuple[int, int, int, int], steps: int, counts: np.ndarray, img: np.ndarray,
                 state: np.ndarray, snap: np.ndarray) -> None:  # fmt: skip
    """:func:`observe` with ``maps`` the plain tuple of the fields of a :class:`MapContext` (numba types a
    plain tuple argument in C, a named tuple field by field in Python: about 1.5 µs less per call) and
    ``counts`` ``(2,)`` int64, updated in place: the certified count (``observe``'s ``n_prev`` and result)
    and the number of clear cells of the grid (the state's certified share). Given that number before the
    step (``>= 0``), only the cells of ``win`` are counted again (the others did not change); ``-1``: all
    of them are counted. Same image, state and snapshot as :func:`observe`, to the bit."""
    _observe(MapContext(*maps), pose_lo, pose_hi, heading, win, steps, counts, img, state, snap)


@njit
def _count(c8: np.ndarray, win: tuple[int, int, int, int]) -> int:
    """The number of ones of the ``uint8`` 0 / 1 plane ``c8`` in the cells ``win = (r0, r1, c0, c1)``."""
    r0, r1, c0, c1 = win
    n = 0
    for i in range(r0, r1):
        row = c8[i, c0:c1]
        for j in range(row.size):
            n += np.int64(row[j])
    return n


@njit
def _observe(maps: MapContext, pose_lo: np.ndarray, pose_hi: np.ndarray, heading: tuple[float, float],
             win: tuple[int, int, int, int], steps: int, counts: np.ndarray, img: np.ndarray,
             state: np.ndarray, snap: np.ndarray) -> None:  # fmt: skip
    """The body of :func:`observe` and :func:`observe_step` (``counts`` as in :func:`observe_step`)."""
    sure, free = maps.sure, maps.free
    ny, nx = sure.shape
    planes = MapPlanes(maps.explored, maps.clear, maps.dark, maps.reach)
    blocks = PixelBlocks(maps.row_start, maps.row_end, maps.col_start, maps.col_end)
    base = maps.base
    r0, r1, c0, c1 = win
    p0, p1 = _pixels(blocks.row_start, r0, r1, ny)
    q0, q1 = _pixels(blocks.col_start, c0, c1, nx)
    c8, d8 = planes.clear.view(np.uint8), planes.dark.view(np.uint8)
    n_clear = counts[1]
    if n_clear >= 0:  # the clear cells outside the window are unchanged: count the window before and after
        n_clear -= _count(c8, win)
    counts[0] += _sets(sure, maps.maybe, free, planes, win)
    if n_clear >= 0:
        n_clear += _count(c8, win)
    _fill(c8, d8, base, 0, blocks, (p0, p1, q0, q1))
    e8, c8, s8 = planes.explored.view(np.uint8).reshape(-1), c8.reshape(-1), snap.reshape(-1)
    f8 = free.view(np.uint8).reshape(-1)
    k = e8.size
    s_e, s_c, s_f = s8[:k], s8[k : 2 * k], s8[2 * k :]  # the snapshot: explored, clear, free
    if n_clear < 0:  # every clear cell of the grid: the state's certified share (no ground truth)
        n_clear = 0
        for i in range(k):  # (slices indexed from 0: no wraparound checks, the loops vectorize)
            n_clear += np.int64(c8[i])
    counts[1] = n_clear
    if s8.size:  # the snapshot, when asked for (an empty ``snap``: none)
        for i in range(k):
            s_e[i] = e8[i]
        for i in range(k):
            s_c[i] = c8[i]
        for i in range(k):
            s_f[i] = f8[i]
    b8 = base.reshape(-1)  # flat loops (C-contiguous): they vectorize
    k = b8.size
    o_b, o_p = img.reshape(-1)[:k], img.reshape(-1)[k : k + k // 3]
    for i in range(k):
        o_b[i] = b8[i]
    for i in range(k // 3):
        o_p[i] = 0
    x0, y0, x1, y1 = pose_lo[0], pose_lo[1], pose_hi[0], pose_hi[1]
    f0, f1, g0, g1 = window(maps.xs, maps.nys, x0, y0, x1, y1)
    p0, p1 = _pixels(blocks.row_start, f0, f1, ny)
    q0, q1 = _pixels(blocks.col_start, g0, g1, nx)
    full = np.uint8(255)
    for p in range(p0, p1):
        row = img[3, p]
        for q in range(q0, q1):
            row[q] = full
    h0, h1 = heading
    xs, nys = maps.xs, maps.nys
    gx0, gx1, gy0, gy1 = xs[0], xs[xs.size - 1], -nys[nys.size - 1], -nys[0]  # the frame (exact)
    cx, cy, hx, hy = 0.5 * (gx0 + gx1), 0.5 * (gy0 + gy1), 0.5 * (gx1 - gx0), 0.5 * (gy1 - gy0)
    hm, hw = 0.5 * (h0 + h1), 0.5 * (h1 - h0)
    state[0] = min(max((x0 - cx) / hx, -1.0), 1.0)
    state[1] = min(max((y0 - cy) / hy, -1.0), 1.0)
    state[2] = min(max((x1 - cx) / hx, -1.0), 1.0)
    state[3] = min(max((y1 - cy) / hy, -1.0), 1.0)
    state[4], state[5] = math.cos(hm), math.sin(hm)
    state[6] = min(hw / math.pi, 1.0)
    state[7] = math.tanh(max(x1 - x0, y1 - y0))
    state[8] = min(steps / maps.horizon, 1.0)
    state[9] = n_clear / ny / nx
    state[10] = 1.0


def map_context(sets: tuple[np.ndarray, np.ndarray, np.ndarray], planes: MapPlanes, base: np.ndarray,
                xs: np.ndarray, nys: np.ndarray, horizon: float) -> MapContext:  # fmt: skip
    """The :class:`MapContext` of :func:`observe`: the filter's ``sets = (sure, maybe, free)``, the caller's
    ``planes`` and ``base`` (kept), the pixel blocks of ``base.shape[-1]`` pixels a side, the grid's cell
    bounds ``xs``, ``nys = -ys`` (its frame's ends first and last) and the ``horizon``."""
    blocks = pixel_blocks(planes.clear.shape, base.shape[-1])
    return MapContext(*sets, *planes, base, *blocks, xs, nys, float(horizon))


@lru_cache(maxsize=64)
def pixel_blocks(shape: tuple[int, int], m: int) -> PixelBlocks:
    """The :class:`PixelBlocks` of a ``shape`` grid drawn on ``m x m`` pixels (:func:`_bounds`; cached, do not
    write into it)."""
    rs, re, _ = _bounds(shape[0], m)
    cs, ce, _ = _bounds(shape[1], m)
    return PixelBlocks(rs, re, cs, ce)


def _check_sets(arrays: tuple[np.ndarray, ...]) -> None:
    shape = arrays[0].shape
    if not all(v.flags.c_contiguous and v.shape == shape and v.itemsize == 1 for v in arrays):
        names = "sure, maybe, free, reach, explored, clear, dark"
        raise ValueError(f"{names}: expected C-contiguous one-byte arrays of shape {shape}")


def observer_sets(sure: np.ndarray, maybe: np.ndarray, free: np.ndarray, reach: np.ndarray,
                  explored: np.ndarray, clear: np.ndarray, dark: np.ndarray) -> int:  # fmt: skip
    """One pass over the filter's ``(ny, nx)`` bool cells (all C-contiguous): the explored codes (CLEAR
    certainly sensed, PENUMBRA possibly, DARK not) into the int8 ``explored``, the clear mask (certainly
    sensed and proved free) and the dark mask into the bool ``clear`` and ``dark``; returns the number of
    clear cells inside ``reach``."""
    _check_sets((sure, maybe, free, reach, explored, clear, dark))
    clear[:] = False
    planes = MapPlanes(explored, clear, dark, reach)
    return int(_sets(sure, maybe, free, planes, (0, sure.shape[0], 0, sure.shape[1])))


def sets_and_map(sure: np.ndarray, maybe: np.ndarray, free: np.ndarray, reach: np.ndarray,
                 explored: np.ndarray, clear: np.ndarray, dark: np.ndarray, img: np.ndarray,
                 window: tuple[int, int, int, int]) -> int:  # fmt: skip
    """:func:`observer_sets` then :func:`fill_map` into ``img[0:3]``, restricted to the cells of ``window``
    ``(r0, r1, c0, c1)`` and the pixels whose blocks meet it (the rest is kept: the cells outside did not
    change); returns the change of the count. No argument checks: the wrapper's own arrays."""
    planes = MapPlanes(explored, clear, dark, reach)
    r0, r1, c0, c1 = window
    blocks = pixel_blocks(sure.shape, img.shape[-1])
    return int(_sets_and_map(sure, maybe, free, planes, img, blocks, (int(r0), int(r1), int(c0), int(c1))))


def pixel_range(r0: int, r1: int, n: int, m: int) -> tuple[int, int]:
    """Pixels ``p0:p1`` whose blocks meet the cells ``r0:r1`` (empty when ``r0 >= r1``)."""
    if r0 >= r1:
        return 0, 0
    s = _bounds(n, m)[2]
    p0 = bisect_right(s, r0) - 1
    p1 = bisect_right(s, r1 - 1)
    if n < m:  # several pixels share a cell: take them all
        p0 = bisect_left(s, s[p0])
    return max(p0, 0), min(p1, m)


def crop_window(mask: np.ndarray, r0: int, c0: int, k: int, fill: bool) -> np.ndarray:
    """``(k, k)`` window of ``mask`` from ``(r0, c0)``, ``fill`` outside the array."""
    ny, nx = mask.shape
    out = np.full((k, k), fill, dtype=bool)
    a0, a1, b0, b1 = max(r0, 0), min(r0 + k, ny), max(c0, 0), min(c0 + k, nx)
    if a0 < a1 and b0 < b1:
        out[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0] = mask[a0:a1, b0:b1]
    return out


__all__ = [
    "MapContext",
    "MapPlanes",
    "PixelBlocks",
    "all_blocks",
    "block_starts",
    "crop_window",
    "fill_map",
    "map_context",
    "observe",
    "observe_step",
    "observer_sets",
    "pixel_blocks",
    "pixel_range",
    "sets_and_map",
    "three_state",
]
