"""Regular pavings (thesis §2.4.3): every cell of a grid over a 2-d box classified by one separator call.

>>> ring = SepInverse(Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2), Interval(1, 2.25))
>>> s = classify_grid(Box([(-1, 5), (-0.5, 5.5)]), ring, (12, 12))       # cells of 0.5 × 0.5
>>> int(s[5, 6]), int(s[0, 0]), int(s[2, 6])     # by the centre, a corner, across the ring
(-1, -1, 0)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core.boxes import empty_rows
from digslam.observer.core.interval import IntervalArray
from digslam.observer.sets.separators import Sep


def classify_grid(x0: IntervalArray | Any, sep: Sep, shape: tuple[int, int]) -> np.ndarray:
    """Regular paving of a 2-d box: classify each cell of an ``(ny, nx)`` grid with ``sep``.

    Cells are the boxes of a regular grid over ``x0`` (a batch, so the same separator as the paver
    runs once on all cells). Rows follow the image convention (Remark 2.7): row 0 is the top
    (largest ``y``).

    Returns:
        ``int8`` array ``(ny, nx)``: ``1`` proved inside, ``-1`` proved outside, ``0`` undetermined.
    """
    lo0, hi0 = x0.pair if isinstance(x0, IntervalArray) else x0
    lo0, hi0 = np.asarray(lo0, dtype=np.float64), np.asarray(hi0, dtype=np.float64)
    ny, nx = shape
    if lo0.shape != (2,) or nx < 1 or ny < 1:
        raise ValueError(f"classify_grid: need a 2-d box and a positive shape, got {lo0.shape} and {shape}")
    xs = np.linspace(lo0[0], hi0[0], nx + 1)
    ys = np.linspace(hi0[1], lo0[1], ny + 1)  # top to bottom
    gx, gy = np.meshgrid(np.arange(nx), np.arange(ny))
    lo = np.stack([xs[gx.ravel()], ys[gy.ravel() + 1]], axis=1)
    hi = np.stack([xs[gx.ravel() + 1], ys[gy.ravel()]], axis=1)
    xin, xout = sep.separate(lo, hi)
    status = np.zeros(nx * ny, dtype=np.int8)
    status[empty_rows(*xin)] = 1
    status[empty_rows(*xout)] = -1
    return status.reshape(ny, nx)


__all__ = [
    "classify_grid",
]
