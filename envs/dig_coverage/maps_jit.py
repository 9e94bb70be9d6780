"""Conservative downsampling of the observer's cell sets into the policy's ``"map"`` image.

Each map pixel stands for a block of grid cells: pixel ``p`` of a side of ``n`` cells drawn on ``m`` pixels
covers cells ``starts[p] <= c < starts[p + 1]`` with ``starts[p] = floor(p n / m)`` (a partition when
``n >= m``; when ``n < m`` each pixel lies inside one cell, repeated). The rule never upgrades a claim:

* a pixel is CLEAR only if all its cells are clear (proved free and certainly explored);
* it is DARK only if all its cells are dark (certainly not explored);
* otherwise it is PENUMBRA (mixed or possibly explored: nothing is claimed).

The per-cell work is compiled (``digslam.observer.core.scalar_jit.njit``): :func:`observer_sets` turns the
filter's certainly / possibly sensed and dug cells into the explored codes, the clear and dark masks and
the certified count in one pass (:func:`update_sets` on a window of cells), and :func:`sets_and_map` keeps
them and the image up to date on the window of cells a step changed (:func:`fill_pixels` on the pixels
whose blocks meet it). :mod:`.observe_jit` draws a whole observation with these kernels.

The ``reach`` plane of :class:`MapPlanes` (the true reachable free cells, ground truth) feeds nothing but
the count these kernels return, which the wrapper puts in ``info`` and the reward, never a pixel.

>>> clear = np.zeros((4, 4), bool); clear[:2, :2] = True; clear[0, 2] = True
>>> dark = np.zeros((4, 4), bool); dark[2:, 2:] = True
>>> c, p, d = three_state(clear, dark, 2)
>>> c.tolist(), d.tolist(), p.tolist()
([[True, False], [False, False]], [[False, False], [False, True]], [[False, True], [True, False]])
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from digslam.envs.observation import Channel
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


@njit
def fill_pixels(clear: np.ndarray, dark: np.ndarray, img: np.ndarray, ch: int, blocks: PixelBlocks,
                pix: tuple[int, int, int, int]) -> None:  # fmt: skip
    """Pixels ``pix = (p0, p1, q0, q1)`` (rows ``p0:p1``, columns ``q0:q1``) of channels ``ch +
    Channel.CLEAR``, ``ch + Channel.PENUMBRA`` and ``ch + Channel.DARK`` of ``img`` (255 / 0): all clear,
    mixed, all dark per pixel block (``ch``: 0 for the map's own channels, ``Channel.CROP_CLEAR`` for the
    crop window's, :class:`~digslam.envs.observation.Channel`). The masks come as ``uint8`` views; each
    block row is first AND-reduced over its cells' rows."""
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
        o0, o1 = img[ch + Channel.CLEAR, p, q0:q1], img[ch + Channel.PENUMBRA, p, q0:q1]
        o2 = img[ch + Channel.DARK, p, q0:q1]
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
    """Write the clear / penumbra / dark pixel masks of the cell masks into the channels ``ch +
    Channel.CLEAR``, ``ch + Channel.PENUMBRA``, ``ch + Channel.DARK`` of ``img`` (0 / 255; see
    :func:`fill_pixels`)."""
    blocks = pixel_blocks(clear.shape, img.shape[-1])
    u8 = [np.ascontiguousarray(v).view(np.uint8) for v in (clear, dark)]
    fill_pixels(u8[0], u8[1], img, ch, blocks, (0, blocks.row_start.size, 0, blocks.col_start.size))


def three_state(clear: np.ndarray, dark: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(clear, penumbra, dark)`` pixel masks of side ``m`` (mutually exclusive, covering every pixel)."""
    img = np.empty((3, m, m), dtype=np.uint8)
    fill_map(np.asarray(clear, dtype=bool), np.asarray(dark, dtype=bool), img)
    return img[Channel.CLEAR] > 0, img[Channel.PENUMBRA] > 0, img[Channel.DARK] > 0


def all_blocks(mask: np.ndarray, m: int) -> np.ndarray:
    """``(m, m)``: True where every cell of the pixel's block is True."""
    return three_state(mask, np.zeros_like(mask, dtype=bool), m)[0]


@njit
def update_sets(sure: np.ndarray, maybe: np.ndarray, free: np.ndarray, planes: MapPlanes,
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
    """:func:`sets_and_map` (compiled): :func:`update_sets` of ``win``, then :func:`fill_pixels` of its
    pixels."""
    r0, r1, c0, c1 = win
    ny, nx = sure.shape
    n = update_sets(sure, maybe, free, planes, win)
    pix = (*pixel_span(blocks.row_start, r0, r1, ny), *pixel_span(blocks.col_start, c0, c1, nx))
    fill_pixels(planes.clear.view(np.uint8), planes.dark.view(np.uint8), img, 0, blocks, pix)
    return n


@njit
def pixel_span(s: np.ndarray, r0: int, r1: int, n: int) -> tuple[int, int]:
    """:func:`pixel_range` on the block starts ``s`` (compiled twin, same result): ``np.searchsorted`` with
    ``side="right"`` is ``bisect_right`` and ``side="left"`` is ``bisect_left``."""
    if r0 >= r1:
        return 0, 0
    m = s.size
    p0 = np.searchsorted(s, r0, side="right") - 1
    p1 = np.searchsorted(s, r1 - 1, side="right")
    if n < m:  # several pixels share a cell: take them all (bisect_left(s, s[p0]))
        p0 = np.searchsorted(s, s[p0], side="left")
    return max(int(p0), 0), min(int(p1), m)


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
    return int(update_sets(sure, maybe, free, planes, (0, sure.shape[0], 0, sure.shape[1])))


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
    "MapPlanes",
    "PixelBlocks",
    "all_blocks",
    "block_starts",
    "crop_window",
    "fill_map",
    "fill_pixels",
    "observer_sets",
    "pixel_blocks",
    "pixel_range",
    "pixel_span",
    "sets_and_map",
    "three_state",
    "update_sets",
]
