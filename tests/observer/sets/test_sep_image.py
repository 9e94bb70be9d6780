"""Tests of the image contractor/separator (thesis §2.5.3, Eq. 2.71–2.74) and its agreement with the
polygon separator on a rasterised polygon."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from digslam.observer.core.boxes import empty_rows
from digslam.observer.sets.sep_image import CtcImage, SepImage
from digslam.observer.sets.sep_polygon import SepPolygon
from digslam.observer.sets.separators import check_separation

RNG_IMG = np.random.default_rng(7).random((23, 31)) < 0.3


def brute_hull(img: np.ndarray, x0: float, y0: float, ex: float, ey: float, lo: np.ndarray, hi: np.ndarray):
    """Hull of (closed set pixels ∩ box), pixel by pixel (dyadic geometry: float is exact)."""
    rlo, rhi = np.full(2, np.inf), np.full(2, -np.inf)
    for i, j in np.argwhere(img):
        plo = np.maximum([x0 + j * ex, y0 - (i + 1) * ey], lo)
        phi = np.minimum([x0 + (j + 1) * ex, y0 - i * ey], hi)
        if (plo <= phi).all():
            rlo, rhi = np.minimum(rlo, plo), np.maximum(rhi, phi)
    return rlo, rhi


def boxes(rng: np.random.Generator, n: int, lo: float, hi: float, grid: float | None = None) -> tuple:
    c = rng.uniform(lo, hi, (n, 2))
    w = rng.exponential(1.0, (n, 2)) * (rng.random((n, 2)) > 0.1)
    blo, bhi = c - w, c + w
    if grid is not None:  # snap some bounds onto pixel borders
        snap = rng.random((n, 2)) < 0.5
        blo = np.where(snap, np.floor(blo / grid) * grid, blo)
        bhi = np.where(snap, np.ceil(bhi / grid) * grid, bhi)
    return blo, bhi


def test_contractor_is_minimal_on_dyadic_grid() -> None:
    x0, y0, ex, ey = -2.0, 3.5, 0.25, 0.125
    c = CtcImage(RNG_IMG, (x0, y0), (ex, ey))
    lo, hi = boxes(np.random.default_rng(1), 150, -3.0, 6.0, grid=0.125)
    clo, chi = c.contract(lo, hi)
    for r in range(len(lo)):
        blo, bhi = brute_hull(RNG_IMG, x0, y0, ex, ey, lo[r], hi[r])
        assert clo[r].tolist() == blo.tolist() and chi[r].tolist() == bhi.tolist(), r


@pytest.mark.parametrize("outside", [False, True])
def test_separation_invariant_and_exact_soundness(outside: bool) -> None:
    x0, y0, ex, ey = 0.1, 2.3, 0.1, -0.07  # non-dyadic, thesis sign convention for ey
    s = SepImage(RNG_IMG, (x0, y0), (ex, ey), outside=outside)
    rng = np.random.default_rng(2)
    lo, hi = boxes(rng, 400, -0.5, 4.0, grid=0.1)
    lo = np.vstack([lo, [[-np.inf, -np.inf], [np.inf, np.inf], [0.1, 2.3]]])
    hi = np.vstack([hi, [[np.inf, np.inf], [-np.inf, -np.inf], [0.2, 2.3]]])
    xin, xout = s.separate(lo, hi)
    assert not check_separation(xin, xout, lo, hi).any()
    assert empty_rows(*xin).any() and empty_rows(*xout).any()
    fx0, fy0, fex, fey = (Fraction(v) for v in (x0, y0, ex, -ey))
    h, w = RNG_IMG.shape
    for r in range(len(lo) - 3):
        for p in (rng.uniform(lo[r], hi[r]), lo[r], hi[r], np.array([lo[r, 0], hi[r, 1]])):
            fx, fy = (Fraction(float(p[0])) - fx0) / fex, (fy0 - Fraction(float(p[1]))) / fey
            # the set is the union of the CLOSED set pixels (a point on a border belongs to every pixel it
            # touches), so its complement is open: a border point touching a set pixel is in the set
            js, is_ = ({math.floor(f), math.ceil(f) - 1} for f in (fx, fy))
            vals = {bool(RNG_IMG[i, j]) if 0 <= i < h and 0 <= j < w else outside for i in is_ for j in js}
            inside = (xout[0][r] <= p).all() and (p <= xout[1][r]).all()
            in_comp = (xin[0][r] <= p).all() and (p <= xin[1][r]).all()
            assert inside or True not in vals, (r, p)  # a point of the set is in x_out
            assert in_comp or True in vals, (r, p)  # a point outside the set is in x_in


def test_outside_option() -> None:
    img = np.ones((2, 2), bool)
    far = (np.array([[10.0, 10.0]]), np.array([[11.0, 11.0]]))
    for outside in (False, True):
        xin, xout = SepImage(img, (0.0, 2.0), (1.0, 1.0), outside=outside).separate(*far)
        assert empty_rows(*xout)[0] != outside and empty_rows(*xin)[0] == outside
    # a box across the image border with everything set: only the outside part is in x_in
    xin, xout = SepImage(img, (0.0, 2.0), (1.0, 1.0)).separate(np.array([[1.0, 0.5]]), np.array([[3.0, 1.5]]))
    assert xin[0].tolist() == [[2.0, 0.5]] and xout[1].tolist() == [[2.0, 1.5]]
    r = CtcImage(img, (0.0, 2.0), (1.0, 1.0))(([1.0, 0.5], [3.0, 1.5]))  # the Ctc call interface
    assert r[0].tolist() == [1.0, 0.5] and r[1].tolist() == [2.0, 1.5]


def test_inner_image_and_errors() -> None:
    img = np.zeros((4, 4), bool)
    img[1:3, 1:3] = True
    low = np.zeros_like(img)
    low[1, 1] = True
    s = SepImage(img, (0.0, 4.0), (1.0, 1.0), inner=low)
    xin, xout = s.separate(np.array([[1.2, 2.2], [2.2, 1.2]]), np.array([[1.8, 2.8], [2.8, 1.8]]))
    assert empty_rows(*xin).tolist() == [True, False] and not empty_rows(*xout).any()
    with pytest.raises(ValueError, match="inner: pixel"):
        SepImage(low, (0.0, 4.0), (1.0, 1.0), inner=img)
    with pytest.raises(ValueError, match="inner: shape"):
        SepImage(img, (0.0, 4.0), (1.0, 1.0), inner=low[:2])
    with pytest.raises(ValueError, match="image: expected"):
        CtcImage(np.zeros(4), (0.0, 0.0), (1.0, 1.0))
    with pytest.raises(ValueError, match="pixel_size"):
        CtcImage(img, (0.0, 0.0), (0.0, 1.0))
    with pytest.raises(ValueError, match="origin"):
        CtcImage(img, (np.nan, 0.0), (1.0, 1.0))


def test_agrees_with_polygon_separator() -> None:
    outer = [(0.3, 0.2), (7.7, 0.9), (6.1, 7.4), (3.9, 3.3), (0.8, 6.6)]
    hole = [(2.0, 1.5), (4.5, 1.5), (3.0, 2.8)]
    poly = SepPolygon([outer, hole])
    x0, y0, e, n = 0.0, 8.0, 0.125, 64
    jj, ii = np.meshgrid(np.arange(n), np.arange(n))
    plo = np.stack([x0 + jj * e, y0 - (ii + 1) * e], -1).reshape(-1, 2)
    phi = np.stack([x0 + (jj + 1) * e, y0 - ii * e], -1).reshape(-1, 2)
    pin, pout = poly.separate(plo, phi)
    upper = ~empty_rows(*pout).reshape(n, n)  # pixels meeting the polygon (X+)
    lower = empty_rows(*pin).reshape(n, n)  # pixels inside it (X-)
    sep = SepImage(upper, (x0, y0), (e, e), inner=lower)
    centre = SepImage(poly.test(0.5 * (plo + phi)).reshape(n, n) == 1, (x0, y0), (e, e))
    g = np.arange(-0.2, 8.2, 0.3)
    gx, gy = np.meshgrid(g, g)
    lo = np.stack([gx.ravel(), gy.ravel()], 1)
    hi = lo + 0.3
    verdict = {}
    for name, s in (("poly", poly), ("image", sep), ("centre", centre)):
        xin, xout = s.separate(lo, hi)
        verdict[name] = np.where(empty_rows(*xin), 1, np.where(empty_rows(*xout), -1, 0))
    p, im, ce = verdict["poly"], verdict["image"], verdict["centre"]
    assert not ((p * im) == -1).any()  # X-/X+ rasterisation: never contradicts, no tolerance
    assert ((p != 0) & (p == im)).sum() > 0.7 * (p != 0).sum()
    # centre rasterisation: differences only in cells within one pixel of the polygon boundary
    near = ~empty_rows(*poly.ctc.contract(lo - e, hi + e))
    assert not ((p != ce) & ~near).any()
