"""Compiled grid primitive: the window of cells a box meets, on the exact cell bounds of a grid.

A grid's columns are bounded by the increasing ``xs`` (``nx + 1`` values) and its rows, top to bottom, by the
decreasing ``ys``; the kernels take ``nys = -ys`` (increasing) so that rows and columns are found the same
way. :func:`window` is :meth:`.record.grid.Grid.window` for one box, in machine code: two ``np.searchsorted``
per axis, every comparison exact (nothing is rounded).

>>> xs = np.array([0.0, 1.0, 2.0, 3.0]); nys = -np.array([3.0, 2.0, 1.0, 0.0])
>>> window(xs, nys, 0.5, 0.5, 1.0, 1.5)       # the closed box meets the cells touching x = 1 and y = 1
(1, 3, 0, 2)
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core.scalar_jit import njit

__all__ = ["window"]


@njit(forceinline=True)
def _count(a: np.ndarray, v: float, strict: bool) -> int:
    """Number of entries of the increasing ``a`` that are ``< v`` (``<= v`` unless ``strict``).

    ``np.searchsorted`` with ``side="left"`` counts the entries ``< v`` and ``side="right"`` those
    ``<= v`` (equal values included or not, exactly); a NaN ``v`` counts 0 (numpy would place it after
    every number), so a NaN bound never widens a window.
    """
    if v != v:
        return 0
    if strict:
        return int(np.searchsorted(a, v, side="left"))
    return int(np.searchsorted(a, v, side="right"))


@njit
def window(xs: np.ndarray, nys: np.ndarray, x0: float, y0: float, x1: float, y1: float
           ) -> tuple[int, int, int, int]:  # fmt: skip
    """Rows ``r0:r1`` and columns ``c0:c1`` of the cells meeting the closed box ``[x0, x1] × [y0, y1]``.

    ``xs`` and ``nys = -ys`` are the grid's exact cell bounds (increasing). A cell meets the box when its
    closed extent does, so a box edge on a cell bound takes the cells on both sides; the result is clipped
    to the grid, and is empty (``r0 >= r1`` or ``c0 >= c1``) when the box misses it.
    """
    nx, ny = xs.size - 1, nys.size - 1
    c0 = min(max(_count(xs, x0, True) - 1, 0), nx)
    c1 = min(max(_count(xs, x1, False), c0), nx)
    r0 = min(max(_count(nys, -y1, True) - 1, 0), ny)
    r1 = min(max(_count(nys, -y0, False), r0), ny)
    return r0, r1, c0, c1
