"""Exact planar geometry on edge soups.

The world's obstacles are described by closed polylines (rings) stored as an edge array ``(E, 4)`` of
``x1, y1, x2, y2``. A point is free iff a ray from it crosses the edges an odd number of times (even-odd rule
with half-open vertex handling); every generator follows that convention.

The key routine, :func:`sector_distance`, returns the distance from an apex to the nearest edge point inside
a circular sector of any half-aperture in ``(0, pi]``. Since a sector is star-shaped about its apex, that is
the nearest obstacle point in the sector whenever the apex is free. It is exact (no ray fan): per edge, the
minimum of the convex distance function over the edge's part inside the sector is reached at the foot of
the perpendicular, at an endpoint inside the sector, or where the edge crosses a boundary ray. The distance
routines run compiled (:mod:`.geometry_jit`); numpy versions of them are the test oracles of
``tests/envs/sim/test_kernels.py``.
"""

from __future__ import annotations

import numpy as np

from digslam.envs.sim import geometry_jit as jit

Edges = np.ndarray  # (E, 4) float64


def rings_to_edges(rings: list[np.ndarray]) -> Edges:
    """Closed polylines ``(k, 2)`` (last vertex not repeated) to an edge array ``(E, 4)``."""
    parts = []
    for r in rings:
        r = np.asarray(r, dtype=np.float64)
        if r.ndim != 2 or r.shape[1] != 2 or len(r) < 3:
            raise ValueError(f"rings: each ring must be a (k>=3, 2) array, got shape {r.shape}")
        parts.append(np.hstack([r, np.roll(r, -1, axis=0)]))
    if not parts:
        return np.zeros((0, 4))
    return np.vstack(parts)


def point_free(points: np.ndarray, edges: Edges, chunk: int = 2048) -> np.ndarray:
    """Even-odd test: True where a point is in free space (odd crossing count), shape ``(N,)``."""
    pts = np.atleast_2d(np.asarray(points, dtype=np.float64))
    if len(pts) > chunk:
        return np.concatenate(
            [point_free(pts[i : i + chunk], edges, chunk) for i in range(0, len(pts), chunk)]
        )
    x, y = pts[:, :1], pts[:, 1:2]
    x1, y1, x2, y2 = (edges[None, :, k] for k in range(4))
    straddle = (y1 > y) != (y2 > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
    return (np.count_nonzero(straddle & (xc > x), axis=1) % 2) == 1


def point_edge_distance(points: np.ndarray, edges: Edges) -> np.ndarray:
    """Distance from each point to the nearest edge, shape ``(N,)`` (``inf`` with no edges).

    Compiled (:func:`.geometry_jit.points_edges_kernel`); a numpy version of it is the test oracle of
    ``tests/envs/sim/test_kernels.py``.
    """
    pts = np.ascontiguousarray(np.atleast_2d(np.asarray(points, dtype=np.float64)))
    e = np.ascontiguousarray(edges, dtype=np.float64).reshape(-1, 4)
    out = np.empty(len(pts))
    jit.points_edges_kernel(pts, e, jit.edge_boxes(e), np.inf, out)
    return out


def edge_bboxes(edges: Edges) -> np.ndarray:
    """Bounding boxes ``(E, 4)`` of the edges."""
    return jit.edge_boxes(edges)


def sector_distance(
    x: float, y: float, axis: np.ndarray, gamma: np.ndarray, edges: Edges, return_witness: bool = False
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Distance from ``(x, y)`` to the nearest edge point inside each sector.

    Args:
        x: Apex abscissa.
        y: Apex ordinate.
        axis: World-frame sector directions (rad), shape ``(S,)``; any real value (no ``±pi`` cut).
        gamma: Half-apertures in ``(0, pi]``, shape ``(S,)``.
        edges: Edge array ``(E, 4)`` (the kernel skips edges whose bounding box cannot beat a sector's best).
        return_witness: Also return the nearest points ``(S, 2)`` (NaN where none).

    Returns:
        Distances ``(S,)``, ``inf`` where no edge meets the (unbounded) sector.
    """
    axis = np.ascontiguousarray(axis, dtype=np.float64).reshape(-1)
    gamma = np.ascontiguousarray(gamma, dtype=np.float64).reshape(-1)
    e = np.ascontiguousarray(edges, dtype=np.float64).reshape(-1, 4)
    d, wit = np.empty(len(axis)), np.empty((len(axis), 2))
    cut = np.full(len(axis), np.inf)
    jit.sector_kernel(float(x), float(y), 0.0, axis, gamma, cut, e, jit.edge_boxes(e), np.inf, d, wit)
    return (d, wit) if return_witness else d


__all__ = [
    "Edges",
    "edge_bboxes",
    "point_edge_distance",
    "point_free",
    "rings_to_edges",
    "sector_distance",
]
