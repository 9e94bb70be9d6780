"""Image contractor and separator on a georeferenced binary image (thesis §2.5.3, Eq. 2.71–2.74).

Pixel ``(i, j)`` (row ``i``, column ``j``) is the closed square
``[x0 + j ex, x0 + (j+1) ex] × [y0 - (i+1) ey, y0 - i ey]``: row 0 is the top, at the largest ``y``
(Remark 2.7), ``(x0, y0)`` the top-left corner of the image. The set is the union of the closed set
pixels; points outside the image extent are outside the set unless ``outside=True``. Counts come from
an int64 summed-area table (Eq. 2.71–2.72); every world/pixel conversion is outward rounded, so a pixel
that meets a box is never dropped.

>>> img = np.zeros((4, 4), bool); img[1:3, 1:3] = True          # the square [1, 3] x [1, 3]
>>> c = CtcImage(img, origin=(0.0, 4.0), pixel_size=(1.0, 1.0))
>>> c.contract(np.array([[0.5, 0.5]]), np.array([[3.5, 2.5]]))
(array([[1., 1.]]), array([[3. , 2.5]]))
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.boxes import normalize_empty
from digslam.observer.core.interval import IntervalArray
from digslam.observer.core.types import Batch
from digslam.observer.sets.contractors import Ctc
from digslam.observer.sets.separators import Sep, SepBox


class CtcImage(Ctc):
    """Minimal image contractor (Eq. 2.73) onto the closed set pixels, plus the outside if ``outside``.

    Args:
        image: ``(H, W)`` array, non-zero pixels belong to the set.
        origin: ``(x0, y0)``, world coordinates of the top-left corner of pixel ``(0, 0)``.
        pixel_size: ``(ex, ey)``, pixel width and height; the sign of ``ey`` is ignored (Remark 2.7's
            negative ``ey`` and a positive height describe the same y-down grid).
        outside: whether points outside the image extent belong to the set.
    """

    n = 2

    def __init__(self, image: Any, origin: Any, pixel_size: Any, outside: bool = False) -> None:
        img = np.asarray(image)
        if img.ndim != 2 or 0 in img.shape:
            raise ValueError(f"image: expected a non-empty 2-d array (H, W), got shape {img.shape}")
        o, e = np.asarray(origin, dtype=np.float64), np.asarray(pixel_size, dtype=np.float64)
        if o.shape != (2,) or not np.isfinite(o).all():
            raise ValueError(f"origin: expected two finite numbers (x0, y0), got {origin!r}")
        if e.shape != (2,) or not (np.isfinite(e).all() and e[0] > 0 and e[1] != 0):
            raise ValueError(f"pixel_size: expected finite (ex > 0, ey != 0), got {pixel_size!r}")
        e = np.abs(e)
        self.image, self.origin, self.pixel_size, self.outside = img != 0, o, e, bool(outside)
        sat = np.zeros((img.shape[0] + 1, img.shape[1] + 1), dtype=np.int64)
        sat[1:, 1:] = self.image.astype(np.int64).cumsum(0).cumsum(1)
        self.sat = sat  # sat[i, j] = number of set pixels in rows < i and columns < j (Eq. 2.71)
        h, w = img.shape
        # extent shrunk inward by rounding, so the outside region is over-approximated
        ylo = rnd.add_up(o[1], -rnd.mul_down(np.float64(h), e[1]))
        xhi = rnd.add_down(o[0], rnd.mul_down(np.float64(w), e[0]))
        self.extent = SepBox(IntervalArray([o[0], ylo], [xhi, o[1]]))

    def count(self, r0: np.ndarray, r1: np.ndarray, c0: np.ndarray, c1: np.ndarray) -> np.ndarray:
        """Set pixels in rows ``r0..r1`` and columns ``c0..c1`` (inclusive, clipped indices) (Eq. 2.72)."""
        s = self.sat
        n = s[r1 + 1, c1 + 1] - s[r0, c1 + 1] - s[r1 + 1, c0] + s[r0, c0]
        return np.where((r0 <= r1) & (c0 <= c1), n, 0)

    def pixel_range(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, ...]:
        """Rows ``r0..r1`` and columns ``c0..c1`` of the pixels meeting each box, clipped to the image."""
        (x0, y0), (ex, ey), (h, w) = self.origin, self.pixel_size, self.image.shape
        with np.errstate(invalid="ignore"):
            # column j meets [xl, xu] iff (xl - x0)/ex - 1 <= j <= (xu - x0)/ex: bounds rounded outward
            c0 = np.ceil(rnd.div_down(rnd.sub_down(lo[:, 0], x0), ex)) - 1
            c1 = np.floor(rnd.div_up(rnd.sub_up(hi[:, 0], x0), ex))
            r0 = np.ceil(rnd.div_down(rnd.sub_down(y0, hi[:, 1]), ey)) - 1
            r1 = np.floor(rnd.div_up(rnd.sub_up(y0, lo[:, 1]), ey))
        bad = np.isnan(c0) | np.isnan(c1) | np.isnan(r0) | np.isnan(r1) | (lo > hi).any(axis=1)
        out = [
            np.clip(np.nan_to_num(v, nan=0.0), -1, n).astype(np.int64)
            for v, n in ((r0, h), (r1, h), (c0, w), (c1, w))
        ]
        out[0], out[2] = np.maximum(out[0], 0), np.maximum(out[2], 0)
        out[1], out[3] = np.where(bad, -1, np.minimum(out[1], h - 1)), np.minimum(out[3], w - 1)
        return tuple(out)

    def _search(self, lo: np.ndarray, hi: np.ndarray, cnt: Any, first: bool) -> np.ndarray:
        """Vectorised dichotomy: first (or last) index ``m`` in ``[lo, hi]`` with ``cnt(m) > 0``."""
        a, b = lo.copy(), hi.copy()
        while (a < b).any():
            mid = (a + b) // 2 if first else (a + b + 1) // 2
            hit = cnt(mid) > 0
            if first:
                a, b = np.where(hit, a, mid + 1), np.where(hit, mid, b)
            else:
                a, b = np.where(hit, mid, a), np.where(hit, b, mid - 1)
        return a

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        r0, r1, c0, c1 = self.pixel_range(lo, hi)
        has = self.count(r0, r1, c0, c1) > 0
        c0, c1, r0, r1 = (np.where(has, v, 0) for v in (c0, c1, r0, r1))
        cl = self._search(c0, c1, lambda m: self.count(r0, r1, c0, m), True)
        cu = self._search(c0, c1, lambda m: self.count(r0, r1, m, c1), False)
        rl = self._search(r0, r1, lambda m: self.count(r0, m, cl, cu), True)
        ru = self._search(r0, r1, lambda m: self.count(m, r1, cl, cu), False)
        (x0, y0), (ex, ey) = self.origin, self.pixel_size
        plo = np.stack(
            [
                rnd.add_down(x0, rnd.mul_down(cl.astype(float), ex)),
                rnd.sub_down(y0, rnd.mul_up(ru.astype(float) + 1, ey)),
            ],
            axis=1,
        )
        phi = np.stack(
            [
                rnd.add_up(x0, rnd.mul_up(cu.astype(float) + 1, ex)),
                rnd.sub_up(y0, rnd.mul_down(rl.astype(float), ey)),
            ],
            axis=1,
        )
        plo = np.where(has[:, None], np.maximum(plo, lo), np.inf)
        phi = np.where(has[:, None], np.minimum(phi, hi), -np.inf)
        if self.outside:
            for p in self.extent.pieces(lo, hi):
                plo, phi = np.minimum(plo, p[0]), np.maximum(phi, p[1])
        return normalize_empty(plo, phi)


class SepImage(Sep):
    """Image separator (§2.5.3.2, Fig. 2.18): outer contractor on ``image``, inner on the complement.

    Args:
        image: ``(H, W)`` upper approximation ``X⁺`` (non-zero pixels cover the set).
        origin, pixel_size, outside: as for :class:`CtcImage`.
        inner: optional ``(H, W)`` lower approximation ``X⁻ ⊂ X⁺`` (pixels inside the set); by default
            ``image`` itself, i.e. the set is exactly the union of the closed set pixels.
    """

    n = 2

    def __init__(
        self, image: Any, origin: Any, pixel_size: Any, outside: bool = False, inner: Any = None
    ) -> None:
        self.ctc_out = CtcImage(image, origin, pixel_size, outside)
        low = self.ctc_out.image if inner is None else np.asarray(inner) != 0
        if low.shape != self.ctc_out.image.shape:
            raise ValueError(f"inner: shape {low.shape} differs from image shape {self.ctc_out.image.shape}")
        if (low & ~self.ctc_out.image).any():
            i, j = np.argwhere(low & ~self.ctc_out.image)[0]
            raise ValueError(f"inner: pixel ({i}, {j}) is set in inner but not in image (need inner ⊂ image)")
        self.ctc_in = CtcImage(~low, origin, pixel_size, not outside)

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        return self.ctc_in.contract(lo, hi), self.ctc_out.contract(lo, hi)


__all__ = [
    "CtcImage",
    "SepImage",
]
