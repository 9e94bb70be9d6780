"""Conservative downsampling of the observer's cell sets into the policy's ``"map"`` image.

Each map pixel stands for a block of grid cells: pixel ``p`` of a side of ``n`` cells drawn on ``m`` pixels
covers cells ``starts[p] <= c < starts[p + 1]`` with ``starts[p] = floor(p n / m)`` (a partition when
``n >= m``; when ``n < m`` each pixel lies inside one cell, repeated). The rule never upgrades a claim:

* a pixel is CLEAR only if all its cells are clear (proved free and certainly explored);
* it is DARK only if all its cells are dark (certainly not explored);
* otherwise it is PENUMBRA (mixed or possibly explored: nothing is claimed).

>>> clear = np.zeros((4, 4), bool); clear[:2, :2] = True; clear[0, 2] = True
>>> dark = np.zeros((4, 4), bool); dark[2:, 2:] = True
>>> c, p, d = three_state(clear, dark, 2)
>>> c.tolist(), d.tolist(), p.tolist()
([[True, False], [False, False]], [[False, False], [False, True]], [[False, True], [True, False]])
"""

from __future__ import annotations

import numpy as np


def block_starts(n: int, m: int) -> np.ndarray:
    """First cell of each of the ``m`` pixel blocks over ``n`` cells."""
    return (np.arange(m, dtype=np.int64) * n) // m


def all_blocks(mask: np.ndarray, m: int) -> np.ndarray:
    """``(m, m)``: True where every cell of the pixel's block is True."""
    ny, nx = mask.shape
    if ny % m == 0 and nx % m == 0:  # equal blocks: AND of strided slices (much faster than reductions)
        by, bx = ny // m, nx // m
        rows = mask[0::by].copy()
        for i in range(1, by):
            rows &= mask[i::by]
        out = rows[:, 0::bx].copy()
        for j in range(1, bx):
            out &= rows[:, j::bx]
        return out
    a = np.minimum.reduceat(mask.view(np.uint8), block_starts(ny, m), axis=0)
    return np.minimum.reduceat(a, block_starts(nx, m), axis=1).astype(bool)


def three_state(clear: np.ndarray, dark: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(clear, penumbra, dark)`` pixel masks of side ``m`` (mutually exclusive, covering every pixel)."""
    c, d = all_blocks(clear, m), all_blocks(dark, m)
    return c, ~(c | d), d


def pixel_range(r0: int, r1: int, n: int, m: int) -> tuple[int, int]:
    """Pixels ``p0:p1`` whose blocks meet the cells ``r0:r1`` (empty when ``r0 >= r1``)."""
    if r0 >= r1:
        return 0, 0
    s = block_starts(n, m)
    p0 = int(np.searchsorted(s, r0, side="right")) - 1
    p1 = int(np.searchsorted(s, r1 - 1, side="right"))
    if n < m:  # several pixels share a cell: take them all
        p0 = int(np.searchsorted(s, s[p0], side="left"))
        p1 = int(np.searchsorted(s, r1 - 1, side="right"))
    return max(p0, 0), min(p1, m)


def crop_window(mask: np.ndarray, r0: int, c0: int, k: int, fill: bool) -> np.ndarray:
    """``(k, k)`` window of ``mask`` from ``(r0, c0)``, ``fill`` outside the array."""
    ny, nx = mask.shape
    out = np.full((k, k), fill, dtype=bool)
    a0, a1, b0, b1 = max(r0, 0), min(r0 + k, ny), max(c0, 0), min(c0 + k, nx)
    if a0 < a1 and b0 < b1:
        out[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0] = mask[a0:a1, b0:b1]
    return out
