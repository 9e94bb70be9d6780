"""A thick shape measured on a pixel raster in the robot frame (thesis §6.2.3, Eq. 6.4, Fig. 6.1–6.3).

:class:`RasterShape` holds ``[Z] = [Z⁻, Z⁺]`` as two pixel masks and answers, for batches of boxes, which
pixel windows they meet and how many pixels of each mask those windows hold (summed-area tables): the
queries of the carving and the registration of explicit SLAM (:mod:`.shape_srac`).

>>> z = RasterShape(np.ones((2, 2), bool), np.ones((2, 2), bool), (-0.5, 0.5), 0.5)   # Z⁻ = [-0.5, 0.5]²
>>> [v.tolist() for v in z.box]
[[[-0.5, -0.5]], [[0.5, 0.5]]]
>>> w = z.windows(np.array([[-0.2, -0.2]]), np.array([[0.2, 0.2]]), "overlaps")
>>> [int(v[0]) for v in w], int(z.count("lower", *w)[0])        # rows 0..1, columns 0..1: all in Z⁻
([0, 1, 0, 1], 4)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.types import Batch
from digslam.observer.slam.shape_registration import ThickImage

__all__ = ["RasterShape"]


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
    def from_thick_image(cls, img: ThickImage) -> RasterShape:
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
        """Whether each window is non-empty and lies in the raster."""
        h, w = self.lower.shape
        return (ia >= 0) & (ib < h) & (ja >= 0) & (jb < w) & (ia <= ib) & (ja <= jb)
