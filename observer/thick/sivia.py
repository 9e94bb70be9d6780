"""ThickSivia: thick set inversion ``⟦X⟧ = [f]⁻¹(⟦Y⟧)`` (thesis App. A, Algorithm A.2, Theorem A.2).

``[f] = [f⁻, f⁺]`` is a thick function (§A.2) given by a thick inclusion function ``⟦f⟧``
(Theorem A.1, :class:`~.function.ThickFunction`) and ``⟦Y⟧ = [Y⁻, Y⁺]`` a thick set made of two
boxes ``Y⁻ ⊂ Y⁺``. Pointwise ``X⁻ = {x | [f](x) ⊂ Y⁻}`` and ``X⁺ = {x | [f](x) ∩ Y⁺ ≠ ∅}`` (Eq. 5.32,
A.36). For a box ``[x]`` and ``⟦a⟧ = ⟦f⟧([x])`` (Prop. A.1, A.2 on thick boxes):

* clear  ``(⟦a⟧ ⊂ Y⁻)^∀``: ``lb[f⁻ᵢ] ≥ y⁻ᵢ⁻`` and ``ub[f⁺ᵢ] ≤ y⁻ᵢ⁺`` for every ``i``;
* dark   ``(⟦a⟧ ∩ Y⁺ = ∅)^∀``: ``ub[f⁺ᵢ] < y⁺ᵢ⁻`` or ``lb[f⁻ᵢ] > y⁺ᵢ⁺`` for some ``i``;
* penumbra ``(⟦a⟧ ∩ Y⁺ ≠ ∅)^∀ ∧ (⟦a⟧ ⊄ Y⁻)^∀``: every ``[f](x)`` meets ``Y⁺`` and leaves ``Y⁻``, so
  ``[x] ⊂ X⁺ \\ X⁻`` (Theorem A.2 iii; this is implied by the test ``(⟦a⟧ ∩ (Y⁺\\Y⁻) ≠ ∅)^∀`` of
  Algorithm A.2 and proves at least as many boxes).

Boxes proved in the penumbra are never bisected (:func:`~.paver.thick_pave`, one generation of
boxes per call). Example A.1: ``f(x) = ‖x − a‖²``, ``a ∈ [0, 1]²``, ``[y] = [0, 4]``, so
``area(X⁻) ≈ 5.647`` (four disks meet) and ``area(X⁺) = 9 + 4π ≈ 21.566`` (a rounded square):

>>> from digslam.observer.thick.sivia import thick_sivia
>>> tf = ThickFunction.sqdist([[0.0, 0.0]], [[1.0, 1.0]])
>>> p = thick_sivia(([-2.0, -2.0], [4.0, 4.0]), tf, [0.0, 4.0], eps=0.05)
>>> 5.3 < p.clear_area < 5.647, 21.566 < p.clear_area + p.penumbra_area + p.boundary_area < 22.0
(True, True)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA, UNKNOWN
from digslam.observer.thick.function import ThickFunction
from digslam.observer.thick.interval import FALSE, TRUE, ThickIntervalArray, thin
from digslam.observer.thick.paver import ThickPaving, thick_pave

_ETA = 2.0**-1070  # absolute error allowance of ThickFunction.approx (underflow)


def _box(y: Any, name: str) -> tuple[np.ndarray, np.ndarray]:
    """``(lo, hi)`` of an :class:`IntervalArray`, an ``(m, 2)`` array of intervals, or ``[lo, hi]``."""
    if hasattr(y, "pair"):
        lo, hi = (np.atleast_1d(np.asarray(v, np.float64)) for v in y.pair)
    else:
        arr = np.asarray(y, np.float64)
        if arr.ndim > 2 or arr.shape[-1:] != (2,):
            raise ValueError(f"{name}: expected [lo, hi] or (m, 2) intervals, got shape {arr.shape}")
        arr = arr.reshape(-1, 2)
        lo, hi = arr[:, 0], arr[:, 1]
    if (
        lo.ndim != 1
        or np.isnan(lo).any()
        or np.isnan(hi).any()
        or np.any(lo > hi)
        or np.any(lo == np.inf)
        or np.any(hi == -np.inf)
    ):
        raise ValueError(f"{name}: expected non-empty intervals, got {lo.tolist()} {hi.tolist()}")
    return lo, hi


def _thr_up(t: np.ndarray, k: int, strict: bool) -> np.ndarray:
    """``T`` with ``A ≥ T ⇒ e ≥ t`` (``A > T ⇒ e > t`` if ``strict``) under the model of ``approx``.

    ``1 + k·2⁻⁵¹ ≥ exp(k·2⁻⁵²) ≥ (1 + 2⁻⁵²)ᵏ ≥ (1 + u)ᵏ`` (exact float for small ``k``).
    """
    big = rnd.add_up(rnd.mul_up(np.maximum(t, 0.0), 1.0 + k * 2.0**-51), _ETA)
    trivial = (t < 0) if strict else (t <= 0)  # e ≥ 0 always
    return np.where(trivial, -np.inf, np.where(t == np.inf, np.inf, big))


def _thr_down(t: np.ndarray, k: int) -> np.ndarray:
    """``T`` with ``A ≤ T ⇒ e ≤ t`` and ``A < T ⇒ e < t`` under the model of ``approx``.

    ``(1 − u)ᵏ ≥ 1 − k·u`` (Bernoulli), an exact float for ``k < 2⁵²``.
    """
    with np.errstate(invalid="ignore"):
        small = rnd.sub_down(rnd.mul_down(np.maximum(t, 0.0), 1.0 - k * 2.0**-53), _ETA)
    return np.where(t < 0, -np.inf, np.where(t == np.inf, np.inf, small))


class ThickInverse:
    """Thick test of ``⟦X⟧ = [f]⁻¹([Y⁻, Y⁺])`` for boxes ``Y⁻ ⊂ Y⁺`` (Algorithm A.2, Theorem A.2).

    Args:
        f: the thick inclusion function ``⟦f⟧`` (``n`` inputs, ``m`` outputs).
        y_lower: the box ``Y⁻`` (``None``: ``Y⁻ = ∅``), as ``[lo, hi]`` for ``m = 1``, an ``(m, 2)``
            array of intervals or an :class:`IntervalArray`; infinite bounds allowed.
        y_upper: the box ``Y⁺ ⊃ Y⁻`` (``None``: the thin set ``Y⁺ = Y⁻``).
        penumbra: ``False`` gives the classical Sivia test (Algorithm A.1), which never proves a box in
            the penumbra.

    Raises:
        ValueError: on a bad box, ``Y⁻ ⊄ Y⁺``, or both bounds ``None``.
    """

    def __init__(self, f: ThickFunction, y_lower: Any, y_upper: Any = None, *, penumbra: bool = True) -> None:
        if not isinstance(f, ThickFunction):
            raise ValueError(f"f: expected a ThickFunction, got {type(f).__name__}")
        if y_lower is None and y_upper is None:
            raise ValueError("y_lower, y_upper: at least one bound of ⟦Y⟧ is needed")
        self.f, self.n, self.penumbra = f, f.n, penumbra
        self.yp = _box(y_lower if y_upper is None else y_upper, "y_upper")
        self.ym = None if y_lower is None else _box(y_lower, "y_lower")
        self.m = self.yp[0].size
        if self.ym is not None:
            if self.ym[0].size != self.m:
                raise ValueError(f"y_lower: {self.ym[0].size} intervals but y_upper has {self.m}")
            if np.any(self.ym[0] < self.yp[0]) or np.any(self.ym[1] > self.yp[1]):
                raise ValueError("y_lower: Y⁻ must be inside Y⁺")
        ym = self.ym if self.ym is not None else (np.full(self.m, np.inf), np.full(self.m, -np.inf))
        # thresholds of (clear: lb f⁻ ≥, ub f⁺ ≤), (dark: ub f⁺ <, lb f⁻ >), (meets Y⁺: ub f⁻ ≤, lb f⁺ ≥),
        # (leaves Y⁻: ub f⁻ <, lb f⁺ >) -- exact values, then moved by the error model of f.approx
        self._nominal = (ym[0], ym[1], self.yp[0], self.yp[1], self.yp[1], self.yp[0], ym[0], ym[1])
        self._thr = None
        if f.approx is not None:
            k = f.approx(np.zeros((1, f.n)), np.zeros((1, f.n)))[1]
            yp = self.yp
            self._thr = (_thr_up(ym[0], k, False), _thr_down(ym[1], k), _thr_down(yp[0], k),
                         _thr_up(yp[1], k, True), _thr_down(yp[1], k), _thr_up(yp[0], k, False),
                         _thr_down(ym[0], k), _thr_up(ym[1], k, True))  # fmt: skip

    def _compare(self, a: tuple[np.ndarray, ...], t: tuple[np.ndarray, ...]) -> list[np.ndarray]:
        """Row masks ``clear, dark, meets Y⁺, leaves Y⁻`` (Prop. A.1, A.2) of the bounds
        ``a = (lb f⁻, ub f⁻, lb f⁺, ub f⁺)``, each ``(N, m)``, against thresholds ``t``."""
        ll, lh, hl, hh = a
        out: list[np.ndarray] = []
        for i in range(self.m):  # loop over the outputs, each on the whole batch
            c = [
                (ll[:, i] >= t[0][i]) & (hh[:, i] <= t[1][i]),
                (hh[:, i] < t[2][i]) | (ll[:, i] > t[3][i]),
                (lh[:, i] <= t[4][i]) & (hl[:, i] >= t[5][i]),
                (lh[:, i] < t[6][i]) | (hl[:, i] > t[7][i]),
            ]
            out = c if not out else [out[0] & c[0], out[1] | c[1], out[2] & c[2], out[3] | c[3]]
        return out

    def _rigorous(self, lo: np.ndarray, hi: np.ndarray) -> list[np.ndarray]:
        """The four masks from the outward-rounded ``f.eval`` (Prop. A.1, A.2 via thick intervals)."""
        a = self._shape(self.f.eval(lo, hi), lo.shape[0])
        ov = a.overlaps(thin(*self.yp))
        dark, meets = (ov == FALSE).any(axis=1), (ov == TRUE).all(axis=1)
        if self.ym is None:
            clear, leaves = np.zeros_like(dark), np.ones_like(dark)
        else:
            sub = a.subset_of(thin(*self.ym))
            clear, leaves = (sub == TRUE).all(axis=1), (sub == FALSE).any(axis=1)
        bad = (np.isnan(a.lo_lo) | np.isnan(a.hi_hi) | (a.lo_lo > a.lo_hi) | (a.hi_lo > a.hi_hi)).any(axis=1)
        if np.any(~bad & (a.lo_lo > a.hi_hi).any(axis=1)):
            raise ValueError("f: the enclosures prove f- > f+ on a box: not a thick function")
        return [clear & ~bad, dark & ~bad, meets & ~bad, leaves & ~bad]

    def _shape(self, a: ThickIntervalArray, n_rows: int) -> ThickIntervalArray:
        return ThickIntervalArray(*(v.reshape(n_rows, self.m) for v in (a.lo_lo, a.lo_hi, a.hi_lo, a.hi_hi)),
                                  check=False)  # fmt: skip

    def _masks(self, lo: np.ndarray, hi: np.ndarray) -> list[np.ndarray]:
        approx = self.f.approx
        if self._thr is None or approx is None:
            return self._rigorous(lo, hi)
        a = tuple(v.reshape(lo.shape[0], self.m) for v in approx(lo, hi)[0])
        fast = self._compare(a, self._thr)
        # rows that the nominal thresholds would decide otherwise lie within the rounding slack: redo
        # them with outward rounding (exact bounds such as ‖x − m‖² = 4 on dyadic boxes are common)
        nominal = self._compare(a, self._nominal)
        diff = (fast[0] != nominal[0]) | (fast[1] != nominal[1])
        diff |= (fast[2] != nominal[2]) | (fast[3] != nominal[3])
        redo = np.flatnonzero(diff)
        if redo.size:
            for mask, exact in zip(fast, self._rigorous(lo[redo], hi[redo]), strict=True):
                mask[redo] = exact
        return fast

    def classify(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """``int8`` code per box: ``1`` clear (``⊂ X⁻``), ``-1`` dark (``∩ X⁺ = ∅``), ``2`` penumbra
        (``⊂ X⁺ \\ X⁻``), ``0`` unknown. Empty boxes and NaN or empty enclosures stay unknown.

        Raises:
            ValueError: where the enclosures prove ``f⁻ > f⁺`` on a box (not a thick function).
        """
        lo, hi = np.atleast_2d(np.asarray(lo, np.float64)), np.atleast_2d(np.asarray(hi, np.float64))
        clear, dark, meets, leaves = self._masks(lo, hi)
        # UNKNOWN = 0; the priority clear > dark > penumbra of Algorithm A.2
        st = (meets & leaves).view(np.int8) * PENUMBRA if self.penumbra else np.zeros(lo.shape[0], np.int8)
        st[dark] = DARK
        st[clear] = CLEAR
        empty = lo[:, 0] > hi[:, 0]
        for j in range(1, lo.shape[1]):
            empty |= lo[:, j] > hi[:, j]
        st[empty] = UNKNOWN
        return st


def thick_sivia(x0: Any, f: ThickFunction, y_lower: Any, y_upper: Any = None, *, eps: float,
                penumbra: bool = True, max_boxes: int = 20_000_000) -> ThickPaving:  # fmt: skip
    """ThickSivia (Algorithm A.2): pave ``x0`` into clear / penumbra / dark / undetermined boxes.

    Args:
        x0: initial box ``(lo, hi)`` or :class:`IntervalArray`, assumed to contain ``X⁺``.
        f, y_lower, y_upper, penumbra: as in :class:`ThickInverse`.
        eps: boxes of width ``w∞ ≤ eps`` that stay unknown are not bisected.
        max_boxes: guard on the boxes of one generation.

    Returns:
        :class:`~.paver.ThickPaving` (Theorem A.2: clear ⊂ X⁻, penumbra ⊂ X⁺ \\ X⁻, dark ∩ X⁺ = ∅).
    """
    return thick_pave(x0, ThickInverse(f, y_lower, y_upper, penumbra=penumbra), eps, max_boxes)


__all__ = ["ThickInverse", "thick_sivia"]
