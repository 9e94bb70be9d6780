"""``C_SRAC`` for a raster shape: carving the thick map and registering the state (thesis Prop. 5.3–5.4).

:func:`shape_carve` is ``[M] := [M] ⊓ g⁻¹_{[x]}([Z])`` (Prop. 5.3, Eq. 5.48 with Theorem 5.1, Eq. 5.40–5.41)
on the cells of a :class:`~.thick_map.ThickMap`; :func:`shape_register` is
``[x] := [x] ∩ ⟦{x | g_x(M⁻) ⊂ Z⁺, g_x⁻¹(Z⁻) ⊂ M⁺}⟧`` (Prop. 5.4, Remark 5.7, Eq. 5.56), paved with the
separator :class:`SepShapeRegistration`. Every claim is about whole cells and pixels, with outward-rounded
natural inclusion functions of the :class:`~.thick_map.MapFunction` and integer pixel windows, so both are
sound contractors: the true state stays in ``[x]`` and ``M⁻ ⊂ M ⊂ M⁺`` holds at cell level.

>>> g = Grid((-2.0, -2.0), (2.0, 2.0), (8, 8))
>>> z = RasterShape(np.ones((2, 2), bool), np.ones((2, 2), bool), (-0.5, 0.5), 0.5)   # Z⁻ = [-0.5, 0.5]²
>>> m = ThickMap(g)
>>> shape_carve(m, z, MapFunction.translation(), np.array([[0.0, 0.0]]), np.array([[0.0, 0.0]]))
>>> int(m.lower.sum()), int((~m.upper).sum())                     # the 4 central cells are in M
(4, 0)
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core.boxes import empty_rows
from digslam.observer.core.types import Batch
from digslam.observer.record.grid import Grid
from digslam.observer.sets.separators import Sep
from digslam.observer.slam.raster_shape import RasterShape
from digslam.observer.slam.thick_map import MapFunction, ThickMap
from digslam.observer.thick.carving import param_hull

__all__ = ["SepShapeRegistration", "shape_carve", "shape_register"]

#: (box, cell) pairs classified at once (memory bound of the registration separator).
PAIR_CHUNK = 1 << 21


def _finite_rows(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    return np.all(np.isfinite(lo) & np.isfinite(hi) & (lo <= hi), axis=1)


def _cells_in(grid: Grid, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Row and column indices of the cells meeting the box ``(lo, hi)`` of shape ``(2,)``."""
    r0, r1, c0, c1 = (int(v[0]) for v in grid.window(lo[None], hi[None]))
    rr, cc = np.meshgrid(np.arange(r0, r1), np.arange(c0, c1), indexing="ij")
    return rr.ravel(), cc.ravel()


def shape_carve(m: ThickMap, z: RasterShape, g: MapFunction, x_lo: np.ndarray, x_hi: np.ndarray) -> None:
    """``[M] := [M] ⊓ g⁻¹_{[x]}([Z])`` (Prop. 5.3, Eq. 5.48 with Theorem 5.1, Eq. 5.40–5.41) on the grid.

    A cell ``c`` joins ``M⁻`` when the enclosure ``[g]([x], c)`` lies in the union of the ``Z⁻`` pixels
    (then ``g_x(c) ⊂ Z⁻ ⊂ g_x(M)`` for every ``x ∈ [x]``, so ``c ⊂ M``); it leaves ``M⁺`` when the enclosure
    meets no ``Z⁺`` pixel and stays inside the raster (then ``c ∩ M = ∅``).

    Args:
        m: the thick map (changed in place); z: the measured shape; g: the map function.
        x_lo, x_hi: ``(1, n)`` the state box ``[x](t_i)`` (unbounded or empty: nothing is carved).
    """
    x_lo, x_hi = np.atleast_2d(x_lo), np.atleast_2d(x_hi)
    if not _finite_rows(x_lo, x_hi)[0]:
        return
    hull = g.preimage(x_lo, x_hi, *z.box)
    if not _finite_rows(*hull)[0]:
        return
    rows, cols = _cells_in(m.grid, hull[0][0], hull[1][0])
    if not rows.size:
        return
    c_lo, c_hi = m.grid.cell_boxes(rows, cols)
    k = rows.size
    z_lo, z_hi = g.image(np.repeat(x_lo, k, 0), np.repeat(x_hi, k, 0), c_lo, c_hi)
    w = z.windows(z_lo, z_hi, "overlaps")
    inside = z.inside(*w)
    into = inside & (z.count("notlower", *w) == 0)
    out = inside & (z.count("upper", *w) == 0)
    m.free[rows[into], cols[into]] = True
    m.upper[rows[out], cols[out]] = False


