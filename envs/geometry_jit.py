"""Compiled kernels of the simulator's exact geometry: sector distances and point-edge distances.

Each kernel loops over the world's edges in machine code (:func:`digslam.observer.jit.njit`), with the
bounding-box pre-filter fused in (an edge whose box lies farther than
``reach`` from the point is skipped; ``reach = inf`` keeps every edge). They compute the simulator's truth,
a float64 value widened afterwards by :data:`.sensors.SIM_TOL`, with the same formulas as the numpy code
they replace (kept as test oracles in ``tests/test_sim_jit.py``):

* :func:`sector_kernel` -- the sonar distance of thesis Eq. (4.22), ``d = inf {d | f(S_1, d) ∩ not M ≠ ∅}``:
  the nearest edge point inside each circular sector (exact, no ray fan): per edge,
  the minimum of the convex distance over the edge's part inside the sector is reached at the foot of the
  perpendicular, at an endpoint inside the sector, or where the edge crosses a boundary ray. A sector of
  half-aperture ``pi`` is the whole plane: its distance is the plain point-edge distance. An edge whose
  nearest point is no nearer than a sector's best so far is skipped for that sector (none of its points
  can improve it).
* :func:`points_edges_kernel` -- distance from points to the nearest edge.

The robot's swept-disc checks (:mod:`.robot_jit`) reuse the scalar helpers.

Example (a cone facing a wall 2 m away, and one facing away from it):
    >>> import numpy as np
    >>> edges = np.array([[2.0, -1.0, 2.0, 1.0]])
    >>> d = np.empty(2); w = np.empty((2, 2))
    >>> sector_kernel(0.0, 0.0, 0.0, np.array([0.0, np.pi]), np.array([0.3, 0.3]), np.full(2, np.inf),
    ...               edges, edge_boxes(edges), np.inf, d, w)
    >>> d.tolist(), w[0].tolist()
    ([2.0, inf], [2.0, 0.0])
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.jit import njit

_INF = math.inf


def edge_boxes(edges: np.ndarray) -> np.ndarray:
    """Bounding boxes ``(E, 4)`` (xmin, ymin, xmax, ymax), C-contiguous float64, of an edge array."""
    e = np.asarray(edges, dtype=np.float64).reshape(-1, 4)
    return np.ascontiguousarray(
        np.stack([np.minimum(e[:, 0], e[:, 2]), np.minimum(e[:, 1], e[:, 3]),
                  np.maximum(e[:, 0], e[:, 2]), np.maximum(e[:, 1], e[:, 3])], axis=1)  # fmt: skip
    )


@njit(inline="always")
def _near(bbox: np.ndarray, k: int, x: float, y: float, reach2: float) -> bool:
    """Whether edge ``k``'s box comes within ``sqrt(reach2)`` of ``(x, y)``."""
    dx = max(max(bbox[k, 0] - x, x - bbox[k, 2]), 0.0)
    dy = max(max(bbox[k, 1] - y, y - bbox[k, 3]), 0.0)
    return dx * dx + dy * dy <= reach2


@njit(inline="always")
def _seg_dist(ax: float, ay: float, dx: float, dy: float) -> float:
    """Distance from the origin to the segment ``a + t d``, ``t in [0, 1]`` (clamped foot)."""
    dd = dx * dx + dy * dy
    t = 0.0
    if dd > 0.0:
        t = min(max(-(ax * dx + ay * dy) / dd, 0.0), 1.0)
    px, py = ax + t * dx, ay + t * dy
    return math.sqrt(px * px + py * py)


