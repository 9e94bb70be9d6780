"""Explicit shape-based SLAM (thesis §6.2.1–6.2.3, Algorithm 6.1, Eq. 6.1–6.4, 6.17–6.22).

The constraint network (6.3) has three variables: the trajectory ``x(·)``, the map ``M ⊂ R^q`` and the
measured shapes ``Z(t_i) = g_{x(t_i)}(M)`` (Eq. 6.1), with ``g_x`` bijective (Eq. 6.2). Algorithm 6.1
keeps the map explicitly, as a thick set ``[M] = [M⁻, M⁺]`` that starts as ``[∅, R^q]``, and alternates
the two contractors of the network until the tube stops shrinking:

1. ``[x](·) := C_d/dt([x](·))`` (§2.5.4, :func:`~.tube.ctc_deriv`);
2. for every ``t_i``: ``C_SRAC([x](t_i), [Z](t_i), [M])`` (Algorithm 5.1), i.e. carving
   ``[M] := [M] ⊓ g⁻¹_{[x](t_i)}([Z](t_i))`` (Prop. 5.3, Eq. 5.48, Theorem 5.1 Eq. 5.40–5.41):
   ``M⁻ := M⁻ ∪ ⋂_x g_x⁻¹(Z⁻)`` and ``M⁺ := M⁺ ∩ ⋃_x g_x⁻¹(Z⁺)``, then registration
   ``[x](t_i) := [x](t_i) ∩ ⟦{x | g_x(M⁻) ⊂ Z⁺, g_x⁻¹(Z⁻) ⊂ M⁺}⟧`` (Prop. 5.4, Remark 5.7, Eq. 5.56).

Here the map is a :class:`ThickMap` on a :class:`~.grid.Grid` (two boolean rasters, every claim about whole
cells), and the measurements come in families that act on all the gates of the tube at once:

* :class:`ShapeMeasurements`: thick shapes ``[Z](t_i)`` given as rasters (:class:`RasterShape`) in the
  robot frame, double-sided (Eq. 6.4, §6.2.3.1) or one-sided (``Z⁺ = R^q``, §6.2.3.2), with any bijective
  map function (:class:`MapFunction`: ``g``, its inverse, and their natural inclusion functions);
* :class:`RangeMeasurements`: the one-sided range readings of a :class:`~.record.MissionRecord` (disks
  and sonar sectors, Fig. 6.9) in the translation case ``g_x(m) = m - x`` (Eq. 6.16), with the impact
  constraint ``ΔZ ∩ g_x(comp M) ≠ ∅`` (Eq. 6.17, contractor ``C_g^≠`` of Eq. 6.22): with one-sided
  shapes ``M⁺`` stays ``R^q`` and the registration of Prop. 5.4 is void (Eq. 6.19–6.21), so the impact
  zone is what localizes.

Special cases (tested in ``tests/observer/slam/test_explicit_slam.py``):

* Algorithm 6.3 (:func:`~.digslam.dig_slam`) is :func:`explicit_slam` with one
  :class:`RangeMeasurements` family: same schedule, same contractors, so the same tube and ``M⁻``
  (bit for bit) under the same stopping rule;
* Algorithm 6.2 (:func:`~.shape_slam.shape_slam`) removes the map from the network by the inter-temporal
  constraint ``Z(t_i) = Z(t_j) + p_ij`` (Eq. 6.5–6.10). Registering ``Z(t_j)`` against the explicit map
  carved by ``Z(t_i)`` at ``[x](t_i)`` is the same constraint with ``x(t_i)`` blurred over its box, so at
  their fixpoints the explicit tube contains the inter-temporal one (up to the paving width ``eps_x``).

Every step is a sound contractor: the true trajectory stays in the tube and ``M⁻ ⊂ M ⊂ M⁺`` holds at cell
level, floating point included (outward-rounded natural inclusion and integer pixel windows).

>>> g = Grid((-2.0, -2.0), (2.0, 2.0), (8, 8))
>>> z = RasterShape(np.ones((2, 2), bool), np.ones((2, 2), bool), (-0.5, 0.5), 0.5)   # Z⁻ = [-0.5, 0.5]²
>>> m = ThickMap(g)
>>> shape_carve(m, z, MapFunction.translation(), np.array([[0.0, 0.0]]), np.array([[0.0, 0.0]]))
>>> int(m.lower.sum()), int((~m.upper).sum())                     # the 4 central cells are in M
(4, 0)
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.boxes import empty_rows
from digslam.observer.core.types import Batch
from digslam.observer.expr.expr import Function
from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord
from digslam.observer.sets.separators import Sep
from digslam.observer.slam.digmap import DigMap
from digslam.observer.slam.digslam import dig_readings, impact_bound, odometry_velocity
from digslam.observer.thick.carving import param_hull
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA
from digslam.observer.tube.tube import Tube, ctc_deriv, heading_from_compass

__all__ = [
    "ExplicitSlamConfig", "ExplicitSlamResult", "MapFunction", "Measurements", "RangeMeasurements",
    "RasterShape", "SepShapeRegistration", "ShapeMeasurements", "ThickMap", "explicit_slam",
    "mission_tube", "shape_carve", "shape_register",
]  # fmt: skip

#: (box, cell) pairs classified at once (memory bound of the registration separator).
PAIR_CHUNK = 1 << 21


class ThickMap(DigMap):
    """The thick map ``[M] = [M⁻, M⁺]`` on a grid, initially ``[∅, R^q]`` (Algorithm 6.1, line 1).

    ``lower`` (``M⁻``, cells proved in ``M``) is the :class:`~.digmap.DigMap`'s ``free`` raster, so the
    closed-form digging (Eq. 6.21) and impact contractor (Eq. 6.22) of Dig-SLAM act on it directly;
    ``upper`` (``M⁺``) is False on the cells proved outside ``M``. Outside the grid ``[M] = [∅, R^q]``.
    """

    def __init__(self, grid: Grid) -> None:
        super().__init__(grid)
        self.upper = np.ones(grid.shape, dtype=bool)

    @property
    def lower(self) -> np.ndarray:
        """``M⁻`` (the same array as :attr:`free`)."""
        return self.free

    def codes(self) -> np.ndarray:
        """int8 codes of :mod:`.thick.sep`: CLEAR in ``M⁻``, DARK outside ``M⁺``, PENUMBRA between."""
        out = np.full(self.grid.shape, PENUMBRA, dtype=np.int8)
        out[self.free] = CLEAR
        out[~self.upper] = DARK
        return out

    def consistent(self) -> bool:
        """``M⁻ ⊂ M⁺``: False when the data contradict their bounds."""
        return not bool((self.free & ~self.upper).any())


class MapFunction:
    """A bijective map function ``g_x: R^q → R^q`` and its inverse (Eq. 6.1–6.2), with inclusion functions.

    Args:
        g: ``g(x, m)`` returning the ``q`` coordinates of ``g_x(m)`` (robot frame), built from the
            operations of :class:`~.expr.Function` (e.g. ``lambda x, m: [m[0] - x[0], m[1] - x[1]]``).
        g_inv: ``g_inv(x, z) = g_x⁻¹(z)``.
        n: the state dimension; q: the map dimension.
    """

    def __init__(self, g: Callable[..., Any] | None, g_inv: Callable[..., Any] | None, n: int = 2,
                 q: int = 2) -> None:  # fmt: skip
        self.n, self.q = int(n), int(q)
        self._exact_translation = g is None
        if g is not None:
            if g_inv is None:
                raise ValueError("g_inv: the inverse of g is needed (g must be bijective, Eq. 6.2)")
            n_, q_ = self.n, self.q

            def split(v: Any) -> tuple[list, list]:
                return [v[i] for i in range(n_)], [v[n_ + i] for i in range(q_)]

            self.g = Function(lambda v: g(*split(v)), n_ + q_)
            self.g_inv = Function(lambda v: g_inv(*split(v)), n_ + q_)
            if self.g.m != q_ or self.g_inv.m != q_:
                raise ValueError(f"g, g_inv: expected {q_} outputs, got {self.g.m} and {self.g_inv.m}")

    @classmethod
    def translation(cls) -> MapFunction:
        """``g_x(m) = m - x`` (Eq. 6.16), evaluated with outward-rounded subtractions."""
        return cls(None, None, 2, 2)

    def image(self, x_lo: np.ndarray, x_hi: np.ndarray, m_lo: np.ndarray, m_hi: np.ndarray) -> Batch:
        """Enclosure of ``g_[x]([m])`` for batches ``(N, n)`` and ``(N, q)``."""
        if self._exact_translation:
            return rnd.sub_down(m_lo, x_hi[:, :2]), rnd.sub_up(m_hi, x_lo[:, :2])
        r = self.g.eval((np.concatenate([x_lo, m_lo], 1), np.concatenate([x_hi, m_hi], 1)))
        return r.pair

    def preimage(self, x_lo: np.ndarray, x_hi: np.ndarray, z_lo: np.ndarray, z_hi: np.ndarray) -> Batch:
        """Enclosure of ``g_[x]⁻¹([z])``."""
        if self._exact_translation:
            return rnd.add_down(z_lo, x_lo[:, :2]), rnd.add_up(z_hi, x_hi[:, :2])
        r = self.g_inv.eval((np.concatenate([x_lo, z_lo], 1), np.concatenate([x_hi, z_hi], 1)))
        return r.pair


@dataclass(frozen=True)
class RasterShape:
    """A thick shape ``[Z] = [Z⁻, Z⁺]`` in the robot frame on a pixel raster (Eq. 6.4, Fig. 6.1–6.3).

    Pixel ``(i, j)`` is the closed square ``[x₀ + j e, x₀ + (j+1) e] × [y₀ - (i+1) e, y₀ - i e]`` (row 0 on
    top). Outside the raster the shape is unknown (``Z⁻`` empty, ``Z⁺`` everything). A one-sided shape
    (§6.2.3.2) has ``upper`` all True.

    Args:
        lower: ``(H, W)`` pixels in ``Z⁻``; upper: ``(H, W)`` pixels in ``Z⁺`` (``lower ⊂ upper``).
        origin: ``(x₀, y₀)`` the top-left corner; cell: the pixel side ``e > 0``.
    """

    lower: np.ndarray
    upper: np.ndarray
    origin: tuple[float, float]
    cell: float

    def __post_init__(self) -> None:
        lo, up = np.asarray(self.lower, bool), np.asarray(self.upper, bool)
        if lo.ndim != 2 or lo.shape != up.shape or 0 in lo.shape:
            raise ValueError(f"lower, upper: expected two (H, W) masks of one shape, got {lo.shape}, "
                             f"{up.shape}")  # fmt: skip
        if (lo & ~up).any():
            raise ValueError("lower: a pixel of Z⁻ is not in Z⁺")
        if not (np.isfinite(self.cell) and self.cell > 0) or not np.all(np.isfinite(self.origin)):
            raise ValueError(f"cell, origin: expected a positive cell and a finite origin, got {self.cell}, "
                             f"{self.origin}")  # fmt: skip
        object.__setattr__(self, "lower", lo)
        object.__setattr__(self, "upper", up)
        object.__setattr__(self, "origin", (float(self.origin[0]), float(self.origin[1])))
        object.__setattr__(self, "cell", float(self.cell))
        for k, m in (("_sat_notlower", ~lo), ("_sat_upper", up), ("_sat_notupper", ~up), ("_sat_lower", lo)):
            s = np.zeros((m.shape[0] + 1, m.shape[1] + 1), dtype=np.int64)
            s[1:, 1:] = m.astype(np.int64).cumsum(0).cumsum(1)
            object.__setattr__(self, k, s)

    @classmethod
    def from_thick_image(cls, img: Any) -> RasterShape:
        """From a :class:`~.shape_registration.ThickImage` (same pixels, same convention)."""
        return cls(img.lower, img.upper, img.origin, img.cell)

    @property
    def box(self) -> Batch:
        """The raster's extent ``(lo, hi)`` of shape ``(1, 2)``."""
        (x0, y0), (h, w), e = self.origin, self.lower.shape, self.cell
        lo = np.array([[x0, rnd.sub_down(np.float64(y0), np.float64(h * e))]])
        hi = np.array([[rnd.add_up(np.float64(x0), np.float64(w * e)), y0]])
        return lo, hi

    def windows(self, z_lo: np.ndarray, z_hi: np.ndarray, kind: str = "meets") -> tuple[np.ndarray, ...]:
        """Pixel index ranges ``i_a..i_b``, ``j_a..j_b`` (inclusive, unclipped) of the box ``[z]``.

        ``kind="meets"``: a superset of the pixels whose closed square meets ``[z]``; ``"overlaps"``: a
        superset of the pixels whose interior meets ``[z]`` (a box with a non-empty interior lies in the
        union of those, so "every pixel of the window is in ``Z⁻``" proves ``[z] ⊂ Z⁻``). Quotients are
        rounded outward.
        """
        (x0, y0), e = self.origin, np.float64(self.cell)
        with np.errstate(invalid="ignore", over="ignore"):
            ql = rnd.div_down(rnd.sub_down(z_lo[:, 0], x0), e)
            qh = rnd.div_up(rnd.sub_up(z_hi[:, 0], x0), e)
            rl = rnd.div_down(rnd.sub_down(np.float64(y0), z_hi[:, 1]), e)
            rh = rnd.div_up(rnd.sub_up(np.float64(y0), z_lo[:, 1]), e)
            if kind == "meets":
                ja, jb, ia, ib = np.ceil(ql) - 1, np.floor(qh), np.ceil(rl) - 1, np.floor(rh)
            else:
                ja, jb, ia, ib = np.floor(ql), np.ceil(qh) - 1, np.floor(rl), np.ceil(rh) - 1
        h, w = self.lower.shape
        lim = float(4 * (h + w) + 8)
        return tuple(np.clip(np.nan_to_num(v, nan=-lim), -lim, lim).astype(np.int64)
                     for v in (ia, ib, ja, jb))  # fmt: skip

    def count(self, which: str, ia: np.ndarray, ib: np.ndarray, ja: np.ndarray, jb: np.ndarray) -> np.ndarray:
        """Number of pixels of ``which`` (``"notlower"``, ``"upper"``, ``"notupper"``, ``"lower"``) in the
        windows, clipped to the raster."""
        sat = getattr(self, "_sat_" + which)
        h, w = self.lower.shape
        r0, r1 = np.clip(ia, 0, h), np.clip(ib + 1, 0, h)
        c0, c1 = np.clip(ja, 0, w), np.clip(jb + 1, 0, w)
        n = sat[r1, c1] - sat[r0, c1] - sat[r1, c0] + sat[r0, c0]
        return np.where((r0 < r1) & (c0 < c1), n, 0)

    def inside(self, ia: np.ndarray, ib: np.ndarray, ja: np.ndarray, jb: np.ndarray) -> np.ndarray:
        h, w = self.lower.shape
        return (ia >= 0) & (ib < h) & (ja >= 0) & (jb < w) & (ia <= ib) & (ja <= jb)


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


