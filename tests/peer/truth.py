"""200-bit truths of the elementary interval functions and their backward (preimage) versions.

Each function takes float bounds ``(lo, hi)`` (``±inf`` allowed, ``(inf, -inf)`` empty) and returns the
exact range (or preimage hull) as mpf bounds at 200 bits, from the function's monotone pieces and critical
points. A float ``±inf`` operand (not an interval) is no real number: its range is empty (IEEE 1788).
"""

from __future__ import annotations

import math
from typing import Any

import mpmath
from judge import EMPTY, PREC, hull, inter, is_empty, mpf

Iv = tuple[Any, Any]
_MINF, _PINF = mpmath.mpf("-inf"), mpmath.mpf("inf")
BIG = mpmath.mpf(2) ** 1000  # stands for an infinite end in limits (far beyond any double)


def iv(lo: float, hi: float | None = None) -> Iv:
    hi = lo if hi is None else hi
    if lo > hi:
        return EMPTY
    return mpf(lo), mpf(hi)


def scalar(x: float) -> Iv:
    """A float operand: the point ``[x, x]``, empty for ``±inf``."""
    return iv(x) if math.isfinite(x) else EMPTY


def neg(a: Iv) -> Iv:
    return EMPTY if is_empty(a) else (-a[1], -a[0])


def add(a: Iv, b: Iv) -> Iv:
    if is_empty(a) or is_empty(b):
        return EMPTY
    with mpmath.workprec(PREC):
        return a[0] + b[0], a[1] + b[1]


def sub(a: Iv, b: Iv) -> Iv:
    return add(a, neg(b))


def _mul0(x: Any, y: Any) -> Any:
    return mpf(0) if x == 0 or y == 0 else x * y  # the limit at a corner with a zero factor is 0


def mul(a: Iv, b: Iv) -> Iv:
    if is_empty(a) or is_empty(b):
        return EMPTY
    with mpmath.workprec(PREC):
        c = [_mul0(x, y) for x in a for y in b]
    return min(c), max(c)


def inv(b: Iv) -> Iv:
    """Hull of ``{1/y | y ∈ [b], y ≠ 0}``."""
    if is_empty(b) or (b[0] == 0 and b[1] == 0):
        return EMPTY
    with mpmath.workprec(PREC):
        if b[0] < 0 < b[1]:
            return _MINF, _PINF
        if b[0] == 0:
            return 1 / b[1], _PINF
        if b[1] == 0:
            return _MINF, 1 / b[0]
        return 1 / b[1], 1 / b[0]


def div(a: Iv, b: Iv) -> Iv:
    if is_empty(a) or is_empty(b):
        return EMPTY
    return mul(a, inv(b))


def _mono(a: Iv, f: Any, dom: Iv) -> Iv:
    a = inter(a, dom)
    if is_empty(a):
        return EMPTY
    with mpmath.workprec(PREC):
        return f(a[0]), f(a[1])


def sqrt(a: Iv) -> Iv:
    return _mono(a, mpmath.sqrt, (mpf(0), _PINF))


def log(a: Iv) -> Iv:
    a = inter(a, (mpf(0), _PINF))
    if is_empty(a) or a[1] == 0:
        return EMPTY
    with mpmath.workprec(PREC):
        return (_MINF if a[0] == 0 else mpmath.log(a[0])), mpmath.log(a[1])


def exp(a: Iv) -> Iv:
    return _mono(a, mpmath.exp, (_MINF, _PINF))


def atan(a: Iv) -> Iv:
    return _mono(a, mpmath.atan, (_MINF, _PINF))


def _holds_k(a: Iv, phase: Any, period: Any) -> bool:
    """Some ``phase + k·period`` lies in ``[a]``."""
    with mpmath.workprec(PREC):
        k = mpmath.ceil((a[0] - phase) / period)
        return bool(phase + k * period <= a[1])


def sin(a: Iv) -> Iv:
    if is_empty(a):
        return EMPTY
    if not (mpmath.isfinite(a[0]) and mpmath.isfinite(a[1])):
        return mpf(-1), mpf(1)
    with mpmath.workprec(PREC):
        pi = mpmath.pi
        lo, hi = min(mpmath.sin(a[0]), mpmath.sin(a[1])), max(mpmath.sin(a[0]), mpmath.sin(a[1]))
        if _holds_k(a, pi / 2, 2 * pi):
            hi = mpf(1)
        if _holds_k(a, -pi / 2, 2 * pi):
            lo = mpf(-1)
    return lo, hi


def cos(a: Iv) -> Iv:
    with mpmath.workprec(PREC):
        return sin(add(a, (mpmath.pi / 2, mpmath.pi / 2)))


def tan(a: Iv) -> Iv:
    if is_empty(a):
        return EMPTY
    if not (mpmath.isfinite(a[0]) and mpmath.isfinite(a[1])):
        return _MINF, _PINF
    with mpmath.workprec(PREC):
        if _holds_k(a, mpmath.pi / 2, mpmath.pi):
            return _MINF, _PINF
        return mpmath.tan(a[0]), mpmath.tan(a[1])


