"""The type aliases shared by the whole project (one home, as in stable-baselines3's ``type_aliases``).

A batch of boxes is two float64 arrays ``lo, hi`` of shape ``(N, n)``: row ``i`` is the box
``[lo[i, 0], hi[i, 0]] x ... x [lo[i, n-1], hi[i, n-1]]``; an empty box has a row with ``lo > hi`` (NaN-free).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

#: A float64 array.
FloatArray = npt.NDArray[np.float64]
#: A Boolean array.
BoolArray = npt.NDArray[np.bool_]
#: Lower and upper bounds of intervals of the same shape: ``(lo, hi)``.
Pair = tuple[np.ndarray, np.ndarray]
#: A float array or a float (what the outward-rounded operations of :mod:`.rounding` accept).
Floats = np.ndarray | float
#: A batch of boxes: ``(lo, hi)`` of shape ``(N, n)`` each.
Batch = tuple[np.ndarray, np.ndarray]

__all__ = ["Batch", "BoolArray", "FloatArray", "Floats", "Pair"]
