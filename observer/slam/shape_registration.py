"""Double-sided thick shapes on a pixel lattice and their translation registration (thesis §6.2.3.1, §6.3).

A :class:`ThickImage` is a measured shape ``[Z] = [Z⁻, Z⁺]`` (Eq. 6.4) in the robot frame: ``Z⁻`` the pixels
proved inside the map set, ``Z⁺`` the pixels that may meet it plus everything the sensor did not see (the
penumbra holds the detection band and the unobserved area). :func:`level_thick_image` builds one from a local
elevation grid and a level band (the bathymetric shapes of §6.3.2). Pixel ``(i, j)`` is the closed square
``[(c₀+j) e, (c₀+j+1) e] × [(r₀-i-1) e, (r₀-i) e]`` on the lattice ``e·Z²`` (row 0 on top), so two images
share their pixel edges and a translation moves whole lattice windows.

:func:`register_translation` contracts ``[p]`` for ``Z(t_i) = Z(t_j) + p`` (constraint 2 of the CN of §6.3.2)
by ``C_f=`` of Remark 5.7 (Eq. 5.54–5.56): ``p`` stays unless ``A⁻ + p ⊄ B⁺`` or ``B⁻ - p ⊄ A⁺`` is proved,
``[p]`` being paved by :func:`~digslam.observer.thick.carving.param_hull` with the lattice separators
:class:`SepTranslationInclusion` (``method="image"``), or with the generic projection separators of §4.2.2
(``method="projection"``, :func:`~digslam.observer.thick.carving.ctc_param_equal`).

>>> z = np.array([[0.0, 0.0, 5.0, 5.0]] * 2)                  # a step: z <= 1 on the left half
>>> a = level_thick_image(z, 0.1, 1.0, cell=1.0, corner=(0, 1))
>>> a.lower.astype(int).tolist(), a.upper.astype(int).tolist()
([[1, 1, 0, 0], [1, 1, 0, 0]], [[1, 1, 0, 0], [1, 1, 0, 0]])
>>> b = level_thick_image(z, 0.1, 1.0, cell=1.0, corner=(-1, 1))    # the same step seen 1 m to the left
>>> lo, hi = register_translation(a, b, [(-3.0, 3.0), (-0.5, 0.5)], eps_p=0.05)
>>> bool(-1.05 < lo[0] <= -1.0), float(hi[0])   # A + p = B: p₁ = -1 kept; p₁ >= 3 moves A⁻ out of B's view
(True, 3.0)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.boxes import empty_rows
from digslam.observer.core.types import Batch
from digslam.observer.sets.projection import bounded_box
from digslam.observer.sets.sep_image import SepImage
from digslam.observer.sets.separators import Sep
from digslam.observer.thick.carving import ctc_param_equal, param_hull
from digslam.observer.thick.sep import ThickSep

__all__ = ["ThickImage", "level_thick_image", "SepTranslationInclusion", "register_translation"]


def _exact(v: float, e: float) -> bool:
    a, b = np.float64(v), np.float64(e)
    return bool(rnd.mul_down(a, b) == rnd.mul_up(a, b))


@dataclass(frozen=True)
class ThickImage:
    """A double-sided thick shape ``[Z⁻, Z⁺]`` on the lattice ``e·Z²`` (Eq. 6.4, Fig. 6.2).

    Args:
        lower: ``(H, W)`` pixels of ``Z⁻`` (proved in the set).
        upper: ``(H, W)`` pixels of ``Z⁺`` (may meet the set); outside the image everything is in ``Z⁺``.
        scope: ``(H, W)`` pixels the sensor observed (the scope ``V`` of Eq. 6.14).
        cell: the pixel side ``e > 0``.
        corner: ``(c₀, r₀)`` integers, the top-left image corner is ``(c₀ e, r₀ e)``; its four corners
            must be exact floats (``e`` a power of two times a small integer, e.g. 0.5, 1, 2).

    Raises:
        ValueError: naming the argument (shapes, ``Z⁻ ⊄ Z⁺``, pixels not in ``Z⁺`` outside the scope,
            inexact corners).
    """

    lower: np.ndarray
    upper: np.ndarray
    scope: np.ndarray
    cell: float
    corner: tuple[int, int]
    _cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        lo, up, sc = (np.asarray(getattr(self, k)) != 0 for k in ("lower", "upper", "scope"))
        if lo.ndim != 2 or 0 in lo.shape:
            raise ValueError(f"lower: expected a non-empty (H, W) mask, got shape {lo.shape}")
        for k, v in (("upper", up), ("scope", sc)):
            if v.shape != lo.shape:
                raise ValueError(f"{k}: shape {v.shape} differs from lower's {lo.shape}")
        if (lo & ~up).any():
            raise ValueError(f"lower: pixel {tuple(np.argwhere(lo & ~up)[0])} is in Z⁻ but not in Z⁺")
        if (~sc & ~up).any():
            raise ValueError(f"upper: unobserved pixel {tuple(np.argwhere(~sc & ~up)[0])} must be in Z⁺")
        e = float(self.cell)
        if not (np.isfinite(e) and e > 0):
            raise ValueError(f"cell: must be a positive finite number, got {self.cell!r}")
        c = np.asarray(self.corner)
        if c.shape != (2,) or not np.issubdtype(c.dtype, np.integer):
            raise ValueError(f"corner: expected two integers (c0, r0), got {self.corner!r}")
        c0, r0 = int(c[0]), int(c[1])
        h, w = lo.shape
        if not all(_exact(v, e) for v in (c0, c0 + w, r0, r0 - h)):
            raise ValueError(
                f"corner: image corners {(c0, r0)}·{e} are not exact floats (choose a dyadic cell)"
            )
        for k, v in (("lower", lo), ("upper", up), ("scope", sc)):
            v.setflags(write=False)
            object.__setattr__(self, k, v)
        object.__setattr__(self, "cell", e)
        object.__setattr__(self, "corner", (c0, r0))

    @property
    def shape(self) -> tuple[int, int]:
        return self.lower.shape  # type: ignore[return-value]  # 2-d (checked): numpy says tuple[int, ...]

    @property
    def origin(self) -> tuple[float, float]:
        """Top-left corner ``(x₀, y₀)`` in the robot frame (exact)."""
        return self.corner[0] * self.cell, self.corner[1] * self.cell

    @cached_property
    def sep(self) -> ThickSep:
        """The thick separator ``[S(Z⁻), S(Z⁺)]`` from image separators (§2.5.3.2)."""
        px = (self.cell, self.cell)
        return ThickSep(
            SepImage(self.lower, self.origin, px), SepImage(self.upper, self.origin, px, outside=True)
        )

    def scope_box(self) -> Batch:
        """Hull ``(lo, hi)`` of the observed pixels, exact; empty ``[+inf, -inf]`` when nothing was seen."""
        r, c = np.nonzero(self.scope)
        if r.size == 0:
            return np.full(2, np.inf), np.full(2, -np.inf)
        (c0, r0), e = self.corner, self.cell
        return (np.array([(c0 + c.min()) * e, (r0 - r.max() - 1) * e]),
                np.array([(c0 + c.max() + 1) * e, (r0 - r.min()) * e]))  # fmt: skip

    def lower_box(self) -> list[tuple[float, float]]:
        """Hull of the ``Z⁻`` pixels ``[(x⁻, x⁺), (y⁻, y⁺)]`` (projection box of ``method="projection"``)."""
        r, c = np.nonzero(self.lower)
        (c0, r0), e = self.corner, self.cell
        if r.size == 0:
            return [(c0 * e, (c0 + 1) * e), ((r0 - 1) * e, r0 * e)]
        return [((c0 + c.min()) * e, (c0 + c.max() + 1) * e), ((r0 - r.max() - 1) * e, (r0 - r.min()) * e)]


def level_thick_image(elevation: Any, error: Any, level: Any, cell: float, corner: tuple[int, int],
                      scope: Any = None) -> ThickImage:  # fmt: skip
    """Thick shape of the level set ``{m | z(m) ∈ [h]}`` from a local elevation grid (§6.2.3.1, §6.3.2).

    Contract: for every point ``m`` of the closed pixel ``(i, j)`` of the scope,
    ``|z(m) - elevation[i, j]| <= error[i, j]`` (the detection band: sounding error plus the relief
    inside the pixel). Then ``Z⁻`` holds the pixels where ``[elevation ± error] ⊂ [h]`` (proved in the
    set), ``Z⁺`` those where ``[elevation ± error]`` meets ``[h]`` plus every pixel outside the scope
    (unobserved: penumbra); outside the image everything is penumbra too. Bounds are outward rounded.

    Args:
        elevation: ``(H, W)`` measured elevations (NaN allowed outside the scope).
        error: scalar or ``(H, W)`` error bounds ``>= 0``.
        level: ``h`` for ``z <= h``, or ``(h⁻, h⁺)`` for ``h⁻ <= z <= h⁺``.
        cell, corner: the pixel lattice (see :class:`ThickImage`).
        scope: ``(H, W)`` mask of observed pixels (default: where ``elevation`` is finite).

    Raises:
        ValueError: naming the argument (shape, NaN or negative error inside the scope, empty level).
    """
    z = np.asarray(elevation, dtype=np.float64)
    if z.ndim != 2 or 0 in z.shape:
        raise ValueError(f"elevation: expected a non-empty (H, W) array, got shape {z.shape}")
    sc = np.isfinite(z) if scope is None else np.asarray(scope) != 0
    if sc.shape != z.shape:
        raise ValueError(f"scope: shape {sc.shape} differs from elevation's {z.shape}")
    try:
        err = np.broadcast_to(np.asarray(error, dtype=np.float64), z.shape)
    except ValueError as exc:
        raise ValueError(f"error: cannot broadcast shape {np.shape(error)} to {z.shape}") from exc
    if not np.isfinite(z[sc]).all():
        raise ValueError("elevation: non-finite value inside the scope")
    if not (np.isfinite(err[sc]).all() and (err[sc] >= 0).all()):
        raise ValueError("error: must be finite and >= 0 inside the scope")
    lv = np.atleast_1d(np.asarray(level, dtype=np.float64)).ravel()
    if lv.size not in (1, 2) or np.isnan(lv).any():
        raise ValueError(f"level: expected h or (h_lo, h_hi), got {level!r}")
    h_lo, h_hi = (-np.inf, lv[0]) if lv.size == 1 else (lv[0], lv[1])
    if not h_lo <= h_hi:
        raise ValueError(f"level: empty band [{h_lo}, {h_hi}]")
    zs, es = np.where(sc, z, 0.0), np.where(sc, err, 0.0)
    z_lo, z_hi = rnd.sub_down(zs, es), rnd.add_up(zs, es)
    lower = sc & (z_lo >= h_lo) & (z_hi <= h_hi)
    upper = ~sc | ((z_hi >= h_lo) & (z_lo <= h_hi))
    return ThickImage(lower, upper, sc, cell, corner)


class SepTranslationInclusion(Sep):
    """Separator of ``P = {p ∈ R² | A⁻ + s·p ⊂ B⁺}`` (Eq. 5.54, ``f_p(a) = a + s·p``, ``s = ±1``).

    On a box ``[p]``, with windows of lattice pixels computed once per box (outward rounded):

    * outer (``[p]`` proved outside ``P``): for some ``Z⁻`` pixel ``Q``, either one pixel ``X`` proved
      outside ``B⁺`` has its interior meeting ``Q + s·p`` for every ``p ∈ [p]`` (narrow boxes), or one of
      ``k²`` sample points ``a`` strictly inside ``Q`` has ``a + s[p]`` inside ``B``'s image and meeting no
      ``B⁺`` pixel (wide boxes); either way ``Q + s·p ⊄ B⁺`` for every ``p ∈ [p]``;
    * inner (``[p]`` proved inside ``P``): for every ``Z⁻`` pixel ``Q``, ``Q + s[p]`` meets no pixel
      outside ``B⁺`` (the rest of the plane is in ``B⁺``).

    The work is a batch of integer window counts on a summed-area table: ``(N boxes) × (points)``,
    chunked over boxes to bound memory.

    Args:
        a, b: the thick images (``A⁻`` from ``a.lower``, ``B⁺`` from ``b.upper``); same ``cell``.
        sign: ``+1`` for ``A⁻ + p ⊂ B⁺``, ``-1`` for ``A⁻ - p ⊂ B⁺``.
        samples: ``k``, sample points per pixel side (a power of two).
    """

    n = 2

    def __init__(self, a: ThickImage, b: ThickImage, sign: int = 1, samples: int = 1) -> None:
        if a.cell != b.cell:
            raise ValueError(f"b: cell {b.cell} differs from a's {a.cell} (images must share a lattice)")
        if sign not in (1, -1):
            raise ValueError(f"sign: expected +1 or -1, got {sign!r}")
        if not (isinstance(samples, int) and samples >= 1 and samples & (samples - 1) == 0):
            raise ValueError(f"samples: expected a power of two >= 1, got {samples!r}")
        self.e, self.sign, self.k = a.cell, sign, samples
        self.pow2 = bool(np.frexp(a.cell)[0] == 0.5)  # cell = 2^k: division by it is a scaling
        r, c = np.nonzero(a.lower)
        self.px_x, self.px_y = a.corner[0] + c, a.corner[1] - r - 1  # lattice indices of the Z⁻ pixels
        self.b_c0, self.b_r0, (self.bh, self.bw) = b.corner[0], b.corner[1], b.shape
        self.sat_in = _sat(b.upper)  # B⁺ pixels
        self.sat_out = _sat(~b.upper)  # pixels proved outside B⁺
        self.frac = (np.arange(samples) + 0.5) / samples  # exact dyadic offsets inside a pixel
        # offsets beyond this reach no pixel of B from any pixel of A: clip them (integer-safe)
        self.lim = (
            4
            + self.bw
            + self.bh
            + 2 * int(np.abs(np.concatenate([self.px_x, self.px_y, [0]])).max())
            + 2 * (abs(self.b_c0) + abs(self.b_r0))
        )

    def _quotients(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        """``[p⁻/e, p⁺/e]`` for the signed translation ``s[p]`` (``(N, 2)``), rounded outward."""
        plo, phi = (lo, hi) if self.sign == 1 else (-hi, -lo)
        e = np.float64(self.e)
        with np.errstate(invalid="ignore", over="ignore"):
            if self.pow2:  # p · 2^-k is exact unless it falls below the normal range (then round outward)
                ql, qh = plo * (1.0 / e), phi * (1.0 / e)
                if not ((np.abs(ql) < 2.0**-1000) | (np.abs(qh) < 2.0**-1000)).any():
                    return ql, qh
            return rnd.div_down(plo, e), rnd.div_up(phi, e)

    def _offsets(self, q: Batch, kind: str, f: Any = 0.5) -> Batch:
        """Lattice index offsets ``[k⁻, k⁺]`` relative to a ``Z⁻`` pixel's column (and row) index ``J``.

        ``kind="meets"``: the ``K`` that ``[J e + p⁻, (J+1) e + p⁺]`` meets, ``K - J ∈ [p⁻/e - 1, p⁺/e + 1]``
        (enlarged); ``"overlaps"``: the ``K`` with ``(J - K) e + p ∈ (-e, e)`` for every ``p``, i.e.
        ``K - J ∈ (p⁺/e - 1, p⁻/e + 1)`` (shrunk); ``"point"``: the ``K`` met by ``(J + f) e + [p]``,
        ``K - J ∈ [f + p⁻/e - 1, f + p⁺/e]`` (enlarged).
        """
        ql, qh = q
        with np.errstate(invalid="ignore", over="ignore"):
            if kind == "meets":
                k_lo, k_hi = np.ceil(ql) - 1, np.floor(qh) + 1
            elif kind == "overlaps":
                k_lo, k_hi = np.floor(qh), np.ceil(ql)
            else:
                k_lo, k_hi = np.ceil(rnd.add_down(ql, f - 1.0)), np.floor(rnd.add_up(qh, f))
        lim = float(self.lim)  # no NaN here: p bounds are finite or infinite, never inf - inf
        return np.clip(k_lo, -lim, lim).astype(np.int64), np.clip(k_hi, -lim, lim).astype(np.int64)

    def _windows(self, px: Batch, k: Batch) -> tuple[np.ndarray, ...]:
        """``(N, M)`` local B rows ``r_a..r_b`` and columns ``c_a..c_b`` (unclipped) for the pixels ``px``."""
        (jx, jy), (k_lo, k_hi) = px, k
        ca = jx[None, :] + (k_lo[:, 0] - self.b_c0)[:, None]
        cb = jx[None, :] + (k_hi[:, 0] - self.b_c0)[:, None]
        ra = (self.b_r0 - 1 - k_hi[:, 1])[:, None] - jy[None, :]
        rb = (self.b_r0 - 1 - k_lo[:, 1])[:, None] - jy[None, :]
        return ra, rb, ca, cb

    def _count(self, sat: np.ndarray, ra: np.ndarray, rb: np.ndarray, ca: np.ndarray, cb: np.ndarray
               ) -> np.ndarray:  # fmt: skip
        """Pixels counted by the summed-area table ``sat`` in each (clipped) window, ``(N, M)``."""
        w1 = self.bw + 1
        r0, r1 = np.minimum(np.maximum(ra, 0), self.bh) * w1, np.minimum(np.maximum(rb + 1, 0), self.bh) * w1
        c0, c1 = np.minimum(np.maximum(ca, 0), self.bw), np.minimum(np.maximum(cb + 1, 0), self.bw)
        s = sat.ravel()
        n = s[r1 + c1] - s[r0 + c1] - s[r1 + c0] + s[r0 + c0]
        return np.where((r0 < r1) & (c0 < c1), n, 0)

    def _classify(self, lo: np.ndarray, hi: np.ndarray, px: Batch) -> tuple[np.ndarray, np.ndarray]:
        """``(infeasible, feasible)`` masks of ``(N,)`` boxes, from the ``Z⁻`` pixels ``px``."""
        n, q = lo.shape[0], self._quotients(lo, hi)
        # "meets" windows (to prove feasibility) and "overlaps" windows (one pixel outside B⁺ whose
        # interior meets Q + p for every p ∈ [p]) count the same pixels: one call for both
        (m_lo, m_hi), (o_lo, o_hi) = self._offsets(q, "meets"), self._offsets(q, "overlaps")
        cnt = self._count(self.sat_out, *self._windows(px, (np.concatenate([m_lo, o_lo]),
                                                            np.concatenate([m_hi, o_hi])))) > 0  # fmt: skip
        feasible, infeasible = ~cnt[:n].any(axis=1), cnt[n:].any(axis=1)
        f = np.stack(np.meshgrid(self.frac, self.frac, indexing="ij"), -1).reshape(-1, 1, 2)  # (k², 1, 2)
        p_lo, p_hi = self._offsets((q[0][None], q[1][None]), "point", f)
        ra, rb, ca, cb = self._windows(px, (p_lo.reshape(-1, 2), p_hi.reshape(-1, 2)))
        free = (ra >= 0) & (rb < self.bh) & (ca >= 0) & (cb < self.bw)
        free &= self._count(self.sat_in, ra, rb, ca, cb) == 0
        infeasible |= free.any(axis=1).reshape(-1, n).any(axis=0)
        return np.asarray(infeasible), np.asarray(feasible & ~infeasible)

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        live = ~empty_rows(lo, hi)
        bad, good = np.zeros(lo.shape[0], bool), live.copy()
        if live.any() and self.px_x.size:
            # only the Z⁻ pixels whose window over the hull of the batch meets a pixel outside B⁺ can
            # refute a box, or fail to prove one (for every box of the batch, the others prove nothing)
            h = lo[live].min(axis=0, keepdims=True), hi[live].max(axis=0, keepdims=True)
            px = (self.px_x, self.px_y)
            win = self._windows(px, self._offsets(self._quotients(*h), "meets"))
            act = self._count(self.sat_out, *win)[0] > 0
            px = (self.px_x[act], self.px_y[act])
            rows = np.flatnonzero(live)
            chunk = max(1, (1 << 20) // max(1, px[0].size * self.k**2))  # bound the (N, M) work arrays
            for s in range(0, rows.size if px[0].size else 0, chunk):  # chunks of boxes, for memory only
                r = rows[s : s + chunk]
                bad[r], good[r] = self._classify(lo[r], hi[r], px)
        empty = np.full_like(lo, np.inf), np.full_like(hi, -np.inf)
        xin = (np.where(good[:, None], empty[0], lo), np.where(good[:, None], empty[1], hi))
        xout = (np.where(bad[:, None] | ~live[:, None], empty[0], lo),
                np.where(bad[:, None] | ~live[:, None], empty[1], hi))  # fmt: skip
        return xin, xout


def _sat(mask: np.ndarray) -> np.ndarray:
    s = np.zeros((mask.shape[0] + 1, mask.shape[1] + 1), dtype=np.int64)
    s[1:, 1:] = mask.astype(np.int64).cumsum(0).cumsum(1)
    return s


def _shift(a: Any, p: Any) -> tuple[Any, Any]:
    return a[0] + p[0], a[1] + p[1]


def _unshift(b: Any, p: Any) -> tuple[Any, Any]:
    return b[0] - p[0], b[1] - p[1]


_shift.q = _unshift.q = 2  # type: ignore[attr-defined]  # the parameter count rides on the function


def register_translation(a: ThickImage, b: ThickImage, p_box: Any, eps_p: float, method: str = "image",
                         samples: int = 1, eps: float | None = None, presplit: int = 2) -> Batch:  # fmt: skip
    """``C_f=([p], [A], [B])`` for ``A + p = B`` (Remark 5.7, Eq. 5.56; constraint 2 of §6.3.2).

    With ``A = Z(t_j)`` and ``B = Z(t_i)`` the translation is ``p_ij = x(t_j) - x(t_i)`` (Eq. 6.10). The
    shapes are not carved (§6.3.3: accurate measured shapes), so this is the registration step of SRAC.

    Args:
        a, b: the two thick images on one lattice.
        p_box: ``[p]`` as ``[(lo, hi), (lo, hi)]``.
        eps_p: paving width of ``[p]`` (``> 0``).
        method: ``"image"`` (lattice separators) or ``"projection"`` (generic SepProj, slow).
        samples: sample points per pixel side (``"image"``); eps: projection width (``"projection"``,
            default ``cell / 2``); presplit: initial bisections of ``[p]``.

    Returns:
        The contracted ``(lo, hi)`` of shape ``(2,)``; ``[+inf, -inf]`` when no translation fits.
    """
    if not isinstance(a, ThickImage) or not isinstance(b, ThickImage):
        raise ValueError(f"a: expected two ThickImage, got {type(a).__name__} and {type(b).__name__}")
    bounded_box(p_box, "p_box")
    if method == "image":
        seps = [SepTranslationInclusion(a, b, 1, samples), SepTranslationInclusion(b, a, -1, samples)]
        return param_hull(seps, p_box, eps_p, presplit)
    if method == "projection":
        e = a.cell / 2 if eps is None else eps
        return ctc_param_equal(p_box, a.sep, b.sep, _shift, _unshift, a.lower_box(), b.lower_box(), e, eps_p,
                               presplit)  # fmt: skip
    raise ValueError(f"method: expected 'image' or 'projection', got {method!r}")
