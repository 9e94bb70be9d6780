"""Thick paver: clear / penumbra / dark pavings of a thick set (thesis §5.3, Remark 5.3).

One generation of boxes is classified per separator call, as in :func:`observer.paver.pave`. A box
proved in the penumbra ``X⁺ \\ X⁻`` is never bisected: this is what keeps the paving from
accumulating deep inside the penumbra (§5.3). The clear zone lower-bounds ``X⁻`` and
``clear ∪ penumbra ∪ undetermined`` upper-bounds ``X⁺``:

>>> from digslam.observer import Box, SepBox
>>> from digslam.observer.thick.sep import ThickSep
>>> ts = ThickSep(SepBox(Box([(-1, 1), (-1, 1)])), SepBox(Box([(-2, 2), (-2, 2)])))
>>> p = thick_pave(([-3.0, -3.0], [3.0, 3.0]), ts, 0.1)
>>> 3.4 < p.clear_area <= 4.0, 16.0 <= p.penumbra_area + p.clear_area + p.boundary_area < 17.1
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from digslam.observer.core.boxes import empty_rows, validate_batch, volume
from digslam.observer.core.types import Batch
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA


class ThickTest(Protocol):
    """What :func:`thick_pave` needs: ``n`` and ``classify(lo, hi)`` returning ``int8`` codes
    (:data:`CLEAR`, :data:`PENUMBRA`, :data:`DARK`, ``0`` unknown), e.g. a
    :class:`~.sep.ThickSep` or a :class:`~.sivia.ThickInverse`."""

    n: int | None

    def classify(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray: ...


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

    def draw(self, ax: Any = None, frame: Any = None, title: str | None = None,
             linewidth: float = 0.1) -> Any:  # fmt: skip
        """Draw the paving (needs matplotlib): clear red, penumbra orange, dark blue, undetermined yellow."""
        from digslam.observer.paving.draw import (
            BOUNDARY_COLOR,
            CLEAR_COLOR,
            DARK_COLOR,
            PENUMBRA_COLOR,
            draw_boxes,
            new_figure,
        )

        ax = new_figure()[1] if ax is None else ax
        for b, col in ((self.dark, DARK_COLOR), (self.clear, CLEAR_COLOR), (self.penumbra, PENUMBRA_COLOR),
                       (self.boundary, BOUNDARY_COLOR)):  # fmt: skip
            if b[0].shape[0]:
                draw_boxes(b[0], b[1], ax=ax, color=col, linewidth=linewidth)
        if frame is not None:
            pair = frame.pair if hasattr(frame, "pair") else frame
            flo, fhi = (np.asarray(v, np.float64).ravel() for v in pair)
            ax.set_xlim(flo[0], fhi[0]), ax.set_ylim(flo[1], fhi[1])
        ax.set_aspect("equal")
        if title:
            ax.set_title(title)
        return ax

    @property
    def n_boxes(self) -> int:
        """Number of boxes of the paving (``bisections + 1`` leaves of the bisection tree)."""
        return sum(int(b[0].shape[0]) for b in (self.clear, self.penumbra, self.dark, self.boundary))


def _bisect_finite(box: np.ndarray, w: np.ndarray, n: int) -> np.ndarray:
    """Halve bounded boxes ``[lo | hi]`` ``(N, 2n)`` across their (first) widest coordinate
    (Algorithm A.2); the two halves are stacked. Loops run over the dimension, not the boxes."""
    k, best = np.zeros(box.shape[0], dtype=np.intp), w[:, 0]
    for j in range(1, n):
        wider = w[:, j] > best
        k[wider], best = j, np.maximum(best, w[:, j])
    a, b = box[:, 0], box[:, n]
    sel = [k == j for j in range(n)]
    for j in range(1, n):
        a, b = np.where(sel[j], box[:, j], a), np.where(sel[j], box[:, n + j], b)
    cut = np.minimum(np.maximum(0.5 * a + 0.5 * b, a), b)  # inside [a, b] whatever the rounding
    m = box.shape[0]
    out = np.concatenate([box, box])
    for j in range(n):
        out[:m, n + j] = np.where(sel[j], cut, box[:, n + j])
        out[m:, j] = np.where(sel[j], cut, box[:, j])
    return out


def thick_pave(x0: Any, tsep: ThickTest, eps: float, max_boxes: int = 20_000_000) -> ThickPaving:
    """Pave ``x0`` with a thick separator down to width ``eps``; penumbra boxes are not bisected.

    Args:
        x0: the initial box ``(lo, hi)`` or an :class:`IntervalArray` of shape ``(n,)``.
        tsep: the thick separator of ``[X⁻, X⁺]`` (Eq. 5.19), or any :class:`ThickTest`.
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
    n = lo.shape[1]
    out: dict[int, list[np.ndarray]] = {int(CLEAR): [], int(PENUMBRA): [], int(DARK): [], 0: []}
    bisections = 0
    box = np.concatenate([lo, hi], axis=1)  # one generation as rows [lo | hi]: one compress per list
    while box.shape[0]:
        if box.shape[0] > max_boxes:
            raise ValueError(f"thick_pave: a generation holds {box.shape[0]} > max_boxes={max_boxes} boxes")
        st = tsep.classify(box[:, :n], box[:, n:])
        for code in (CLEAR, PENUMBRA, DARK):
            out[int(code)].append(np.compress(st == code, box, axis=0))
        box = np.compress(st == 0, box, axis=0)
        w = box[:, n:] - box[:, :n]  # the stopping rule only: no claim rests on it
        wmax = w[:, 0]
        for j in range(1, n):
            wmax = np.maximum(wmax, w[:, j])
        small = wmax <= eps
        out[0].append(np.compress(small, box, axis=0))
        split = ~small
        bisections += int(np.count_nonzero(split))
        box = _bisect_finite(np.compress(split, box, axis=0), np.compress(split, w, axis=0), n)

    def cat(parts: list[np.ndarray]) -> Batch:
        b = np.concatenate(parts)
        return np.ascontiguousarray(b[:, :n]), np.ascontiguousarray(b[:, n:])

    return ThickPaving(cat(out[1]), cat(out[2]), cat(out[-1]), cat(out[0]), bisections)


__all__ = ["ThickPaving", "ThickTest", "thick_pave"]
