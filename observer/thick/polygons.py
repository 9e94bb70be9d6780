"""Polygons of a boolean raster: the exact union of its cells as rings of cell edges (numpy only).

:func:`mask_polygons` turns a ``(ny, nx)`` boolean mask over a :class:`~digslam.observer.record.grid.Grid`
into polygons whose vertices are the grid's own cell corners ``(xs[i], ys[j])``: each polygon is one
4-connected component of the mask, its exterior ring counter-clockwise and its holes clockwise (GeoJSON's
right-hand rule, RFC 7946 §3.1.6), so the polygons cover exactly the cells of the mask, no more and no less.
Two cells that touch only at a corner belong to different polygons (they meet at that vertex); a hole is an
8-connected component of the complement enclosed by one component. Collinear vertices are dropped.

How: every cell edge between a masked and an unmasked cell becomes a directed unit edge with the mask on its
left; each edge is followed by the outgoing edge of its end vertex (at a vertex where two components touch
diagonally, the left turn: it keeps to the same cell); the cycles of that successor map are the rings. A
ring with positive signed area is an exterior, a negative one a hole; a hole belongs to the innermost
exterior of the component whose cells lie on its left (components labelled by union-find).

>>> import numpy as np
>>> from digslam.observer.record.grid import Grid
>>> m = np.ones((3, 3), bool); m[1, 1] = False                      # a ring of 8 cells around a hole
>>> polys = mask_polygons(m, Grid((0.0, 0.0), (3.0, 3.0), (3, 3)))
>>> len(polys), len(polys[0]), polygon_area(polys[0])
(1, 2, 8.0)
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: Unit steps of the four directions (east, north, west, south) in corner indices ``(i, v)``, ``v`` upward.
_STEP = np.array([[1, 0], [0, 1], [-1, 0], [0, -1]], dtype=np.int64)

Ring = np.ndarray  # (m + 1, 2) float64 closed ring: first vertex repeated last
Polygon = list  # [exterior, *holes], each a Ring


def _edges(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Directed unit boundary edges with the mask on their left: start corners ``(i, v)`` and directions."""
    ny, nx = mask.shape
    up = np.zeros((ny + 2, nx + 2), dtype=bool)
    up[1:-1, 1:-1] = mask[::-1]  # row b of `up` (b >= 1) is cell row b - 1 counted from the bottom
    cell = up[1:-1, 1:-1]
    b, c = np.nonzero(cell & ~up[:-2, 1:-1])  # south side free: edge east along the bottom
    parts = [(c, b, 0)]
    b, c = np.nonzero(cell & ~up[1:-1, 2:])  # east side free: edge north along the right
    parts.append((c + 1, b, 1))
    b, c = np.nonzero(cell & ~up[2:, 1:-1])  # north side free: edge west along the top
    parts.append((c + 1, b + 1, 2))
    b, c = np.nonzero(cell & ~up[1:-1, :-2])  # west side free: edge south along the left
    parts.append((c, b + 1, 3))
    i = np.concatenate([p[0] for p in parts]).astype(np.int64)
    v = np.concatenate([p[1] for p in parts]).astype(np.int64)
    d = np.concatenate([np.full(p[0].size, p[2], dtype=np.int64) for p in parts])
    return i, v, d


