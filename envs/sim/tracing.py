"""Tracing grids into closed edge soups: marching squares for scalar fields, pixel borders for binary masks.

Both return edges ``(E, 4)`` whose closed curves separate free from occupied cells, with everything outside
the grid occupied, so that the even-odd rule (free where the crossing count is odd) holds. Shared vertices are
computed once per grid edge, so neighbouring cells produce bit-identical endpoints.
"""

from __future__ import annotations

import numpy as np

# Marching-squares segments per case (corner bits: 1 bottom-left, 2 bottom-right, 4 top-right, 8 top-left;
# a set bit means occupied). Cell sides: 0 bottom, 1 right, 2 top, 3 left. Saddles (5, 10) keep the
# occupied corners apart.
_CASES: dict[int, list[tuple[int, int]]] = {
    1: [(3, 0)],
    2: [(0, 1)],
    3: [(3, 1)],
    4: [(1, 2)],
    5: [(3, 0), (1, 2)],
    6: [(0, 2)],
    7: [(3, 2)],
    8: [(2, 3)],
    9: [(2, 0)],
    10: [(0, 1), (2, 3)],
    11: [(2, 1)],
    12: [(1, 3)],
    13: [(1, 0)],
    14: [(0, 3)],
}


def marching_squares(field: np.ndarray, level: float, frame: tuple[float, float, float, float]) -> np.ndarray:
    """Contour ``field > level`` (occupied) of node values ``(ny, nx)`` spread over ``frame``.

    The border nodes should be occupied so that every contour closes.
    """
    f = np.asarray(field, dtype=np.float64)
    ny, nx = f.shape
    xs = np.linspace(frame[0], frame[2], nx)
    ys = np.linspace(frame[1], frame[3], ny)
    occ = f > level
    with np.errstate(divide="ignore", invalid="ignore"):
        # Crossings kept off the nodes, so that points on different grid edges never coincide.
        th = np.clip((level - f[:, :-1]) / (f[:, 1:] - f[:, :-1]), 1e-6, 1 - 1e-6)  # horizontal node edges
        tv = np.clip((level - f[:-1, :]) / (f[1:, :] - f[:-1, :]), 1e-6, 1 - 1e-6)  # vertical node edges
    hx = xs[:-1][None, :] + th * np.diff(xs)[None, :]
    hy = np.broadcast_to(ys[:, None], hx.shape)
    vy = ys[:-1][:, None] + tv * np.diff(ys)[:, None]
    vx = np.broadcast_to(xs[None, :], vy.shape)
    case = (occ[:-1, :-1] * 1 + occ[:-1, 1:] * 2 + occ[1:, 1:] * 4 + occ[1:, :-1] * 8).astype(np.int64)
    # Side points of every cell (ny-1, nx-1): bottom, right, top, left.
    sx = np.stack([hx[:-1], vx[:, 1:], hx[1:], vx[:, :-1]])
    sy = np.stack([hy[:-1], vy[:, 1:], hy[1:], vy[:, :-1]])
    out = []
    for c, segs in _CASES.items():
        iy, ix = np.nonzero(case == c)
        for a, b in segs:
            out.append(np.column_stack([sx[a, iy, ix], sy[a, iy, ix], sx[b, iy, ix], sy[b, iy, ix]]))
    return np.vstack(out) if out else np.zeros((0, 4))


def _runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Row, start and end (exclusive) of every run of True along axis 1."""
    m = np.zeros((mask.shape[0], mask.shape[1] + 2), dtype=np.int8)
    m[:, 1:-1] = mask
    d = np.diff(m, axis=1)
    rs, cs = np.nonzero(d == 1)
    _, ce = np.nonzero(d == -1)
    return rs, cs, ce


def mask_edges(free: np.ndarray, frame: tuple[float, float, float, float]) -> np.ndarray:
    """Border edges of a binary free mask ``(ny, nx)`` (row 0 at ``ymin``), collinear runs merged."""
    free = np.asarray(free, dtype=bool)
    ny, nx = free.shape
    rx = (frame[2] - frame[0]) / nx
    ry = (frame[3] - frame[1]) / ny
    p = np.zeros((ny + 2, nx + 2), dtype=bool)
    p[1:-1, 1:-1] = free
    hmask = p[1:, 1:-1] != p[:-1, 1:-1]  # (ny+1, nx): horizontal line i at y0 + i*ry
    vmask = p[1:-1, 1:] != p[1:-1, :-1]  # (ny, nx+1): vertical line j at x0 + j*rx
    r, s, e = _runs(hmask)
    h = np.column_stack([frame[0] + s * rx, frame[1] + r * ry, frame[0] + e * rx, frame[1] + r * ry])
    c, s, e = _runs(vmask.T)
    v = np.column_stack([frame[0] + c * rx, frame[1] + s * ry, frame[0] + c * rx, frame[1] + e * ry])
    return np.vstack([h, v]).astype(np.float64)


def smooth_noise(rng: np.random.Generator, shape: tuple[int, int], sigma: float) -> np.ndarray:
    """White noise smoothed by a periodic Gaussian of ``sigma`` nodes (FFT), scaled to zero mean, unit std."""
    w = rng.standard_normal(shape)
    ky = np.fft.fftfreq(shape[0])[:, None]
    kx = np.fft.rfftfreq(shape[1])[None, :]
    g = np.exp(-2.0 * (np.pi * sigma) ** 2 * (kx**2 + ky**2))
    f = np.fft.irfft2(np.fft.rfft2(w) * g, s=shape)
    return (f - f.mean()) / (f.std() + 1e-300)


def chain_rings(edges: np.ndarray) -> list[np.ndarray] | None:
    """Assemble a closed edge soup into rings ``(k, 2)``; None if some vertex does not have exactly two edges.

    Walks each closed curve once (a loop over curves and edges, not over grid cells).
    """
    if len(edges) == 0:
        return []
    pts, inv = np.unique(np.concatenate([edges[:, :2], edges[:, 2:]]), axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    ends = np.stack([inv[: len(edges)], inv[len(edges) :]], axis=1)
    if np.any(np.bincount(ends.ravel(), minlength=len(pts)) != 2) or np.any(ends[:, 0] == ends[:, 1]):
        return None
    order = np.argsort(ends.ravel(), kind="stable")
    incident = (order // 2).reshape(-1, 2)  # the two edges at each vertex
    used = np.zeros(len(edges), dtype=bool)
    rings = []
    for start in range(len(edges)):
        if used[start]:
            continue
        ring, e, v = [], start, ends[start, 0]
        while not used[e]:
            used[e] = True
            ring.append(v)
            v = ends[e, 1] if ends[e, 0] == v else ends[e, 0]
            a, b = incident[v]
            e = b if a == e else a
        rings.append(pts[np.array(ring)])
    return rings


__all__ = [
    "chain_rings",
    "marching_squares",
    "mask_edges",
    "smooth_noise",
]
