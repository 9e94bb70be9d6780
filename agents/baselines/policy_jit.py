"""Compiled kernel of the baselines' bookkeeping (:mod:`.policy`): the pixels of a disc.

:func:`disk` is :meth:`.policy.BaselinePolicy._disk` without numpy's per-call costs: the pixels whose centre
``(r + 0.5, c + 0.5)`` lies within the radius of a fractional pixel, tested on the disc's bounding window
only, with the same floating-point operations (``(r + 0.5 - y)² + (c + 0.5 - x)² <= r²``, ``r²`` given).

>>> int(disk(5, 2.5, 2.5, 1.0, 1.0).sum()), bool(disk(5, 2.5, 2.5, 1.0, 1.0)[2, 2])
(5, True)
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.scalar_jit import njit


@njit
def disk(m: int, y: float, x: float, radius: float, r2: float) -> np.ndarray:
    """``(m, m)`` bool: the pixels whose centre lies within ``radius`` (``r2`` = its square) of ``(y, x)``
    (row, column; fractional pixels)."""
    out = np.zeros((m, m), dtype=np.bool_)
    r0, r1 = max(int(math.floor(y - radius)) - 1, 0), min(int(math.ceil(y + radius)) + 1, m)
    c0, c1 = max(int(math.floor(x - radius)) - 1, 0), min(int(math.ceil(x + radius)) + 1, m)
    for r in range(r0, r1):
        dy = r + 0.5 - y
        for c in range(c0, c1):
            dx = c + 0.5 - x
            out[r, c] = dy * dy + dx * dx <= r2
    return out
