"""Grid planning and motion primitives of the heuristic baselines.

The agents read only the observation (``"map"`` channels clear / penumbra / dark / pose box, row 0 at the
top = largest ``y``; ``"state"`` with the pose box normalised to ``[-1, 1]`` over the grid frame). Planning
runs on the ``m x m`` map in pixel coordinates ``(row, col)``:

* :func:`shortest_paths`: Dijkstra over the 8-connected graph of traversable pixels (``scipy.sparse.csgraph``
  over :func:`pixel_graph`); :func:`path_lengths` from several pixels at once;
* :func:`path_to`: the pixel path from the predecessor array (a loop over the path's pixels, not the grid);
* :func:`line_of_sight`: the farthest path pixel reachable in a straight line over traversable pixels
  (string pulling, vectorised over the path and its samples);
* :func:`turn_then_go`: the unicycle command. Turning while driving makes the observer's box wrap around the
  arc (a 60-step arc at ``ω = 0.5`` grows the pose box about 17 times more than a straight line), so the
  robot turns in place (``v = 0``) and drives straight (``ω = 0``).

>>> free = np.ones((5, 5), dtype=bool); free[1:4, 2] = False
>>> dist, pred = shortest_paths(free, (2, 0))
>>> path_to(pred, free.shape, (2, 4))[-1].tolist(), round(float(dist[2, 4]), 3)  # around the wall
([2, 4], 6.828)
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import dijkstra

#: 8-neighbourhood offsets (dr, dc) and their lengths (pixels).
_OFFSETS = [(0, 1), (1, -1), (1, 0), (1, 1)]
SQUARE = np.ones((3, 3), dtype=bool)


def shortest_paths(
    free: np.ndarray, start: tuple[int, int], weight: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Path lengths (pixels, ``inf`` if unreachable) from ``start`` over the 8-connected ``free`` pixels,
    and the predecessor index of each pixel (``-9999`` where none).

    Diagonal moves need both side pixels free (no corner cutting). ``start`` is treated as free. With
    ``weight`` (``(h, w)`` costs per pixel > 0), a move costs its length times the mean of its two ends'.
    """
    free = np.asarray(free, dtype=bool).copy()
    if free.ndim != 2:
        raise ValueError(f"free: expected a 2-D mask, got shape {free.shape}")
    h, w = free.shape
    r0, c0 = start
    if not (0 <= r0 < h and 0 <= c0 < w):
        raise ValueError(f"start: {start} lies outside the {h} x {w} grid")
    free[r0, c0] = True
    dist, pred = dijkstra(pixel_graph(free, weight), indices=r0 * w + c0, return_predecessors=True)
    return dist.reshape(h, w), pred


def path_lengths(free: np.ndarray, starts: np.ndarray, weight: np.ndarray | None = None) -> np.ndarray:
    """``(S, h, w)`` path lengths from each of the ``(S, 2)`` pixels ``starts`` over the same graph as
    :func:`shortest_paths` (one Dijkstra call for all of them; the starts are treated as free).

    >>> free = np.ones((3, 4), dtype=bool); free[:2, 1] = False
    >>> path_lengths(free, np.array([[0, 0], [0, 3]]))[:, 0, 3].round(3).tolist()   # around the wall, and 0
    [6.414, 0.0]
    """
    free = np.asarray(free, dtype=bool).copy()
    starts = np.asarray(starts, dtype=np.int64).reshape(-1, 2)
    h, w = free.shape
    if starts.size and not ((starts >= 0).all() and (starts[:, 0] < h).all() and (starts[:, 1] < w).all()):
        raise ValueError(f"starts: a pixel lies outside the {h} x {w} grid")
    free[starts[:, 0], starts[:, 1]] = True
    if not len(starts):
        return np.zeros((0, h, w))
    dist = dijkstra(pixel_graph(free, weight), indices=starts[:, 0] * w + starts[:, 1])
    return np.asarray(dist).reshape(len(starts), h, w)


