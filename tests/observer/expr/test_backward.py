"""Minimal backward operators and open complements (issue 24, items 2–4), against exact values (mpmath at
60 digits, from the exact float inputs).

* ``atan``: ``x ∈ tan([z] ∩ (-π/2, π/2))`` end by end, so a pole at one end gives a half-line.
* ``atan2``: as sharp as the minimal polar contractor (§3.2.3) on bounded boxes.
* ``SepInverse``: the complement of ``Y`` is open; a box whose image touches ``Y``'s bound from inside
  has no point outside (numpy and compiled paths), so the centre of ``x² + y² ∈ [0, 1]`` is inside.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from digslam.observer import Box, CtcFwdBwd, Function, Interval, SepInverse, pave
from digslam.observer.expr.ops import atan, atan2, sin, sqr
from digslam.observer.sets.transforms import SepTransform, Transform

mpmath.mp.dps = 60
ULP = 2.0**-52


def _close_below(lo: float, exact: mpmath.mpf, rel: float = 8 * ULP) -> bool:
    """``lo <= exact`` and within a few ulps (tight)."""
    return mpmath.mpf(lo) <= exact and exact - mpmath.mpf(lo) <= rel * max(1, abs(exact))


def _close_above(hi: float, exact: mpmath.mpf, rel: float = 8 * ULP) -> bool:
    return exact <= mpmath.mpf(hi) and mpmath.mpf(hi) - exact <= rel * max(1, abs(exact))


def test_atan_backward_pole_at_one_end() -> None:
    zl, zh = -math.pi / 4, math.pi / 2
    r = CtcFwdBwd(Function(lambda x: atan(x[0]), n=1), Interval(zl, zh))(Box([(-math.inf, math.inf)]))
    assert _close_below(float(r.lo[0]), mpmath.tan(mpmath.mpf(zl)))
    assert mpmath.mpf(float(r.hi[0])) >= mpmath.tan(mpmath.mpf(zh))  # the float π/2 < π/2: 1.6e16 or +∞


@pytest.mark.parametrize(
    "z", [(0.5, 1.0), (-1.5, -0.25), (-1.0, 1.5707963267948966), (-1.5707963267948966, 0.0)]
)
def test_atan_backward_minimal(z: tuple[float, float]) -> None:
    r = CtcFwdBwd(Function(lambda x: atan(x[0]), n=1), Interval(*z))(Box([(-1e300, 1e300)]))
    lo_ok = _close_below(float(r.lo[0]), mpmath.tan(mpmath.mpf(z[0])))
    hi_ok = mpmath.mpf(float(r.hi[0])) >= mpmath.tan(mpmath.mpf(z[1]))
    if abs(z[1]) < 1.5:
        hi_ok = _close_above(float(r.hi[0]), mpmath.tan(mpmath.mpf(z[1])))
    if abs(z[0]) > 1.5:
        lo_ok = float(r.lo[0]) <= mpmath.tan(mpmath.mpf(z[0]))
    assert lo_ok and hi_ok, r


def test_atan_backward_out_of_range_is_empty() -> None:
    c = CtcFwdBwd(Function(lambda x: atan(x[0]), n=1), Interval(1.6, 3.0))
    assert bool(c(Box([(-math.inf, math.inf)])).is_empty().all())


@pytest.mark.parametrize("ydom", [(-2.0, 2.0), (-math.inf, math.inf), (-1.5, 10.0)])
def test_atan2_backward_issue_case(ydom: tuple[float, float]) -> None:
    """``a = [-π/3, π/4]``, ``x = √3/2``: ``y ∈ [x·tan(-π/3), x·tan(π/4)] = [-1.5, 0.866]``."""
    zl, zh = -math.pi / 3, math.pi / 4
    x = math.sqrt(3) / 2
    r = CtcFwdBwd(Function(lambda y, x: atan2(y, x)), Interval(zl, zh))(Box([ydom, (x, x)]))
    ex_lo = max(mpmath.mpf(x) * mpmath.tan(mpmath.mpf(zl)), mpmath.mpf(ydom[0]))
    ex_hi = mpmath.mpf(x) * mpmath.tan(mpmath.mpf(zh))
    assert _close_below(float(r.lo[0]), ex_lo, 64 * ULP) and _close_above(float(r.hi[0]), ex_hi, 64 * ULP), r
    assert r.lo[1] == x and r.hi[1] == x


def _atan2_hull_sampled(z: tuple[float, float], box: list[tuple[float, float]], k: int = 4001) -> tuple:
    """Exact hull of ``{(y, x) ∈ box | atan2(y, x) ∈ z}`` on the boundary of the region (mpmath): the
    region is a box ∩ a sector, so its hull is reached on the box edges or the two rays."""
    pts = []
    (yl, yh), (xl, xh) = box
    zl, zh = mpmath.mpf(z[0]), mpmath.mpf(z[1])
    for t in np.linspace(0, 1, k):
        for y, x in ((yl, xl + t * (xh - xl)), (yh, xl + t * (xh - xl)), (yl + t * (yh - yl), xl),
                     (yl + t * (yh - yl), xh)):  # fmt: skip
            if (x, y) != (0.0, 0.0) and zl <= mpmath.atan2(y, x) <= zh:
                pts.append((y, x))
    for a in (zl, zh):  # the rays, clipped by the box
        for rho in np.linspace(0, 10, k):
            y, x = float(rho * mpmath.sin(a)), float(rho * mpmath.cos(a))
            if yl <= y <= yh and xl <= x <= xh:
                pts.append((y, x))
    ys, xs = [p[0] for p in pts], [p[1] for p in pts]
    return (min(ys), max(ys)), (min(xs), max(xs))


@pytest.mark.parametrize(
    "z, box",
    [
        ((2.0, 3.0), [(-1.0, 2.0), (-3.0, 3.0)]),
        ((-0.5, 0.3), [(-1.0, 1.0), (0.5, 2.0)]),
        ((-3.0, -1.8), [(-2.0, 0.5), (-1.0, 1.0)]),
        ((0.2, 1.2), [(0.1, 0.9), (0.2, 2.0)]),
    ],
)
def test_atan2_backward_as_sharp_as_sampling(z, box) -> None:
    """Sound (holds every sampled solution) and tight (within 2e-3 of the sampled hull)."""
    r = CtcFwdBwd(Function(lambda y, x: atan2(y, x)), Interval(*z))(Box(box))
    (syl, syh), (sxl, sxh) = _atan2_hull_sampled(z, box)
    assert r.lo[0] <= syl and syh <= r.hi[0] and r.lo[1] <= sxl and sxh <= r.hi[1]
    assert max(syl - r.lo[0], r.hi[0] - syh, sxl - r.lo[1], r.hi[1] - sxh) < 2e-3, r


def _disk_sep(numpy_path: bool) -> SepInverse:
    if numpy_path:  # a sin(0·x) term keeps the function off the tape: the numpy forward-backward
        return SepInverse(Function(lambda x: sqr(x[0]) + sqr(x[1]) + sin(0.0 * x[0]), n=2), Interval(0, 1))
    return SepInverse(Function(lambda x: sqr(x[0]) + sqr(x[1]), n=2), Interval(0, 1))


@pytest.mark.parametrize("numpy_path", [False, True])
def test_interior_point_on_lower_bound_is_inside(numpy_path: bool) -> None:
    xin, xout = _disk_sep(numpy_path)(Box([(-0.2, 0.2)] * 2))
    assert bool(xin.is_empty().all())
    assert bool((xout == Box([(-0.2, 0.2)] * 2)).all())
    xin, _ = _disk_sep(numpy_path)(Box([(0.0, 0.0)] * 2))  # the degenerate centre box: f = 0 = Y⁻
    assert bool(xin.is_empty().all())


@pytest.mark.parametrize("numpy_path", [False, True])
def test_boundary_boxes_keep_the_outside_part(numpy_path: bool) -> None:
    """A box across the circle keeps exactly its outside part in ``x_in`` (x² + y² >= 1 there)."""
    xin, xout = _disk_sep(numpy_path)(Box([(-0.2, 0.2), (0.9, 1.1)]))
    ex = mpmath.sqrt(1 - mpmath.mpf(0.2) ** 2)
    assert _close_below(float(xin.lo[1]), ex, 64 * ULP) and xin.hi[1] == 1.1
    assert xout.hi[1] == 1.0 or _close_above(float(xout.hi[1]), mpmath.mpf(1), 8 * ULP)


def test_sep_transform_inner_part() -> None:
    """codac's SepTransform test: the disk of radius 1 at (-2, -2); ``x_in`` is ``[-2.5,-1.5]×[-1.134, 10]``."""
    s1 = SepInverse(Function(lambda x: sqr(x[0]) + sqr(x[1]), n=2), Interval(0, 1))
    s2 = SepTransform(
        s1, Transform(Function(lambda x: (x[0] - 2, x[1] - 2)), Function(lambda x: (x[0] + 2, x[1] + 2)))
    )
    xin, xout = s2(Box([(-2.5, -1.5), (-2, 10)]))
    ex = -2 + mpmath.sqrt(mpmath.mpf(3) / 4)  # -1.1339...
    assert _close_below(float(xin.lo[1]), ex, 64 * ULP) and xin.hi[1] == 10.0
    assert xin.lo[0] == -2.5 and xin.hi[0] == -1.5
    assert bool(xout.issubset(Box([(-2.5, -1.5), (-2, -1 + 1e-15)])).all())
    assert bool(Box([(-2.5, -1.5), (-2, -1)]).issubset(xout).all())


def test_pave_has_no_zero_area_boundary_boxes() -> None:
    p = pave(Box([(-1.5, 1.5)] * 2), SepInverse(Function(lambda x: sqr(x[0]) + sqr(x[1]), n=2), Interval(0, 1)),
             eps=0.05)  # fmt: skip
    blo, bhi = p.boundary
    area = np.prod(bhi - blo, axis=1)
    assert (area > 0).all()
