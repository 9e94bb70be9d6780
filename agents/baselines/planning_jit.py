"""Compiled kernels of the grid planner (:mod:`.planning`): the pixel graph, path lengths and box morphology.

* :func:`grid_csr`: the 8-connected graph of the free pixels in compressed sparse row form, exactly the
  matrix that :func:`.planning.pixel_graph` once assembled with whole-array numpy and ``scipy.sparse``
  (rows over the flat pixel indices, each row's columns ascending, a move costing its length 1 or
  ``√2``, times the mean of its two ends' weights when weighted; a diagonal move needs both side pixels
  free), built in one pass over the pixels;
* :func:`grid_lengths`: Dijkstra's algorithm over that graph (:func:`csr_lengths`: an indexed binary
  heap), from several starts, each optionally stopped once a set of target pixels is settled.
  Every path length is the fixed point ``d(v) = min_u fl(d(u) + w(u, v))`` over the neighbours ``u``
  (the weights are positive, so a neighbour settled later never lowers it): the same floats as any other
  exact-minimum Dijkstra over the same edge weights, whatever its order among equal keys;
* :func:`box_dilate`, :func:`box_erode`: ``k`` iterations of the 3 x 3 binary dilation / erosion
  (outside the grid counts as not in the mask), i.e. the ``(2k + 1)``-square window, as two separable
  passes of prefix counts.

>>> free = np.ones((3, 3), dtype=bool); free[1, 1] = False
>>> indptr, indices, data = grid_csr(free, np.ones((3, 3)), False)
>>> indices[indptr[0]:indptr[1]].tolist()                      # pixel 0: right and below, no diagonal
[1, 3]
>>> float(grid_lengths(free, np.ones((3, 3)), False, np.array([0]), np.array([8]))[0, 8])
4.0
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.scalar_jit import njit

#: Length of a diagonal move (``math.hypot(1, 1)``, as :func:`.planning.pixel_graph` had it).
_DIAG = math.hypot(1.0, 1.0)
# The neighbour loops below are written out in each kernel (offsets ``dr``, ``dc`` in -1..1, i.e. ascending
# flat index, the column order of a CSR row): a helper taking the arrays costs far more per call than the
# move itself.


@njit
def grid_csr(
    free: np.ndarray, weight: np.ndarray, weighted: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(indptr, indices, data)`` (``int32``, ``int32``, ``float64``) of the ``(h w, h w)`` graph of the
    ``(h, w)`` bool ``free`` pixels; ``weight`` (``(h, w)`` float) is read only when ``weighted``."""
    h, w = free.shape
    n = h * w
    indptr = np.zeros(n + 1, dtype=np.int32)
    indices = np.empty(8 * n, dtype=np.int32)
    data = np.empty(8 * n, dtype=np.float64)
    k = 0
    for r in range(h):
        for c in range(w):
            if free[r, c]:
                for dr in range(-1, 2):
                    rr = r + dr
                    if rr < 0 or rr >= h:
                        continue
                    for dc in range(-1, 2):
                        cc = c + dc
                        if (dr == 0 and dc == 0) or cc < 0 or cc >= w or not free[rr, cc]:
                            continue
                        hyp = 1.0
                        if dr != 0 and dc != 0:
                            if not (free[r, cc] and free[rr, c]):
                                continue
                            hyp = _DIAG
                        indices[k] = rr * w + cc
                        data[k] = hyp * 0.5 * (weight[r, c] + weight[rr, cc]) if weighted else hyp
                        k += 1
            indptr[r * w + c + 1] = k
    return indptr, indices[:k].copy(), data[:k].copy()


@njit
def grid_lengths(
    free: np.ndarray, weight: np.ndarray, weighted: bool, starts: np.ndarray, targets: np.ndarray
) -> np.ndarray:
    """``(S, h w)`` path lengths (``inf``: unreachable) from each flat pixel of ``starts`` over the graph of
    :func:`grid_csr` (a start not free has no moves). With ``targets`` (flat pixels, may be empty: no
    stop), each search stops once all of them are settled; only their lengths (and those settled
    before) are then final, the others are upper bounds or ``inf``."""
    indptr, indices, data = grid_csr(free, weight, weighted)
    return csr_lengths(indptr, indices, data, starts, targets)