class Measurements(Protocol):
    """A family of measurements at some gates of the tube: the two halves of ``C_SRAC`` on all of them."""

    def carve(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray, changed: np.ndarray) -> None:
        """Carve ``[M]`` with the gates ``(lo, hi)`` ``(T+1, n)`` (only the ``changed`` ones need to)."""

    def contract(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray) -> Batch:
        """The contracted gates ``(lo, hi)``."""


@dataclass
class ShapeMeasurements:
    """Thick shapes ``[Z](t_i)`` at gates ``k_i`` with a bijective map function (Eq. 6.1, §6.2.3).

    Attributes:
        gates: ``(m,)`` gate indices; shapes: ``m`` :class:`RasterShape` in the robot frame.
        g: the map function (default: the translation ``g_x(m) = m - x`` of Eq. 6.16).
        eps: paving width of the state boxes in the registration (Prop. 5.4).
        register: run the registration (False: carving only, the map is built from the tube).
    """

    gates: np.ndarray
    shapes: Sequence[RasterShape]
    g: MapFunction = field(default_factory=MapFunction.translation)
    eps: float = 0.05
    register: bool = True

    def __post_init__(self) -> None:
        self.gates = np.asarray(self.gates)
        if self.gates.ndim != 1 or not np.issubdtype(self.gates.dtype, np.integer):
            raise ValueError("gates: expected (m,) integer gate indices")
        if len(self.shapes) != self.gates.size or not all(isinstance(s, RasterShape) for s in self.shapes):
            raise ValueError(f"shapes: expected {self.gates.size} RasterShape (one per gate)")
        if not (np.isfinite(self.eps) and self.eps > 0):
            raise ValueError(f"eps: must be > 0, got {self.eps!r}")

    def carve(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray, changed: np.ndarray) -> None:
        for k, z in zip(self.gates.tolist(), self.shapes, strict=True):
            if changed[k]:
                shape_carve(m, z, self.g, lo[k : k + 1], hi[k : k + 1])

    def contract(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray) -> Batch:
        if not self.register:
            return lo, hi
        lo, hi = lo.copy(), hi.copy()
        for k, z in zip(self.gates.tolist(), self.shapes, strict=True):
            lo[k], hi[k] = shape_register(m, z, self.g, lo[k], hi[k], self.eps)
        return lo, hi


