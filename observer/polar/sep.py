"""Minimal separators from minimal contractors, and the polar separators (thesis §3.3, §3.4.1).

* :class:`SepCtcPreimage` is Theorem 3.2 (Eq. 3.46): from the minimal contractor ``C`` of
  ``f(x) = y`` and a subpaving ``Y = ∪[y_i]``, the minimal separator of ``f⁻¹(Y)`` is
  ``{⊔_{[y]∈Ȳ} ∂ₓC([x],[y]), ⊔_{[y]∈Y} ∂ₓC([x],[y])}``, with ``Ȳ`` a subpaving of the closed complement.
* :class:`SepPi` is ``S_π^{[x],[y]}`` (Eq. 3.51): on ``(ρ, θ)`` boxes, the set ``π⁻¹([x]×[y])`` of polar
  coordinates whose point lies in a fixed ``(x, y)`` box.
* :class:`SepPiInv` is ``S_{π⁻¹}^{[ρ],[θ]}`` (Eq. 3.53): on ``(x, y)`` boxes, the pie
  ``π([ρ]×[θ])``. The complement of the pie is the image of a 3-box subpaving of the fundamental
  domain ``ρ >= 0, θ ∈ [θ⁻, θ⁻ + 2π]``, where ``π`` is one-to-one, so the construction stays minimal.
* :class:`SepLandmark` is ``S_m = g_m ∘ S_{π⁻¹}^{[y]}`` (Eq. 3.54–3.56): robot positions ``x`` from
  which a landmark ``m`` is seen at range ``[ρ]`` and bearing ``[θ]``, i.e. ``m - x ∈ π([ρ]×[θ])``.

:class:`SepPiInv` and :class:`SepLandmark` separate a whole batch in one call of the compiled kernel
:func:`digslam.observer.core.polar_jit.sep_pie_batch` (:meth:`~SepPiInv.separate_stacked`); the same
construction through :func:`project_contract` and a numpy contractor is the kernel's oracle in the tests
(``tests/polar_oracle.py``).

>>> s = SepLandmark((0.0, 0.0), (4.0, 6.0), (-np.pi / 12, np.pi / 4))     # §3.4.1.1
>>> (ilo, ihi), (olo, ohi) = s.separate(np.array([[-6.0, -6.0]]), np.array([[4.0, 4.0]]))
>>> [round(float(v), 4) for v in olo[0]], [round(float(v), 4) for v in ohi[0]]   # first outer box
([-6.0, -4.2426], [-2.8284, 1.5529])
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.boxes import box_difference, normalize_empty
from digslam.observer.core.polar_jit import sep_pie_batch
from digslam.observer.core.polar_ops_jit import cos_sin
from digslam.observer.core.types import Batch
from digslam.observer.polar.ctc import CtcPolar
from digslam.observer.sets.contractors import Ctc
from digslam.observer.sets.separators import Sep

_INF = np.inf


def complement_boxes(ylo: np.ndarray, yhi: np.ndarray) -> Batch:
    """Closed boxes covering the closure of ``Rᵐ \\ ∪[y_i]`` (a subpaving ``Ȳ``, Eq. 3.43).

    Args:
        ylo, yhi: ``(k, m)`` bounds of the boxes of ``Y``.
    """
    m = ylo.shape[1]
    plo, phi = np.full((1, m), -_INF), np.full((1, m), _INF)
    for i in range(ylo.shape[0]):
        ilo, ihi = np.maximum(plo, ylo[i]), np.minimum(phi, yhi[i])
        (plo, phi), _ = box_difference(plo, phi, *normalize_empty(ilo, ihi))
    return plo, phi


def project_contract(
    ctc: Ctc,
    x_cols: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    ylo: np.ndarray,
    yhi: np.ndarray,
    live: np.ndarray | None = None,
    groups: Any = None,
    n_groups: int = 1,
) -> Any:
    """``⊔_j ∂ₓC([x], [y_j])`` for every box ``[x]`` of the batch and the ``k`` boxes ``[y_j]``.

    ``ylo, yhi`` are ``(k, m)`` (the same for every row) or ``(N, k, m)`` (per row). ``live`` is an
    optional ``(N, k)`` mask: pairs known to contract to the empty set are skipped. With ``groups``
    (``(k,)`` labels below ``n_groups``) one contractor call serves ``n_groups`` hulls, returned as a list.
    """
    n, nx = lo.shape
    if ylo.ndim == 2:
        ylo, yhi = np.broadcast_to(ylo, (n, *ylo.shape)), np.broadcast_to(yhi, (n, *yhi.shape))
    k, m = ylo.shape[1], ylo.shape[2]
    lab = np.zeros(k, dtype=np.int64) if groups is None else np.asarray(groups, dtype=np.int64)
    g = n_groups
    rlo, rhi = np.full((g * n, nx), _INF), np.full((g * n, nx), -_INF)
    rows, js = np.nonzero(np.ones((n, k), dtype=bool) if live is None else live)
    if rows.size:
        y_cols = np.setdiff1d(np.arange(nx + m), x_cols)
        full_lo, full_hi = np.empty((rows.size, nx + m)), np.empty((rows.size, nx + m))
        full_lo[:, x_cols], full_hi[:, x_cols] = lo[rows], hi[rows]
        full_lo[:, y_cols], full_hi[:, y_cols] = ylo[rows, js], yhi[rows, js]
        clo, chi = normalize_empty(*ctc.contract(full_lo, full_hi))
        dest = lab[js] * n + rows
        np.minimum.at(rlo, dest, clo[:, x_cols])
        np.maximum.at(rhi, dest, chi[:, x_cols])
    parts = [(rlo[i * n : (i + 1) * n], rhi[i * n : (i + 1) * n]) for i in range(g)]
    return parts[0] if groups is None else parts


class SepCtcPreimage(Sep):
    """Minimal separator of ``f⁻¹(Y)`` from the minimal contractor of ``f(x) = y`` (Theorem 3.2).

    Args:
        ctc: a (minimal) contractor on the joint space of ``x`` and ``y``.
        x_cols: the columns of ``ctc``'s boxes that hold ``x`` (the separated variables); the others,
            in order, hold ``y``.
        y: ``Y`` as a box ``(m,)`` / ``(lo, hi)`` pair, or a subpaving ``(k, m)`` pair of bounds; or a
            :class:`Sep` on ``Rᵐ``. With a separator, the image ``∂_y C([x], Rᵐ)`` is separated and
            its two parts projected back (sound; minimal only as far as ``Y``'s separator is).
        complement: a subpaving covering the closure of ``Rᵐ \\ Y``; computed when omitted.

    Raises:
        ValueError: if ``x_cols`` does not fit ``ctc``'s dimension or ``y`` has the wrong shape.
    """

    def __init__(self, ctc: Ctc, x_cols: Any, y: Any, complement: tuple[Any, Any] | None = None) -> None:
        self.ctc, self.x_cols = ctc, np.asarray(x_cols, dtype=np.int64)
        if (
            ctc.n is None
            or not (0 < self.x_cols.size < ctc.n)
            or len(set(self.x_cols)) != self.x_cols.size
            or self.x_cols.min() < 0
            or self.x_cols.max() >= ctc.n
        ):
            raise ValueError(
                f"x_cols: expected distinct columns among the contractor's {ctc.n}, got {x_cols!r}"
            )
        self.n, m = int(self.x_cols.size), ctc.n - int(self.x_cols.size)
        self.sep_y = None
        if isinstance(y, Sep):
            if y.n is not None and y.n != m:
                raise ValueError(
                    f"y: separator of dimension {y.n}, but the contractor leaves {m} columns for y"
                )
            self.sep_y, self.m = y, m
            return
        ylo, yhi = (np.atleast_2d(np.asarray(v, dtype=np.float64)) for v in y)
        if ylo.shape != yhi.shape or ylo.shape[1] != m or np.isnan(ylo).any() or (ylo > yhi).any():
            raise ValueError(f"y: expected non-empty boxes of dimension {m} as (lo, hi), got shapes "
                             f"{ylo.shape} and {yhi.shape}")  # fmt: skip
        self.y = (ylo, yhi)
        if complement is None:
            self.ybar = complement_boxes(ylo, yhi)
        else:
            clo, chi = (np.atleast_2d(np.asarray(v, dtype=np.float64)) for v in complement)
            if clo.shape != chi.shape or clo.shape[1] != m:
                raise ValueError(f"complement: expected boxes of dimension {m}, got {clo.shape}, {chi.shape}")
            self.ybar = (clo, chi)

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        if self.sep_y is not None:  # separate the image, then project both parts back (per row)
            yin, yout = (normalize_empty(*b) for b in self.sep_y.separate(*self._image(lo, hi)))
            ylo, yhi = np.stack([yout[0], yin[0]], axis=1), np.stack([yout[1], yin[1]], axis=1)
            xout, xin = project_contract(self.ctc, self.x_cols, lo, hi, ylo, yhi, groups=[0, 1], n_groups=2)
            return xin, xout
        ylo, yhi = np.r_[self.y[0], self.ybar[0]], np.r_[self.y[1], self.ybar[1]]
        groups = np.r_[np.zeros(len(self.y[0]), dtype=np.int64), np.ones(len(self.ybar[0]), dtype=np.int64)]
        xout, xin = project_contract(self.ctc, self.x_cols, lo, hi, ylo, yhi, groups=groups, n_groups=2)
        return xin, xout

    def _image(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        """``∂_y C([x], Rᵐ)``: the image of every box, as an ``(N, m)`` batch."""
        nt = self.ctc.n
        assert nt is not None
        y_cols = np.setdiff1d(np.arange(nt), self.x_cols)
        full_lo, full_hi = np.full((lo.shape[0], nt), -_INF), np.full((lo.shape[0], nt), _INF)
        full_lo[:, self.x_cols], full_hi[:, self.x_cols] = lo, hi
        clo, chi = normalize_empty(*self.ctc.contract(full_lo, full_hi))
        return clo[:, y_cols], chi[:, y_cols]


def _check_pie(rho: Any, theta: Any) -> tuple[tuple[float, float], tuple[float, float]]:
    r = tuple(float(v) for v in np.asarray(rho, dtype=np.float64).reshape(-1))
    t = tuple(float(v) for v in np.asarray(theta, dtype=np.float64).reshape(-1))
    if len(r) != 2 or len(t) != 2:
        raise ValueError(f"rho, theta: expected two (lo, hi) intervals, got {rho!r} and {theta!r}")
    if np.isnan(r).any() or not r[0] <= r[1] or r[0] < 0 or r[0] == _INF:
        raise ValueError(f"rho: expected a range interval 0 <= lo <= hi, got {r}")
    if not (np.isfinite(t).all() and 0 < t[1] - t[0] < rnd.TWO_PI_DOWN):
        raise ValueError(f"theta: expected a finite bearing interval of aperture in (0, 2π), got {t} "
                         f"(aperture {t[1] - t[0]!r})")  # fmt: skip
    return (r[0], r[1]), (t[0], t[1])


class SepPi(Sep):
    """``S_π^{[x],[y]}`` (Eq. 3.51): separator on ``(ρ, θ)`` boxes for ``π⁻¹([x]×[y])``.

    Args:
        box: the ``(x, y)`` box as ``((x_lo, x_hi), (y_lo, y_hi))``.

    Raises:
        ValueError: on an empty or malformed box.
    """

    n = 2

    def __init__(self, box: Any) -> None:
        b = np.asarray(box, dtype=np.float64)
        if b.shape != (2, 2) or np.isnan(b).any() or (b[:, 0] > b[:, 1]).any():
            raise ValueError(f"box: expected ((x_lo, x_hi), (y_lo, y_hi)) with lo <= hi, got {box!r}")
        self.sep = SepCtcPreimage(CtcPolar(), (2, 3), (b[:, 0], b[:, 1]))

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        return self.sep.separate(lo, hi)


class SepPiInv(Sep):
    """``S_{π⁻¹}^{[ρ],[θ]}`` (Eq. 3.53): separator on ``(x, y)`` boxes for the pie ``π([ρ]×[θ])``.

    Args:
        rho: range interval ``(lo, hi)`` with ``0 <= lo <= hi`` (``hi`` may be ``inf``).
        theta: bearing interval ``(lo, hi)``, finite, of aperture ``0 < hi - lo < 2π``.

    Raises:
        ValueError: on a negative range, or an aperture ``<= 0`` or ``>= 2π``.

    Attributes:
        pie: the ``(ρ, θ)`` box ``[ρ]×[θ]`` as a ``(lo, hi)`` pair of ``(1, 2)`` arrays.
        ybar: the subpaving ``Ȳ`` (at most 3 boxes) of the rest of the fundamental domain, same form.
        convex: whether the aperture is certainly below π (the cone is convex).
    """

    n = 2

    def __init__(self, rho: Any, theta: Any) -> None:
        (r0, r1), (t0, t1) = self.rho, self.theta = _check_pie(rho, theta)
        end = float(rnd.next_up(np.float64(t0) + rnd.TWO_PI_UP, 2))  # >= θ⁻ + 2π
        pieces = [((r0, t1), (r1, end))]  # same ranges, the rest of the turn
        if r0 > 0:
            pieces.append(((0.0, t0), (r0, end)))  # inside the inner circle
        if r1 < _INF:
            pieces.append(((r1, t0), (_INF, end)))  # beyond the outer circle
        self.pie = (np.array([[r0, t0]]), np.array([[r1, t1]]))
        self.convex = t1 - t0 < 3.0  # aperture certainly below π
        self.ybar = (np.array([p[0] for p in pieces]), np.array([p[1] for p in pieces]))
        rows = [(r0, r1, t0, t1)] + [(a[0], b[0], a[1], b[1]) for a, b in pieces]
        self._pieces = np.array(rows, dtype=np.float64)  # (ρ⁻, ρ⁺, θ⁻, θ⁺): the pie, then Ȳ
        self._cs = np.array([cos_sin(r[2], r[3], np.zeros(8)) for r in rows])

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        r = self.separate_stacked(lo, hi)
        return (r[0], r[1]), (r[2], r[3])

    def separate_stacked(self, lo: np.ndarray, hi: np.ndarray, m: np.ndarray | None = None) -> np.ndarray:
        """One call of :func:`.polar_jit.sep_pie_batch`; with ``m``, on ``g_m(x) = m - x`` (Eq. 3.55)."""
        lo, hi = np.ascontiguousarray(lo, dtype=np.float64), np.ascontiguousarray(hi, dtype=np.float64)
        if lo.ndim != 2 or lo.shape[1] != 2 or hi.shape != lo.shape:
            raise ValueError(f"lo, hi: expected two (N, 2) batches, got {lo.shape} and {hi.shape}")
        mm = np.zeros(2) if m is None else m
        return sep_pie_batch(lo, hi, mm, m is not None, self._pieces, self._cs, self.convex)


#: the separator of ``(x, y)`` points inside a ``(ρ, θ)`` pie, under codac's naming
SepPolarXY = SepPiInv


class SepLandmark(Sep):
    """Robot positions from which landmark ``m`` is seen at range ``[ρ]`` and bearing ``[θ]`` (Eq. 3.56).

    The set is ``{x | m - x ∈ π([ρ]×[θ])}``; the bearing is measured in the world frame. The separator
    is ``g_m ∘ S_{π⁻¹}`` with the box-conservative ``g_m(x) = m - x`` (Eq. 3.55), rounded outward.

    Raises:
        ValueError: on a malformed landmark, a negative range, or an aperture ``<= 0`` or ``>= 2π``.
    """

    n = 2

    def __init__(self, m: Any, rho: Any, theta: Any) -> None:
        mm = np.asarray(m, dtype=np.float64).reshape(-1)
        if mm.shape != (2,) or not np.isfinite(mm).all():
            raise ValueError(f"m: expected a finite landmark position (m1, m2), got {m!r}")
        self.m, self.pie = mm, SepPiInv(rho, theta)

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        r = self.separate_stacked(lo, hi)
        return (r[0], r[1]), (r[2], r[3])

    def separate_stacked(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return self.pie.separate_stacked(lo, hi, self.m)


def sep_landmark_fwdbwd(m: Any, rho: Any, theta: Any) -> Sep:
    """The classical forward-backward separator of the same set as :class:`SepLandmark` (for comparisons).

    ``SepInverse`` of ``x ↦ (|m - x|, atan2(m₂ - x₂, m₁ - x₁))`` into ``[ρ]×[θ]``; a bearing interval
    crossing the ``±π`` cut of atan2 is shifted into ``(-π, π]`` and split into two.

    Raises:
        ValueError: as :class:`SepLandmark`.
    """
    from digslam.observer.core.interval import Box
    from digslam.observer.expr.expr import Function
    from digslam.observer.expr.ops import atan2, sqrt
    from digslam.observer.sets.sep_inverse import SepInverse
    from digslam.observer.sets.separators import SepUnion

    mm = SepLandmark(m, rho, theta).m
    (r0, r1), (t0, t1) = _check_pie(rho, theta)
    m1, m2 = float(mm[0]), float(mm[1])
    f = Function(lambda x: (sqrt((m1 - x[0]) ** 2 + (m2 - x[1]) ** 2), atan2(m2 - x[1], m1 - x[0])))
    k = np.floor((t0 + np.pi) / (2 * np.pi))  # shift θ⁻ into [-π, π)
    shift = rnd.mul_up(np.float64(k), rnd.TWO_PI_UP if k > 0 else rnd.TWO_PI_DOWN)  # >= 2kπ
    lo_t = float(rnd.sub_down(np.float64(t0), shift))
    hi_t = float(rnd.add_up(np.float64(lo_t), rnd.sub_up(np.float64(t1), np.float64(t0))))
    if hi_t <= np.pi:
        return SepInverse(f, Box([(r0, r1), (lo_t, hi_t)]))
    wrap = float(rnd.sub_up(np.float64(hi_t), rnd.TWO_PI_DOWN))
    return SepUnion(SepInverse(f, Box([(r0, r1), (lo_t, rnd.PI_UP)])),
                    SepInverse(f, Box([(r0, r1), (-rnd.PI_UP, wrap)])))  # fmt: skip


__all__ = [
    "SepCtcPreimage",
    "SepLandmark",
    "SepPi",
    "SepPiInv",
    "SepPolarXY",
    "complement_boxes",
    "project_contract",
    "sep_landmark_fwdbwd",
]
