"""Images of separators by bijections and unions of symmetries (§3.2.1, Prop. 3.3, Corollary 2)."""

from __future__ import annotations

import numpy as np
import pytest

from digslam.observer import (
    Box,
    CtcFwdBwd,
    CtcTransform,
    Function,
    Interval,
    SepInverse,
    SepTransform,
    Transform,
    pave,
    symmetric_union,
)
from digslam.observer.core.boxes import box_difference
from digslam.observer.sets.separators import check_separation

RING = SepInverse(Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2), Interval(1, 2.25))  # Ex. 2.7
QUARTER = Transform(Function(lambda x: (-x[1], x[0])), Function(lambda y: (y[1], -y[0])))


def in_ring(p: np.ndarray) -> np.ndarray:
    d = (p[:, 0] - 2) ** 2 + (p[:, 1] - 2.5) ** 2
    return (d >= 1) & (d <= 2.25)


def rot(p: np.ndarray, k: int) -> np.ndarray:
    for _ in range(k):
        p = np.stack([-p[:, 1], p[:, 0]], axis=1)
    return p


def boxes(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    c = rng.uniform(-5, 5, (n, 2))
    r = rng.uniform(0, 0.8, (n, 2))
    return c - r, c + r


def test_union_of_rotations_is_sound_and_a_separator() -> None:
    sep = symmetric_union(RING, QUARTER, 3)  # X ∪ R(X) ∪ R²(X) ∪ R³(X)

    def member(p: np.ndarray) -> np.ndarray:  # p ∈ Rᵏ(X)  <=>  R⁻ᵏ(p) = R^(4-k)(p) ∈ X
        return np.any([in_ring(rot(p, (4 - k) % 4)) for k in range(4)], axis=0)

    lo, hi = boxes(3000, 0)
    xin, xout = sep.separate(lo, hi)
    assert not check_separation(xin, xout, lo, hi).any()
    rng = np.random.default_rng(1)
    for contracted, want in ((xin, True), (xout, False)):
        (plo, phi), _ = box_difference(lo, hi, *contracted)
        pts = rng.uniform(plo, phi)
        assert (member(pts) == want).all()
    p = pave(Box([(-5, 5), (-5, 5)]), sep, 0.05)
    area = 4 * np.pi * (2.25 - 1)  # the four rotated rings are disjoint
    assert p.inner_area <= area <= p.inner_area + p.boundary_area


def test_box_conservative_image_is_as_tight_as_the_original() -> None:
    """Prop. 3.3: with a box-conservative f, f(S) separates f(X) as well as S separates X."""
    lo, hi = boxes(2000, 2)
    a_in, a_out = RING.separate(lo, hi)
    rlo, rhi = np.stack([-hi[:, 1], lo[:, 0]], 1), np.stack([-lo[:, 1], hi[:, 0]], 1)  # R(boxes)
    b_in, b_out = SepTransform(RING, QUARTER).separate(rlo, rhi)
    # widths are permuted, not enlarged
    wa = np.nan_to_num(a_out[1] - a_out[0], neginf=0)[:, ::-1]
    wb = np.nan_to_num(b_out[1] - b_out[0], neginf=0)
    assert np.allclose(wa, wb, rtol=1e-12, atol=1e-12)


def test_ctc_transform_keeps_solutions() -> None:
    ctc = CtcTransform(CtcFwdBwd(Function(lambda x: x[0] ** 2 + x[1] ** 2), Interval(1, 4)), QUARTER)
    lo, hi = boxes(2000, 3)
    clo, chi = ctc.contract(lo, hi)
    rng = np.random.default_rng(4)
    pts = rng.uniform(lo, hi)
    d = (pts**2).sum(1)
    sol = (d >= 1) & (d <= 4)
    kept = ((pts >= clo) & (pts <= chi)).all(1)
    assert kept[sol].all()


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: Transform(Function(lambda x: x[0] + x[1]), Function(lambda y: (y[0], y[1]))), "f"),
        (
            lambda: Transform(Function(lambda x: (x[0], x[1])), Function(lambda y: (y[0], y[1], y[2]))),
            "f_inv",
        ),
        (lambda: symmetric_union(RING, QUARTER, -1), "k"),
        (
            lambda: SepTransform(RING, Transform(Function(lambda x: (x[0],)), Function(lambda y: (y[0],)))),
            "t",
        ),
    ],
)
def test_bad_input(make, message: str) -> None:  # noqa: ANN001
    with pytest.raises(ValueError, match=message):
        make()
