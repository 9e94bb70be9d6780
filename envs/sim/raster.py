"""Exact rasterisation of the ground truth: each cell is free, occupied or mixed.

A cell is MIXED iff some obstacle edge meets its open interior; otherwise the whole cell lies on one side of
every edge and its class is that of its centre (even-odd rule). Both steps are vectorised: edges are paired
with the cells of their bounding box, and centres are classified row by row with crossing toggles
and a cumsum.

``rasterize(..., closed=True)`` classifies the *closed* cells instead: a cell is MIXED as soon as an edge
meets its closed box, its boundary included (a wall lying on a cell edge, a vertex on a cell corner), up to
a relative tolerance of :data:`CLOSED_TOL` cells, so that a wall on a grid line counts on both sides
whatever the rounding of the cell bounds. A FREE cell of that raster is free with its boundary: the cells
that a sound observer, whose claims are about closed cells, can prove free.
"""

from __future__ import annotations

import numpy as np

FREE, OCCUPIED, MIXED = 0, 1, 2
#: Slack of the closed-cell test (``rasterize(..., closed=True)``), in cells: an edge within this share of a
#: cell of the closed box counts as meeting it.
CLOSED_TOL = 1e-9


def grid_shape(frame: tuple[float, float, float, float], resolution: float) -> tuple[int, int]:
    """``(ny, nx)`` cells of size ``resolution`` covering ``frame = (xmin, ymin, xmax, ymax)``."""
    if not resolution > 0:
        raise ValueError(f"resolution: must be > 0, got {resolution!r}")
    return (
        int(np.ceil((frame[3] - frame[1]) / resolution - 1e-9)),
        int(np.ceil((frame[2] - frame[0]) / resolution - 1e-9)),
    )


def _centre_free(edges: np.ndarray, x0: float, y0: float, res: float, ny: int, nx: int) -> np.ndarray:
    cy = y0 + (np.arange(ny) + 0.5) * res
    y1, y2 = edges[None, :, 1], edges[None, :, 3]
    c = cy[:, None]
    straddle = (y1 > c) != (y2 > c)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = edges[None, :, 0] + (c - y1) * (edges[None, :, 2] - edges[None, :, 0]) / (y2 - y1)
    rows, cols = np.nonzero(straddle)
    k = np.clip(np.ceil((xc[rows, cols] - x0) / res - 0.5), 0, nx).astype(np.int64)  # cells with cx < xc
    acc = np.zeros((ny, nx + 1), dtype=np.int64)
    np.add.at(acc, (rows, np.zeros_like(k)), 1)
    np.add.at(acc, (rows, k), -1)
    return (np.cumsum(acc, axis=1)[:, :nx] % 2) == 1


def _mixed(edges: np.ndarray, x0: float, y0: float, res: float, ny: int, nx: int,
           closed: bool = False) -> np.ndarray:  # fmt: skip
    out = np.zeros((ny, nx), dtype=bool)
    if len(edges) == 0:
        return out
    grow = 1 if closed else 0  # a closed cell also meets the edges on its boundary: look one cell further
    lo_x = np.clip(np.floor((np.minimum(edges[:, 0], edges[:, 2]) - x0) / res) - grow, 0, nx - 1).astype(
        np.int64
    )
    hi_x = np.clip(np.floor((np.maximum(edges[:, 0], edges[:, 2]) - x0) / res) + grow, 0, nx - 1).astype(
        np.int64
    )
    lo_y = np.clip(np.floor((np.minimum(edges[:, 1], edges[:, 3]) - y0) / res) - grow, 0, ny - 1).astype(
        np.int64
    )
    hi_y = np.clip(np.floor((np.maximum(edges[:, 1], edges[:, 3]) - y0) / res) + grow, 0, ny - 1).astype(
        np.int64
    )
    wx, wy = hi_x - lo_x + 1, hi_y - lo_y + 1
    counts = wx * wy
    e = np.repeat(np.arange(len(edges)), counts)
    local = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    ix = lo_x[e] + local % wx[e]
    iy = lo_y[e] + local // wx[e]
    px, py = edges[e, 0], edges[e, 1]
    dx, dy = edges[e, 2] - px, edges[e, 3] - py
    L = np.zeros(len(e))
    U = np.ones(len(e))
    ok = np.ones(len(e), dtype=bool)
    slack = CLOSED_TOL * res if closed else 0.0
    for p, d, lo_c in ((px, dx, x0 + ix * res), (py, dy, y0 + iy * res)):
        lo_b, hi_b = lo_c - slack, lo_c + res + slack
        flat = d == 0
        ok &= ~flat | (((lo_b <= p) & (p <= hi_b)) if closed else ((lo_b < p) & (p < hi_b)))
        with np.errstate(divide="ignore", invalid="ignore"):
            ta, tb = (lo_b - p) / d, (hi_b - p) / d
        L = np.where(flat, L, np.maximum(L, np.minimum(ta, tb)))
        U = np.where(flat, U, np.minimum(U, np.maximum(ta, tb)))
    # Open slabs: the t-set is (L', U') intersected with [0, 1]; strictness matters only for the slab ends.
    # Closed slabs (``closed``): [L', U'], so an edge that only touches the cell's boundary meets it.
    hit = ok & ((L <= U) if closed else (L < U))
    out[iy[hit], ix[hit]] = True
    return out


def rasterize(edges: np.ndarray, frame: tuple[float, float, float, float], resolution: float,
              closed: bool = False) -> np.ndarray:  # fmt: skip
    """Classify the cells of ``frame`` as FREE (0), OCCUPIED (1) or MIXED (2).

    Args:
        edges: Obstacle edges ``(E, 4)`` (even-odd convention: free where the crossing count is odd).
        frame: ``(xmin, ymin, xmax, ymax)``; cell ``[i, j]`` spans ``x0 + j*res`` .. and ``y0 + i*res`` ..
        resolution: Cell size.
        closed: Classify closed cells: an edge on a cell's boundary makes it MIXED (see the module).

    Returns:
        ``int8`` array ``(ny, nx)``, row index along y.
    """
    ny, nx = grid_shape(frame, resolution)
    x0, y0 = float(frame[0]), float(frame[1])
    free = _centre_free(edges, x0, y0, resolution, ny, nx)
    mixed = _mixed(edges, x0, y0, resolution, ny, nx, closed)
    return np.where(mixed, MIXED, np.where(free, FREE, OCCUPIED)).astype(np.int8)


def cell_centres(
    frame: tuple[float, float, float, float], resolution: float
) -> tuple[np.ndarray, np.ndarray]:
    """Cell-centre coordinates ``(xs (nx,), ys (ny,))`` of the grid used by :func:`rasterize`."""
    ny, nx = grid_shape(frame, resolution)
    return frame[0] + (np.arange(nx) + 0.5) * resolution, frame[1] + (np.arange(ny) + 0.5) * resolution


__all__ = [
    "CLOSED_TOL",
    "cell_centres",
    "grid_shape",
    "rasterize",
]
