"""Regular grids of cells over a 2-d frame: the raster the observer's sets live on.

A :class:`Grid` is a batch of cell boxes (thesis §2.4.3, regular paving): the same separators that
drive the paver classify its cells. Cell bounds are the floats ``xs[i]`` and ``ys[j]`` themselves, so a
cell is *exactly* the box ``[xs[i], xs[i+1]] × [ys[j+1], ys[j]]`` and no claim about it depends on a
rounded cell position. Rows follow the image convention (Remark 2.7): row 0 is the top (largest ``y``).

>>> g = Grid((-1.0, -1.0), (1.0, 1.0), (4, 4))
>>> g.cell_size, g.shape
((0.5, 0.5), (4, 4))
>>> lo, hi = g.cell_boxes()
>>> lo[0].tolist(), hi[0].tolist()            # top-left cell
([-1.0, 0.5], [-0.5, 1.0])
>>> g.window(np.array([[0.1, 0.1]]), np.array([[0.2, 0.9]]))   # rows r0:r1, columns c0:c1 that meet a box
(array([0]), array([2]), array([2]), array([3]))
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Grid:
    """``(ny, nx)`` cells over the frame ``[lo[0], hi[0]] × [lo[1], hi[1]]``.

    Args:
        lo: lower-left corner ``(x0, y0)`` of the frame.
        hi: upper-right corner ``(x1, y1)``.
        shape: ``(ny, nx)``, the number of rows and columns (both ``>= 1``).
    """

    lo: tuple[float, float]
    hi: tuple[float, float]
    shape: tuple[int, int]
    xs: np.ndarray = field(init=False, repr=False, compare=False)
    ys: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        lo = tuple(float(v) for v in np.ravel(self.lo))
        hi = tuple(float(v) for v in np.ravel(self.hi))
        shape = tuple(int(v) for v in np.ravel(self.shape))
        if len(lo) != 2 or len(hi) != 2 or not all(np.isfinite(lo + hi)):
            raise ValueError(f"Grid: lo and hi must be finite 2-d points, got {self.lo} and {self.hi}")
        if not (lo[0] < hi[0] and lo[1] < hi[1]):
            raise ValueError(f"Grid: the frame must have positive size, got lo={lo} hi={hi}")
        if len(shape) != 2 or min(shape) < 1:
            raise ValueError(f"Grid: shape must be two positive integers (ny, nx), got {self.shape}")
        ny, nx = shape
        xs = np.linspace(lo[0], hi[0], nx + 1)
        ys = np.linspace(hi[1], lo[1], ny + 1)  # top to bottom
        if not (np.all(np.diff(xs) > 0) and np.all(np.diff(ys) < 0)):
            raise ValueError(f"Grid: cells too small for float64 over {lo}..{hi} with shape {shape}")
        xs.setflags(write=False)
        ys.setflags(write=False)
        for k, v in (("lo", lo), ("hi", hi), ("shape", shape), ("xs", xs), ("ys", ys)):
            object.__setattr__(self, k, v)

    @staticmethod
    def from_cell_size(lo: Any, hi: Any, cell_size: float) -> Grid:
        """The grid of square-ish cells of side at most ``cell_size`` covering ``[lo, hi]``."""
        if not (np.isfinite(cell_size) and cell_size > 0):
            raise ValueError(f"cell_size: must be a positive finite number, got {cell_size!r}")
        lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
        if lo.shape != (2,) or hi.shape != (2,):
            raise ValueError(f"Grid: lo and hi must be 2-d points, got {lo.shape} and {hi.shape}")
        nx, ny = (int(np.ceil((hi[k] - lo[k]) / cell_size)) for k in (0, 1))
        return Grid(tuple(lo), tuple(hi), (max(ny, 1), max(nx, 1)))

    @property
    def cell_size(self) -> tuple[float, float]:
        """Nominal ``(dx, dy)`` (the exact cells are given by :attr:`xs`, :attr:`ys`)."""
        ny, nx = self.shape
        return ((self.hi[0] - self.lo[0]) / nx, (self.hi[1] - self.lo[1]) / ny)

    @property
    def n_cells(self) -> int:
        return self.shape[0] * self.shape[1]

    def cell_boxes(
        self, rows: np.ndarray | None = None, cols: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Batch ``(lo, hi)`` of the cells ``(rows[k], cols[k])``, or of every cell in row-major order."""
        if rows is None or cols is None:
            rows, cols = (a.ravel() for a in np.indices(self.shape))
        rows, cols = np.asarray(rows), np.asarray(cols)
        lo = np.stack([self.xs[cols], self.ys[rows + 1]], axis=-1)
        hi = np.stack([self.xs[cols + 1], self.ys[rows]], axis=-1)
        return lo, hi

    def window(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, ...]:
        """Index ranges ``r0:r1, c0:c1`` of the cells that meet each box of an ``(N, 2)`` batch.

        A cell meets a box when their closed boxes intersect; ranges are clipped to the grid and
        empty (``r0 == r1`` or ``c0 == c1``) when the box misses the frame.
        """
        lo, hi = np.atleast_2d(lo), np.atleast_2d(hi)
        ny, nx = self.shape
        # cell column c spans [xs[c], xs[c+1]]: it meets [a, b] iff xs[c] <= b and xs[c+1] >= a
        c0 = np.searchsorted(self.xs, lo[:, 0], side="left") - 1
        c1 = np.searchsorted(self.xs, hi[:, 0], side="right")
        # rows are top-down: row r spans [ys[r+1], ys[r]]; -ys is increasing
        neg = -self.ys
        r0 = np.searchsorted(neg, -hi[:, 1], side="left") - 1
        r1 = np.searchsorted(neg, -lo[:, 1], side="right")
        c0, c1 = np.clip(c0, 0, nx), np.clip(c1, 0, nx)
        r0, r1 = np.clip(r0, 0, ny), np.clip(r1, 0, ny)
        return r0, np.maximum(r1, r0), c0, np.maximum(c1, c0)

    @staticmethod
    def count_below(edges: np.ndarray, v: np.ndarray, strict: bool = True) -> np.ndarray:
        """Exact number of ``edges`` (a uniform increasing ``linspace``) ``< v`` (``<= v`` if not strict).

        Same result as ``np.searchsorted(edges, v, "left" if strict else "right")``: an arithmetic
        estimate, then exact corrections by comparison with the edges themselves.
        """
        m = edges.size
        with np.errstate(invalid="ignore"):
            est = np.floor((v - edges[0]) * ((m - 1) / (edges[-1] - edges[0]))) + 1
        j = np.clip(np.nan_to_num(est, nan=0.0), 0, m).astype(np.int64)

        def above(k: np.ndarray) -> np.ndarray:  # edge k-1 is not counted: move down
            e = edges[np.maximum(k - 1, 0)]
            return (k > 0) & ((e >= v) if strict else (e > v))

        def below(k: np.ndarray) -> np.ndarray:  # edge k is counted: move up
            e = edges[np.minimum(k, m - 1)]
            return (k < m) & ((e < v) if strict else (e <= v))

        for test, step in ((above, -1), (below, 1)):
            bad = test(j)
            while bad.any():
                j = j + step * bad
                bad = test(j)
        return j

    def centers(self) -> tuple[np.ndarray, np.ndarray]:
        """Cell centres as two ``(ny, nx)`` arrays ``(x, y)`` (for drawing, never for proofs)."""
        cx = 0.5 * (self.xs[:-1] + self.xs[1:])
        cy = 0.5 * (self.ys[:-1] + self.ys[1:])
        gx, gy = np.meshgrid(cx, cy)
        return gx, gy

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """``(left, right, bottom, top)`` for ``matplotlib.pyplot.imshow``."""
        return (self.lo[0], self.hi[0], self.lo[1], self.hi[1])


__all__ = ["Grid"]
