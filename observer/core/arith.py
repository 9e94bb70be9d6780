"""Interval arithmetic kernels on batches (thesis §2.3.1, Eq. 2.5–2.11).

Every kernel takes and returns pairs ``(lo, hi)`` of float64 arrays of broadcastable shapes. The empty
interval is ``[+inf, -inf]``: it goes in, it comes out, and no NaN ever reaches a bound. Bounds are
rounded outward by :mod:`.rounding`. These kernels are the fast path under :class:`IntervalArray`.

Infinite operands (IEEE 1788-2015 §7.2, §10.5.1): ``±∞`` is no real number, so a pair with an infinite
*point* — ``[+∞, +∞]``, ``[-∞, -∞]``, or any pair with ``lo = +∞`` or ``hi = -∞`` — holds no real
and is read as the empty interval by every kernel (:func:`empty_mask`). A raw float ``±∞`` meeting an
interval therefore gives the empty interval: ``[0, 1] + ∞ = ∅``, ``[1, 2]·∞ = ∅``, ``[1, 2]/∞ = ∅``,
``[2¹⁰²⁴⁻, +∞) + (-∞) = ∅``; unbounded intervals such as ``[0, +∞)`` are of course fine.
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.types import Pair

_INF = np.inf


def empty_mask(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """True where ``[lo, hi]`` holds no real number: ``lo > hi``, or an infinite point (``lo = +∞`` or
    ``hi = -∞``, IEEE 1788: ``±∞`` is not a real)."""
    return (lo > hi) | (lo == _INF) | (hi == -_INF)


def set_empty(lo: np.ndarray, hi: np.ndarray, mask: np.ndarray) -> Pair:
    """Replace entries where ``mask`` holds by the empty interval ``[+inf, -inf]``."""
    if not mask.any():
        return lo, hi
    return np.where(mask, _INF, lo), np.where(mask, -_INF, hi)


def neg(a: Pair) -> Pair:
    """``-[a] = [-a⁺, -a⁻]``."""
    return np.negative(a[1]) + 0.0, np.negative(a[0]) + 0.0


def add(a: Pair, b: Pair) -> Pair:
    """``[a] + [b]`` (Eq. 2.5)."""
    e = empty_mask(*a) | empty_mask(*b)
    return set_empty(rnd.add_down(a[0], b[0]), rnd.add_up(a[1], b[1]), e)


def sub(a: Pair, b: Pair) -> Pair:
    """``[a] - [b] = [a⁻ - b⁺, a⁺ - b⁻]``."""
    e = empty_mask(*a) | empty_mask(*b)
    return set_empty(rnd.sub_down(a[0], b[1]), rnd.sub_up(a[1], b[0]), e)


def _corner_bounds(cands_lo: list[np.ndarray], cands_hi: list[np.ndarray]) -> Pair:
    """Min of lower candidates and max of upper ones; NaN candidates (``0·inf``) count as 0."""
    lo = cands_lo[0]
    for c in cands_lo[1:]:
        lo = np.fmin(lo, c)
    hi = cands_hi[0]
    for c in cands_hi[1:]:
        hi = np.fmax(hi, c)
    return np.nan_to_num(lo, nan=0.0, posinf=_INF, neginf=-_INF), np.nan_to_num(
        hi, nan=0.0, posinf=_INF, neginf=-_INF
    )


def mul(a: Pair, b: Pair) -> Pair:
    """``[a]·[b]``: hull of the four corner products, ``0·∞ = 0`` (Eq. 2.6)."""
    e = empty_mask(*a) | empty_mask(*b)
    with np.errstate(invalid="ignore"):
        corners = [(a[i], b[j]) for i in (0, 1) for j in (0, 1)]
        los = [np.where(np.isnan(c := rnd.mul_down(x, y)), 0.0, c) for x, y in corners]
        his = [np.where(np.isnan(c := rnd.mul_up(x, y)), 0.0, c) for x, y in corners]
    lo, hi = _corner_bounds(los, his)
    return set_empty(lo, hi, e)


def sqr(a: Pair) -> Pair:
    """``[a]²`` (tighter than ``[a]·[a]``: the result is never negative)."""
    lo, hi = a
    e = empty_mask(lo, hi)
    mig = np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(np.abs(lo), np.abs(hi)))
    mag = np.maximum(np.abs(lo), np.abs(hi))
    return set_empty(np.maximum(rnd.mul_down(mig, mig), 0.0), rnd.mul_up(mag, mag), e)


def div(a: Pair, b: Pair) -> Pair:
    """``[a]/[b]`` as the hull of the set ``{x/y : x ∈ [a], y ∈ [b], y ≠ 0}`` (IEEE 1788 set-based).

    When ``0 ∈ [b]`` the result is sound and possibly unbounded: ``[1,2]/[0,1] = [1,+∞]``,
    ``[1,2]/[-1,1] = (-∞,+∞)``, ``[a]/[0,0] = ∅`` and ``[0,0]/[b] = [0,0]`` for ``[b] ≠ [0,0]``.
    """
    al, ah, bl, bh = np.broadcast_arrays(*a, *b)
    e = empty_mask(al, ah) | empty_mask(bl, bh) | ((bl == 0) & (bh == 0))
    with np.errstate(invalid="ignore", divide="ignore"):
        # 0 ∉ [b]: four corner quotients (inf/inf corners are dominated: drop them)
        corners = [(x, y) for x in (al, ah) for y in (bl, bh)]
        los = [rnd.div_down(x, y) for x, y in corners]
        his = [rnd.div_up(x, y) for x, y in corners]
        lo, hi = los[0], his[0]
        for c_lo, c_hi in zip(los[1:], his[1:], strict=True):  # fmin/fmax skip NaN (inf/inf, 0/0) corners
            lo, hi = np.fmin(lo, c_lo), np.fmax(hi, c_hi)
        # 0 ∈ [b], one-sided divisor and 0 ∉ [a]
        pos_a, neg_a = al >= 0, ah <= 0  # [a] on one side of 0 (a = [0,0] handled below)
        b0lo, b0hi = (bl == 0) & (bh > 0), (bh == 0) & (bl < 0)
        lo = np.where(b0lo & pos_a, rnd.div_down(al, bh), lo)
        hi = np.where(b0lo & pos_a, _INF, hi)
        lo = np.where(b0lo & neg_a, -_INF, lo)
        hi = np.where(b0lo & neg_a, rnd.div_up(ah, bh), hi)
        lo = np.where(b0hi & pos_a, -_INF, lo)
        hi = np.where(b0hi & pos_a, rnd.div_up(al, bl), hi)
        lo = np.where(b0hi & neg_a, rnd.div_down(ah, bl), lo)
        hi = np.where(b0hi & neg_a, _INF, hi)
    zero_in_b = (bl <= 0) & (bh >= 0)
    a_zero = (al == 0) & (ah == 0)
    entire = zero_in_b & ~a_zero & ~((b0lo | b0hi) & (pos_a | neg_a))
    lo = np.where(entire, -_INF, np.where(zero_in_b & a_zero, 0.0, lo))
    hi = np.where(entire, _INF, np.where(zero_in_b & a_zero, 0.0, hi))
    return set_empty(lo + 0.0, hi + 0.0, e)


def sqrt(a: Pair) -> Pair:
    """``√[a]`` on ``[a] ∩ [0, +∞)`` (empty when ``[a] < 0``)."""
    lo, hi = a
    e = empty_mask(lo, hi) | (hi < 0)
    with np.errstate(invalid="ignore"):
        return set_empty(rnd.sqrt_down(np.maximum(lo, 0.0)), rnd.sqrt_up(np.maximum(hi, 0.0)), e)


def _pow_pos(x: np.ndarray, n: int, up: bool) -> np.ndarray:
    """Directed ``x**n`` for ``x >= 0`` and ``n >= 1`` by square-and-multiply (monotone steps)."""
    mul = rnd.mul_up if up else rnd.mul_down
    result = None
    base = x
    while n:
        if n & 1:
            result = base if result is None else mul(result, base)
        n >>= 1
        if n:
            base = mul(base, base)
    assert result is not None
    return np.maximum(result, 0.0)


def pown(a: Pair, n: int) -> Pair:
    """``[a]ⁿ`` for an integer ``n`` (``[a]⁰ = [1,1]``, negative ``n`` through division)."""
    if not isinstance(n, (int, np.integer)):
        raise ValueError(f"pown: exponent must be an integer, got {n!r}")
    n = int(n)
    lo, hi = a
    e = empty_mask(lo, hi)
    if n == 0:
        one = np.ones(np.shape(lo))
        return set_empty(one, one.copy(), e)
    if n < 0:
        return div((np.ones(np.shape(lo)), np.ones(np.shape(lo))), pown(a, -n))
    mig = np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(np.abs(lo), np.abs(hi)))
    mag = np.maximum(np.abs(lo), np.abs(hi))
    if n % 2 == 0:
        return set_empty(_pow_pos(mig, n, False), _pow_pos(mag, n, True), e)
    # odd: monotone increasing, sign preserving
    plo = np.where(lo >= 0, _pow_pos(np.abs(lo), n, False), -_pow_pos(np.abs(lo), n, True))
    phi = np.where(hi >= 0, _pow_pos(np.abs(hi), n, True), -_pow_pos(np.abs(hi), n, False))
    return set_empty(plo + 0.0, phi + 0.0, e)


def abs_(a: Pair) -> Pair:
    """``|[a]|``."""
    lo, hi = a
    e = empty_mask(lo, hi)
    mig = np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(np.abs(lo), np.abs(hi)))
    return set_empty(mig, np.maximum(np.abs(lo), np.abs(hi)), e)


def minimum(a: Pair, b: Pair) -> Pair:
    """``min([a], [b]) = [min(a⁻, b⁻), min(a⁺, b⁺)]``."""
    e = empty_mask(*a) | empty_mask(*b)
    return set_empty(np.minimum(a[0], b[0]), np.minimum(a[1], b[1]), e)


def maximum(a: Pair, b: Pair) -> Pair:
    """``max([a], [b]) = [max(a⁻, b⁻), max(a⁺, b⁺)]``."""
    e = empty_mask(*a) | empty_mask(*b)
    return set_empty(np.maximum(a[0], b[0]), np.maximum(a[1], b[1]), e)


def exp(a: Pair) -> Pair:
    """``exp([a])``, monotone; libm error covered by :data:`~.rounding.LIBM_ULPS`."""
    lo, hi = a
    e = empty_mask(lo, hi)
    with np.errstate(over="ignore", under="ignore"):
        elo = np.where(lo == 0, 1.0, np.maximum(rnd.widen_down(np.exp(lo)), 0.0))
        ehi = np.where(hi == 0, 1.0, rnd.widen_up(np.exp(hi)))
    return set_empty(elo, ehi, e)


def log(a: Pair) -> Pair:
    """``log([a] ∩ (0, +∞))``; empty when ``[a] <= 0``."""
    lo, hi = a
    e = empty_mask(lo, hi) | (hi <= 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        llo = np.where(lo <= 0, -_INF, np.where(lo == 1, 0.0, rnd.widen_down(np.log(np.maximum(lo, 0)))))
        lhi = np.where(hi == 1, 0.0, rnd.widen_up(np.log(np.maximum(hi, 0))))
    return set_empty(llo, lhi, e)


def intersect(a: Pair, b: Pair) -> Pair:
    """``[a] ∩ [b]`` (Eq. 2.3)."""
    lo, hi = np.maximum(a[0], b[0]), np.minimum(a[1], b[1])
    return set_empty(lo, hi, lo > hi)


def hull(a: Pair, b: Pair) -> Pair:
    """``[a] ⊔ [b]``, the smallest interval containing both (Eq. 2.4); empties are neutral."""
    return np.minimum(a[0], b[0]), np.maximum(a[1], b[1])


__all__ = [
    "abs_",
    "add",
    "div",
    "empty_mask",
    "exp",
    "hull",
    "intersect",
    "log",
    "maximum",
    "minimum",
    "mul",
    "neg",
    "pown",
    "set_empty",
    "sqr",
    "sqrt",
    "sub",
]
