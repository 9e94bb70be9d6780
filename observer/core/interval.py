"""Interval arrays: the user-facing interval type, batched (thesis §2.3.1).

An :class:`IntervalArray` holds two float64 arrays ``lo`` and ``hi`` of one shape. Shape ``()`` is a
single interval, ``(n,)`` a box, ``(N, n)`` a batch of ``N`` boxes. Arithmetic broadcasts like numpy
and rounds outward. :func:`Interval` and :func:`Box` are conveniences for scalars and single boxes.
A float ``±inf`` operand is no real number and reads as the empty interval (:func:`as_pair`).

>>> Interval(-1, 5) & Interval(-3, 2)          # Ex. 2.1
Interval(-1.0, 2.0)
>>> Interval(-3, 3) | Interval(4, 10)
Interval(-3.0, 10.0)
>>> Interval(-3, 3) - Interval(4, 10)
Interval(-13.0, -1.0)
>>> float(Interval(-2, 9).width())
11.0
>>> bool((Interval(1, 2) & Interval(3, 4)).is_empty())
True
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from digslam.observer.core import arith
from digslam.observer.core.types import Pair

#: types an interval operator hands over to (their reflected operator builds the result);
#: :mod:`digslam.observer.expr.expr` registers its ``Expr`` here
DEFER_TO: tuple[type, ...] = ()


def _check_bounds(lo: np.ndarray, hi: np.ndarray, name: str) -> None:
    if np.isnan(lo).any() or np.isnan(hi).any():
        raise ValueError(f"{name}: NaN bound at index {np.argwhere(np.isnan(lo) | np.isnan(hi))[0].tolist()}")
    empty = (lo == np.inf) & (hi == -np.inf)
    bad = (lo > hi) & ~empty
    if bad.any():
        i = tuple(np.argwhere(bad)[0].tolist())
        raise ValueError(f"{name}: lower bound {lo[i]} above upper bound {hi[i]} at index {list(i)}")
    inf_member = ((lo == np.inf) | (hi == -np.inf)) & ~empty
    if inf_member.any():
        i = tuple(np.argwhere(inf_member)[0].tolist())
        raise ValueError(f"{name}: [{lo[i]}, {hi[i]}] at index {list(i)} has an infinite point as a member")


def as_pair(x: Any, name: str = "x") -> Pair:
    """Bounds of ``x`` (an :class:`IntervalArray`, a number or a float array taken as points).

    A point ``±inf`` is no real number (IEEE 1788-2015 §7.2): it becomes the empty interval, so every
    operation of a float ``±inf`` with an interval is empty (``Interval(0, 1) + inf``,
    ``Interval(1, 2) * inf``, ``Interval(1, 2) / inf``: all ``Interval.empty()``).

    Raises:
        ValueError: on a NaN point.
    """
    if isinstance(x, IntervalArray):
        return x.lo, x.hi
    a = np.asarray(x, dtype=np.float64)
    if np.isnan(a).any():
        raise ValueError(f"{name}: NaN is not a point")
    inf = np.isinf(a)
    if inf.any():
        return np.where(inf, np.inf, a), np.where(inf, -np.inf, a)
    return a, a


class IntervalArray:
    """Array of closed real intervals ``[lo, hi]``; the empty interval is ``[+inf, -inf]``.

    Args:
        lo: lower bounds (array-like of floats).
        hi: upper bounds, same shape as ``lo``; when omitted, ``lo`` is read as ``(..., 2)`` pairs.

    Raises:
        ValueError: on NaN bounds, ``lo > hi`` (other than the empty pair) or mismatched shapes.
    """

    __slots__ = ("lo", "hi")
    __array_priority__ = 1000  # numpy defers to our reflected operators

    def __init__(self, lo: Any, hi: Any = None) -> None:
        lo = np.array(lo, dtype=np.float64)
        if hi is None:
            if lo.ndim == 0 or lo.shape[-1] != 2:
                raise ValueError(f"lo: without hi, expected pairs of shape (..., 2), got shape {lo.shape}")
            lo, hi = lo[..., 0].copy(), lo[..., 1].copy()
        else:
            hi = np.array(hi, dtype=np.float64)
        if lo.shape != hi.shape:
            raise ValueError(f"hi: shape {hi.shape} differs from the shape {lo.shape} of lo")
        _check_bounds(lo, hi, "IntervalArray")
        self.lo, self.hi = lo + 0.0, hi + 0.0

    @classmethod
    def _raw(cls, lo: np.ndarray, hi: np.ndarray) -> IntervalArray:
        obj = cls.__new__(cls)
        obj.lo, obj.hi = lo, hi
        return obj

    @classmethod
    def empty(cls, shape: int | tuple[int, ...] = ()) -> IntervalArray:
        """Empty intervals of the given shape."""
        return cls._raw(np.full(shape, np.inf), np.full(shape, -np.inf))

    @classmethod
    def entire(cls, shape: int | tuple[int, ...] = ()) -> IntervalArray:
        """``(-inf, +inf)`` intervals of the given shape."""
        return cls._raw(np.full(shape, -np.inf), np.full(shape, np.inf))

    # ---- array protocol -------------------------------------------------------------------------
    @property
    def pair(self) -> Pair:
        """``(lo, hi)``, the form the batch kernels take."""
        return self.lo, self.hi

    @property
    def shape(self) -> tuple[int, ...]:
        return self.lo.shape

    @property
    def ndim(self) -> int:
        return self.lo.ndim

    def __len__(self) -> int:
        return len(self.lo)

    def __getitem__(self, idx: Any) -> IntervalArray:
        return IntervalArray._raw(self.lo[idx], self.hi[idx])

    def __setitem__(self, idx: Any, value: Any) -> None:
        lo, hi = as_pair(value, "value")
        self.lo[idx], self.hi[idx] = lo, hi

    def copy(self) -> IntervalArray:
        return IntervalArray._raw(self.lo.copy(), self.hi.copy())

    def __repr__(self) -> str:
        if self.ndim == 0:
            if self.is_empty():
                return "Interval.empty()"
            return f"Interval({float(self.lo)!r}, {float(self.hi)!r})"
        return f"IntervalArray(lo={self.lo!r}, hi={self.hi!r})"

    # ---- predicates and measures ---------------------------------------------------------------
    def is_empty(self) -> Any:
        """Elementwise emptiness."""
        return self.lo > self.hi

    def width(self) -> Any:
        """``w([x]) = x⁺ - x⁻`` rounded up (Ex. 2.1); 0 for the empty interval."""
        from digslam.observer.core.rounding import sub_up

        with np.errstate(invalid="ignore"):
            return np.where(self.is_empty(), 0.0, sub_up(self.hi, self.lo))

    def mid(self) -> Any:
        """A midpoint inside each non-empty interval (finite when possible); NaN when empty."""
        from digslam.observer.core.boxes import midpoint

        return midpoint(self.lo, self.hi)

    def contains(self, x: Any) -> Any:
        """Whether the points (or intervals) ``x`` lie inside; ``±inf`` is never a member."""
        if not isinstance(x, IntervalArray):
            a = as_pair(x)[0]
            return (self.lo <= a) & (a <= self.hi) & np.isfinite(a)
        lo, hi = as_pair(x)
        return (self.lo <= lo) & (hi <= self.hi) | (lo > hi)

    def issubset(self, other: Any) -> Any:
        """``[self] ⊂ [other]`` elementwise (the empty set is a subset of everything)."""
        lo, hi = as_pair(other)
        return self.is_empty() | ((lo <= self.lo) & (self.hi <= hi))

    def overlaps(self, other: Any) -> Any:
        """``[self] ∩ [other] ≠ ∅`` elementwise."""
        lo, hi = as_pair(other)
        return np.maximum(self.lo, lo) <= np.minimum(self.hi, hi)

    # elementwise, as numpy's: a bool array, where object.__eq__ returns a bool
    def __eq__(self, other: object) -> Any:  # type: ignore[override]
        if not isinstance(other, (IntervalArray, int, float, np.ndarray)):
            return NotImplemented
        lo, hi = as_pair(other)
        return (self.lo == lo) & (self.hi == hi)

    # elementwise, as __eq__
    def __ne__(self, other: object) -> Any:  # type: ignore[override]
        eq = self.__eq__(other)
        return eq if eq is NotImplemented else ~eq

    __hash__ = None  # type: ignore[assignment]  # mutable arrays compared elementwise: unhashable

    def __bool__(self) -> bool:
        raise TypeError("IntervalArray: truth value is ambiguous; use is_empty(), contains() or issubset()")

    # ---- set operations ----------------------------------------------------------------------------
    def __and__(self, other: Any) -> Any:
        return self._binary(other, arith.intersect, False)

    __rand__ = __and__

    def __or__(self, other: Any) -> Any:
        return self._binary(other, arith.hull, False)

    __ror__ = __or__

    # ---- arithmetic --------------------------------------------------------------------------------
    def __neg__(self) -> IntervalArray:
        return IntervalArray._raw(*arith.neg(self.pair))

    def __pos__(self) -> IntervalArray:
        return self

    def __abs__(self) -> IntervalArray:
        return IntervalArray._raw(*arith.abs_(self.pair))

    def _binary(self, o: Any, kernel: Any, reflected: bool) -> Any:
        if isinstance(o, DEFER_TO):
            return NotImplemented  # e.g. an expression: let it build the node
        a, b = (as_pair(o), self.pair) if reflected else (self.pair, as_pair(o))
        return IntervalArray._raw(*kernel(a, b))

    def __add__(self, o: Any) -> Any:
        return self._binary(o, arith.add, False)

    def __radd__(self, o: Any) -> Any:
        return self._binary(o, arith.add, True)

    def __sub__(self, o: Any) -> Any:
        return self._binary(o, arith.sub, False)

    def __rsub__(self, o: Any) -> Any:
        return self._binary(o, arith.sub, True)

    def __mul__(self, o: Any) -> Any:
        return self._binary(o, arith.mul, False)

    def __rmul__(self, o: Any) -> Any:
        return self._binary(o, arith.mul, True)

    def __truediv__(self, o: Any) -> Any:
        return self._binary(o, arith.div, False)

    def __rtruediv__(self, o: Any) -> Any:
        return self._binary(o, arith.div, True)

    def __pow__(self, n: int) -> IntervalArray:
        if not isinstance(n, (int, np.integer)):
            raise ValueError(f"IntervalArray ** n: n must be an integer, got {n!r} (use exp(n*log(x)))")
        return IntervalArray._raw(*(arith.sqr(self.pair) if n == 2 else arith.pown(self.pair, n)))


def Interval(lo: float, hi: float | None = None) -> IntervalArray:  # noqa: N802 - thesis name
    """A single interval ``[lo, hi]`` (``[lo, lo]`` when ``hi`` is omitted).

    >>> Interval(1, 2) + Interval(0.5)
    Interval(1.5, 2.5)
    """
    return IntervalArray(lo, lo if hi is None else hi)


def Box(bounds: Sequence[Sequence[float]] | IntervalArray) -> IntervalArray:  # noqa: N802
    """A single box from per-dimension ``(lo, hi)`` pairs: ``Box([(1, 2), (2, 9)])`` (Ex. 2.2)."""
    if isinstance(bounds, IntervalArray):
        return bounds
    b = np.array(bounds, dtype=np.float64)
    if b.ndim != 2 or b.shape[1] != 2:
        raise ValueError(f"bounds: expected a sequence of (lo, hi) pairs, got shape {b.shape}")
    return IntervalArray(b[:, 0], b[:, 1])


# Interval is a factory function: the constructors of IntervalArray ride on it as attributes
Interval.empty = IntervalArray.empty  # type: ignore[attr-defined]
Interval.entire = IntervalArray.entire  # type: ignore[attr-defined]  # as Interval.empty
Interval.pi = lambda: IntervalArray._raw(  # type: ignore[attr-defined]  # as Interval.empty
    np.asarray(3.141592653589793), np.asarray(np.nextafter(3.141592653589793, np.inf))
)


def dot(x: IntervalArray, y: IntervalArray) -> IntervalArray:
    """Scalar product along the last axis, rounded outward (Ex. 2.2: ``[x]·[y]``)."""
    prod = x * y
    lo, hi = prod.lo[..., 0], prod.hi[..., 0]
    for k in range(1, prod.shape[-1]):
        lo, hi = arith.add((lo, hi), (prod.lo[..., k], prod.hi[..., k]))
    return IntervalArray._raw(lo, hi)


__all__ = [
    "Box",
    "DEFER_TO",
    "Interval",
    "IntervalArray",
    "as_pair",
    "dot",
]