def pown(a: Iv, n: int) -> Iv:
    if is_empty(a):
        return EMPTY
    if n < 0:
        return inv(pown(a, -n))
    with mpmath.workprec(PREC):
        f = lambda t: t**n  # noqa: E731 - mpf powers of ±inf are ±inf
        if n % 2 == 1:
            return f(a[0]), f(a[1])
        if a[0] >= 0:
            return f(a[0]), f(a[1])
        if a[1] <= 0:
            return f(a[1]), f(a[0])
        return mpf(0), max(f(a[0]), f(a[1]))


def _finite(x: Any) -> Any:
    return BIG if x == _PINF else (-BIG if x == _MINF else x)


def atan2(y: Iv, x: Iv) -> Iv:
    """Hull of the angles of the points of ``[y] × [x]`` other than the origin (limits at infinite ends)."""
    if is_empty(y) or is_empty(x):
        return EMPTY
    with mpmath.workprec(PREC):
        pi = mpmath.pi
        if x[0] < 0 and y[0] < 0 <= y[1]:  # the box meets the cut {x < 0, y = 0} from below
            return -pi, pi
        if y[0] == 0 == y[1] and x[0] == 0 == x[1]:
            return EMPTY
        ang = [mpmath.atan2(_finite(b), _finite(a)) for b in y for a in x if not (a == 0 and b == 0)]
        # an edge through the origin: the angles of the points next to it on that edge
        if x[0] <= 0 <= x[1] and y[0] <= 0 <= y[1]:
            eps = mpmath.mpf(2) ** -600
            for b in (y[0], y[1]):
                for a in (x[0], x[1]):
                    if (a == 0) != (b == 0):
                        ang.append(mpmath.atan2(b, a))
            ang += [
                mpmath.atan2(b, a) for b in (eps, -eps) if y[0] <= b <= y[1] for a in (x[0], x[1]) if a != 0
            ]
        return min(ang), max(ang)


# --- backward truths: hull of {x ∈ [x] | f(x) ∈ [y]} ---------------------------------------------------


def bwd_sin(y: Iv, x: Iv) -> Iv:
    """Hull of ``{t ∈ [x] | sin t ∈ [y]}`` (bounded ``[x]``, or ℝ-wide answers clipped to ``[x]``)."""
    y = inter(y, (mpf(-1), mpf(1)))
    if is_empty(y) or is_empty(x):
        return EMPTY
    with mpmath.workprec(PREC):
        pi = mpmath.pi
        a, b = mpmath.asin(y[0]), mpmath.asin(y[1])
        pieces = [(a, b), (pi - b, pi - a)]
        lo, hi = max(x[0], -BIG), min(x[1], BIG)
        k0, k1 = int(mpmath.floor(lo / (2 * pi))) - 1, int(mpmath.ceil(hi / (2 * pi))) + 1
        if k1 - k0 > 8:  # an unbounded [x]: every period is met
            return x
        found = [inter((p + 2 * k * pi, q + 2 * k * pi), x) for k in range(k0, k1 + 1) for p, q in pieces]
    return hull(*found)


def bwd_cos(y: Iv, x: Iv) -> Iv:
    with mpmath.workprec(PREC):
        h = mpmath.pi / 2
        return sub(bwd_sin(y, add(x, (h, h))), (h, h))


def bwd_pown(y: Iv, x: Iv, n: int) -> Iv:
    if is_empty(y) or is_empty(x):
        return EMPTY
    with mpmath.workprec(PREC):
        if n < 0:
            return bwd_pown(inv(y), x, -n)
        root = lambda t: mpmath.root(t, n) if t >= 0 else -mpmath.root(-t, n)  # noqa: E731
        if n % 2 == 1:
            return inter((root(y[0]), root(y[1])), x)
        y = inter(y, (mpf(0), _PINF))
        if is_empty(y):
            return EMPTY
        r0, r1 = root(y[0]), root(y[1])
        return hull(inter((r0, r1), x), inter((-r1, -r0), x))


def bwd_sqrt(y: Iv, x: Iv) -> Iv:
    y = inter(y, (mpf(0), _PINF))
    if is_empty(y):
        return EMPTY
    with mpmath.workprec(PREC):
        return inter((y[0] ** 2, y[1] ** 2), inter(x, (mpf(0), _PINF)))


def bwd_log(y: Iv, x: Iv) -> Iv:
    if is_empty(y):
        return EMPTY
    with mpmath.workprec(PREC):
        e = inter((mpmath.exp(y[0]), mpmath.exp(y[1])), x)
        return EMPTY if is_empty(e) or e[1] == 0 else e


def bwd_atan(y: Iv, x: Iv) -> Iv:
    with mpmath.workprec(PREC):
        h = mpmath.pi / 2
        y = inter(y, (-h, h))
        if is_empty(y):
            return EMPTY
        ends = [(_MINF if t == -h else _PINF if t == h else mpmath.tan(t)) for t in y]
        return inter((ends[0], ends[1]), x)