@njit
def sector_kernel(x: float, y: float, th: float, alpha: np.ndarray, gamma: np.ndarray, cut: np.ndarray,
                  edges: np.ndarray, bbox: np.ndarray, reach: float, dist: np.ndarray,
                  wit: np.ndarray) -> None:  # fmt: skip
    """Nearest edge point from ``(x, y)`` inside each sector ``(th + alpha[s], gamma[s])``, written in place.

    ``dist[s]`` is the distance, ``inf`` if no kept edge meets the unbounded sector or if it exceeds
    ``cut[s]``, and ``wit[s]`` the nearest point (NaN where the distance is ``inf``). Half-apertures must
    lie in ``(0, pi]``.
    """
    S, E = alpha.shape[0], edges.shape[0]
    ux, uy, cg = np.empty(S), np.empty(S), np.empty(S)
    wx, wy = np.empty((S, 2)), np.empty((S, 2))
    for s in range(S):
        a = th + alpha[s]
        ux[s], uy[s], cg[s] = math.cos(a), math.sin(a), math.cos(gamma[s])
        wx[s, 0], wy[s, 0] = math.cos(a - gamma[s]), math.sin(a - gamma[s])
        wx[s, 1], wy[s, 1] = math.cos(a + gamma[s]), math.sin(a + gamma[s])
        dist[s] = _INF
        wit[s, 0], wit[s, 1] = np.nan, np.nan
    reach2 = reach * reach
    px, py, nrm = np.empty(3), np.empty(3), np.empty(3)
    for k in range(E):
        if not _near(bbox, k, x, y, reach2):
            continue
        ax, ay = edges[k, 0] - x, edges[k, 1] - y
        dx, dy = edges[k, 2] - edges[k, 0], edges[k, 3] - edges[k, 1]
        dd = dx * dx + dy * dy
        px[0], py[0], px[1], py[1] = ax, ay, ax + dx, ay + dy
        npts = 2
        if dd > 0.0:  # zero-length edges have no foot: their endpoints suffice
            t = min(max(-(ax * dx + ay * dy) / dd, 0.0), 1.0)
            px[2], py[2] = ax + t * dx, ay + t * dy
            npts = 3
        for j in range(npts):
            nrm[j] = math.hypot(px[j], py[j])
        near = npts - 1  # the nearest point of the edge: its foot, or its nearer endpoint
        if npts == 2 and nrm[1] < nrm[0]:
            near = 1
        cross = ax * dy - ay * dx
        for s in range(S):
            if nrm[near] >= dist[s]:  # no point of this edge is nearer than what sector s already has
                continue
            if gamma[s] >= math.pi:  # the whole plane
                dist[s], wit[s, 0], wit[s, 1] = nrm[near], px[near] + x, py[near] + y
                continue
            for j in range(npts):
                n = nrm[j]
                # angle(u, v) <= gamma  <=>  u.v >= |v| cos(gamma) for gamma in (0, pi]: no angle wrapping
                if n < dist[s] and ux[s] * px[j] + uy[s] * py[j] >= n * cg[s]:
                    dist[s], wit[s, 0], wit[s, 1] = n, px[j] + x, py[j] + y
            for b in range(2):  # boundary rays r w (r >= 0) crossing a + s d (s in [0, 1])
                den = wx[s, b] * dy - wy[s, b] * dx
                if den == 0.0:
                    continue
                r = cross / den
                sp = (wy[s, b] * ax - wx[s, b] * ay) / den
                if r >= 0.0 and sp >= 0.0 and sp <= 1.0 and r < dist[s]:
                    dist[s], wit[s, 0], wit[s, 1] = r, r * wx[s, b] + x, r * wy[s, b] + y
    for s in range(S):
        if not dist[s] <= cut[s]:
            dist[s], wit[s, 0], wit[s, 1] = _INF, np.nan, np.nan


@njit(inline="always")
def _min_dist(x: float, y: float, edges: np.ndarray, bbox: np.ndarray, reach2: float) -> float:
    best = _INF
    for k in range(edges.shape[0]):
        if _near(bbox, k, x, y, reach2):
            ax, ay = edges[k, 0] - x, edges[k, 1] - y
            best = min(best, _seg_dist(ax, ay, edges[k, 2] - edges[k, 0], edges[k, 3] - edges[k, 1]))
    return best


@njit
def points_edges_kernel(pts: np.ndarray, edges: np.ndarray, bbox: np.ndarray, reach: float,
                        out: np.ndarray) -> None:  # fmt: skip
    """``out[i]``: distance from ``pts[i]`` to the nearest kept edge (``inf`` if none)."""
    reach2 = reach * reach
    for i in range(pts.shape[0]):
        out[i] = _min_dist(pts[i, 0], pts[i, 1], edges, bbox, reach2)