class SepShapeRegistration(Sep):
    """Separator of ``{x | g_x(M⁻) ⊂ Z⁺ and g_x⁻¹(Z⁻) ⊂ M⁺}`` on state boxes (Prop. 5.4, Eq. 5.54–5.56).

    * outer (``[x']`` proved infeasible): a cell of ``M⁻`` whose image ``[g]([x'], c)`` meets no ``Z⁺``
      pixel and stays in the raster (``g_x(c) ⊂ comp Z⁺`` though ``c ⊂ M``), or a cell outside ``M⁺``
      whose image lies in ``Z⁻`` pixels (``g_x(c) ⊂ Z⁻ ⊂ g_x(M)`` though ``c ∩ M = ∅``);
    * inner (``[x']`` proved feasible): every ``M⁻`` cell's image meets no pixel outside ``Z⁺`` and every
      cell outside ``M⁺`` has an image meeting no ``Z⁻`` pixel (the part of the plane outside the grid is
      ``[∅, R^q]``: it constrains nothing).

    Only the cells whose image over the hull of a batch could refute a box are kept (for a sub-box the
    pixel windows shrink, so the other cells prove nothing either way).
    """

    def __init__(self, m: ThickMap, z: RasterShape, g: MapFunction, samples: int = 2) -> None:
        if not (isinstance(samples, int) and samples >= 1):
            raise ValueError(f"samples: expected an integer >= 1, got {samples!r}")
        self.m, self.z, self.g, self.n, self.k = m, z, g, g.n, samples

    def _pairs(self, lo: np.ndarray, hi: np.ndarray, rows: np.ndarray, cols: np.ndarray,
               points: bool = False) -> Batch:  # fmt: skip
        """``[g]([x]_a, c_b)`` for every box ``a`` and cell ``b`` (flattened ``(N·K,)``, box-major).

        With ``points``, ``[g]([x]_a, s)`` for the ``k²`` sample points ``s`` inside each cell
        (``(N·K·k²,)``): a point of a cell of ``M⁻`` is in ``M``, one of a cell outside ``M⁺`` is not.
        """
        n = lo.shape[0]
        c_lo, c_hi = self.m.grid.cell_boxes(rows, cols)
        if points:
            f = (np.arange(self.k) + 0.5) / self.k
            fx, fy = (v.ravel() for v in np.meshgrid(f, f, indexing="ij"))
            px = c_lo[:, None, 0] + fx[None] * (c_hi[:, None, 0] - c_lo[:, None, 0])
            py = c_lo[:, None, 1] + fy[None] * (c_hi[:, None, 1] - c_lo[:, None, 1])
            # a sample that rounding pushed onto the cell's border is still in the closed cell
            c_lo = c_hi = np.stack([px.ravel(), py.ravel()], axis=1)
        k = c_lo.shape[0]
        xl, xh = np.repeat(lo, k, 0), np.repeat(hi, k, 0)
        return self.g.image(xl, xh, np.tile(c_lo, (n, 1)), np.tile(c_hi, (n, 1)))

    def _informative(self, lo: np.ndarray, hi: np.ndarray) -> tuple[tuple, tuple]:
        h_lo, h_hi = lo.min(axis=0, keepdims=True), hi.max(axis=0, keepdims=True)
        z, m = self.z, self.m
        hull = self.g.preimage(h_lo, h_hi, *z.box)
        rows, cols = _cells_in(m.grid, hull[0][0], hull[1][0])
        sel_in, sel_out = m.free[rows, cols], ~m.upper[rows, cols]
        keep = []
        for sel, which in ((sel_in, "notupper"), (sel_out, "lower")):
            r, c = rows[sel], cols[sel]
            w = z.windows(*self._pairs(h_lo, h_hi, r, c))
            act = z.count(which, *w) > 0
            keep.append((r[act], c[act]))
        return keep[0], keep[1]

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        live = ~empty_rows(lo, hi) & _finite_rows(lo, hi)
        bad, good = np.zeros(lo.shape[0], bool), live.copy()
        rows_live = np.flatnonzero(live)
        if rows_live.size:
            (ri, ci), (ro, co) = self._informative(lo[live], hi[live])
            k = ri.size + ro.size
            chunk = max(1, PAIR_CHUNK // max(1, k * self.k**2))
            z = self.z
            for s in range(0, rows_live.size if k else 0, chunk):
                r = rows_live[s : s + chunk]
                nb = r.size
                if ri.size:
                    zb, zp = self._pairs(lo[r], hi[r], ri, ci), self._pairs(lo[r], hi[r], ri, ci, True)
                    w = z.windows(*zp)
                    bad[r] |= (z.inside(*w) & (z.count("upper", *w) == 0)).reshape(nb, -1).any(axis=1)
                    good[r] &= (z.count("notupper", *z.windows(*zb)) == 0).reshape(nb, -1).all(axis=1)
                if ro.size:
                    zb, zp = self._pairs(lo[r], hi[r], ro, co), self._pairs(lo[r], hi[r], ro, co, True)
                    w = z.windows(*zp)
                    bad[r] |= (z.inside(*w) & (z.count("notlower", *w) == 0)).reshape(nb, -1).any(axis=1)
                    good[r] &= (z.count("lower", *z.windows(*zb)) == 0).reshape(nb, -1).all(axis=1)
        good &= ~bad & live
        drop = (bad | ~live)[:, None]
        e_lo, e_hi = np.full_like(lo, np.inf), np.full_like(hi, -np.inf)
        done = (good | ~live)[:, None]
        xin = (np.where(done, e_lo, lo), np.where(done, e_hi, hi))
        xout = (np.where(drop, e_lo, lo), np.where(drop, e_hi, hi))
        return xin, xout


def shape_register(m: ThickMap, z: RasterShape, g: MapFunction, x_lo: np.ndarray, x_hi: np.ndarray,
                   eps: float) -> Batch:  # fmt: skip
    """``[x] := [x] ∩ ⟦{x | g_x(M⁻) ⊂ Z⁺, g_x⁻¹(Z⁻) ⊂ M⁺}⟧`` (Prop. 5.4, Eq. 5.56), paved to width ``eps``.

    Returns:
        The contracted ``(lo, hi)`` of shape ``(n,)`` (``[+inf, -inf]`` when no state fits).
    """
    x_lo, x_hi = np.asarray(x_lo, np.float64).ravel(), np.asarray(x_hi, np.float64).ravel()
    if not _finite_rows(x_lo[None], x_hi[None])[0]:
        return x_lo, x_hi
    return param_hull(SepShapeRegistration(m, z, g), [(a, b) for a, b in zip(x_lo, x_hi, strict=True)], eps)
