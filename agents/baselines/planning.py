"""Grid planning and motion primitives of the heuristic baselines.

The agents read only the observation (``"map"`` channels clear / penumbra / dark / pose box, row 0 at the
top = largest ``y``; ``"state"`` with the pose box normalised to ``[-1, 1]`` over the grid frame). Planning
runs on the ``m x m`` map in pixel coordinates ``(row, col)``:

* :func:`shortest_paths`: Dijkstra over the 8-connected graph of traversable pixels (``scipy.sparse.csgraph``
  over the graph of :func:`pixel_graph`, whose tie-breaking between equal paths the agents' decisions
  follow); :func:`path_lengths` from several pixels at once and :func:`pair_lengths` between them (compiled,
  :mod:`.planning_jit`: the same lengths bit for bit);
* :func:`path_to`: the pixel path from the predecessor array (a loop over the path's pixels, not the grid);
* :func:`erode`, :func:`dilate`: the masks grown or shrunk by whole pixels; :func:`pixel_centres`: the
  pixels' centre coordinates;
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

import functools
import math

import numpy as np
from scipy.sparse import csr_array, csr_matrix
from scipy.sparse.csgraph import dijkstra

from digslam.agents.baselines import planning_jit as pj

#: The 8-neighbourhood (the structuring element of :func:`erode` and :func:`dilate`).
SQUARE = np.ones((3, 3), dtype=bool)
_ONE = np.ones((1, 1))  # the kernels' weight argument when unweighted (not read)


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
    indptr, indices, data = pj.grid_csr(*_grid_args(free, weight))
    graph = csr_array((data, indices, indptr), shape=(h * w, h * w))  # a csr_array: dijkstra takes it as is
    dist, pred = dijkstra(graph, indices=r0 * w + c0, return_predecessors=True)
    return dist.reshape(h, w), pred


def _with_starts(free: np.ndarray, starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A copy of ``free`` with the ``(S, 2)`` pixels ``starts`` made free, and the starts as int64, checked.

    Raises:
        ValueError: a start outside the grid.
    """
    free = np.asarray(free, dtype=bool).copy()
    starts = np.asarray(starts, dtype=np.int64).reshape(-1, 2)
    h, w = free.shape
    if starts.size and not ((starts >= 0).all() and (starts[:, 0] < h).all() and (starts[:, 1] < w).all()):
        raise ValueError(f"starts: a pixel lies outside the {h} x {w} grid")
    free[starts[:, 0], starts[:, 1]] = True
    return free, starts


def path_lengths(free: np.ndarray, starts: np.ndarray, weight: np.ndarray | None = None) -> np.ndarray:
    """``(S, h, w)`` path lengths from each of the ``(S, 2)`` pixels ``starts`` over the same graph as
    :func:`shortest_paths` (one Dijkstra call for all of them; the starts are treated as free).

    >>> free = np.ones((3, 4), dtype=bool); free[:2, 1] = False
    >>> path_lengths(free, np.array([[0, 0], [0, 3]]))[:, 0, 3].round(3).tolist()   # around the wall, and 0
    [6.414, 0.0]
    """
    free, starts = _with_starts(free, starts)
    h, w = free.shape
    if not len(starts):
        return np.zeros((0, h, w))
    flat = starts[:, 0] * w + starts[:, 1]
    dist = pj.grid_lengths(*_grid_args(free, weight), flat, np.zeros(0, dtype=np.int64))
    return dist.reshape(len(starts), h, w)


def pair_lengths(free: np.ndarray, starts: np.ndarray, weight: np.ndarray | None = None) -> np.ndarray:
    """``(S, S)`` path lengths between the ``(S, 2)`` pixels ``starts``: ``path_lengths(free, starts,
    weight)[:, starts[:, 0], starts[:, 1]]``, each search stopped once every start is settled.

    >>> free = np.ones((3, 4), dtype=bool); free[:2, 1] = False
    >>> pair_lengths(free, np.array([[0, 0], [0, 3]])).round(3).tolist()
    [[0.0, 6.414], [6.414, 0.0]]
    """
    free, starts = _with_starts(free, starts)
    h, w = free.shape
    flat = starts[:, 0] * w + starts[:, 1]
    return pj.grid_lengths(*_grid_args(free, weight), flat, flat)[:, flat]


def pixel_graph(free: np.ndarray, weight: np.ndarray | None = None) -> csr_matrix:
    """The 8-connected graph of the ``free`` pixels as a sparse matrix over the flat pixel indices (built by
    the compiled :func:`.planning_jit.grid_csr`, each row's columns ascending): a move costs its length (1 or
    √2), times the mean of its two ends' ``weight`` when given; diagonal moves need both side pixels free."""
    h, w = free.shape
    indptr, indices, data = pj.grid_csr(*_grid_args(free, weight))
    return csr_matrix((data, indices, indptr), shape=(h * w, h * w))


def _grid_args(free: np.ndarray, weight: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, bool]:
    """The kernels' ``(free, weight, weighted)``: contiguous bool and float64 arrays."""
    free = np.ascontiguousarray(free, dtype=bool)
    if weight is None:
        return free, _ONE, False
    return free, np.ascontiguousarray(weight, dtype=np.float64), True


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
    return pj.box_erode(np.ascontiguousarray(mask, dtype=bool), int(k))


def dilate(mask: np.ndarray, k: int = 1) -> np.ndarray:
    """``mask`` dilated by ``k`` pixels (8-neighbourhood)."""
    if k <= 0:
        return mask.copy()
    return pj.box_dilate(np.ascontiguousarray(mask, dtype=bool), int(k))


@functools.lru_cache(maxsize=8)
def pixel_centres(m: int) -> np.ndarray:
    """``(2, m, m)`` read-only row and column coordinates of the pixel centres of an ``m x m`` map."""
    out = np.mgrid[:m, :m] + 0.5
    out.flags.writeable = False
    return out


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
        return np.array([0.0, min(max(e / turn_per_step, -1.0), 1.0)], dtype=np.float32), False
    v = min(max(float(distance) / step_length, 0.2), 1.0)
    return np.array([v, 0.0], dtype=np.float32), True


__all__ = [
    "SQUARE",
    "dilate",
    "erode",
    "line_of_sight",
    "pair_lengths",
    "path_lengths",
    "path_to",
    "pixel_centres",
    "pixel_graph",
    "shortest_paths",
    "turn_then_go",
    "wrap",
]