def _cycles(nxt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For a permutation made of cycles: each element's cycle label (its smallest member) and its rank
    (steps from that member), by pointer doubling."""
    n = nxt.size
    lab, p = np.arange(n), nxt.copy()
    for _ in range(max(1, int(np.ceil(np.log2(max(n, 2))))) + 1):
        lab = np.minimum(lab, lab[p])
        p = p[p]
    # rank: distance from the head along the cycle, with the edge into each head cut
    succ = nxt.copy()
    head = lab == np.arange(n)
    succ[head[nxt]] = -1  # the last element of each cycle points nowhere
    dist = np.where(succ < 0, 0, 1)
    q = succ.copy()
    while np.any(q >= 0):
        ok = q >= 0
        dist[ok] += dist[q[ok]]
        q[ok] = q[q[ok]]
    length = np.bincount(lab, minlength=n)
    return lab, length[lab] - 1 - dist


def _rings(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The boundary rings of ``mask``: their integer corners ``(M, 2)`` (``i``, ``v`` upward; vertices only
    where the direction turns), ring after ring, and where each ring starts."""
    i, v, d = _edges(mask)
    if i.size == 0:
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
    nv = mask.shape[1] + 3
    key = (v * nv + i) * 4 + d
    order = np.argsort(key)
    sk = key[order]
    ei, ev = i + _STEP[d, 0], v + _STEP[d, 1]
    nxt = np.full(i.size, -1, dtype=np.int64)
    for turn in (1, 0, 3):  # left, straight, right: the first that exists
        want = (ev * nv + ei) * 4 + (d + turn) % 4
        pos = np.clip(np.searchsorted(sk, want), 0, sk.size - 1)
        hit = (sk[pos] == want) & (nxt < 0)
        nxt[hit] = order[pos[hit]]
    lab, rank = _cycles(nxt)
    turns = d != d[np.argsort(nxt)]  # an edge starts a vertex where its direction differs from the previous
    keep = np.lexsort((rank, lab))
    keep = keep[turns[keep]]
    cuts = np.flatnonzero(np.diff(lab[keep])) + 1
    return np.stack([i[keep], v[keep]], axis=1), np.concatenate([[0], cuts])


def _areas2(verts: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Twice the signed area of each ring (shoelace; exact on integer corners)."""
    nxt = np.arange(1, len(verts) + 1)
    ends = np.append(starts[1:], len(verts))
    nxt[ends - 1] = starts
    x, y = verts[:, 0], verts[:, 1]
    return np.add.reduceat(x * y[nxt] - x[nxt] * y, starts).astype(np.float64)


def _labels(mask: np.ndarray) -> np.ndarray:
    """4-connected component labels of the masked cells (``(ny, nx)`` int64, each component labelled by its
    smallest flat index; -1 off the mask): union by minimum with pointer jumping."""
    ny, nx = mask.shape
    idx = np.arange(ny * nx).reshape(ny, nx)
    pairs = [(idx[:, :-1][mask[:, :-1] & mask[:, 1:]], idx[:, 1:][mask[:, :-1] & mask[:, 1:]]),
             (idx[:-1][mask[:-1] & mask[1:]], idx[1:][mask[:-1] & mask[1:]])]  # fmt: skip
    a = np.concatenate([p[0] for p in pairs])
    b = np.concatenate([p[1] for p in pairs])
    parent = np.arange(ny * nx)
    while True:
        pa, pb = parent[a], parent[b]
        diff = pa != pb
        if not diff.any():
            break
        np.minimum.at(parent, np.maximum(pa, pb)[diff], np.minimum(pa, pb)[diff])  # hook roots to smaller
        while True:
            pp = parent[parent]
            if np.array_equal(pp, parent):
                break
            parent = pp
    return np.where(mask, parent.reshape(ny, nx), -1)


#: The cell on the left of a unit edge from corner ``(i, v)`` in each direction: offsets ``(column, up-row)``.
_LEFT = np.array([[0, 0], [-1, 0], [-1, -1], [0, -1]], dtype=np.int64)


def _owners(mask: np.ndarray, verts: np.ndarray, starts: np.ndarray, area: np.ndarray) -> np.ndarray:
    """For each hole (negative area), the exterior of the same component (the one whose cells lie on the
    left of both); -1 for an exterior."""
    owner = np.full(len(starts), -1, dtype=np.int64)
    if not np.any(area < 0):
        return owner
    lab = _labels(mask)
    ny = mask.shape[0]
    first, step = verts[starts], verts[starts + 1] - verts[starts]
    d = np.select([step[:, 0] > 0, step[:, 1] > 0, step[:, 0] < 0], [0, 1, 2], 3)
    cell = first + _LEFT[d]
    comp = lab[ny - 1 - cell[:, 1], cell[:, 0]]
    ext = np.flatnonzero(area > 0)
    by_comp = dict(zip(comp[ext].tolist(), ext.tolist()))
    for h in np.flatnonzero(area < 0):
        owner[h] = by_comp[int(comp[h])]
    return owner


def mask_polygons(mask: Any, grid: Any) -> list[Polygon]:
    """The polygons of the cells where ``mask`` is True (see the module docstring).

    Args:
        mask: ``(ny, nx)`` bool, row 0 the top (largest ``y``), as the observer's rasters.
        grid: the :class:`~digslam.observer.record.grid.Grid` of the mask (its ``xs``, ``ys``: the corners).

    Returns:
        One ``[exterior, *holes]`` per 4-connected component; each ring a closed ``(m + 1, 2)`` float64 array
        of metres (the first vertex repeated last), the exterior counter-clockwise, the holes clockwise.
    """
    m = np.asarray(mask, dtype=bool)
    if m.ndim != 2 or m.shape != tuple(grid.shape):
        raise ValueError(f"mask: expected shape {tuple(grid.shape)}, got {m.shape}")
    verts, starts = _rings(m)
    if not starts.size:
        return []
    area = _areas2(verts, starts)
    owner = _owners(m, verts, starts, area)
    xs, ys = np.asarray(grid.xs), np.asarray(grid.ys)[::-1]  # ys upward: corner v is ys[ny - v]
    pts = np.stack([xs[verts[:, 0]], ys[verts[:, 1]]], axis=1)
    rings = np.split(pts, starts[1:])
    polys: dict[int, Polygon] = {
        int(k): [np.concatenate([rings[k], rings[k][:1]])] for k in np.flatnonzero(area > 0)
    }
    for h in np.flatnonzero(area < 0):
        polys[int(owner[h])].append(np.concatenate([rings[h], rings[h][:1]]))
    return list(polys.values())


def ring_area(ring: np.ndarray) -> float:
    """Signed area of a closed ring (m², positive counter-clockwise)."""
    r = np.asarray(ring, dtype=np.float64)
    return 0.5 * float(np.sum(r[:-1, 0] * r[1:, 1] - r[1:, 0] * r[:-1, 1]))


def polygon_area(poly: Polygon) -> float:
    """Area of ``[exterior, *holes]`` (m²): the exterior's minus its holes'."""
    return float(sum(ring_area(r) for r in poly))


def contains(polys: list[Polygon], x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Even-odd point-in-polygon of points ``(x, y)`` against every ring of ``polys`` (points on an edge:
    either answer)."""
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    odd = np.zeros(np.broadcast(x, y).shape, dtype=bool)
    for poly in polys:
        for ring in poly:
            for (x0, y0), (x1, y1) in zip(ring[:-1], ring[1:]):
                if y0 == y1:
                    continue
                cross = (y0 > y) != (y1 > y)
                xc = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
                odd ^= cross & (x < xc)
    return odd


__all__ = ["contains", "mask_polygons", "polygon_area", "ring_area"]
