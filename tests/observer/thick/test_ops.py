"""Operations on thick sets (thesis §5.2.3, Eq. 5.10, 5.12, 5.13): soundness by sampling thin sets."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from digslam.observer import Box, Function, Interval, SepBox, SepInverse, Transform
from digslam.observer.thick.cells import CLEAR, DARK
from digslam.observer.thick.ops import thick_image, thick_image_param, thick_minkowski_sum, thick_product
from digslam.observer.thick.sep import ThickSep

Pred = Callable[[np.ndarray], np.ndarray]
RNG_SEED = 7


def disk(c: tuple[float, ...], r: float) -> SepInverse:
    n = len(c)
    return SepInverse(
        Function(lambda x: sum((x[i] - c[i]) ** 2 for i in range(n)), n=n), Interval(-np.inf, r * r)
    )


def thick_disk(c: tuple[float, float], r_lo: float, r_hi: float) -> ThickSep:
    return ThickSep(disk(c, r_lo), disk(c, r_hi))


def thick_box(lo_m: list[float], hi_m: list[float], lo_p: list[float], hi_p: list[float]) -> ThickSep:
    return ThickSep(SepBox(Box(list(zip(lo_m, hi_m)))), SepBox(Box(list(zip(lo_p, hi_p)))))


def in_disk(c: np.ndarray, r: float, margin: float) -> Pred:
    return lambda p: ((p - c) ** 2).sum(axis=-1) <= r * r + margin


def in_box(lo: np.ndarray, hi: np.ndarray) -> Pred:
    return lambda p: ((p >= lo) & (p <= hi)).all(axis=-1)


def random_batch(rng: np.random.Generator, lo: list[float], hi: list[float], n: int = 300, w: float = 0.8):
    lo_, hi_ = np.asarray(lo, float), np.asarray(hi, float)
    c = rng.uniform(lo_, hi_, (n, lo_.size))
    h = rng.uniform(0.0, w, (n, lo_.size))
    return c - h, c + h


def samples(lo: np.ndarray, hi: np.ndarray, rng: np.random.Generator, k: int = 48) -> np.ndarray:
    u = rng.uniform(0, 1, (lo.shape[0], k, lo.shape[1]))
    u[:, 0], u[:, 1] = 0.0, 1.0  # two opposite corners
    return lo[:, None] + u * (hi - lo)[:, None]


def check_thin_sets(ts: ThickSep, lo: np.ndarray, hi: np.ndarray, thin: list[Pred], rng: np.random.Generator,
                    minus: Pred | None = None, plus: Pred | None = None) -> np.ndarray:  # fmt: skip
    """Clear boxes lie in every thin result (and in X⁻), dark boxes meet none of them (nor X⁺)."""
    st = ts.classify(lo, hi)
    pts = samples(lo, hi, rng)
    for member in thin:
        m = member(pts)
        assert m[st == CLEAR].all(), "a clear box has a point outside a thin set of the thick set"
        assert not m[st == DARK].any(), "a dark box meets a thin set of the thick set"
    if minus is not None:
        assert minus(pts)[st == CLEAR].all()
    if plus is not None:
        assert not plus(pts)[st == DARK].any()
    return st


def test_image_by_bijection() -> None:
    """Eq. 5.13 with f(x) = (2 x₁ + 1, x₂ - x₁): f(A) for random disks A⁻ ⊂ A ⊂ A⁺."""
    rng = np.random.default_rng(RNG_SEED)
    t = Transform(
        Function(lambda x: (2 * x[0] + 1, x[1] - x[0])),
        Function(lambda y: ((y[0] - 1) / 2, y[1] + (y[0] - 1) / 2)),
    )
    a = thick_disk((0.0, 0.0), 1.0, 1.5)
    img = thick_image(a, t)

    def pre(p: np.ndarray) -> np.ndarray:
        x1 = (p[..., 0] - 1) / 2
        return np.stack([x1, p[..., 1] + x1], axis=-1)

    thin = []
    for _ in range(6):  # a disk of radius ρ centred at u with |u| + 1 <= ρ <= 1.5 - |u|
        u = rng.uniform(-0.2, 0.2, 2)
        rho = rng.uniform(1.0 + np.hypot(*u), 1.5 - np.hypot(*u))
        thin.append(lambda p, u=u, rho=rho: in_disk(u, rho, -1e-9)(pre(p)))
    lo, hi = random_batch(rng, [-3, -4], [5, 4])
    st = check_thin_sets(img, lo, hi, thin, rng, lambda p: in_disk(np.zeros(2), 1.0, -1e-9)(pre(p)),
                         lambda p: in_disk(np.zeros(2), 1.5, 1e-9)(pre(p)))  # fmt: skip
    assert (st == CLEAR).any() and (st == DARK).any()
    with pytest.raises(TypeError, match="Transform"):
        thick_image(a, None)  # type: ignore[arg-type]


def test_image_param_translation() -> None:
    """f_p(x) = x + p, p ∈ [0, 1]²: [∩ (A⁻ + p), ∪ (A⁺ + p)] is [[1, 2]², [-1, 4]²] for [A] = [[0,2]², [-1,3]²]."""
    rng = np.random.default_rng(RNG_SEED + 1)
    a = thick_box([0, 0], [2, 2], [-1, -1], [3, 3])
    img = thick_image_param(a, lambda y, p: (y[0] - p[0], y[1] - p[1]), [(0, 1), (0, 1)], n=2, eps=0.02)
    thin = []
    for _ in range(6):
        p = rng.uniform(0, 1, 2)
        blo, bhi = rng.uniform(-1, 0, 2), rng.uniform(2, 3, 2)
        thin.append(in_box(blo + p, bhi + p))
    lo, hi = random_batch(rng, [-2, -2], [5, 5], w=0.3)
    st = check_thin_sets(img, lo, hi, thin, rng, in_box(np.ones(2), 2 * np.ones(2)),
                         in_box(-np.ones(2), 4 * np.ones(2)))  # fmt: skip
    assert (st == CLEAR).any() and (st == DARK).any()
    with pytest.raises(ValueError, match="p_box"):
        thick_image_param(a, lambda y, p: (y[0] - p[0], y[1] - p[1]), [(0, 1)], n=2, eps=0.1, q=2)


def test_cartesian_product() -> None:
    """Eq. 5.10: [A] × [B] with [A] = [[0,1], [0,2]] on R and [B] a thick disk of R²."""
    rng = np.random.default_rng(RNG_SEED + 2)
    a = thick_box([0], [1], [0], [2])
    b = thick_disk((0.0, 0.0), 0.5, 1.0)
    ab = thick_product(a, b)
    assert ab.n == 3
    thin = []
    for _ in range(6):
        alo, ahi = rng.uniform(0, 0), rng.uniform(1, 2)
        rho = rng.uniform(0.5, 1.0)
        thin.append(lambda p, alo=alo, ahi=ahi, rho=rho: (p[..., 0] >= alo) & (p[..., 0] <= ahi)
                    & in_disk(np.zeros(2), rho, 0.0)(p[..., 1:]))  # fmt: skip
    lo, hi = random_batch(rng, [-1, -1.5, -1.5], [3, 1.5, 1.5], w=0.4)
    st = check_thin_sets(ab, lo, hi, thin, rng)
    assert (st == CLEAR).any() and (st == DARK).any()
    with pytest.raises(ValueError, match="n_a"):
        thick_product(
            ThickSep(
                SepInverse(Function(lambda x: x[0]), Interval(0, 1)),
                SepInverse(Function(lambda x: x[0]), Interval(0, 2)),
            ),
            b,
            n_a=2,
        )


def test_minkowski_sum() -> None:
    """Eq. 5.12: a thick disk ⊕ a thick box; thin sets: random disks ⊕ random boxes (distance test)."""
    rng = np.random.default_rng(RNG_SEED + 3)
    a = thick_disk((0.0, 0.0), 0.5, 1.0)
    b = thick_box([2, 0], [3, 1], [1.5, -0.5], [3.5, 1.5])
    s = thick_minkowski_sum(a, b, [(-1, 1), (-1, 1)], eps=0.05)

    def disk_plus_box(rho: float, blo: np.ndarray, bhi: np.ndarray) -> Pred:
        return lambda p: (np.clip(p, blo, bhi) - p).__pow__(2).sum(axis=-1) <= rho * rho

    thin = []
    for _ in range(5):
        rho = rng.uniform(0.5, 1.0)
        blo, bhi = rng.uniform([1.5, -0.5], [2, 0]), rng.uniform([3, 1], [3.5, 1.5])
        thin.append(disk_plus_box(rho, blo, bhi))
    lo, hi = random_batch(rng, [0, -2.5], [5, 3.5], n=150, w=0.4)
    st = check_thin_sets(s, lo, hi, thin, rng, disk_plus_box(0.5, np.array([2, 0]), np.array([3, 1])),
                         disk_plus_box(1.0, np.array([1.5, -0.5]), np.array([3.5, 1.5])))  # fmt: skip
    assert (st == CLEAR).any() and (st == DARK).any()
    with pytest.raises(TypeError, match="ThickSep"):
        thick_minkowski_sum(a, None, [(-1, 1), (-1, 1)], eps=0.1)  # type: ignore[arg-type]