def pixel_graph(free: np.ndarray, weight: np.ndarray | None = None) -> csr_matrix:
    """The 8-connected graph of the ``free`` pixels as a sparse matrix over the flat pixel indices (edges
    built with whole-array numpy, no per-cell Python loop): a move costs its length (1 or √2), times the
    mean of its two ends' ``weight`` when given; diagonal moves need both side pixels free."""
    h, w = free.shape
    idx = np.arange(h * w).reshape(h, w)
    rows, cols, wts = [], [], []
    for dr, dc in _OFFSETS:  # four edge directions, each a whole-array operation
        a = free[: h - dr, max(-dc, 0) : w - max(dc, 0)]
        b = free[dr:, max(dc, 0) : w + min(dc, 0) or None]
        ok = a & b
        if dr and dc:  # diagonal: both side pixels free
            side1 = free[: h - dr, max(dc, 0) : w + min(dc, 0) or None]
            ok &= side1 & free[dr:, max(-dc, 0) : w - max(dc, 0)]
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


def path_to(pred: np.ndarray, shape: tuple[int, int], goal: tuple[int, int]) -> np.ndarray:
    """``(P, 2)`` pixels from the start (excluded) to ``goal`` along the predecessor array."""
    w = shape[1]
    out = []
    k = int(goal[0]) * w + int(goal[1])
    while k >= 0:  # loop over the path's pixels only
        out.append(k)
        k = int(pred[k])
    out = out[::-1][1:] if len(out) > 1 else out
    a = np.array(out, dtype=np.int64)
    return np.stack([a // w, a % w], axis=1)


def line_of_sight(free: np.ndarray, start: np.ndarray, path: np.ndarray, samples: int = 24) -> int:
    """Index of the farthest pixel of ``path`` whose segment from ``start`` (fractional pixel
    ``(row, col)``) crosses only ``free`` pixels (0 if none does: the first pixel is then the waypoint)."""
    if len(path) == 0:
        return 0
    t = np.linspace(0.0, 1.0, samples)[None, :, None]
    pts = start[None, None, :] + t * (path[:, None, :] + 0.5 - start[None, None, :])
    ij = np.clip(np.floor(pts).astype(np.int64), 0, np.array(free.shape) - 1)
    ok = free[ij[..., 0], ij[..., 1]].all(axis=1)
    ok = np.logical_and.accumulate(ok)  # a prefix: beyond the first blocked one, keep nothing
    n = int(np.count_nonzero(ok))
    return max(n - 1, 0)


def erode(mask: np.ndarray, k: int = 1) -> np.ndarray:
    """``mask`` eroded by ``k`` pixels (8-neighbourhood); outside the map counts as not in the mask."""
    if k <= 0:
        return mask.copy()
    return ndimage.binary_erosion(mask, SQUARE, iterations=k, border_value=0)


def dilate(mask: np.ndarray, k: int = 1) -> np.ndarray:
    """``mask`` dilated by ``k`` pixels (8-neighbourhood)."""
    if k <= 0:
        return mask.copy()
    return ndimage.binary_dilation(mask, SQUARE, iterations=k)


def wrap(a: float) -> float:
    """Angle in ``(-π, π]``."""
    return (a + math.pi) % (2 * math.pi) - math.pi


def turn_then_go(
    bearing_err: float,
    distance: float,
    moving: bool,
    go_tol: float = 0.05,
    stop_tol: float = 0.25,
    turn_per_step: float = 0.1,
    step_length: float = 0.1,
) -> tuple[np.ndarray, bool]:
    """Normalised ``(v, ω)`` towards a waypoint ``distance`` m away at heading error ``bearing_err`` (rad).

    Turns in place until ``|error| <= go_tol``, then drives straight until ``|error| > stop_tol``;
    ``turn_per_step`` and ``step_length`` are the rotation (rad) and travel (m) of a full-scale action over
    one step. Returns the action and whether the robot is now driving.
    """
    e = float(bearing_err)
    if moving and abs(e) > stop_tol or not moving and abs(e) > go_tol:
        return np.array([0.0, float(np.clip(e / turn_per_step, -1.0, 1.0))], dtype=np.float32), False
    v = float(np.clip(distance / step_length, 0.2, 1.0))
    return np.array([v, 0.0], dtype=np.float32), True


__all__ = [
    "SQUARE",
    "dilate",
    "erode",
    "line_of_sight",
    "path_to",
    "shortest_paths",
    "turn_then_go",
    "wrap",
]