@njit
def csr_lengths(
    indptr: np.ndarray, indices: np.ndarray, data: np.ndarray, starts: np.ndarray, targets: np.ndarray
) -> np.ndarray:
    """:func:`grid_lengths` over a graph in CSR form (:func:`grid_csr`). With every move costing at least 1
    (the baselines' graphs), a bucket queue over ``floor(length)`` (Dial 1969): a pixel's length is final
    once its bucket comes up, since a move from the same bucket costs at least 1 and lands in a later one;
    else an indexed binary heap."""
    n = len(indptr) - 1
    out = np.full((len(starts), n), np.inf)
    is_target = np.zeros(n, dtype=np.bool_)
    for t in targets:
        is_target[t] = True
    n_targets = int(np.count_nonzero(is_target))
    if len(data) and data.min() < 1.0:
        _heap_lengths(indptr, indices, data, starts, is_target, n_targets, out)
        return out
    n_buckets = int(data.max()) + 2 if len(data) else 2  # a move lands at most int(max) + 1 buckets on
    head = np.empty(n_buckets, dtype=np.int64)
    entry = np.empty(len(data) + 1, dtype=np.int64)  # queued pixels, one linked list per bucket
    nxt = np.empty(len(data) + 1, dtype=np.int64)
    done = np.zeros(n, dtype=np.bool_)
    for s in range(len(starts)):
        dist = out[s]
        done[:] = False
        head[:] = -1
        left = n_targets if n_targets else -1  # -1: no stop
        src = starts[s]
        dist[src] = 0.0
        entry[0], nxt[0], head[0], used, queued, cur = src, -1, 0, 1, 1, 0
        while queued > 0 and left != 0:
            b = cur % n_buckets
            while head[b] != -1:
                k = head[b]
                head[b] = nxt[k]
                queued -= 1
                u = entry[k]
                if done[u]:
                    continue
                done[u] = True
                if is_target[u]:
                    left -= 1
                    if left == 0:
                        break
                d = dist[u]
                for e in range(indptr[u], indptr[u + 1]):
                    v = indices[e]
                    nd = d + data[e]
                    if done[v] or not nd < dist[v]:
                        continue
                    dist[v] = nd
                    c = int(nd) % n_buckets
                    entry[used], nxt[used] = v, head[c]
                    head[c] = used
                    used += 1
                    queued += 1
            cur += 1
    return out


@njit
def _heap_lengths(
    indptr: np.ndarray,
    indices: np.ndarray,
    data: np.ndarray,
    starts: np.ndarray,
    is_target: np.ndarray,
    n_targets: int,
    out: np.ndarray,
) -> None:
    """Dijkstra with an indexed binary heap (decrease-key in place) into ``out``, any positive costs."""
    n = len(indptr) - 1
    heap = np.empty(n, dtype=np.int64)  # pixels, ordered by their tentative length
    pos = np.empty(n, dtype=np.int64)  # heap slot of each pixel; -1 never queued, -2 settled
    for s in range(len(starts)):
        dist = out[s]
        pos[:] = -1
        left = n_targets
        src = starts[s]
        dist[src] = 0.0
        heap[0], pos[src], size = src, 0, 1
        while size > 0:
            u = heap[0]
            pos[u] = -2
            size -= 1
            if size > 0:  # the last entry sifts down from the root
                x, dx, i = heap[size], dist[heap[size]], 0
                while True:
                    child = 2 * i + 1
                    if child >= size:
                        break
                    if child + 1 < size and dist[heap[child + 1]] < dist[heap[child]]:
                        child += 1
                    if dist[heap[child]] >= dx:
                        break
                    heap[i] = heap[child]
                    pos[heap[i]] = i
                    i = child
                heap[i], pos[x] = x, i
            if is_target[u]:
                left -= 1
                if left == 0:
                    break
            d = dist[u]
            for e in range(indptr[u], indptr[u + 1]):
                v = indices[e]
                if pos[v] == -2:
                    continue
                nd = d + data[e]
                if not nd < dist[v]:
                    continue
                dist[v] = nd
                i = pos[v]
                if i == -1:  # a new entry at the end
                    i = size
                    size += 1
                while i > 0:  # sift up
                    parent = (i - 1) >> 1
                    if dist[heap[parent]] <= nd:
                        break
                    heap[i] = heap[parent]
                    pos[heap[i]] = i
                    i = parent
                heap[i], pos[v] = v, i


@njit
def _window_rows(mask: np.ndarray, k: int, erode: bool) -> np.ndarray:
    """Along each row: any (dilation) / all with the window inside the row (erosion) of ``[c - k, c + k]``."""
    h, w = mask.shape
    out = np.zeros((w, h), dtype=np.bool_)  # transposed, so that the second pass runs over rows again
    pre = np.zeros(w + 1, dtype=np.int64)
    for r in range(h):
        for c in range(w):
            pre[c + 1] = pre[c] + (1 if mask[r, c] else 0)
        for c in range(w):
            if erode:
                out[c, r] = c - k >= 0 and c + k < w and pre[c + k + 1] - pre[c - k] == 2 * k + 1
            else:
                out[c, r] = pre[min(c + k + 1, w)] - pre[max(c - k, 0)] > 0
    return out


@njit
def box_dilate(mask: np.ndarray, k: int) -> np.ndarray:
    """``(h, w)`` bool: the pixels within Chebyshev distance ``k`` of a ``mask`` pixel."""
    return _window_rows(_window_rows(mask, k, False), k, False)


@njit
def box_erode(mask: np.ndarray, k: int) -> np.ndarray:
    """``(h, w)`` bool: the pixels whose ``(2k + 1)``-square lies inside the grid and inside ``mask``."""
    return _window_rows(_window_rows(mask, k, True), k, True)
