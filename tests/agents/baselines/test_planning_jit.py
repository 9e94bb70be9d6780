"""The compiled grid kernels (:mod:`digslam.agents.baselines.planning_jit`) against numpy / scipy oracles:
the same graph matrix, the same path lengths (bit for bit), the same morphology."""

import math

import numpy as np
import pytest
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from digslam.agents.baselines import planning as pl
from digslam.agents.baselines import planning_jit as pj


def oracle_graph(free, weight=None):
    """The pixel graph assembled with whole-array numpy and ``scipy.sparse`` (four edge directions)."""
    h, w = free.shape
    idx = np.arange(h * w).reshape(h, w)
    rows, cols, wts = [], [], []
    for dr, dc in [(0, 1), (1, -1), (1, 0), (1, 1)]:
        a = free[: h - dr, max(-dc, 0) : w - max(dc, 0)]
        b = free[dr:, max(dc, 0) : w + min(dc, 0) or None]
        ok = a & b
        if dr and dc:
            ok &= (
                free[: h - dr, max(dc, 0) : w + min(dc, 0) or None] & free[dr:, max(-dc, 0) : w - max(dc, 0)]
            )
        ia = idx[: h - dr, max(-dc, 0) : w - max(dc, 0)][ok]
        ib = idx[dr:, max(dc, 0) : w + min(dc, 0) or None][ok]
        rows += [ia, ib]
        cols += [ib, ia]
        step = np.full(ia.size, math.hypot(dr, dc))
        if weight is not None:
            step = step * 0.5 * (weight.flat[ia] + weight.flat[ib])
        wts += [step, step]
    r, c = np.concatenate(rows), np.concatenate(cols)
    return coo_matrix((np.concatenate(wts), (r, c)), shape=(h * w, h * w)).tocsr()


def random_grid(rng, h, w):
    free = ndimage.binary_opening(rng.random((h, w)) < 0.75)  # walls and pockets
    weight = rng.choice([1.0, 2.0, 3.0, 1.7], size=(h, w))
    return free, weight


@pytest.mark.parametrize("seed", range(6))
def test_graph_matches_oracle(seed):
    rng = np.random.default_rng(seed)
    free, weight = random_grid(rng, 17 + seed, 23)
    for wt in (None, weight):
        a, b = pl.pixel_graph(free, wt), oracle_graph(free, wt)
        assert np.array_equal(a.indptr, b.indptr) and np.array_equal(a.indices, b.indices)
        assert np.array_equal(a.data, b.data)


@pytest.mark.parametrize("seed", range(6))
def test_shortest_paths_match_scipy_on_the_oracle_graph(seed):
    rng = np.random.default_rng(seed)
    free, weight = random_grid(rng, 20, 20 + seed)
    start = tuple(int(v) for v in np.argwhere(free)[seed])
    for wt in (None, weight):
        dist, pred = pl.shortest_paths(free, start, wt)
        d0, p0 = dijkstra(oracle_graph(free, wt), indices=start[0] * free.shape[1] + start[1],
                          return_predecessors=True)  # fmt: skip
        assert np.array_equal(dist.ravel(), d0) and np.array_equal(pred, p0)


@pytest.mark.parametrize("seed", range(8))
def test_path_lengths_bit_equal_to_scipy(seed):
    rng = np.random.default_rng(100 + seed)
    free, weight = random_grid(rng, 24, 19)
    starts = np.argwhere(free)[rng.choice(np.count_nonzero(free), 5, replace=False)]
    starts[0] = (0, 0)  # a start need not be free
    for wt in (None, weight):
        f = free.copy()
        f[starts[:, 0], starts[:, 1]] = True
        ref = dijkstra(oracle_graph(f, wt), indices=starts[:, 0] * f.shape[1] + starts[:, 1])
        got = pl.path_lengths(free, starts, wt)
        assert np.array_equal(got.reshape(len(starts), -1), ref)
        pairs = pl.pair_lengths(free, starts, wt)
        assert np.array_equal(pairs, got[:, starts[:, 0], starts[:, 1]])


def test_lengths_stop_at_targets_and_handle_no_moves():
    free = np.zeros((4, 4), dtype=bool)
    free[0, 0] = True  # the start alone: no moves
    out = pj.grid_lengths(free, np.ones((1, 1)), False, np.array([0]), np.array([5]))
    assert out[0, 0] == 0.0 and np.isinf(out[0, 1:]).all()
    assert pl.pair_lengths(free, np.zeros((0, 2))).shape == (0, 0)


@pytest.mark.parametrize("k", [0, 1, 2, 3, 5])
def test_box_morphology_matches_ndimage(k):
    rng = np.random.default_rng(k)
    for shape in [(13, 17), (30, 30), (3, 9)]:
        mask = rng.random(shape) < 0.6
        ref_e = (
            mask.copy() if k == 0 else ndimage.binary_erosion(mask, pl.SQUARE, iterations=k, border_value=0)
        )
        ref_d = mask.copy() if k == 0 else ndimage.binary_dilation(mask, pl.SQUARE, iterations=k)
        assert np.array_equal(pl.erode(mask, k), ref_e)
        assert np.array_equal(pl.dilate(mask, k), ref_d)
        sparse = rng.random(shape) < 0.03
        ref = sparse.copy() if k == 0 else ndimage.binary_dilation(sparse, pl.SQUARE, iterations=k)
        assert np.array_equal(pl.dilate(sparse, k), ref)


@pytest.mark.parametrize("seed", range(4))
def test_bucket_and_heap_queues_agree_bit_for_bit(seed):
    """Costs >= 1 take the bucket queue, a cost below 1 the heap; the same lengths either way."""
    rng = np.random.default_rng(200 + seed)
    free, weight = random_grid(rng, 21, 26)
    starts = np.flatnonzero(free)[:4]
    ip, ix, data = pj.grid_csr(free, weight, True)
    small = data.copy()
    small[0] = 0.999  # one cheap move: the heap path
    for d in (data, small):
        ref = dijkstra(pl.csr_matrix((d, ix, ip), shape=(free.size, free.size)), indices=starts)
        got = pj.csr_lengths(ip, ix, d, starts, np.zeros(0, dtype=np.int64))
        assert np.array_equal(got, ref)
        part = pj.csr_lengths(ip, ix, d, starts, starts[1:3])
        assert np.array_equal(part[:, starts[1:3]], ref[:, starts[1:3]])
