"""Thick intervals ``⟦[x⁻],[x⁺]⟧`` on batches (thesis App. A, §A.3, Eq. A.16, Prop. A.1-A.2).

A thick interval is the set of intervals ``[x] = [x⁻, x⁺]`` whose lower bound lies in ``[x⁻]`` and
upper bound in ``[x⁺]``. It is stored as two :mod:`arith` pairs: ``lo = (lo_lo, lo_hi)`` and
``hi = (hi_lo, hi_hi)``. Comparisons return int8 tri-states :data:`TRUE`, :data:`FALSE`,
:data:`UNKNOWN` ("proved for every member", "proved false for every member", undecided).

Example (§A.3):
    >>> a = ThickIntervalArray([1.0], [2.0], [4.0], [5.0])
    >>> b = ThickIntervalArray([3.0], [7.0], [6.0], [8.0])
    >>> (a & b).as_tuple()
    ((3.0, 7.0), (4.0, 5.0))
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core import arith

TRUE = np.int8(1)
FALSE = np.int8(0)
UNKNOWN = np.int8(-1)


def tri_state(true: np.ndarray, false: np.ndarray) -> np.ndarray:
    """The int8 tri-state of two masks: :data:`TRUE` where ``true``, else :data:`FALSE` where ``false``,
    else :data:`UNKNOWN`."""
    out = np.full(np.shape(true), UNKNOWN, dtype=np.int8)
    out[np.asarray(false)] = FALSE
    out[np.asarray(true)] = TRUE
    return out


class ThickIntervalArray:
    """Batch of thick intervals ``⟦[x⁻],[x⁺]⟧`` (§A.3), all arrays of the same shape.

    Raises:
        ValueError: shapes differ, a bound interval is empty, or ``x⁻ > x⁺`` for every member
            (``lo_lo > hi_hi``).
    """

    def __init__(self, lo_lo, lo_hi, hi_lo, hi_hi, *, check: bool = True) -> None:
        arrs = [np.asarray(v, dtype=np.float64) for v in (lo_lo, lo_hi, hi_lo, hi_hi)]
        if len({a.shape for a in arrs}) != 1:
            raise ValueError(f"thick interval arrays must share one shape, got {[a.shape for a in arrs]}")
        self.lo_lo, self.lo_hi, self.hi_lo, self.hi_hi = arrs
        if check:
            if np.any(self.lo_lo > self.lo_hi) or np.any(self.hi_lo > self.hi_hi):
                raise ValueError("thick interval: bound intervals [x-] and [x+] must be non-empty")
            bad = self.lo_lo > self.hi_hi
            if np.any(bad):
                raise ValueError(
                    f"thick interval with x- > x+ for every member at indices {np.flatnonzero(bad)[:5]}"
                )

    @property
    def lo(self) -> tuple[np.ndarray, np.ndarray]:
        """Interval ``[x⁻]`` of lower bounds as an arith pair."""
        return self.lo_lo, self.lo_hi

    @property
    def hi(self) -> tuple[np.ndarray, np.ndarray]:
        """Interval ``[x⁺]`` of upper bounds as an arith pair."""
        return self.hi_lo, self.hi_hi

    @classmethod
    def _from_pairs(cls, lo, hi, check: bool = False) -> ThickIntervalArray:
        return cls(lo[0], lo[1], hi[0], hi[1], check=check)

    def as_tuple(self) -> tuple:
        """Scalar view ``((lo_lo, lo_hi), (hi_lo, hi_hi))`` for a batch of one element."""
        return (
            (float(self.lo_lo.ravel()[0]), float(self.lo_hi.ravel()[0])),
            (float(self.hi_lo.ravel()[0]), float(self.hi_hi.ravel()[0])),
        )

    # Arithmetic on the bounds (Eq. A.16): monotonic operations act bound-wise.
    def __add__(self, o: ThickIntervalArray) -> ThickIntervalArray:
        """``⟦a⁻ + b⁻, a⁺ + b⁺⟧`` with outward rounding."""
        return self._from_pairs(arith.add(self.lo, o.lo), arith.add(self.hi, o.hi))

    def __sub__(self, o: ThickIntervalArray) -> ThickIntervalArray:
        """``⟦a⁻ − b⁺, a⁺ − b⁻⟧`` with outward rounding."""
        return self._from_pairs(arith.sub(self.lo, o.hi), arith.sub(self.hi, o.lo))

    def __neg__(self) -> ThickIntervalArray:
        """``⟦−a⁺, −a⁻⟧``."""
        return self._from_pairs(arith.neg(self.hi), arith.neg(self.lo))

    def __and__(self, o: ThickIntervalArray) -> ThickIntervalArray:
        """Intersection ``⟦max(a⁻, b⁻), min(a⁺, b⁺)⟧`` (Eq. A.16)."""
        return self._from_pairs(arith.maximum(self.lo, o.lo), arith.minimum(self.hi, o.hi))

    def __or__(self, o: ThickIntervalArray) -> ThickIntervalArray:
        """Hull union ``⟦min(a⁻, b⁻), max(a⁺, b⁺)⟧`` (Eq. A.16, the ⊔ of §A.3)."""
        return self._from_pairs(arith.minimum(self.lo, o.lo), arith.maximum(self.hi, o.hi))

    # ∀-comparisons (Prop. A.1, A.2); `o` may be thick, an IntervalArray-like (lo, hi) pair too.
    def subset_of(self, o: ThickIntervalArray) -> np.ndarray:
        """Tri-state of ``[a] ⊂ [b]`` for all ``[a] ∈ ⟦a⟧, [b] ∈ ⟦b⟧`` (Prop. A.1)."""
        true = (self.lo_lo >= o.lo_hi) & (self.hi_hi <= o.hi_lo)
        false = (self.lo_hi < o.lo_lo) | (self.hi_lo > o.hi_hi)
        return tri_state(true, false)

    def not_subset_of(self, o: ThickIntervalArray) -> np.ndarray:
        """Tri-state of ``[a] ⊄ [b]`` for all members (negation of :meth:`subset_of`)."""
        return _negate(self.subset_of(o))

    def overlaps(self, o: ThickIntervalArray) -> np.ndarray:
        """Tri-state of ``[a] ∩ [b] ≠ ∅`` for all members (Prop. A.2, Example A.2)."""
        true = (self.lo_hi <= o.hi_lo) & (o.lo_hi <= self.hi_lo)
        false = (self.lo_lo > o.hi_hi) | (o.lo_lo > self.hi_hi)
        return tri_state(true, false)

    def disjoint(self, o: ThickIntervalArray) -> np.ndarray:
        """Tri-state of ``[a] ∩ [b] = ∅`` for all members (negation of :meth:`overlaps`)."""
        return _negate(self.overlaps(o))


def _negate(t: np.ndarray) -> np.ndarray:
    out = t.copy()
    out[t == TRUE] = FALSE
    out[t == FALSE] = TRUE
    return out


def thin(lo, hi) -> ThickIntervalArray:
    """Degenerate thick interval ``⟦[lo, lo], [hi, hi]⟧`` holding the single interval ``[lo, hi]``."""
    return ThickIntervalArray(lo, lo, hi, hi)


__all__ = [
    "FALSE",
    "TRUE",
    "ThickIntervalArray",
    "UNKNOWN",
    "thin",
    "tri_state",
]
