"""The kernels of the paver (:mod:`digslam.observer.paving.paver`, thesis Algorithm 2.1): one generation of
boxes per call.

:func:`pave_generation` takes a generation ``(N, n)`` and its separation ``(4, N, n)`` and writes, in one
machine-code loop, the inner and outer pieces (the closed pieces of ``[x] \\ [x_in]`` and
``[x] \\ [x_out]``, as :func:`digslam.observer.core.boxes.box_difference`), the boundary boxes and the
bisected children, each with the tree node it came from.

>>> lo, hi = np.array([[0.0, 0.0]]), np.array([[1.0, 1.0]])
>>> sep = np.array([[[0.5, 0.0]], [[1.0, 1.0]], [[0.0, 0.0]], [[1.0, 1.0]]])  # x_in = [0.5, 1]×[0, 1]
>>> out, rows, left, cnt = pave_generation(lo, hi, sep, 0.1, 0.5, False, np.inf, 0, 1)
>>> cnt.tolist(), out[:, 0].tolist()          # one inner piece [0, 0.5]×[0, 1]; two children
([1, 0, 0, 2], [[0.0, 0.0], [0.5, 1.0]])
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core.scalar_jit import njit

__all__ = ["pave_generation"]


@njit(forceinline=True)
def _diff(lo: np.ndarray, hi: np.ndarray, r: int, y: np.ndarray, out: np.ndarray, rows: np.ndarray,
          c: int) -> int:  # fmt: skip
    """Write the closed pieces of ``[x_r] \\ [y]`` (``[y] ⊂ [x_r]``; ``y = (2, n)``) from slot ``c``, as
    :func:`.boxes.box_difference` does; return the next free slot."""
    n = lo.shape[1]
    if y[0, 0] > y[1, 0]:
        for i in range(n):
            out[0, c, i], out[1, c, i] = lo[r, i], hi[r, i]
        rows[c] = r
        return c + 1
    for k in range(n):
        for side in range(2):
            if (y[0, k] > lo[r, k]) if side == 0 else (hi[r, k] > y[1, k]):
                for i in range(n):
                    inner = i < k
                    out[0, c, i] = y[0, i] if inner else lo[r, i]
                    out[1, c, i] = y[1, i] if inner else hi[r, i]
                if side == 0:
                    out[1, c, k] = y[0, k]
                else:
                    out[0, c, k] = y[1, k]
                rows[c] = r
                c += 1
    return c


@njit(forceinline=True)
def _meet_row(lo: np.ndarray, hi: np.ndarray, r: int, a: np.ndarray, j: int, y: np.ndarray) -> None:
    """``y = [a_r] ∩ [x_r]`` (``a`` is ``x_in`` for ``j = 0``, ``x_out`` for ``j = 2``); empty as
    ``[+inf, -inf]``."""
    empty = False
    for k in range(lo.shape[1]):
        y[0, k], y[1, k] = max(a[j, r, k], lo[r, k]), min(a[j + 1, r, k], hi[r, k])
        empty |= y[0, k] > y[1, k]
    if empty:
        y[0, :], y[1, :] = np.inf, -np.inf


@njit
def pave_generation(lo: np.ndarray, hi: np.ndarray, sep: np.ndarray, eps: float, ratio: float, grid: bool,
                max_vol: float, base: int, n_nodes: int) -> tuple[np.ndarray, ...]:  # fmt: skip
    """One step of Algorithm 2.1 on a generation ``(N, n)`` separated into ``sep = (in_lo, in_hi, out_lo,
    out_hi)``: the pieces of ``[x] \\ [x_in]`` (inner) and ``[x] \\ [x_out]`` (outer), the boxes
    ``[x_in] ∩ [x_out]`` with ``w∞ < ε`` (widths rounded up) and volume ``< max_vol`` (boundary), and
    the others bisected across their widest side (children; the cut is :func:`_cut`). Returns ``(boxes
    (2, M, n), nodes (M,), left (N,), counts (4,))``: the four groups lie from offsets ``0, 2nN, 4nN,
    4nN + N`` on, each box with the tree node it came from (row ``r`` is node ``base + r``); ``left`` is
    the first child's node (``n_nodes + 2j``) or -1."""
    nb, n = lo.shape
    off = np.array([0, 2 * n * nb, 4 * n * nb, 4 * n * nb + nb])
    out = np.empty((2, 4 * n * nb + 3 * nb, n))
    rows = np.empty(4 * n * nb + 3 * nb, np.int64)
    cnt = off.copy()
    left = np.full(nb, -1, np.int64)
    a, b = np.empty((2, n)), np.empty((2, n))
    for r in range(nb):
        _meet_row(lo, hi, r, sep, 0, a)
        _meet_row(lo, hi, r, sep, 2, b)
        cnt[0] = _diff(lo, hi, r, a, out, rows, cnt[0])
        cnt[1] = _diff(lo, hi, r, b, out, rows, cnt[1])
        wmax, kmax, live, vol = -1.0, 0, True, 1.0
        for k in range(n):
            b[0, k], b[1, k] = max(a[0, k], b[0, k]), min(a[1, k], b[1, k])
            live &= b[0, k] <= b[1, k]
            d = b[1, k] - b[0, k]
            t = d - b[1, k]
            e = (b[1, k] - (d - t)) + (-b[0, k] - t)  # TwoSum: the width rounded up
            w = np.nextafter(d, np.inf) if e > 0 else d
            vol *= d
            if w > wmax:
                wmax, kmax = w, k
        if not live:
            continue
        split = wmax >= eps or vol >= max_vol
        cut = _cut(b[0, kmax], b[1, kmax], wmax, eps, ratio, grid) if split else np.nan
        g = 3 if b[0, kmax] < cut < b[1, kmax] else 2  # a side too narrow to cut stays a boundary box
        c = cnt[g]
        for side in range(g - 1):
            for i in range(n):
                out[0, c + side, i], out[1, c + side, i] = b[0, i], b[1, i]
            rows[c + side] = r
        if g == 3:
            out[1, c, kmax], out[0, c + 1, kmax] = cut, cut
            left[r] = n_nodes + c - off[3]
        cnt[g] = c + g - 1
    return out, rows + base, left, cnt - off


@njit(forceinline=True)
def _cut(lo_k: float, hi_k: float, w: float, eps: float, ratio: float, grid: bool) -> float:
    """Where to cut the side ``[lo_k, hi_k]`` (rounded-up width ``w``): at ``ratio``, or (``grid`` and
    ``w >= eps``) at the boundary nearest the middle of ``⌊w / eps⌋ + 1`` equal cells."""
    if grid and w >= eps:
        m = np.floor(w / eps) + 1.0
        f = np.floor(0.5 * m) / m
    else:
        f = ratio
    c = 0.5 * lo_k + 0.5 * hi_k if f == 0.5 else lo_k + f * (hi_k - lo_k)
    return min(max(c, lo_k), hi_k)
