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

import numpy as np

from digslam.observer.core.scalar_jit import njit
from digslam.observer.online.dig_jit import window
from digslam.observer.thick.sep import CLEAR, DARK, PENUMBRA

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


@njit
def _fill(clear: np.ndarray, dark: np.ndarray, img: np.ndarray, ch: int, rs: np.ndarray, re: np.ndarray,
          cs: np.ndarray, ce: np.ndarray, p0: int, p1: int, q0: int, q1: int) -> None:  # fmt: skip
    """Pixels ``[p0:p1, q0:q1]`` of channels ``ch, ch + 1, ch + 2`` of ``img`` (255 / 0): all clear, mixed,
    all dark per pixel block. The masks come as ``uint8`` views; each block row is first AND-reduced
    over its cells' rows."""
    if p0 >= p1 or q0 >= q1:
        return
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
    m = img.shape[-1]
    rs, re, _ = _bounds(clear.shape[0], m)
    cs, ce, _ = _bounds(clear.shape[1], m)
    u8 = [np.ascontiguousarray(v).view(np.uint8) for v in (clear, dark)]
    _fill(u8[0], u8[1], img, ch, rs, re, cs, ce, 0, rs.size, 0, cs.size)


def three_state(clear: np.ndarray, dark: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(clear, penumbra, dark)`` pixel masks of side ``m`` (mutually exclusive, covering every pixel)."""
    img = np.empty((3, m, m), dtype=np.uint8)
    fill_map(np.asarray(clear, dtype=bool), np.asarray(dark, dtype=bool), img)
    return img[0] > 0, img[1] > 0, img[2] > 0


def all_blocks(mask: np.ndarray, m: int) -> np.ndarray:
    """``(m, m)``: True where every cell of the pixel's block is True."""
    return three_state(mask, np.zeros_like(mask, dtype=bool), m)[0]


@njit
def _sets(sure: np.ndarray, maybe: np.ndarray, free: np.ndarray, reach: np.ndarray, explored: np.ndarray,
          clear: np.ndarray, dark: np.ndarray, r0: int, r1: int, c0: int, c1: int) -> int:  # fmt: skip
    """The cells ``[r0:r1, c0:c1]`` of the sets; returns the change of the clear cells inside ``reach``."""
    n = 0
    s8, m8, f8, r8 = sure.view(np.uint8), maybe.view(np.uint8), free.view(np.uint8), reach.view(np.uint8)
    e8, c8, d8 = explored.view(np.uint8), clear.view(np.uint8), dark.view(np.uint8)
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
def _sets_and_map(sure: np.ndarray, maybe: np.ndarray, free: np.ndarray, reach: np.ndarray,
                  explored: np.ndarray, clear: np.ndarray, dark: np.ndarray, img: np.ndarray, rs: np.ndarray,
                  re: np.ndarray, cs: np.ndarray, ce: np.ndarray, r0: int, r1: int, c0: int, c1: int,
                  p0: int, p1: int, q0: int, q1: int) -> int:  # fmt: skip
    n = _sets(sure, maybe, free, reach, explored, clear, dark, r0, r1, c0, c1)
    _fill(clear.view(np.uint8), dark.view(np.uint8), img, 0, rs, re, cs, ce, p0, p1, q0, q1)
    return n


@njit
def _right(s: np.ndarray, v: int) -> int:
    """``bisect_right(s, v)`` on the increasing int array ``s``."""
    lo, hi = 0, s.size
    while lo < hi:
        mid = (lo + hi) // 2
        if s[mid] <= v:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit
def _pixels(s: np.ndarray, r0: int, r1: int, n: int) -> tuple[int, int]:
    """:func:`pixel_range` on the block starts ``s`` (compiled twin, same result)."""
    if r0 >= r1:
        return 0, 0
    m = s.size
    p0 = _right(s, r0) - 1
    p1 = _right(s, r1 - 1)
    if n < m:  # several pixels share a cell: take them all (bisect_left(s, s[p0]))
        v = s[p0]
        lo, hi = 0, m
        while lo < hi:
            mid = (lo + hi) // 2
            if s[mid] < v:
                lo = mid + 1
            else:
                hi = mid
        p0 = lo
    return max(p0, 0), min(p1, m)


@njit
def _observe(sure: np.ndarray, maybe: np.ndarray, free: np.ndarray, planes: np.ndarray, base: np.ndarray,
             img: np.ndarray, blocks: np.ndarray, r0: int, r1: int, c0: int, c1: int, xs: np.ndarray,
             nys: np.ndarray, lo: np.ndarray, hi: np.ndarray, h0: float, h1: float, norm: np.ndarray,
             steps: int, n_reach: int, n_prev: int, state: np.ndarray, snap: np.ndarray) -> int:  # fmt: skip
    """:func:`observe` (``planes`` ``(4, ny, nx)`` uint8: explored, clear, dark, reach; ``blocks``
    ``(4, m)``: the pixel block bounds ``rs, re, cs, ce`` of :func:`_bounds`)."""
    ny, nx = sure.shape
    explored, clear, dark, reach = planes[0], planes[1], planes[2], planes[3]
    rs, re, cs, ce = blocks[0], blocks[1], blocks[2], blocks[3]
    p0, p1 = _pixels(rs, r0, r1, ny)
    q0, q1 = _pixels(cs, c0, c1, nx)
    n = n_prev + _sets(sure, maybe, free, reach, explored, clear, dark, r0, r1, c0, c1)
    _fill(clear, dark, base, 0, rs, re, cs, ce, p0, p1, q0, q1)
    e8, c8, s8 = explored.reshape(-1), clear.reshape(-1), snap.reshape(-1)
    f8 = free.view(np.uint8).reshape(-1)
    k = e8.size
    for i in range(k):  # the snapshot: explored, clear, free
        s8[i] = e8[i]
    for i in range(k):
        s8[k + i] = c8[i]
    for i in range(k):
        s8[2 * k + i] = f8[i]
    b8, o8 = base.reshape(-1), img.reshape(-1)  # flat loops (C-contiguous): they vectorize
    k = b8.size
    for i in range(k):
        o8[i] = b8[i]
    for i in range(k, k + k // 3):
        o8[i] = 0
    x0, y0, x1, y1 = lo[0], lo[1], hi[0], hi[1]
    f0, f1, g0, g1 = window(xs, nys, x0, y0, x1, y1)
    p0, p1 = _pixels(rs, f0, f1, ny)
    q0, q1 = _pixels(cs, g0, g1, nx)
    full = np.uint8(255)
    for p in range(p0, p1):
        row = img[3, p]
        for q in range(q0, q1):
            row[q] = full
    cx, cy, hx, hy = norm[0], norm[1], norm[2], norm[3]
    hm, hw = 0.5 * (h0 + h1), 0.5 * (h1 - h0)
    state[0] = min(max((x0 - cx) / hx, -1.0), 1.0)
    state[1] = min(max((y0 - cy) / hy, -1.0), 1.0)
    state[2] = min(max((x1 - cx) / hx, -1.0), 1.0)
    state[3] = min(max((y1 - cy) / hy, -1.0), 1.0)
    state[4], state[5] = math.cos(hm), math.sin(hm)
    state[6] = min(hw / math.pi, 1.0)
    state[7] = math.tanh(max(x1 - x0, y1 - y0))
    state[8] = min(steps / norm[4], 1.0)
    state[9] = n / n_reach
    state[10] = 1.0
    return n


def observe(sure: np.ndarray, maybe: np.ndarray, free: np.ndarray, planes: np.ndarray, base: np.ndarray,
            img: np.ndarray, window: tuple[int, int, int, int], xs: np.ndarray, nys: np.ndarray,
            lo: np.ndarray, hi: np.ndarray, heading: tuple[float, float], norm: np.ndarray, steps: int,
            n_reach: int, n_prev: int, state: np.ndarray, snap: np.ndarray) -> int:  # fmt: skip
    """One step of the wrapper's observation in one compiled call: :func:`sets_and_map` of ``window`` into
    the sets and ``base`` (the clear / penumbra / dark channels), then ``img[:3] = base``, ``img[3]`` the
    pose-box footprint (the pixels whose blocks meet the cells of the box ``lo, hi``,
    :func:`.online_jit.window`) and the 11 values of ``state`` (the wrapper's ``"state"``).

    ``planes`` is ``(4, ny, nx)`` uint8: the explored codes (int8 bytes), the clear and dark masks and the
    reachable free cells (0 / 1); ``norm`` is ``(cx, cy, hx, hy, horizon)`` (grid centre and half-sides);
    ``steps`` the elapsed steps, ``n_reach`` the reachable free cells and ``n_prev`` the certified count
    before the step; ``snap`` ``(3, ny, nx)`` uint8 receives copies of the explored codes, the clear mask and
    ``free``. Returns the new count. No argument checks: the wrapper's own arrays.
    """
    blocks = pixel_blocks(sure.shape, img.shape[-1])
    return int(_observe(sure, maybe, free, planes, base, img, blocks, *window, xs, nys, lo, hi, heading[0],
                        heading[1], norm, steps, n_reach, n_prev, state, snap))  # fmt: skip


def pixel_blocks(shape: tuple[int, int], m: int) -> np.ndarray:
    """``(4, m)`` int64: block bounds ``rs, re`` of the rows, ``cs, ce`` of the columns (:func:`_bounds`)."""
    return np.array([*_bounds(shape[0], m)[:2], *_bounds(shape[1], m)[:2]], dtype=np.int64)


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
    return int(_sets(sure, maybe, free, reach, explored, clear, dark, 0, sure.shape[0], 0, sure.shape[1]))


def sets_and_map(sure: np.ndarray, maybe: np.ndarray, free: np.ndarray, reach: np.ndarray,
                 explored: np.ndarray, clear: np.ndarray, dark: np.ndarray, img: np.ndarray,
                 window: tuple[int, int, int, int]) -> int:  # fmt: skip
    """:func:`observer_sets` then :func:`fill_map` into ``img[0:3]``, restricted to the cells of ``window``
    ``(r0, r1, c0, c1)`` and the pixels whose blocks meet it (the rest is kept: the cells outside did not
    change); returns the change of the count. No argument checks: the wrapper's own arrays."""
    ny, nx = sure.shape
    m = img.shape[-1]
    rs, re, _ = _bounds(ny, m)
    cs, ce, _ = _bounds(nx, m)
    r0, r1, c0, c1 = window
    p0, p1 = pixel_range(r0, r1, ny, m)
    q0, q1 = pixel_range(c0, c1, nx, m)
    return int(_sets_and_map(sure, maybe, free, reach, explored, clear, dark, img, rs, re, cs, ce, r0, r1, c0,
                             c1, p0, p1, q0, q1))  # fmt: skip


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
    "all_blocks",
    "block_starts",
    "crop_window",
    "fill_map",
    "observe",
    "observer_sets",
    "pixel_blocks",
    "pixel_range",
    "sets_and_map",
    "three_state",
]
