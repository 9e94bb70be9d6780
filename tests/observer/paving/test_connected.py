"""Connected subsets of a paving (codac's ``connected_subsets``) and pavings of a contractor through
:class:`SepCtcPair`."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.observer import Box, CtcFwdBwd, Function, Interval, SepInverse, pave
from digslam.observer.paving import connected_subsets
from digslam.observer.sets import SepCtcPair, check_separation


def _oracle(lo: np.ndarray, hi: np.ndarray) -> set[frozenset[int]]:
    """Components by breadth-first search over all pairs of intersecting closed boxes."""
    n = lo.shape[0]
    touch = ((lo[:, None] <= hi[None]) & (lo[None] <= hi[:, None])).all(axis=2)
    seen, comps = np.zeros(n, dtype=bool), set()
    for s in range(n):
        if seen[s]:
            continue
        stack, comp = [s], set()
        seen[s] = True
        while stack:
            i = stack.pop()
            comp.add(i)
            for j in np.flatnonzero(touch[i] & ~seen).tolist():
                seen[j] = True
                stack.append(j)
        comps.add(frozenset(comp))
    return comps


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 40), st.integers(1, 3))
def test_components_match_the_oracle(seed: int, n_box: int, n: int) -> None:
    rng = np.random.default_rng(seed)
    lo = rng.integers(0, 12, (n_box, n)).astype(float)
    hi = lo + rng.integers(0, 3, (n_box, n))  # integer bounds: many boxes touch by a face or a corner
    comps = connected_subsets(lo, hi)
    assert {frozenset(c.tolist()) for c in comps} == _oracle(lo, hi)
    assert [c.size for c in comps] == sorted((c.size for c in comps), reverse=True)


def test_two_rings_make_two_subsets() -> None:
    f = Function(lambda x: x[0] ** 2 + x[1] ** 2)
    two = SepInverse(f, Interval(0.25, 1)) | SepInverse(f, Interval(4, 6.25))
    p = pave(Box([(-3, 3), (-3, 3)]), two, 0.1)
    subsets = p.connected_subsets()
    assert len(subsets) == 2
    outer_ring = subsets[0]  # the largest first
    assert float(outer_ring[1].max()) >= 2.5 and float(subsets[1][1].max()) < 1.5


def test_bad_input() -> None:
    with pytest.raises(ValueError, match="non-empty"):
        connected_subsets(np.array([[1.0]]), np.array([[0.0]]))
    with pytest.raises(ValueError, match="arrays"):
        connected_subsets(np.zeros(3), np.ones(3))
    with pytest.raises(ValueError, match="at least one"):
        SepCtcPair(None, None)
    c1 = CtcFwdBwd(Function(lambda x: x[0], n=1), Interval(0, 1))
    c2 = CtcFwdBwd(Function(lambda x: x[0] + x[1], n=2), Interval(0, 1))
    with pytest.raises(ValueError, match="dimensions"):
        SepCtcPair(c1, c2)


def test_sep_ctc_pair_separates() -> None:
    """``{C_in, C_out}`` of the unit disk's contractor and its complement's: Eq. 2.48 and soundness."""
    f = Function(lambda x: x[0] ** 2 + x[1] ** 2)
    disk_out = CtcFwdBwd(f, Interval(0, 1))
    disk_in = CtcFwdBwd(f, Interval(1, np.inf))  # closure of the complement: sound for C_in
    rng = np.random.default_rng(1)
    lo = rng.uniform(-2, 2, (300, 2))
    hi = lo + rng.uniform(0, 1, (300, 2))
    for sep in (SepCtcPair(disk_in, disk_out), SepCtcPair(None, disk_out)):
        xin, xout = sep.separate(lo, hi)
        assert not check_separation(xin, xout, lo, hi).any()
        pts = rng.uniform(lo[:, None], hi[:, None], (300, 50, 2))
        inside = (pts**2).sum(axis=2) <= 1
        in_out = ((pts >= xout[0][:, None]) & (pts <= xout[1][:, None])).all(axis=2)
        assert in_out[inside].all()
    xin, _ = SepCtcPair(None, disk_out).separate(lo, hi)
    assert (xin[0] == lo).all() and (xin[1] == hi).all()  # nothing proved inside