@dataclass
class RangeMeasurements:
    """One-sided range readings of a record (Fig. 6.9, §6.2.3.2) in the translation case (Eq. 6.16).

    ``[Z](t) = [Z⁻, R²]`` with ``Z⁻`` the free disk or sector (carving: Eq. 6.21, only ``M⁻`` moves) and the
    impact zone ``ΔZ`` with ``ΔZ ∩ g_x(comp M) ≠ ∅`` (Eq. 6.17, ``C_g^≠`` of Eq. 6.22).

    Attributes:
        record: the mission record; heading: its heading tube (see :func:`mission_tube`).
        impacts: apply ``C_g^≠``.
    """

    record: MissionRecord
    heading: Tube
    impacts: bool = True

    def carve(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray, changed: np.ndarray) -> None:
        dig_readings(m, self.record, Tube._trusted(self.record.t, lo, hi, lo[:-1], hi[:-1]), self.heading,
                     changed)  # fmt: skip

    def contract(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray) -> Batch:
        if not self.impacts:
            return lo, hi
        return m.contract_impacts(lo, hi, impact_bound(self.record))


@dataclass(frozen=True)
class ExplicitSlamConfig:
    """Settings of :func:`explicit_slam`.

    Attributes:
        max_iter: most passes of the ``repeat`` loop.
        tol: stop when a pass shrinks the summed gate widths by at most this fraction (0: Algorithm 6.1's
            "until no more contraction on ``[x](·)``", exactly).
    """

    max_iter: int = 20
    tol: float = 0.0

    def __post_init__(self) -> None:
        if not (isinstance(self.max_iter, int) and self.max_iter >= 1):
            raise ValueError(f"max_iter: must be an integer >= 1, got {self.max_iter!r}")
        if not (np.isfinite(self.tol) and self.tol >= 0):
            raise ValueError(f"tol: must be a finite number >= 0, got {self.tol!r}")


