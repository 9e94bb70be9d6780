"""Exact planar geometry on edge soups, vectorised with numpy.

The world's obstacles are described by closed polylines (rings) stored as an edge array ``(E, 4)`` of
``x1, y1, x2, y2``. A point is free iff a ray from it crosses the edges an odd number of times (even-odd rule
with half-open vertex handling); every generator follows that convention.

The key routine, :func:`sector_distance`, returns the distance from an apex to the nearest edge point inside
a circular sector of any half-aperture in ``(0, pi]``. Since a sector is star-shaped about its apex, that is
the nearest obstacle point in the sector whenever the apex is free. It is exact (no ray fan): per edge, the
minimum of the convex distance function over the edge's part inside the sector is reached at the foot of
the perpendicular, at an endpoint inside the sector, or where the edge crosses a boundary ray.
"""

from __future__ import annotations

import numpy as np

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
    """Distance from each point to the nearest edge, shape ``(N,)`` (``inf`` with no edges)."""
    pts = np.atleast_2d(np.asarray(points, dtype=np.float64))
    if len(edges) == 0:
        return np.full(len(pts), np.inf)
    if len(pts) > 2048:
        return np.concatenate(
            [point_edge_distance(pts[i : i + 2048], edges) for i in range(0, len(pts), 2048)]
        )
    ax = edges[None, :, 0] - pts[:, :1]
    ay = edges[None, :, 1] - pts[:, 1:2]
    dx = (edges[:, 2] - edges[:, 0])[None]
    dy = (edges[:, 3] - edges[:, 1])[None]
    dd = dx * dx + dy * dy
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip(np.where(dd > 0, -(ax * dx + ay * dy) / dd, 0.0), 0.0, 1.0)
    return np.sqrt(np.min((ax + t * dx) ** 2 + (ay + t * dy) ** 2, axis=1))


def edges_near(edges: Edges, bbox: np.ndarray, x: float, y: float, reach: float) -> Edges:
    """Edges whose bounding box ``(E, 4)`` (xmin, ymin, xmax, ymax) comes within ``reach`` of ``(x, y)``."""
    dx = np.maximum(np.maximum(bbox[:, 0] - x, x - bbox[:, 2]), 0.0)
    dy = np.maximum(np.maximum(bbox[:, 1] - y, y - bbox[:, 3]), 0.0)
    return edges[dx * dx + dy * dy <= reach * reach]


def edge_bboxes(edges: Edges) -> np.ndarray:
    """Bounding boxes ``(E, 4)`` of the edges."""
    return np.stack(
        [
            np.minimum(edges[:, 0], edges[:, 2]),
            np.minimum(edges[:, 1], edges[:, 3]),
            np.maximum(edges[:, 0], edges[:, 2]),
            np.maximum(edges[:, 1], edges[:, 3]),
        ],
        axis=1,
    )


def sector_distance(
    x: float, y: float, axis: np.ndarray, gamma: np.ndarray, edges: Edges, return_witness: bool = False
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Distance from ``(x, y)`` to the nearest edge point inside each sector.

    Args:
        x: Apex abscissa.
        y: Apex ordinate.
        axis: World-frame sector directions (rad), shape ``(S,)``; any real value (no ``±pi`` cut).
        gamma: Half-apertures in ``(0, pi]``, shape ``(S,)``.
        edges: Edge array ``(E, 4)`` (pre-filter it with :func:`edges_near`).
        return_witness: Also return the nearest points ``(S, 2)`` (NaN where none).

    Returns:
        Distances ``(S,)``, ``inf`` where no edge meets the (unbounded) sector.
    """
    axis = np.asarray(axis, dtype=np.float64)
    gamma = np.asarray(gamma, dtype=np.float64)
    S, E = axis.shape[0], len(edges)
    if E == 0:
        d = np.full(S, np.inf)
        return (d, np.full((S, 2), np.nan)) if return_witness else d
    ax, ay = edges[:, 0] - x, edges[:, 1] - y
    dx, dy = edges[:, 2] - edges[:, 0], edges[:, 3] - edges[:, 1]
    # One matrix of edge vectors (2, 5E): endpoints a, b, feet f, then (dy, -dx) and (-ay, ax) for the rays.
    m = np.empty((2, 5 * E))
    m[0, :E], m[1, :E] = ax, ay
    np.add(ax, dx, out=m[0, E : 2 * E])
    np.add(ay, dy, out=m[1, E : 2 * E])
    with np.errstate(divide="ignore", invalid="ignore"):  # zero-length edges: NaN feet, never selected
        t = np.minimum(np.maximum(-(ax * dx + ay * dy) / (dx * dx + dy * dy), 0.0), 1.0)
        m[0, 2 * E : 3 * E], m[1, 2 * E : 3 * E] = ax + t * dx, ay + t * dy
        m[0, 3 * E : 4 * E], m[1, 3 * E : 4 * E] = dy, -dx
        m[0, 4 * E :], m[1, 4 * E :] = -ay, ax
        # Directions (3S, 2): sector axes u, then boundary rays w (minus rays, then plus rays).
        ang = np.concatenate([axis, axis - gamma, axis + gamma])
        dirs = np.empty((3 * S, 2))
        np.cos(ang, out=dirs[:, 0])
        np.sin(ang, out=dirs[:, 1])
        prod = dirs @ m  # (3S, 5E)
        pts = m[:, : 3 * E]
        norms = np.hypot(pts[0], pts[1])
        # angle(u, v) <= gamma  <=>  u.v >= |v| cos(gamma), valid for gamma in (0, pi]: no angle wrapping.
        inside = prod[:S, : 3 * E] >= norms * np.cos(gamma)[:, None]
        cand_pts = np.where(inside, norms, np.inf)  # (S, 3E)
        # Boundary rays r * w (r >= 0) crossing a + s d (s in [0, 1]).
        den = prod[S:, 3 * E : 4 * E]
        r = (ax * dy - ay * dx) / den
        sp = prod[S:, 4 * E :] / den
        cand_ray = np.where((r >= 0) & (sp >= 0) & (sp <= 1), r, np.inf)  # (2S, E)
    if not return_witness:
        return np.minimum(
            np.minimum(cand_pts.min(axis=1), cand_ray[:S].min(axis=1)), cand_ray[S:].min(axis=1)
        )
    allc = np.concatenate([cand_pts, cand_ray[:S], cand_ray[S:]], axis=1)  # (S, 5E)
    k = np.argmin(allc, axis=1)
    d = allc[np.arange(S), k]
    on_ray = k >= 3 * E
    kp = np.minimum(k, 3 * E - 1)
    ang = np.where(k >= 4 * E, axis + gamma, axis - gamma)
    wx = np.where(on_ray, d * np.cos(ang), pts[0, kp]) + x
    wy = np.where(on_ray, d * np.sin(ang), pts[1, kp]) + y
    wit = np.stack([wx, wy], axis=1)
    wit[~np.isfinite(d)] = np.nan
    return d, wit
