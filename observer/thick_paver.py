"""Thick paver: clear / penumbra / dark pavings of a thick set (thesis §5.3, Remark 5.3).

One generation of boxes is classified per separator call, as in :func:`observer.paver.pave`. A box
proved in the penumbra ``X⁺ \\ X⁻`` is never bisected: this is what keeps the paving from
accumulating deep inside the penumbra (§5.3). The clear zone lower-bounds ``X⁻`` and
``clear ∪ penumbra ∪ undetermined`` upper-bounds ``X⁺``:

>>> from digslam.observer import Box, SepBox
>>> from digslam.observer.thick_sep import ThickSep
>>> ts = ThickSep(SepBox(Box([(-1, 1), (-1, 1)])), SepBox(Box([(-2, 2), (-2, 2)])))
>>> p = thick_pave(([-3.0, -3.0], [3.0, 3.0]), ts, 0.1)
>>> 3.4 < p.clear_area <= 4.0, 16.0 <= p.penumbra_area + p.clear_area + p.boundary_area < 17.1
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .boxes import bisect, empty_rows, validate_batch, volume, width_inf
from .separators import Batch
from .thick_sep import CLEAR, DARK, PENUMBRA, ThickSep


@dataclass
class ThickPaving:
    """Result of :func:`thick_pave`: ``clear`` (⊂ X⁻), ``penumbra`` (⊂ X⁺ \\ X⁻), ``dark``
    (∩ X⁺ = ∅), ``boundary`` (undetermined boxes narrower than ``eps``), and the bisection count."""

    clear: Batch
    penumbra: Batch
    dark: Batch
    boundary: Batch
    bisections: int

    @staticmethod
    def _area(b: Batch) -> float:
        return float(volume(*b).sum()) if b[0].size else 0.0

    @property
    def clear_area(self) -> float:
        """Volume proved in ``X⁻``."""
        return self._area(self.clear)

    @property
    def penumbra_area(self) -> float:
        """Volume proved in the penumbra."""
        return self._area(self.penumbra)

    @property
    def dark_area(self) -> float:
        """Volume proved outside ``X⁺``."""
        return self._area(self.dark)

    @property
    def boundary_area(self) -> float:
        """Volume left undetermined."""
        return self._area(self.boundary)


def thick_pave(x0: Any, tsep: ThickSep, eps: float, max_boxes: int = 20_000_000) -> ThickPaving:
    """Pave ``x0`` with a thick separator down to width ``eps``; penumbra boxes are not bisected.

    Args:
        x0: the initial box ``(lo, hi)`` or an :class:`IntervalArray` of shape ``(n,)``.
        tsep: the thick separator of ``[X⁻, X⁺]`` (Eq. 5.19).
        eps: width ``w∞`` under which an unknown box is kept as boundary (``> 0``).
        max_boxes: guard on the number of boxes in one generation.

    Raises:
        ValueError: on a bad ``eps``, an empty/unbounded/multiple initial box, a generation over
            ``max_boxes``, or inconsistent bounds (``X⁻ ⊄ X⁺`` detected on a box).
    """
    lo0, hi0 = x0.pair if hasattr(x0, "pair") else x0
    if not (isinstance(eps, (int, float, np.floating)) and np.isfinite(eps) and eps > 0):
        raise ValueError(f"eps: must be a positive finite number, got {eps!r}")
    lo, hi = validate_batch(lo0, hi0, "x0", tsep.n)
    if lo.shape[0] != 1 or empty_rows(lo, hi).any() or not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise ValueError(f"x0: expected one non-empty bounded box, got {lo.tolist()} {hi.tolist()}")
    out: dict[int, list[Batch]] = {int(CLEAR): [], int(PENUMBRA): [], int(DARK): [], 0: []}
    bisections = 0
    while lo.shape[0]:
        if lo.shape[0] > max_boxes:
            raise ValueError(f"thick_pave: a generation holds {lo.shape[0]} > max_boxes={max_boxes} boxes")
        st = tsep.classify(lo, hi)
        for code in (CLEAR, PENUMBRA, DARK):
            m = st == code
            out[int(code)].append((lo[m], hi[m]))
        unk = st == 0
        small = unk & (width_inf(lo, hi) <= eps)
        out[0].append((lo[small], hi[small]))
        split = unk & ~small
        bisections += int(split.sum())
        (l1, h1), (l2, h2) = bisect(lo[split], hi[split])
        lo, hi = np.concatenate([l1, l2]), np.concatenate([h1, h2])

    def cat(parts: list[Batch]) -> Batch:
        return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])

    return ThickPaving(cat(out[1]), cat(out[2]), cat(out[-1]), cat(out[0]), bisections)


__all__ = ["ThickPaving", "thick_pave"]