@dataclass
class ExplicitSlamResult:
    """Output of :func:`explicit_slam`.

    Attributes:
        consistent: False when a gate became empty or ``M⁻ ⊄ M⁺`` (data outside their bounds).
        tube: the contracted tube; map: the thick map ``[M]`` (both None when inconsistent).
        dead_reckoning: gate widths of the first ``C_d/dt``.
        iterations: passes run; widths: per pass, the gate widths after ``C_SRAC`` and after ``C_d/dt``;
        seconds: wall time.
    """

    consistent: bool
    tube: Tube | None
    map: ThickMap | None
    dead_reckoning: np.ndarray
    iterations: int = 0
    widths: list[dict[str, np.ndarray]] = field(default_factory=list)
    seconds: float = 0.0


def explicit_slam(tube: Tube, u_lo: Any, u_hi: Any, measurements: Sequence[Measurements], grid: Grid,
                  config: ExplicitSlamConfig | None = None) -> ExplicitSlamResult:  # fmt: skip
    """Algorithm 6.1: ``[M] = [∅, R^q]``, then repeat ``C_d/dt`` and ``C_SRAC`` at every ``t_i``.

    The loop runs in Algorithm 6.3's order (``C_d/dt`` forward from ``[x](0)`` first; then per pass: carve
    with every gate, register every gate against the whole map, ``C_d/dt``), which is Algorithm 6.1's loop
    with its first ``C_d/dt`` hoisted out; carving before registering uses the newest map (each half of
    ``C_SRAC`` is a contractor, so either order is sound).

    Args:
        tube: the initial tube (``[x](0) = X₀``, entire elsewhere).
        u_lo, u_hi: ``(T, n)`` velocity bounds per slice (``ẋ ∈ [u]``, e.g. :func:`~.tube.body_velocity`).
        measurements: families of measurements (:class:`ShapeMeasurements`, :class:`RangeMeasurements`).
        grid: the cells of the map.
        config: :class:`ExplicitSlamConfig`.
    """
    cfg = config or ExplicitSlamConfig()
    if not isinstance(tube, Tube):
        raise ValueError(f"tube: expected a Tube, got {tube!r}")
    t0 = time.perf_counter()
    x = ctc_deriv(tube, u_lo, u_hi, forward=True, backward=False)
    m = ThickMap(grid)
    res = ExplicitSlamResult(True, None, m, x.widths())
    total = float(np.sum(x.widths()))
    dug_lo, dug_hi = np.full_like(x.gate_lo, np.nan), np.full_like(x.gate_hi, np.nan)
    for it in range(cfg.max_iter):
        changed = np.any((x.gate_lo != dug_lo) | (x.gate_hi != dug_hi), axis=1)
        for fam in measurements:
            fam.carve(m, x.gate_lo, x.gate_hi, changed)
        dug_lo, dug_hi = x.gate_lo.copy(), x.gate_hi.copy()
        lo, hi = x.gate_lo, x.gate_hi
        for fam in measurements:
            lo, hi = fam.contract(m, lo, hi)
        srac_w = np.where(empty_rows(lo, hi), 0.0, (hi - lo).max(axis=1))
        x = ctc_deriv(Tube(x.t, lo, hi, x.slice_lo, x.slice_hi), u_lo, u_hi)
        res.iterations = it + 1
        res.widths.append({"srac": srac_w, "deriv": x.widths()})
        if x.is_empty() or empty_rows(lo, hi).any() or not m.consistent():
            res.consistent, res.tube, res.map = False, None, None
            res.seconds = time.perf_counter() - t0
            return res
        new_total = float(np.sum(x.widths()))
        if total - new_total <= cfg.tol * total:
            break
        total = new_total
    res.tube = x
    res.seconds = time.perf_counter() - t0
    return res


def mission_tube(record: MissionRecord, x0_lo: Any, x0_hi: Any) -> tuple[Tube, np.ndarray, np.ndarray, Tube]:
    """The initial tube, velocity bounds and heading tube of a record, as :func:`~.digslam.dig_slam` builds
    them (compass and gyro fused, ``ẋ = R(ψ) v`` with the body-frame velocity ``v = (v_1, v_2)``, Eq. 3.59,
    6.12, B.20: :func:`~.digslam.odometry_velocity`).

    Returns:
        ``(tube, u_lo, u_hi, heading)`` with ``[x](0) = X₀`` and entire gates elsewhere.
    """
    t = record.t
    heading = heading_from_compass(t, record.heading[:, 0], record.heading[:, 1],
                                   record.yaw_rate[1:, 0], record.yaw_rate[1:, 1])  # fmt: skip
    u_lo, u_hi = odometry_velocity(record, heading)
    n = t.shape[0]
    g_lo, g_hi = np.full((n, 2), -np.inf), np.full((n, 2), np.inf)
    g_lo[0], g_hi[0] = np.asarray(x0_lo, np.float64), np.asarray(x0_hi, np.float64)
    return Tube(t, g_lo, g_hi), u_lo, u_hi, heading
