"""Tests of the polygon separator (thesis §2.5.1, Eq. 2.65–2.69): invariants, exact soundness, errors."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from digslam.observer.core.boxes import empty_rows
from digslam.observer.sets.sep_polygon import CtcPolygonBoundary, CtcSegments, SepPolygon, orient
from digslam.observer.sets.separators import check_separation

# a non-convex outer ring (a notch at the top) with a square hole; non-dyadic coordinates on purpose
OUTER = [(0.0, 0.0), (6.1, 0.0), (6.1, 5.3), (3.0, 2.7), (0.0, 5.3)]
HOLE = [(1.1, 1.0), (2.3, 1.0), (2.3, 2.1), (1.1, 2.1)]
RINGS = [OUTER, HOLE]


def exact_inside(p: np.ndarray, rings: list) -> bool | None:
    """Even-odd rule in rational arithmetic; None on the boundary."""
    x, y = Fraction(float(p[0])), Fraction(float(p[1]))
    odd = False
    for r in rings:
        for i in range(len(r)):
            (ax, ay), (bx, by) = (map(Fraction, r[i]), map(Fraction, r[(i + 1) % len(r)]))
            d = (bx - ax) * (y - ay) - (by - ay) * (x - ax)
            if d == 0 and min(ax, bx) <= x <= max(ax, bx) and min(ay, by) <= y <= max(ay, by):
                return None
            if (ay > y) != (by > y) and (d > 0) == (by > ay):
                odd = not odd
    return odd


def random_boxes(rng: np.random.Generator, n: int, lo: float = -1.0, hi: float = 7.5) -> tuple:
    c = rng.uniform(lo, hi, (n, 2))
    w = rng.exponential(0.4, (n, 2)) * (rng.random((n, 2)) > 0.1)  # some degenerate sides
    return c - w, c + w


@pytest.fixture(scope="module")
def sep() -> SepPolygon:
    return SepPolygon(RINGS)


def in_box(b: tuple, r: int, p: np.ndarray) -> bool:
    return bool(((b[0][r] <= p) & (p <= b[1][r])).all())


def test_separation_invariant(sep: SepPolygon) -> None:
    lo, hi = random_boxes(np.random.default_rng(1), 3000)
    lo = np.vstack([lo, [[-np.inf, -np.inf], [np.inf, np.inf], [3.0, 2.7], [-np.inf, 1.0]]])
    hi = np.vstack([hi, [[np.inf, np.inf], [-np.inf, -np.inf], [3.0, 2.7], [0.5, 1.5]]])
    xin, xout = sep.separate(lo, hi)
    assert not check_separation(xin, xout, lo, hi).any()
    assert empty_rows(*xin).sum() > 100 and empty_rows(*xout).sum() > 100  # it does decide boxes
    assert empty_rows(*xin)[-3] and empty_rows(*xout)[-3]  # the empty row stays empty


def test_soundness_by_exact_sampling(sep: SepPolygon) -> None:
    rng = np.random.default_rng(2)
    lo, hi = random_boxes(rng, 300)
    # tiny boxes straddling the boundary, at points on the edges (up to rounding) and at the vertices
    a = np.array(OUTER + HOLE)
    b = np.array(OUTER[1:] + OUTER[:1] + HOLE[1:] + HOLE[:1])
    e, t = rng.integers(0, len(a), 100), rng.random((100, 1))
    c = np.vstack([a[e] + t * (b[e] - a[e]), a])
    w = 10.0 ** rng.uniform(-15, -3, (len(c), 1))
    lo, hi = np.vstack([lo, c - w]), np.vstack([hi, c + w])
    xin, xout = sep.separate(lo, hi)
    for r in range(len(lo)):
        for p in (rng.uniform(lo[r], hi[r]), lo[r], hi[r]):
            v = exact_inside(p, RINGS)
            if v is False:  # outside points must stay in x_in
                assert in_box(xin, r, p), (r, p)
            if v is True:  # inside points must stay in x_out
                assert in_box(xout, r, p), (r, p)


def test_nonconvex_with_hole(sep: SepPolygon) -> None:
    lo = np.array([[1.5, 1.5], [0.2, 0.2], [2.9, 3.5], [7.0, 7.0], [0.5, 0.5], [2.0, 2.5]])
    hi = np.array([[2.0, 2.0], [0.8, 0.8], [3.1, 4.0], [8.0, 8.0], [2.6, 2.4], [4.0, 3.2]])
    (ilo, ihi), (olo, ohi) = sep.separate(lo, hi)
    ein, eout = empty_rows(ilo, ihi), empty_rows(olo, ohi)
    # hole -> outside; corner of the ring region -> inside; in the notch -> outside; far -> outside
    assert eout.tolist()[:4] == [True, False, True, True]
    assert ein.tolist()[:4] == [False, True, False, False]
    # a box containing the hole: x_in shrinks to the hole, x_out keeps everything
    assert np.allclose(ilo[4], [1.1, 1.0]) and np.allclose(ihi[4], [2.3, 2.1])
    assert (olo[4] == lo[4]).all() and (ohi[4] == hi[4]).all()
    # a box across the notch's reflex vertex (3, 2.7): undecided, and the boundary is kept
    assert not ein[5] and not eout[5]
    assert olo[5, 1] <= 2.7 <= ohi[5, 1] and ilo[5, 1] <= 2.7 <= ihi[5, 1]


def test_box_across_edge_is_cut_exactly(sep: SepPolygon) -> None:
    (ilo, ihi), (olo, ohi) = sep.separate(np.array([[4.0, -0.5]]), np.array([[5.0, 0.5]]))
    assert ilo.tolist() == [[4.0, -0.5]] and ihi.tolist() == [[5.0, 0.0]]  # below y = 0: outside
    assert olo.tolist() == [[4.0, 0.0]] and ohi.tolist() == [[5.0, 0.5]]


def test_boxes_on_vertices_and_edges_stay_undecided(sep: SepPolygon) -> None:
    verts = np.array(OUTER + HOLE)
    mids = 0.5 * (verts[[0, 1, 2, 3, 5, 6]] + verts[[1, 2, 3, 4, 6, 7]])
    for pts in (verts, mids):
        for lo, hi in ((pts, pts), (pts - 0.01, pts + 0.01)):
            xin, xout = sep.separate(lo, hi)
            assert not empty_rows(*xin).any() and not empty_rows(*xout).any()


def test_point_test_is_robust() -> None:
    s = SepPolygon([[(0.1, 0.1), (0.7, 0.3), (0.3, 0.9)]])
    a, b = np.array([0.1, 0.1]), np.array([0.7, 0.3])
    t = np.linspace(0, 1, 41)[:, None]
    on = a + t * (b - a)  # on or within an ulp of the edge
    pts = np.concatenate([on, np.nextafter(on, np.inf), np.nextafter(on, -np.inf), s.rings[0]])
    st = s.test(pts)
    for p, v in zip(pts, st, strict=True):
        e = exact_inside(p, s.rings)
        assert v == 0 or (e is not None and (v == 1) == e)
    assert (st[-3:] == 0).all()  # vertices are on the boundary
    lo, hi = orient(np.array([0.0, 0.0]), np.array([1.0, 1.0]), np.array([[3.0, 3.0], [1.0, 2.0]]))
    assert lo[0] == hi[0] == 0 and lo[1] > 0


def test_segment_contractor_is_sound_and_tight() -> None:
    rng = np.random.default_rng(3)
    a, b = rng.uniform(-3, 3, (5, 2)), rng.uniform(-3, 3, (5, 2))
    a[0], b[0] = (0.0, 1.0), (2.0, 1.0)  # horizontal
    a[1], b[1] = (0.5, -1.0), (0.5, 2.0)  # vertical
    c = CtcSegments(a, b)
    lo, hi = random_boxes(rng, 500, -3, 3)
    clo, chi = c.contract(lo, hi)
    t = rng.random(200)
    for e in range(5):
        pts = a[e] + t[:, None] * (b[e] - a[e])
        kept = ((clo[:, None] <= pts) & (pts <= chi[:, None])).all(-1)  # (boxes, points)
        # points of the segment (up to rounding) well inside a box are kept
        deep = ((lo[:, None] + 1e-9 <= pts) & (pts <= hi[:, None] - 1e-9)).all(-1)
        assert (kept | ~deep).all()
        # tight: the result is the hull of the clipped segment (Liang-Barsky in float, tolerance 1e-9)
        d = b[e] - a[e]
        with np.errstate(divide="ignore", invalid="ignore"):
            t1, t2 = (lo - a[e]) / d, (hi - a[e]) / d
        tl = np.nanmax(np.where(d != 0, np.minimum(t1, t2), 0.0), axis=1).clip(0, None)
        tu = np.nanmin(np.where(d != 0, np.maximum(t1, t2), 1.0), axis=1).clip(None, 1)
        flat_ok = ((d != 0) | ((lo <= a[e]) & (a[e] <= hi))).all(axis=1)
        ok = (tl < tu - 1e-9) & flat_ok
        ends = np.stack([a[e] + tl[:, None] * d, a[e] + tu[:, None] * d])
        single = CtcSegments(a[e : e + 1], b[e : e + 1]).contract(lo[ok], hi[ok])
        assert np.allclose(single[0], ends.min(0)[ok], atol=1e-9)
        assert np.allclose(single[1], ends.max(0)[ok], atol=1e-9)
        assert (clo[ok] <= single[0] + 0).all() and (chi[ok] >= single[1]).all()  # union contains it
    # dyadic points exactly on the diagonal, as point boxes and as boxes touching them
    cd = CtcSegments(np.array([[0.0, 0.0]]), np.array([[1.0, 2.0]]))
    p = np.array([[k / 8, k / 4] for k in range(9)])
    assert not empty_rows(*cd.contract(p, p)).any()
    r = cd.contract(np.array([[0.25, -1.0]]), np.array([[0.5, 9.0]]))
    assert r[0].tolist() == [[0.25, 0.5]] and r[1].tolist() == [[0.5, 1.0]]
    assert empty_rows(*cd.contract(np.array([[0.6, 0.0]]), np.array([[1.0, 1.1]]))).all()


@pytest.mark.parametrize(
    ("rings", "msg"),
    [
        ([[(0, 0), (1, 0)]], r"polygons\[0\]: a ring needs at least three"),
        ([[(0, 0), (1, 0), (np.nan, 1)]], r"polygons\[0\]: NaN"),
        ([[(0, 0), (2, 2), (2, 0), (0, 2)]], r"polygons\[0\]: edges 0 and 2 meet \(self-intersecting"),
        (
            [[(0, 0), (4, 0), (4, 4)], [(1, 0.5), (5, 0.5), (5, 1)]],
            r"polygons\[0\]: edge \d meets edge \d of polygons\[1\] \(rings must not touch",
        ),
        ([[(0, 0), (2, 0), (1, 0), (1, 1)]], r"polygons\[0\]: .*folds back"),
        ([[(0, 0), (1, 0), (1, 0), (1, 1)]], r"polygons\[0\]: vertex 1 repeats"),
        ([np.zeros((3, 3))], r"polygons\[0\]: expected vertices of shape"),
        ([], "at least one ring"),
        ([[(0, 0), (4, 0), (4, 4), (0, 4)], [(0, 0), (1, 1), (1, 2)]], r"polygons\[0\].*meets"),
    ],
)
def test_bad_input(rings: list, msg: str) -> None:
    with pytest.raises(ValueError, match=msg):
        SepPolygon(rings)


def test_closing_vertex_and_single_array() -> None:
    sq = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0)])
    s = SepPolygon(sq)
    assert len(s.rings) == 1 and len(s.rings[0]) == 4
    assert isinstance(s.ctc, CtcPolygonBoundary)
    xin, xout = s(([0.2, 0.2], [0.8, 0.8]))
    assert empty_rows(*xin).all() and not empty_rows(*xout).any()
