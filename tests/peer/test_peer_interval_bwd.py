"""codac's ``codac2_tests_Interval_bwd`` re-expressed: the backward operators (``bwd_sin``/``bwd_cos`` in
their four symmetric forms, ``sqr``, ``log``, ``pow``, ``mul``, ``div``, ``max``/``min``, ``atan2``,
``sqrt``, ``atan``, ``add``, ``sub``) against :mod:`digslam.observer.expr.backward`, each case judged
against the 200-bit hull of the preimage (:mod:`truth`)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import mpmath
import numpy as np
import pytest
import truth as T
from judge import EMPTY, INF, hull, inter, judge_box, mpf

from digslam.observer import Interval, sin
from digslam.observer.expr import backward as B

oo = INF
PI_LB, PI_UB = 3.141592653589793, 3.1415926535897936
HPI = (PI_LB / 2, PI_UB / 2)
P = math.pi
Iv = tuple[float, float]


def I(lo: float, hi: float | None = None) -> Iv:  # noqa: E743, N802 - codac's spelling
    hi = lo if hi is None else hi
    return (lo, hi) if lo <= hi else EMPTY


def _pair(iv: Iv) -> tuple[np.ndarray, np.ndarray]:
    return np.array([iv[0]], dtype=float), np.array([iv[1]], dtype=float)


def _out(p: tuple[np.ndarray, np.ndarray]) -> Iv:
    return I(float(p[0][0]), float(p[1][0]))


def neg(a: Iv) -> Iv:
    return EMPTY if a[0] > a[1] else (-a[1], -a[0])


def shift(a: Iv, d: Iv) -> Iv:
    """``[a] + [d]`` (outward: float bounds of the 200-bit sums rounded out)."""
    if a[0] > a[1]:
        return EMPTY
    with mpmath.workprec(200):
        lo, hi = mpf(a[0]) + mpf(d[0]), mpf(a[1]) + mpf(d[1])
    return (float(lo) if not mpmath.isfinite(lo) or lo == int(lo) else math.nextafter(float(lo), -oo),
            float(hi) if not mpmath.isfinite(hi) or hi == int(hi) else math.nextafter(float(hi), oo))  # fmt: skip


def tv(a: Iv) -> T.Iv:
    return T.iv(*a)


CASES: list[tuple[str, Callable[[], list[Iv]], list[Iv], Callable[[], list[T.Iv]], float]] = []


def case(
    name: str, ours: Callable[[], list[Iv]], peer: list[Iv], truth: Callable[[], list[T.Iv]], tol: float
) -> None:
    CASES.append((f"{name}#{len(CASES)}", ours, peer, truth, tol))


def unary(name: str, rule: Callable[..., Any], tf: Callable[[T.Iv, T.Iv], T.Iv], y: Iv, x: Iv, ex: Iv,
          tol: float = 0.0, p: Any = None) -> None:  # fmt: skip
    case(name, lambda: [_out(rule(_pair(y), _pair(x), p)[0])], [ex], lambda: [tf(tv(y), tv(x))], tol)


def check_bwd_trigo(y: Iv, x: Iv, ex: Iv) -> None:
    mhpi, phpi = neg(HPI), HPI
    unary("bwd_sin", B.b_sin, T.bwd_sin, y, x, ex, 1e-5)
    unary("bwd_sin", B.b_sin, T.bwd_sin, neg(y), neg(x), neg(ex), 1e-5)
    unary("bwd_cos", B.b_cos, T.bwd_cos, y, shift(x, mhpi), shift(ex, mhpi) if ex != EMPTY else EMPTY, 1e-5)
    unary(
        "bwd_cos", B.b_cos, T.bwd_cos, neg(y), shift(x, phpi), shift(ex, phpi) if ex != EMPTY else EMPTY, 1e-5
    )


s05 = Interval(0.5, 1.5)
SIN = (float(sin(s05).lo), float(sin(s05).hi))
for x, ex in (((0, PI_UB / 2), (0.5, 1.5)), ((0, 5 * PI_UB / 2), (0.5, 2 * PI_UB + 1.5)),
              ((-2 * PI_UB, PI_UB / 2), (-2 * PI_UB + 0.5, 1.5)),
              ((-2 * PI_UB, 5 * PI_UB / 2), (-2 * PI_UB + 0.5, 2 * PI_UB + 1.5)),
              ((-PI_LB - 0.4, PI_UB / 2), (0.5, 1.5)), ((-PI_UB - 0.5, PI_UB / 2), (-PI_UB - 0.5, 1.5)),
              ((-3 * PI_UB / 2, PI_UB / 2), (-PI_UB - 1.5, 1.5)), ((0.5, PI_LB - 1.6), (0.5, 1.5)),
              ((0.5, PI_UB - 1.5), (0.5, PI_UB - 1.5)), ((0.5, PI_UB), (0.5, PI_UB - 0.5)),
              ((-PI_UB - 0.5, PI_UB - 1.5), (-PI_UB - 0.5, PI_UB - 1.5)),
              ((-3 * PI_UB / 2, PI_UB), (-PI_UB - 1.5, PI_UB - 0.5)), ((-PI_UB / 2, PI_UB / 2), (0.5, 1.5))):  # fmt: skip
    check_bwd_trigo(SIN, x, ex)
check_bwd_trigo((2, 3), (-oo, oo), EMPTY)
S5 = (math.sin(0.5), 1.0)
for x, ex in (((0, PI_UB / 2), (0.5, PI_UB / 2)), ((0, 5 * PI_UB / 2), (0.5, 5 * PI_UB / 2)),
              ((-2 * PI_UB, PI_UB / 2), (-2 * PI_UB + 0.5, PI_UB / 2)),
              ((-2 * PI_UB, 5 * PI_UB / 2), (-2 * PI_UB + 0.5, 5 * PI_UB / 2)),
              ((-PI_LB - 0.4, PI_UB / 2), (0.5, PI_UB / 2)), ((-PI_UB - 0.5, PI_UB / 2), (-PI_UB - 0.5, PI_UB / 2)),
              ((-3 * PI_UB / 2, PI_UB / 2), (-3 * PI_UB / 2, PI_UB / 2)), ((0.5, PI_UB), (0.5, PI_UB - 0.5)),
              ((-3 * PI_UB / 2, PI_UB), (-3 * PI_UB / 2, PI_UB - 0.5))):  # fmt: skip
    check_bwd_trigo(S5, x, ex)
check_bwd_trigo((1.0, 1.0), (4.0, 6.0), EMPTY)

for x, y, ex in (((0, 4), (1, 9), (1, 3)), ((0, 2), (1, 9), (1, 2)), ((-4, 2), (1, 9), (-3, 2)),
                 ((-4, -3), (1, 9), (-3, -3)), ((-4, 1), (-oo, 9), (-3, 1)), ((-1, 5), (4, 9), (2, 3)),
                 ((-oo, oo), (-4, -2), EMPTY)):  # fmt: skip
    unary("bwd_sqr", B.b_sqr, lambda y, x: T.bwd_pown(y, x, 2), y, x, ex)
E1 = math.exp(1.0)
for x, y, ex, tol in (((-oo, oo), (-oo, oo), (0, oo), 0), ((-oo, oo), (-oo, 0), (0, 1), 1e-15),
                      ((0, 1), (0, oo), (1, 1), 1e-15), ((-1, 3), (0, 1), (1, E1), 1e-15),
                      ((-1, 3), (-oo, 1), (0, E1), 1e-15), ((-1, 2), (-oo, 1), (0, 2), 0),
                      ((3, 4), (-oo, 1), EMPTY, 0), ((-0.01, 0.01), (-1, 1), EMPTY, 0)):  # fmt: skip
    unary("bwd_log", B.b_log, T.bwd_log, y, x, ex, tol)


def check_bwd_pow(y: Iv, x: Iv, ex: Iv, p: int) -> None:
    unary(
        "bwd_pow", lambda z, a, n: B.b_pown(z, a, n), lambda yy, xx: T.bwd_pown(yy, xx, p), y, x, ex, 1e-5, p
    )
    y2 = y if p % 2 == 0 else neg(y)
    unary("bwd_pow", lambda z, a, n: B.b_pown(z, a, n), lambda yy, xx: T.bwd_pown(yy, xx, p), y2, neg(x), neg(ex),
          1e-5, p)  # fmt: skip


for y, x, ex, p in (((16, 81), (1, 4), (2, 3), 4), ((16, 81), (3, 4), (3, 3), 4), ((16, 81), (-1, 4), (2, 3), 4),
                    ((16, 81), (-2, 4), (-2, 3), 4), ((16, 81), (-5, 4), (-3, 3), 4), ((16, 81), (1, 1), EMPTY, 4),
                    ((16, 81), (4, 4), EMPTY, 4), ((8, 27), (1, 4), (2, 3), 3), ((8, 27), (3, 4), (3, 3), 3),
                    ((8, 27), (-5, 4), (2, 3), 3), ((-8, 27), (-5, 4), (-2, 3), 3), ((-27, 27), (-5, 4), (-3, 3), 3),
                    ((8, 27), (1, 1), EMPTY, 3), ((8, 27), (4, 4), EMPTY, 3), ((-27, -8), (-1, -1), EMPTY, 3),
                    ((-27, -8), (-4, -4), EMPTY, 3), ((0, 1), (-10, 10), (-10, 10), -2)):  # fmt: skip
    check_bwd_pow(y, x, ex, p)


def _bin_truth(op: Callable[[Any, Any], Any], y: Iv, x1: Iv, x2: Iv) -> list[T.Iv]:
    """Hull of ``{(a, b) ∈ [x1]×[x2] | op(a, b) ∈ [y]}`` per coordinate, from the exact projections
    ``[x1] ∩ op⁻¹``: the contractor of a binary operation is exact on its two projections."""
    return op(tv(y), tv(x1), tv(x2))


def proj_mul(y: T.Iv, a: T.Iv, b: T.Iv) -> list[T.Iv]:
    """Projections of ``{a·b ∈ y}`` on boxes (the rules of ``mul``'s minimal contractor, by halves of b)."""
    return [_proj_div(y, b, a), _proj_div(y, a, b)]


def _proj_div(y: T.Iv, b: T.Iv, a: T.Iv) -> T.Iv:
    """``{t ∈ [a] | ∃ s ∈ [b], t·s ∈ [y]}``: hull over the halves of ``[b]`` (``s = 0`` frees ``t``)."""
    if y[0] == mpf(oo) or b[0] > b[1] or a[0] > a[1]:
        return EMPTY
    if b[0] <= 0 <= b[1] and y[0] <= 0 <= y[1]:
        return a
    parts = []
    for half in (inter(b, (mpf(-oo), mpf(0))), inter(b, (mpf(0), mpf(oo)))):
        if half[0] > half[1] or (half[0] == 0 and half[1] == 0):
            continue
        parts.append(inter(a, T.div(y, half)))
    return hull(*parts)


def check_bwd_mul(y: Iv, x1: Iv, x2: Iv, e1: Iv, e2: Iv) -> None:
    for sy, s1, s2 in ((1, 1, 1), (-1, -1, 1), (-1, 1, -1)):
        yy = y if sy > 0 else neg(y)
        a = x1 if s1 > 0 else neg(x1)
        b = x2 if s2 > 0 else neg(x2)
        ea = e1 if s1 > 0 else neg(e1)
        eb = e2 if s2 > 0 else neg(e2)
        case("bwd_mul", lambda yy=yy, a=a, b=b: [_out(r) for r in B.b_mul(_pair(yy), _pair(a), _pair(b), None)],
             [ea, eb], lambda yy=yy, a=a, b=b: proj_mul(tv(yy), tv(a), tv(b)), 1e-15)  # fmt: skip


for args in (((1, 2), (0.1, 2.0), (-10, 2), (0.5, 2.0), (0.5, 2)), (EMPTY, (0.1, 2.0), (-10, 2), EMPTY, EMPTY),
             ((0, 0), (0.1, 2.0), (-10, 2), (0.1, 2.0), (0, 0)), ((0, 0), (-1, 1), (-1, 1), (-1, 1), (-1, 1)),
             ((1, 1), (0, 10), (0, 10), (0.1, 10.0), (0.1, 10.0))):  # fmt: skip
    check_bwd_mul(*args)


def proj_div(y: T.Iv, a: T.Iv, b: T.Iv) -> list[T.Iv]:
    """``a / b ∈ y`` (b ≠ 0): ``a = y·b`` with ``b ≠ 0``."""
    b_nz = [
        h for h in (inter(b, (mpf(-oo), mpf(0))), inter(b, (mpf(0), mpf(oo)))) if h[0] <= h[1] and h != (0, 0)
    ]
    ra, rb = [], []
    for h in b_nz:  # on each sign of b: a ∈ y·h, and b ∈ a / y
        pa = inter(a, T.mul(y, h))
        if pa[0] > pa[1]:
            continue
        pb = _proj_div(pa, y, h)  # b with some y in [y]: b·y ∈ [pa]
        if pb[0] > pb[1] or (pb[0] == 0 and pb[1] == 0):
            continue
        ra.append(pa)
        rb.append(pb)
    return [hull(*ra), hull(*rb)]


def check_bwd_div(y: Iv, x1: Iv, x2: Iv, e1: Iv, e2: Iv) -> None:
    for sy, s1, s2 in ((1, 1, 1), (1, -1, -1), (-1, -1, 1), (-1, 1, -1)):
        yy = y if sy > 0 else neg(y)
        a = x1 if s1 > 0 else neg(x1)
        b = x2 if s2 > 0 else neg(x2)
        ea = e1 if s1 > 0 else neg(e1)
        eb = e2 if s2 > 0 else neg(e2)
        case("bwd_div", lambda yy=yy, a=a, b=b: [_out(r) for r in B.b_div(_pair(yy), _pair(a), _pair(b), None)],
             [ea, eb], lambda yy=yy, a=a, b=b: proj_div(tv(yy), tv(a), tv(b)), 1e-15)  # fmt: skip


NF0 = 5e-324
for args in (((1, 2), (0, 1), (2, 3), EMPTY, EMPTY), ((1, 2), (0, 1), (1, 3), (1, 1), (1, 1)),
             ((1, 2), (1, 3), (0, 1), (1, 2), (0.5, 1)), ((-1, 1), (-2, 2), (0, 1), (-1, 1), (0, 1)),
             ((-1, 1), (-2, 2), (0, 0), EMPTY, EMPTY), ((0, 0), (-2, 2), (-2, 2), (0, 0), (-2, 2)),
             ((0, oo), (0, 1), (-1, 0), (0, 0), (-1, 0)), ((NF0, oo), (0, 1), (-1, 0), (0, 0), (0, 0)),
             ((0, oo), (NF0, 1), (-1, 0), EMPTY, EMPTY)):  # fmt: skip
    check_bwd_div(*args)


def proj_max(y: T.Iv, a: T.Iv, b: T.Iv, op: str) -> list[T.Iv]:
    """Projections of ``{max(a, b) ∈ y}`` (``min`` by symmetry): either a is the max, in y, and b ≤ a; or
    the converse."""
    if op == "min":
        r = proj_max(T.neg(y), T.neg(a), T.neg(b), "max")
        return [T.neg(r[0]), T.neg(r[1])]
    ra, rb = [], []
    pa = inter(a, y)  # a is the max
    if pa[0] <= pa[1]:
        pb = inter(b, (mpf(-oo), pa[1]))
        if pb[0] <= pb[1]:
            ra.append(inter(pa, (pb[0], mpf(oo))))
            rb.append(pb)
    pb = inter(b, y)  # b is the max
    if pb[0] <= pb[1]:
        pa2 = inter(a, (mpf(-oo), pb[1]))
        if pa2[0] <= pa2[1]:
            ra.append(pa2)
            rb.append(inter(pb, (pa2[0], mpf(oo))))
    return [hull(*ra), hull(*rb)]


def check_bwd_max(y: Iv, x1: Iv, x2: Iv, e1: Iv, e2: Iv) -> None:
    for op, sgn, rule in (("max", 1, B.b_max), ("min", -1, B.b_min)):
        yy = y if sgn > 0 else neg(y)
        a, b = (x1, x2) if sgn > 0 else (neg(x1), neg(x2))
        ea, eb = (e1, e2) if sgn > 0 else (neg(e1), neg(e2))
        case(f"bwd_{op}", lambda yy=yy, a=a, b=b, rule=rule: [_out(r) for r in rule(_pair(yy), _pair(a), _pair(b), None)],
             [ea, eb], lambda yy=yy, a=a, b=b, op=op: proj_max(tv(yy), tv(a), tv(b), op), 0.0)  # fmt: skip
        case(f"bwd_{op}", lambda yy=yy, a=a, b=b, rule=rule: [_out(r) for r in rule(_pair(yy), _pair(b), _pair(a), None)][::-1],
             [ea, eb], lambda yy=yy, a=a, b=b, op=op: proj_max(tv(yy), tv(b), tv(a), op)[::-1], 0.0)  # fmt: skip


for args in ((EMPTY, (-2, -1), (-2, 3), EMPTY, EMPTY), ((0, 1), (-2, -1), (-2, 3), (-2, -1), (0, 1)),
             ((0, 1), (-2, -1), (2, 3), EMPTY, EMPTY), ((0, 1), (-2, 0), (-2, 3), (-2, 0), (-2, 1)),
             ((0, 1), (-2, 2), (-2, 3), (-2, 1), (-2, 1))):  # fmt: skip
    check_bwd_max(*args)


def atan2_truth(a: T.Iv, y: T.Iv, x: T.Iv) -> list[T.Iv]:
    """Hull of ``{(y, x) ∈ box | atan2(y, x) ∈ [a]}`` on a 2-D grid plus the corners of the box and
    the rays' crossings with its sides (a subset of the true hull: the soundness check is necessary)."""
    pts = []
    with mpmath.workprec(200):
        ylo, yhi = max(y[0], mpf(-50)), min(y[1], mpf(50))
        xlo, xhi = max(x[0], mpf(-50)), min(x[1], mpf(50))
        ys = [ylo + (yhi - ylo) * i / 60 for i in range(61)]
        xs = [xlo + (xhi - xlo) * i / 60 for i in range(61)]
        for th in (a[0], a[1]):  # rays at the bounding angles meet the sides of the box
            if not mpmath.isfinite(th):
                continue
            c, s = mpmath.cos(th), mpmath.sin(th)
            for xv in (xlo, xhi):
                if c != 0 and (xv / c) > 0:
                    ys.append(xv * s / c)
            for yv in (ylo, yhi):
                if s != 0 and (yv / s) > 0:
                    xs.append(yv * c / s)
        res = [EMPTY, EMPTY]
        for yv in ys:
            for xv in xs:
                if not (y[0] <= yv <= y[1] and x[0] <= xv <= x[1]) or (xv == 0 and yv == 0):
                    continue
                t = mpmath.atan2(yv, xv)
                if a[0] <= t <= a[1]:
                    res = [hull(res[0], (yv, yv)), hull(res[1], (xv, xv))]
                    pts.append((yv, xv))
    return res


def check_bwd_atan2(a: Iv, y: Iv, x: Iv, ey: Iv, ex: Iv, tol: float = 10 * 2.2e-16) -> None:
    case("bwd_atan2", lambda: [_out(r) for r in B.b_atan2(_pair(a), _pair(y), _pair(x), None)], [ey, ex],
         lambda: atan2_truth(tv(a), tv(y), tv(x)), tol)  # fmt: skip


R3, R2 = math.sqrt(3.0), math.sqrt(2.0)
check_bwd_atan2((P / 6, P / 3), (0.5, 10.0), (0.5, 2.0), (0.5, 2 * R3), (0.5, 2.0))
check_bwd_atan2((P / 6, P / 3), (0.5, 2.0), (0.5, 10.0), (0.5, 2.0), (0.5, 2 * R3))
check_bwd_atan2((-P / 4, P / 4), (1.0, 2.0), (0.5, 2.0), (1.0, 2.0), (1.0, 2.0))
check_bwd_atan2((-P / 2, 0.0), (0.5, 2.0), (0.5, 10.0), EMPTY, EMPTY)
check_bwd_atan2((2 * P, 3 * P), (-0.5, 2.0), (0.5, 10.0), EMPTY, EMPTY)
check_bwd_atan2(
    (2 * P / 3, 5 * P / 6), (0.0, 100.0), (-20.0, -R3 / 2), (0.5, 20 * R3), (-20.0, -R3 / 2), 1e-10
)
check_bwd_atan2((-3 * P / 4, -2 * P / 3), (-R3 / 2, 2.0), (-R2 / 2, 0.0), (-R3 / 2, 0.0), (-R2 / 2, 0.0))
check_bwd_atan2((-3 * P / 4, -2 * P / 3), (-R3 / 2, 2.0), (-1.0, -0.5), (-R3 / 2, -0.5), (-R3 / 2, -0.5))
check_bwd_atan2((-3 * P / 4, -P / 4), (-5.0, -0.5), (-oo, oo), (-5.0, -0.5), (-5.0, 5.0))
check_bwd_atan2((-P / 3, P / 4), (-oo, oo), (R3 / 2, R3 / 2), (-1.5, R3 / 2), (R3 / 2, R3 / 2))
check_bwd_atan2(HPI, (1.0, 1.0), (0.0, 0.0), (1.0, 1.0), (0.0, 0.0))

for x, y, ex in (((0, 15), (1, 3), (1, 9)), ((0, 2), (1, 3), (1, 2)), ((-4, 2), (1, 3), (1, 2)),
                 ((-4, -3), (1, 3), EMPTY), ((-4, 1), (-oo, 9), (0, 1)), ((-1, 5), (2, 5), (4, 5)),
                 ((-oo, oo), (-4, -2), EMPTY)):  # fmt: skip
    unary("bwd_sqrt", B.b_sqrt, T.bwd_sqrt, y, x, ex)

T6 = (0.0, math.tan(P / 6))
for x, y, ex in (((-1.0, 3.0), (0.0, P / 6), T6), ((0, 5 * P / 2), (-P, 1.5), (0, 5 * P / 2)),
                 ((0.2, 0.5), (0.0, P / 6), (0.2, 0.5)), ((-100, 100), (-P / 2 - 0.1, P / 2 + 0.1), (-100, 100)),
                 ((-100, 100), (P / 2 + 0.1, P), EMPTY), ((-100, 100), (-P, -P / 2 - 0.1), EMPTY),
                 ((-oo, oo), (-P / 4, P / 2), (-1, oo)), ((-oo, oo), (-P / 2, P / 4), (-oo, 1))):  # fmt: skip
    unary("bwd_atan", B.b_atan, T.bwd_atan, y, x, ex, 1e-15)
    unary("bwd_atan", B.b_atan, T.bwd_atan, neg(y), neg(x), neg(ex), 1e-15)


def proj_add(y: T.Iv, a: T.Iv, b: T.Iv) -> list[T.Iv]:
    pa = inter(a, T.sub(y, b))
    pb = inter(b, T.sub(y, a))
    return [EMPTY, EMPTY] if pa[0] > pa[1] or pb[0] > pb[1] else [pa, pb]


def proj_sub(y: T.Iv, a: T.Iv, b: T.Iv) -> list[T.Iv]:
    r = proj_add(y, a, T.neg(b))
    return [r[0], T.neg(r[1])]


for name, rule, proj, cases in (
    ("bwd_add", B.b_add, proj_add, (((1, 3), (1, 2), (-10, 5), (1, 2), (-1, 2)), (EMPTY, (0.1, 2.0), (-10, 2), EMPTY, EMPTY),
                                    ((0, 0), (0, 0), (0.1, 5), EMPTY, EMPTY), ((0, 0), (-1, 1), (-1, 1), (-1, 1), (-1, 1)),
                                    ((-1, 1), (1, 2), (-10, 5), (1, 2), (-3, 0)))),
    ("bwd_sub", B.b_sub, proj_sub, (((1, 3), (1, 2), (-10, 5), (1, 2), (-2, 1)), (EMPTY, (0.1, 2.0), (-10, 2), EMPTY, EMPTY),
                                    ((0, 0), (0, 0), (0.1, 5), EMPTY, EMPTY), ((0, 0), (-1, 1), (-1, 1), (-1, 1), (-1, 1)),
                                    ((-1, 1), (1, 2), (-10, 5), (1, 2), (0, 3)))),
):  # fmt: skip
    for y, a, b, ea, eb in cases:
        for sgn in (1, -1):
            yy, aa, bb = (y, a, b) if sgn > 0 else (neg(y), neg(a), neg(b))
            e1, e2 = (ea, eb) if sgn > 0 else (neg(ea), neg(eb))
            case(name, lambda yy=yy, aa=aa, bb=bb, rule=rule: [_out(r) for r in rule(_pair(yy), _pair(aa), _pair(bb), None)],
                 [e1, e2], lambda yy=yy, aa=aa, bb=bb, proj=proj: proj(tv(yy), tv(aa), tv(bb)), 0.0)  # fmt: skip


@pytest.mark.parametrize(("name", "ours", "peer", "truth", "tol"), CASES, ids=[c[0] for c in CASES])
def test_backward_operator(name: str, ours: Callable[[], list[Iv]], peer: list[Iv],
                           truth: Callable[[], list[T.Iv]], tol: float) -> None:  # fmt: skip
    judge_box(name, ours(), peer, truth(), tol)
