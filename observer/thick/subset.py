"""Subset–supset thick intervals and ThickSivia with them (thesis App. A, §A.3, Eqs. A.13–A.15, Fig. A.8).

A thick interval ``⟦x⟧ = ⟦[x⁻], [x⁺]⟧`` (Eq. A.12) can be replaced by its *subset bound*
``[x^⊂] = ⋂ ⟦x⟧ = [ub [x⁻], lb [x⁺]]`` (Eq. A.13, possibly empty) and its *supset bound*
``[x^⊃] = ⋃ ⟦x⟧ = [lb [x⁻], ub [x⁺]]`` (Eq. A.14). The subset–supset representation stands for
every interval ``[x]`` with ``[x^⊂] ⊂ [x] ⊂ [x^⊃]`` (Eq. A.15). It holds every member of ``⟦x⟧``,
and the tests below decide as the lower–upper ones of Prop. A.1 while ``[x^⊂] ≠ ∅``; when
``[x^⊂] = ∅`` it adds pessimism: any interval inside ``[x^⊃]``, a point included, is then a member.
Figure A.2: ``⟦[3, 7], [6, 8]⟧`` has ``[b^⊂] = ∅``, ``[b^⊃] = [3, 8]``, so
``[4, 5]`` is a member of the representation but not of ``⟦b⟧``. Example A.2 / Figure A.3: with
``⟦b⟧ = ⟦[2, 4], [3, 6]⟧`` the lower–upper test proves ``[1, 5] ∩ [b] ≠ ∅`` for every member (Prop. A.1
iv) but the subset–supset one cannot (``[6, 6]`` is a member of ``∅ ⊂ [b] ⊂ [2, 6]``):

>>> from digslam.observer.thick.interval import TRUE, UNKNOWN, ThickIntervalArray, thin
>>> b = ThickIntervalArray([2.0], [4.0], [3.0], [6.0])
>>> bool(b.overlaps(thin([1.0], [5.0]))[0] == TRUE)
True
>>> bool(SubsetSupsetArray.from_thick(b).overlaps([1.0], [5.0])[0] == UNKNOWN)
True

:class:`ThickInverseSubsetSupset` is :class:`~.sivia.ThickInverse` (Algorithm A.2) with the four
tests of Prop. A.1 taken on the subset–supset representation of ``⟦f⟧([x])`` (the centre of Fig. A.8);
:func:`thick_sivia_subset_supset` paves with it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.thick.function import ThickFunction
from digslam.observer.thick.interval import FALSE, TRUE, ThickIntervalArray, tri_state
from digslam.observer.thick.paver import ThickPaving, thick_pave
from digslam.observer.thick.sivia import ThickInverse


class SubsetSupsetArray:
    """Batch of subset–supset intervals ``{[x] | [x^⊂] ⊂ [x] ⊂ [x^⊃]}`` (Eq. A.15).

    ``sub = (sub_lo, sub_hi)`` is empty where ``sub_lo > sub_hi``; ``sup = (sup_lo, sup_hi)`` is never
    empty and contains ``sub``. The members are non-empty intervals.

    Raises:
        ValueError: shapes differ, or (with ``check``) ``sup`` is empty or a non-empty ``sub`` is not
            inside ``sup``.
    """

    def __init__(self, sub_lo: Any, sub_hi: Any, sup_lo: Any, sup_hi: Any, *, check: bool = True) -> None:
        arrs = [np.asarray(v, dtype=np.float64) for v in (sub_lo, sub_hi, sup_lo, sup_hi)]
        if len({a.shape for a in arrs}) != 1:
            raise ValueError(f"subset-supset arrays must share one shape, got {[a.shape for a in arrs]}")
        self.sub_lo, self.sub_hi, self.sup_lo, self.sup_hi = arrs
        ne = self.sub_lo <= self.sub_hi
        outside = ne & ((self.sub_lo < self.sup_lo) | (self.sub_hi > self.sup_hi))
        if check and (np.any(self.sup_lo > self.sup_hi) or np.any(outside)):
            raise ValueError("subset-supset: expected a non-empty supset bound containing the subset bound")

    @classmethod
    def from_thick(cls, t: ThickIntervalArray) -> SubsetSupsetArray:
        """``[x^⊂] = [ub [x⁻], lb [x⁺]]`` (Eq. A.13) and ``[x^⊃] = [lb [x⁻], ub [x⁺]]`` (Eq. A.14)."""
        return cls(t.lo_hi, t.hi_lo, t.lo_lo, t.hi_hi)

    @property
    def sub_empty(self) -> np.ndarray:
        """Where the subset bound is empty (``[x⁻] ∩ [x⁺] = ∅`` with ``[x⁻]`` above ``[x⁺]``)."""
        return self.sub_lo > self.sub_hi

    def subset_of(self, b_lo: Any, b_hi: Any) -> np.ndarray:
        """Tri-state of ``[x] ⊂ [b]`` for every member (Prop. A.1 i–ii on the representation).

        True iff ``[x^⊃] ⊂ [b]``. False for every member iff ``[x^⊂] ⊄ [b]`` when ``[x^⊂] ≠ ∅``, and iff
        ``[x^⊃] ∩ [b] = ∅`` when ``[x^⊂] = ∅`` (points of ``[x^⊃]`` are members).
        """
        b_lo, b_hi = np.asarray(b_lo, np.float64), np.asarray(b_hi, np.float64)
        true = (self.sup_lo >= b_lo) & (self.sup_hi <= b_hi)
        disjoint = (self.sup_hi < b_lo) | (self.sup_lo > b_hi)
        false = np.where(self.sub_empty, disjoint, (self.sub_lo < b_lo) | (self.sub_hi > b_hi))
        return tri_state(true, false)

    def overlaps(self, b_lo: Any, b_hi: Any) -> np.ndarray:
        """Tri-state of ``[x] ∩ [b] ≠ ∅`` for every member (Prop. A.1 iii–iv on the representation).

        True iff ``[x^⊂] ∩ [b] ≠ ∅`` when ``[x^⊂] ≠ ∅``, and iff ``[x^⊃] ⊂ [b]`` when ``[x^⊂] = ∅``.
        False iff ``[x^⊃] ∩ [b] = ∅``.
        """
        b_lo, b_hi = np.asarray(b_lo, np.float64), np.asarray(b_hi, np.float64)
        meets_sub = (self.sub_lo <= b_hi) & (b_lo <= self.sub_hi)
        inside = (self.sup_lo >= b_lo) & (self.sup_hi <= b_hi)
        true = np.where(self.sub_empty, inside, meets_sub)
        false = (self.sup_hi < b_lo) | (self.sup_lo > b_hi)
        return tri_state(true, false)


class ThickInverseSubsetSupset(ThickInverse):
    """Algorithm A.2's tests on the subset–supset representation of ``⟦f⟧([x])`` (Fig. A.8, centre).

    Same arguments and codes as :class:`~.sivia.ThickInverse`; the enclosures always come from
    the outward-rounded ``f.eval`` and the comparisons are exact, so the claims hold in floating point.
    Clear and dark boxes are the same as with lower–upper bounds (they only use ``[x^⊃]``); the
    penumbra is proved for fewer boxes, none while ``[x^⊂]`` is empty and ``[x^⊃]`` straddles a bound.
    """

    def _masks(self, lo: np.ndarray, hi: np.ndarray) -> list[np.ndarray]:
        a = self._shape(self.f.eval(lo, hi), lo.shape[0])
        bad = (np.isnan(a.lo_lo) | np.isnan(a.hi_hi) | (a.lo_lo > a.lo_hi) | (a.hi_lo > a.hi_hi)).any(axis=1)
        if np.any(~bad & (a.lo_lo > a.hi_hi).any(axis=1)):
            raise ValueError("f: the enclosures prove f- > f+ on a box: not a thick function")
        ss = SubsetSupsetArray(a.lo_hi, a.hi_lo, a.lo_lo, a.hi_hi, check=False)  # bad rows masked below
        ov = ss.overlaps(*self.yp)
        dark, meets = (ov == FALSE).any(axis=1), (ov == TRUE).all(axis=1)
        if self.ym is None:
            clear, leaves = np.zeros_like(dark), np.ones_like(dark)
        else:
            sub = ss.subset_of(*self.ym)
            clear, leaves = (sub == TRUE).all(axis=1), (sub == FALSE).any(axis=1)
        return [clear & ~bad, dark & ~bad, meets & ~bad, leaves & ~bad]


def thick_sivia_subset_supset(x0: Any, f: ThickFunction, y_lower: Any, y_upper: Any = None, *, eps: float,
                              max_boxes: int = 20_000_000) -> ThickPaving:  # fmt: skip
    """ThickSivia (Algorithm A.2) with subset–supset thick intervals (Eq. A.15; Fig. A.8, centre).

    Args and result as :func:`~.sivia.thick_sivia` (Theorem A.2 holds: the representation
    contains every member of ``⟦f⟧([x])``).
    """
    return thick_pave(x0, ThickInverseSubsetSupset(f, y_lower, y_upper), eps, max_boxes)


__all__ = ["SubsetSupsetArray", "ThickInverseSubsetSupset", "thick_sivia_subset_supset"]
