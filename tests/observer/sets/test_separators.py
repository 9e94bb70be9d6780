"""Separators: the invariant ``x_in ∪ x_out = x`` for every separator, and soundness by sampling.

Points drawn in parts proved inside satisfy the set's defining condition exactly (exact rational
arithmetic), points in parts proved outside do not; for elementary and composed separators.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from digslam.observer import (
    Box,
    Function,
    Interval,
    SepBox,
    SepImage,
    SepInter,
    SepInverse,
    SepNot,
    SepPolygon,
    SepQInter,
    SepSubpaving,
    SepTransform,
    SepUnion,
    Transform,
    atan2,
    cos,
    pave,
    sin,
)
from digslam.observer.core.boxes import box_difference, empty_rows
from digslam.observer.sets.separators import check_separation, relaxed_intersection

RINGS = [((1, 3), (3, 6)), ((4, 2), (1, 5)), ((-3, -3), (3, 4))]  # Table 2.1


def ring(c: tuple[float, float], r: tuple[float, float]) -> SepInverse:
    return SepInverse(
        Function(lambda x: (x[0] - c[0]) ** 2 + (x[1] - c[1]) ** 2), Interval(r[0] ** 2, r[1] ** 2)
    )


def in_ring(p: np.ndarray, c: tuple[float, float], r: tuple[float, float]) -> np.ndarray:
    """Exact membership (rational arithmetic) of float points in a closed ring."""
    out = []
    for x, y in p:
        d = (Fraction(x) - Fraction(c[0])) ** 2 + (Fraction(y) - Fraction(c[1])) ** 2
        out.append(Fraction(r[0]) ** 2 <= d <= Fraction(r[1]) ** 2)
    return np.array(out, dtype=bool)


def ex26_member(p: np.ndarray) -> np.ndarray:
    x1, x2, x3 = (in_ring(p, c, r) for c, r in RINGS)
    return (x1 & x2) | (x3 & ~x1)


SQUARE = [(-5, -5), (5, -5), (5, 5), (-5, 5)]
CASES = {
    "ring": (ring(*RINGS[0]), lambda p: in_ring(p, *RINGS[0])),
    "complement": (~ring(*RINGS[0]), lambda p: ~in_ring(p, *RINGS[0])),
    "ex2.6": ((ring(*RINGS[0]) & ring(*RINGS[1])) | (ring(*RINGS[2]) & ~ring(*RINGS[0])), ex26_member),
    "difference": (ring(*RINGS[1]) - ring(*RINGS[0]), lambda p: in_ring(p, *RINGS[1]) & ~in_ring(p, *RINGS[0])),
    "box": (SepBox(Box([(-2, 3), (-1, 4)])), lambda p: (p[:, 0] >= -2) & (p[:, 0] <= 3) & (p[:, 1] >= -1) & (p[:, 1] <= 4)),
    "image": (SepImage(np.eye(8, dtype=bool) | np.eye(8, dtype=bool)[::-1], (-4, 4), (1.0, 1.0)),
              lambda p: _image_member(p)),
    "subpaving": (SepSubpaving(pave(Box([(-6, 8), (-4, 10)]), ring(*RINGS[0]), 0.2)), lambda p: in_ring(p, *RINGS[0])),
    "rotated": (SepTransform(ring(*RINGS[0]), Transform(Function(lambda x: (-x[1], x[0])), Function(lambda y: (y[1], -y[0])))),
                lambda p: in_ring(np.stack([p[:, 1], -p[:, 0]], 1), *RINGS[0])),
    "q-relaxed": (SepQInter([ring(*RINGS[0]), ring(*RINGS[1]), ring(*RINGS[2])], 1),
                  lambda p: np.sum([in_ring(p, c, r) for c, r in RINGS], axis=0) >= 2),
    "polygon&ring": (SepPolygon([SQUARE]) & ring(*RINGS[0]), lambda p: (np.abs(p) <= 5).all(1) & in_ring(p, *RINGS[0])),
}  # fmt: skip


def _image_member(p: np.ndarray) -> np.ndarray:
    """A point is in the image set when it lies in a closed set pixel (pixel size 1, origin (-4, 4))."""
    img = np.eye(8, dtype=bool) | np.eye(8, dtype=bool)[::-1]
    out = np.zeros(len(p), dtype=bool)
    u, v = p[:, 0] + 4, 4 - p[:, 1]  # exact for these small dyadic offsets of sampled floats
    for di in (0, 1):  # a point on a pixel border belongs to both pixels
        for dj in (0, 1):
            col = np.floor(u).astype(int) - dj * (u == np.floor(u))
            row = np.floor(v).astype(int) - di * (v == np.floor(v))
            ok = (col >= 0) & (col < 8) & (row >= 0) & (row < 8)
            out[ok] |= img[row[ok], col[ok]]
    return out


def random_boxes(n: int, seed: int, span: float = 12.0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    c = rng.uniform(-span, span, (n, 2))
    r = rng.uniform(0, 3, (n, 2)) * rng.choice([0.01, 0.1, 1.0], (n, 1))
    return c - r, c + r


@pytest.mark.parametrize("name", sorted(CASES))
def test_separation_invariant(name: str) -> None:
    sep, _ = CASES[name]
    lo, hi = random_boxes(3000, 1)
    xin, xout = sep.separate(lo, hi)
    bad = check_separation(xin, xout, lo, hi)
    assert not bad.any(), (
        f"{name}: x_in ∪ x_out != x on {bad.sum()} boxes, first row {np.flatnonzero(bad)[0]}"
    )
    # union covers: every piece of x minus x_in lies in x_out
    (plo, phi), rows = box_difference(lo, hi, *xin)
    inside = ((plo >= xout[0][rows]) & (phi <= xout[1][rows])).all(axis=1)
    assert inside.all(), f"{name}: {np.sum(~inside)} parts of x are in neither x_in nor x_out"


@pytest.mark.parametrize("name", sorted(CASES))
def test_soundness_by_sampling(name: str) -> None:
    sep, member = CASES[name]
    lo, hi = random_boxes(1500, 2)
    rng = np.random.default_rng(3)
    xin, xout = sep.separate(lo, hi)
    for (plo, phi), _rows, want in (
        (*box_difference(lo, hi, *xin), True),  # removed by S_in: proved inside
        (*box_difference(lo, hi, *xout), False),  # removed by S_out: proved outside
    ):
        # interior points only: a closed piece shares its face with the kept box, which may hold the border
        p = rng.uniform(plo, phi)
        ok = member(p) == want
        assert ok.all(), f"{name}: point {p[~ok][0].tolist()} misclassified as {'in' if want else 'out'}side"


def test_sep_inverse_vector_valued_into_separator() -> None:
    """Theorem 2.1 with a separator in the image space: a rotated square."""
    th = np.pi / 4
    rot_inv = Function(lambda x: (cos(th) * x[0] + sin(th) * x[1], -sin(th) * x[0] + cos(th) * x[1]))
    sep = SepInverse(rot_inv, SepPolygon([[(0, 0), (2, 0), (2, 2), (0, 2)]]))
    xin, xout = sep(Box([(-0.05, 0.05), (1.3, 1.4)]))  # on the rotated square's axis, inside
    assert bool(xin.is_empty().all()) and not bool(xout.is_empty().any())
    xin, xout = sep(Box([(1.5, 1.6), (0.0, 0.1)]))  # well outside
    assert bool(xout.is_empty().all())


def test_sep_inverse_atan2_bearing() -> None:
    sep = SepInverse(Function(lambda x: atan2(x[1], x[0])), Interval(0.5, 1.0))
    lo, hi = random_boxes(2000, 4, span=3)
    xin, xout = sep.separate(lo, hi)
    assert not check_separation(xin, xout, lo, hi).any()
    (plo, phi), _ = box_difference(lo, hi, *xin)
    a = np.arctan2(phi[:, 1], phi[:, 0])
    assert ((a >= 0.5 - 1e-12) & (a <= 1.0 + 1e-12)).all()


def test_relaxed_intersection_counts() -> None:
    # intervals [0,2], [1,3], [2,4], [10,11]: points in >= 3 of 4 -> [2,2]; in >= 2 -> [1,3]
    los = np.array([0, 1, 2, 10], float)[:, None, None]
    his = np.array([2, 3, 4, 11], float)[:, None, None]
    assert (
        relaxed_intersection(los, his, 1)[0].item() == 2 and relaxed_intersection(los, his, 1)[1].item() == 2
    )
    lo, hi = relaxed_intersection(los, his, 2)
    assert (lo.item(), hi.item()) == (1.0, 3.0)
    lo, hi = relaxed_intersection(los, his, 3)
    assert (lo.item(), hi.item()) == (0.0, 11.0)
    lo, hi = relaxed_intersection(los, his, 0)
    assert lo.item() > hi.item()  # no point in all four


def test_q_relaxed_intersection_is_robust_to_outliers() -> None:
    good = [SepBox(Box([(-1 + 0.1 * k, 1 + 0.1 * k), (-1, 1)])) for k in range(5)]
    bad = [SepBox(Box([(20, 21), (20, 21)])) for _ in range(2)]
    sep = SepQInter(good + bad, q=2)
    xin, xout = sep(Box([(0.3, 0.5), (-0.5, 0.5)]))  # in every good box
    assert bool(xin.is_empty().all())
    xin, xout = sep(Box([(5, 6), (5, 6)]))
    assert bool(xout.is_empty().all())
    lo, hi = random_boxes(500, 5, span=3)
    assert not check_separation(*sep.separate(lo, hi), lo, hi).any()


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: SepQInter([], 0), "seps"),
        (lambda: SepQInter([SepBox(Box([(0, 1)]))], 1), "q"),
        (lambda: SepInverse(Function(lambda x: x[0] + x[1]), Box([(0, 1), (0, 1)])), "y"),
        (lambda: SepInter(SepBox(Box([(0, 1)])), SepBox(Box([(0, 1), (0, 1)]))), "dimensions"),
        (lambda: SepBox(Box([(0, 1)]))(Box([(0, 1), (0, 1)])), "dimension"),
    ],
)
def test_bad_input(make, message: str) -> None:  # noqa: ANN001
    with pytest.raises(ValueError, match=message):
        make()


def test_not_is_an_involution_and_union_is_de_morgan() -> None:
    a, b = ring(*RINGS[0]), ring(*RINGS[1])
    assert isinstance(~a, SepNot) and (~~a) is a
    lo, hi = random_boxes(800, 6)
    u_in, u_out = SepUnion(a, b).separate(lo, hi)
    d_in, d_out = (~(~a & ~b)).separate(lo, hi)
    for x, y in ((u_in, d_in), (u_out, d_out)):
        assert np.array_equal(empty_rows(*x), empty_rows(*y))
