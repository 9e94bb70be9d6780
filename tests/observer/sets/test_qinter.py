"""The exact box q-intersection (:func:`box_qinter`, Eq. 2.5) against a brute-force oracle, and
:class:`SepQInter` with it (Eq. 2.54): containment of every point lying in ``m - q`` boxes, equality with
the hull of the intersections of all ``m - q``-subsets, and never wider than the coordinate-wise
:func:`relaxed_intersection`."""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.observer import Box, SepBox, SepQInter
from digslam.observer.sets.separators import box_qinter, check_separation, relaxed_intersection

INF = np.inf


def oracle(los: np.ndarray, his: np.ndarray, q: int) -> tuple[np.ndarray, np.ndarray]:
    """Hull of ``∩S`` over the subsets ``S`` of ``m - q`` boxes (Eq. 2.5), row by row."""
    m, n_rows, n = los.shape
    lo, hi = np.full((n_rows, n), INF), np.full((n_rows, n), -INF)
    for r in range(n_rows):
        for sub in itertools.combinations(range(m), m - q):
            a, b = los[list(sub), r].max(axis=0), his[list(sub), r].min(axis=0)
            if (a <= b).all():
                lo[r], hi[r] = np.minimum(lo[r], a), np.maximum(hi[r], b)
    return lo, hi


@st.composite
def stacks(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray, int]:
    """``(m, N, n)`` stacks of boxes on a coarse grid (so that bounds coincide often), some empty, some
    unbounded, and a ``q``."""
    m, n, n_rows = draw(st.integers(1, 6)), draw(st.integers(1, 3)), draw(st.integers(1, 4))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    lo = rng.integers(-3, 4, (m, n_rows, n)).astype(float) / 2
    hi = lo + rng.integers(0, 5, (m, n_rows, n)) / 2
    lo[rng.random((m, n_rows, n)) < 0.05] = -INF
    hi[rng.random((m, n_rows, n)) < 0.05] = INF
    empty = rng.random((m, n_rows)) < 0.1
    lo[empty], hi[empty] = INF, -INF
    return lo, hi, draw(st.integers(0, m - 1))


def _same(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> bool:
    ea, eb = (a[0] > a[1]).any(axis=1), (b[0] > b[1]).any(axis=1)
    live = ~ea
    return bool((ea == eb).all() and (a[0][live] == b[0][live]).all() and (a[1][live] == b[1][live]).all())


@settings(max_examples=150, deadline=None)
@given(stacks())
def test_exact_q_intersection_is_the_oracle_hull(data: tuple[np.ndarray, np.ndarray, int]) -> None:
    los, his, q = data
    assert _same(box_qinter(los, his, q), oracle(los, his, q))


@settings(max_examples=100, deadline=None)
@given(stacks())
def test_exact_holds_every_point_in_enough_boxes_and_lies_in_the_relaxed(
    data: tuple[np.ndarray, np.ndarray, int],
) -> None:
    los, his, q = data
    m = los.shape[0]
    lo, hi = box_qinter(los, his, q)
    rlo, rhi = relaxed_intersection(los, his, q)
    live = ~(lo > hi).any(axis=1)
    assert ((rlo[live] <= lo[live]) & (hi[live] <= rhi[live])).all()  # never wider than coordinate-wise
    rng = np.random.default_rng(0)
    for r in range(los.shape[1]):  # corners of the subset intersections and random points: exact counts
        pts = np.concatenate([np.clip(los[:, r], -5, 5), np.clip(his[:, r], -5, 5),
                              rng.integers(-8, 9, (60, los.shape[2])) / 2])  # fmt: skip
        for p in pts:
            fp = [Fraction(float(c)) for c in p]
            count = sum(all(a <= c <= b for a, c, b in zip(los[i, r], fp, his[i, r])) for i in range(m))
            if count >= m - q:
                assert live[r] and ((lo[r] <= p) & (p <= hi[r])).all()


def test_ibex_qinter_values() -> None:
    """ibex's qinter test (codac 1): five boxes of the plane, in at least 1, 2, 3, 4 of them."""
    boxes = [
        [(1, 5), (1, 6)],
        [(3, 7), (2, 5.5)],
        [(1.5, 2.5), (4.5, 8)],
        [(2.5, 5), (0, 4)],
        [(1.5, 8), (1.5, 3)],
    ]
    los = np.array([[[a for a, _ in b]] for b in boxes], dtype=float)
    his = np.array([[[c for _, c in b]] for b in boxes], dtype=float)
    want = {1: [(1, 8), (0, 8)], 2: [(1.5, 7), (1, 6)], 3: [(2.5, 5), (1.5, 4)], 4: [(3, 5), (2, 3)]}
    for need, box in want.items():
        lo, hi = box_qinter(los, his, 5 - need)
        assert lo[0].tolist() == [a for a, _ in box] and hi[0].tolist() == [b for _, b in box]
    lo, hi = box_qinter(los, his, 0)
    assert (lo > hi).all()  # no point in all five


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_sep_qinter_is_a_sound_separator(seed: int, exact: bool) -> None:
    """Points of a part proved inside lie in ``m - q`` boxes, points of a part proved outside do not."""
    rng = np.random.default_rng(seed)
    m = int(rng.integers(2, 6))
    c = rng.uniform(-2, 2, (m, 2))
    w = rng.uniform(0.2, 2, (m, 2))
    q = int(rng.integers(0, m))
    blo, bhi = c - w, c + w  # the boxes, as given to SepBox (membership below compares with them exactly)
    sep = SepQInter([SepBox(Box(list(zip(a, b)))) for a, b in zip(blo, bhi)], q, exact)
    lo = rng.uniform(-3, 3, (30, 2))
    hi = lo + rng.uniform(0, 1.5, (30, 2))
    xin, xout = sep.separate(lo, hi)
    assert not check_separation(xin, xout, lo, hi).any()
    pts = rng.uniform(lo[:, None], hi[:, None], (30, 40, 2))
    count = ((pts[:, :, None] >= blo) & (pts[:, :, None] <= bhi)).all(axis=3).sum(axis=2)
    member = count >= m - q
    in_out = ((pts >= xout[0][:, None]) & (pts <= xout[1][:, None])).all(axis=2)
    in_in = ((pts >= xin[0][:, None]) & (pts <= xin[1][:, None])).all(axis=2)
    assert in_out[member].all() and in_in[~member].all()
    if exact:  # never wider than the coordinate-wise form
        rin, rout = SepQInter(sep.seps, q, exact=False).separate(lo, hi)
        for a, b in ((xin, rin), (xout, rout)):
            live = ~(a[0] > a[1]).any(axis=1)
            assert ((b[0][live] <= a[0][live]) & (a[1][live] <= b[1][live])).all()


def test_bad_input() -> None:
    with pytest.raises(ValueError, match="q"):
        box_qinter(np.zeros((2, 1, 2)), np.ones((2, 1, 2)), 2)
    with pytest.raises(ValueError, match="exact"):
        SepQInter([SepBox(Box([(0, 1)]))], 0, exact="yes")  # type: ignore[arg-type]
