"""Backward (projection) rules of the forward-backward contractor (thesis §2.4.1.2, Ex. 2.4).

For a node ``z = op(x, y)`` each rule returns the contracted arguments: the smallest intervals this
rule can prove to hold every ``x ∈ [x]``, ``y ∈ [y]`` with ``op(x, y) ∈ [z]``. All rules are sound
(outward rounded through :mod:`.arith`); ``atan`` and ``atan2`` (through the minimal polar contractor
of §3.2.3) are minimal up to rounding on bounded boxes, ``sin``, ``cos``, ``tan`` up to their period
enclosure.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from digslam.observer.core import arith as A
from digslam.observer.core import rounding as rnd
from digslam.observer.core import trig as T
from digslam.observer.core.polar_jit import ctc_polar_batch
from digslam.observer.core.types import Pair

_INF = np.inf
inter, hull = A.intersect, A.hull


def _nonneg(z: Pair) -> Pair:
    return inter(z, (np.zeros_like(z[0]), np.full_like(z[1], _INF)))


def mul_rev(c: Pair, b: Pair, a: Pair) -> Pair:
    """``[a] ∩ {t : ∃ s ∈ [b], t·s ∈ [c]}``, splitting ``[b]`` at 0 (two half-lines, then hull)."""
    bneg = (b[0], np.minimum(b[1], 0.0))
    bpos = (np.maximum(b[0], 0.0), b[1])
    r = hull(inter(a, A.div(c, bneg)), inter(a, A.div(c, bpos)))
    free = (c[0] <= 0) & (c[1] >= 0) & (b[0] <= 0) & (b[1] >= 0)  # t·0 = 0 ∈ [c]: no constraint on t
    return np.where(free, a[0], r[0]), np.where(free, a[1], r[1])


def b_add(z: Pair, x: Pair, y: Pair, p: object) -> tuple[Pair, ...]:
    x = inter(x, A.sub(z, y))
    return x, inter(y, A.sub(z, x))


def b_sub(z: Pair, x: Pair, y: Pair, p: object) -> tuple[Pair, ...]:
    x = inter(x, A.add(z, y))
    return x, inter(y, A.sub(x, z))


def b_mul(z: Pair, x: Pair, y: Pair, p: object) -> tuple[Pair, ...]:
    x = mul_rev(z, y, x)
    return x, mul_rev(z, x, y)


def b_div(z: Pair, x: Pair, y: Pair, p: object) -> tuple[Pair, ...]:
    # z = x / y  <=>  x = z·y with y != 0: a divisor left at {0} leaves no point
    x = inter(x, A.mul(z, y))
    y = mul_rev(x, z, y)
    zero = (y[0] == 0) & (y[1] == 0)
    return A.set_empty(*x, zero), A.set_empty(*y, zero)


def b_neg(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    return (inter(x, A.neg(z)),)


def _symmetric(x: Pair, r: Pair) -> Pair:
    """``[x] ∩ ([r] ∪ -[r])``."""
    return hull(inter(x, r), inter(x, A.neg(r)))


def b_sqr(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    return (_symmetric(x, A.sqrt(_nonneg(z))),)


def b_sqrt(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    return (inter(x, A.sqr(_nonneg(z))),)


def _root(z: Pair, n: int) -> Pair:
    """Enclosure of ``[z]^(1/n)`` for ``[z] ⊂ [0, ∞)``, as ``exp(log(z)/n)`` (rigorous, not tight)."""
    lz = A.log(z)
    r = A.exp(A.div(lz, (np.asarray(float(n)), np.asarray(float(n)))))
    zero = z[0] <= 0
    return np.where(zero & ~(z[0] > z[1]), 0.0, r[0]), np.where(z[1] == 0, 0.0, r[1])


def b_pown(z: Pair, x: Pair, n: int) -> tuple[Pair, ...]:
    if n == 0:
        ok = (z[0] <= 1) & (z[1] >= 1)
        return (A.set_empty(x[0], x[1], ~ok),)
    if n < 0:
        one = (np.ones_like(z[0]), np.ones_like(z[0]))
        return b_pown(A.div(one, z), x, -n)
    if n % 2 == 0:
        return (_symmetric(x, _root(_nonneg(z), n)),)
    pos = _root(_nonneg(z), n)
    neg = A.neg(_root(_nonneg(A.neg(z)), n))
    return (hull(inter(x, pos), inter(x, neg)),)


def b_exp(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    return (inter(x, A.log(_nonneg(z))),)


def b_log(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    return (inter(x, A.exp(z)),)


def b_abs(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    return (_symmetric(x, _nonneg(z)),)


def b_min(z: Pair, x: Pair, y: Pair, p: object) -> tuple[Pair, ...]:
    above = (z[0], np.full_like(z[0], _INF))
    x, y = inter(x, above), inter(y, above)
    x_must = A.empty_mask(*inter(y, z))  # y cannot be the minimum: x is
    y_must = A.empty_mask(*inter(x, z))
    xz, yz = inter(x, z), inter(y, z)
    xn = tuple(np.where(x_must, a, b) for a, b in zip(xz, x, strict=True))
    yn = tuple(np.where(y_must, a, b) for a, b in zip(yz, y, strict=True))
    return xn, yn  # type: ignore[return-value]  # numpy stubs: the tuples have two items


def b_max(z: Pair, x: Pair, y: Pair, p: object) -> tuple[Pair, ...]:
    x, y = b_min(A.neg(z), A.neg(x), A.neg(y), p)
    return A.neg(x), A.neg(y)


def _periodic_rev(x: Pair, pieces: list[Pair], period: tuple[float, float]) -> Pair:
    """``[x] ∩ ⋃_k (piece + k·period)``: nearest pieces to each bound of ``[x]``, then hull.

    ``pieces`` are enclosures over one period starting near 0; ``period`` an enclosure of it.
    """
    lo, hi = x
    with np.errstate(invalid="ignore", over="ignore"):
        k0 = np.floor(lo / period[0]) - 1.0
        k1 = np.floor(hi / period[0]) - 1.0
    far = ~(np.abs(k0) < 2.0**40) | ~(np.abs(k1) < 2.0**40) | ~(k1 - k0 < 1e6)
    k0, k1 = np.where(far, 0.0, k0), np.where(far, 0.0, k1)
    per = (np.asarray(period[0]), np.asarray(period[1]))
    new_lo, new_hi = np.full_like(lo, _INF), np.full_like(hi, -_INF)
    for base in (k0, k1):
        for dk in range(4):
            shift = A.mul((base + dk, base + dk), per)
            for pc in pieces:
                s = inter(x, A.add(pc, shift))
                new_lo, new_hi = np.minimum(new_lo, s[0]), np.maximum(new_hi, s[1])
    return np.where(far, lo, new_lo), np.where(far, hi, new_hi)


_PI = (rnd.PI_DOWN, rnd.PI_UP)
_2PI = (rnd.TWO_PI_DOWN, rnd.TWO_PI_UP)


def b_sin(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    a = T.asin(z)  # ⊂ [-π/2, π/2]; preimage: [a] + 2kπ and π - [a] + 2kπ
    pi = (np.full_like(a[0], _PI[0]), np.full_like(a[0], _PI[1]))
    return (A.set_empty(*_periodic_rev(x, [a, A.sub(pi, a)], _2PI), a[0] > a[1]),)  # z ∩ [-1, 1] = ∅


def b_cos(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    a = T.acos(z)  # ⊂ [0, π]; preimage: ±[a] + 2kπ
    return (A.set_empty(*_periodic_rev(x, [a, A.neg(a)], _2PI), a[0] > a[1]),)


def b_tan(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    return (_periodic_rev(x, [T.atan(z)], _PI),)


def b_atan(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    """``z = atan x``: ``x ∈ tan([z] ∩ (-π/2, π/2))``, taken end by end because ``tan`` is increasing
    there: ``[tan z⁻, tan z⁺]``, with ``-∞`` (``+∞``) when ``z⁻ <= -π/2`` (``z⁺ >= π/2``). Minimal up
    to outward rounding; ``tan`` of the whole clipped interval would be ``ℝ`` whenever it touched a pole.
    """
    zl, zh = z
    lo_ok = zl >= -rnd.HALF_PI_DOWN  # the float -π/2 rounded toward 0 is above -π/2: tan is finite there
    hi_ok = zh <= rnd.HALF_PI_DOWN
    with np.errstate(invalid="ignore"):
        t_lo = T.tan((np.where(lo_ok, zl, 0.0), np.where(lo_ok, zl, 0.0)))[0]
        t_hi = T.tan((np.where(hi_ok, zh, 0.0), np.where(hi_ok, zh, 0.0)))[1]
    lo = np.where(lo_ok, t_lo, -_INF)
    hi = np.where(hi_ok, t_hi, _INF)
    dead = A.empty_mask(zl, zh) | (zl > rnd.HALF_PI_DOWN) | (zh < -rnd.HALF_PI_DOWN)
    return (A.set_empty(*inter(x, (lo, hi)), dead),)


def b_asin(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    zc = inter(z, (np.full_like(z[0], -rnd.HALF_PI_UP), np.full_like(z[1], rnd.HALF_PI_UP)))
    return (inter(x, T.sin(zc)),)


def b_acos(z: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    zc = inter(z, (np.zeros_like(z[0]), np.full_like(z[1], rnd.PI_UP)))
    return (inter(x, T.cos(zc)),)


def _tan_branch(z: Pair) -> Pair:
    """``tan([z])`` when ``[z]`` holds no pole (monotone there: tight), else ``ℝ`` (:func:`.trig.tan`)."""
    return T.tan(z)


def b_atan2(z: Pair, y: Pair, x: Pair, p: object) -> tuple[Pair, ...]:
    """``z = atan2(y, x)``: minimal up to outward rounding on bounded boxes.

    ``atan2(y, x) = z`` means ``(x, y) = (ρ cos z, ρ sin z)`` for some ``ρ > 0`` with ``z ∈ (-π, π]``,
    i.e. the polar constraint of §3.2.3 (Eq. 3.22) with ``[ρ] = [0, |(x, y)|⁺]`` and
    ``[θ] = [z] ∩ [-π, π]``: the minimal polar contractor (:func:`.polar_jit.ctc_polar_batch`, Eq.
    3.34) returns the hull ``⟦Π ∩ [p]⟧`` and hence the smallest ``[x]×[y]`` (the origin, which has no
    angle, can only add itself). For unbounded boxes (where that contractor only clips) the rule is
    also intersected with the sign constraints of the angle range, ``y = x·tan z`` where ``cos z ≠ 0``
    and ``x = y·tan(π/2 - z)`` where ``sin z ≠ 0`` (each with its reverse).
    """
    zl, zh = z
    shape = np.broadcast_shapes(np.shape(zl), np.shape(y[0]), np.shape(x[0]))
    zl, zh, yl0, yh0, xl0, xh0 = (np.broadcast_to(v, shape) for v in (zl, zh, *y, *x))
    # polar geometry (Eq. 3.34): columns (x, y, ρ, θ)
    with np.errstate(invalid="ignore", over="ignore"):
        mx = np.maximum(np.abs(xl0), np.abs(xh0))
        my = np.maximum(np.abs(yl0), np.abs(yh0))
        rho = rnd.sqrt_up(rnd.add_up(rnd.mul_up(mx, mx), rnd.mul_up(my, my)))
    rho = np.where(np.isnan(rho), _INF, rho)
    tl, th = np.maximum(zl, -rnd.PI_UP), np.minimum(zh, rnd.PI_UP)
    plo = np.stack([xl0, yl0, np.zeros(shape), tl], axis=-1).reshape(-1, 4)
    phi = np.stack([xh0, yh0, rho, th], axis=-1).reshape(-1, 4)
    dead = A.empty_mask(zl, zh) | (tl > th) | A.empty_mask(yl0, yh0) | A.empty_mask(xl0, xh0)
    plo[dead.reshape(-1)], phi[dead.reshape(-1)] = _INF, -_INF
    clo, chi = ctc_polar_batch(np.ascontiguousarray(plo), np.ascontiguousarray(phi), False)
    x = (clo[:, 0].reshape(shape), chi[:, 0].reshape(shape))
    y = (clo[:, 1].reshape(shape), chi[:, 1].reshape(shape))
    # sign constraints and the tangent rules (needed where the box is unbounded)
    up, down = (zl >= 0), (zh <= 0)
    right = (zl >= -rnd.HALF_PI_DOWN) & (zh <= rnd.HALF_PI_DOWN)
    left = (zl >= rnd.HALF_PI_UP) | (zh <= -rnd.HALF_PI_UP)
    y = (np.where(up, np.maximum(y[0], 0.0), y[0]), np.where(down, np.minimum(y[1], 0.0), y[1]))
    x = (np.where(right, np.maximum(x[0], 0.0), x[0]), np.where(left, np.minimum(x[1], 0.0), x[1]))
    y, x = A.set_empty(*y, A.empty_mask(*y)), A.set_empty(*x, A.empty_mask(*x))
    t = _tan_branch((zl, zh))
    tan_ok = (t[0] > -_INF) & (t[1] < _INF)
    y1 = inter(y, A.mul(x, t))
    x1 = mul_rev(y1, t, x)
    y, x = _pick(tan_ok, y1, y), _pick(tan_ok, x1, x)
    half_pi = (np.full(shape, rnd.HALF_PI_DOWN), np.full(shape, rnd.HALF_PI_UP))
    ct = _tan_branch(A.sub(half_pi, (zl, zh)))  # cot z = tan(π/2 - z)
    cot_ok = (ct[0] > -_INF) & (ct[1] < _INF)
    x2 = inter(x, A.mul(y, ct))
    y2 = mul_rev(x2, ct, y)
    y, x = _pick(cot_ok, y2, y), _pick(cot_ok, x2, x)
    return A.set_empty(*y, dead), A.set_empty(*x, dead)


def _pick(mask: np.ndarray, a: Pair, b: Pair) -> Pair:
    return np.where(mask, a[0], b[0]), np.where(mask, a[1], b[1])


#: op -> backward rule ``(z, *args, param) -> contracted args``
BACKWARD: dict[str, Callable[..., tuple[Pair, ...]]] = {
    "add": b_add, "sub": b_sub, "mul": b_mul, "div": b_div, "neg": b_neg, "sqr": b_sqr,
    "sqrt": b_sqrt, "pown": b_pown, "exp": b_exp, "log": b_log, "abs": b_abs, "min": b_min,
    "max": b_max, "sin": b_sin, "cos": b_cos, "tan": b_tan, "atan": b_atan, "asin": b_asin,
    "acos": b_acos, "atan2": b_atan2,
}  # fmt: skip


__all__ = [
    "BACKWARD",
    "b_abs",
    "b_acos",
    "b_add",
    "b_asin",
    "b_atan",
    "b_atan2",
    "b_cos",
    "b_div",
    "b_exp",
    "b_log",
    "b_max",
    "b_min",
    "b_mul",
    "b_neg",
    "b_pown",
    "b_sin",
    "b_sqr",
    "b_sqrt",
    "b_sub",
    "b_tan",
    "mul_rev",
]
