"""Checks for separators, for users writing their own (in the spirit of ``numpy.testing``).

>>> from digslam.observer import Function, Interval, SepInverse
>>> disk = SepInverse(Function(lambda x: x[0] ** 2 + x[1] ** 2), Interval(0, 4))
>>> lo, hi = random_boxes([-3, -3], [3, 3], 500, 1.0)
>>> assert_separator_sound(disk, lo, hi, lambda p: (p**2).sum(axis=1) <= 4)
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from digslam.observer.sets.separators import Sep, check_separation


def random_boxes(
    frame_lo: Any, frame_hi: Any, n: int, max_w: float, seed: int = 1
) -> tuple[np.ndarray, np.ndarray]:
    """``n`` boxes with centres uniform in the frame and widths uniform in ``[0, max_w]`` per side."""
    rng = np.random.default_rng(seed)
    flo, fhi = np.asarray(frame_lo, dtype=np.float64), np.asarray(frame_hi, dtype=np.float64)
    c = flo + rng.random((n, flo.size)) * (fhi - flo)
    w = rng.random((n, flo.size)) * max_w
    return c - w / 2, c + w / 2


def assert_separator_sound(
    sep: Sep, lo: np.ndarray, hi: np.ndarray, member: Callable[[np.ndarray], np.ndarray], per_box: int = 64,
    seed: int = 0,
) -> None:  # fmt: skip
    """Assert ``x_in ∪ x_out = x`` and soundness by sampling on a batch.

    Points of ``[x] \\ [x_in]`` (proved inside) must satisfy ``member``; points of ``[x] \\ [x_out]``
    (proved outside) must not. ``member`` maps ``(K, n)`` points to ``(K,)`` booleans and should be exact
    (rational arithmetic) when points may lie within rounding distance of the border.

    Raises:
        AssertionError: naming the first failing box and point.
    """
    (ilo, ihi), (olo, ohi) = sep.separate(lo, hi)
    bad = check_separation((ilo, ihi), (olo, ohi), lo, hi)
    assert not bad.any(), f"x_in ∪ x_out != x for box {int(np.flatnonzero(bad)[0])}"
    rng = np.random.default_rng(seed)
    n, d = lo.shape
    pts = lo[:, None] + rng.random((n, per_box, d)) * (hi - lo)[:, None]
    in_in = ((ilo[:, None] <= pts) & (pts <= ihi[:, None])).all(axis=2)
    in_out = ((olo[:, None] <= pts) & (pts <= ohi[:, None])).all(axis=2)
    m = member(pts.reshape(-1, d)).reshape(n, per_box)
    wrong_in = ~in_in & ~m
    assert not wrong_in.any(), f"point {pts[wrong_in][0].tolist()} proved inside is not in the set"
    wrong_out = ~in_out & m
    assert not wrong_out.any(), f"point {pts[wrong_out][0].tolist()} proved outside is in the set"


__all__ = [
    "assert_separator_sound",
    "random_boxes",
]
