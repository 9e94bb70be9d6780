"""Shape registration and carving on thick sets (thesis §5.5.2–5.5.4, Prop. 5.2–5.5, Algorithm 5.1).

For ``f_p(A) = B`` with ``A ∈ [A]``, ``B ∈ [B]``, ``p ∈ [p]`` (Eq. 5.62):

* registration (Prop. 5.4, Eq. 5.54–5.56): ``[p]`` shrinks to the hull of the ``p`` not excluded from
  ``{p | f_p(A⁻) ⊂ B⁺}`` (and ``{p | f_p⁻¹(B⁻) ⊂ A⁺}`` for an equality), paved over ``[p]`` with the
  registration separators of §4.2.2; for ``f_p(A) ∩ B ≠ ∅`` the set is ``{p | f_p(A⁺) ∩ B⁺ ≠ ∅}``
  (Prop. 5.5, Eq. 5.61);
* carving (Prop. 5.2–5.3, Eq. 5.47–5.48): ``[A] ⊓ f_[p]⁻¹([B])`` and ``[B] ⊓ f_[p]([A])``;
* :func:`srac` chains both (Algorithm 5.1).

The contracted ``[p]`` is the hull of a paving: sound (a ``p`` is dropped only when proved
infeasible), as tight as ``eps`` and the separators allow.

>>> from digslam.observer import Box, SepBox
>>> from digslam.observer.sets.registration import translation
>>> a = ThickSep(SepBox(Box([(0, 1)])), SepBox(Box([(-0.1, 1.1)])))
>>> b = ThickSep(SepBox(Box([(2, 3)])), SepBox(Box([(1.9, 3.1)])))
>>> lo, hi = ctc_param_subset([(-5, 5)], a, b, translation(1), [(0, 1)], eps=0.01, eps_p=0.01)
>>> bool(1.89 <= lo[0] <= 1.9 and 2.1 <= hi[0] <= 2.11)   # A⁻ + p ⊂ B⁺ iff p ∈ [1.9, 2.1]
True
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from digslam.observer.core.boxes import bisect, empty_rows, normalize_empty, width_inf
from digslam.observer.core.interval import IntervalArray
from digslam.observer.core.types import Batch
from digslam.observer.sets.projection import bounded_box
from digslam.observer.sets.registration import (
    Transformation,
    sep_inclusion,
    sep_intersection,
    transform_function,
)
from digslam.observer.sets.separators import Sep, inter_batch
from digslam.observer.sets.transforms import Transform
from digslam.observer.thick.inversion import thick_inverse_proj
from digslam.observer.thick.ops import thick_image
from digslam.observer.thick.sep import ThickSep
from digslam.observer.thick.set import ctc_equal, ctc_subset

__all__ = [
    "SRACResult", "ctc_image_equal", "ctc_image_param", "ctc_param_equal", "ctc_param_meets",
    "ctc_param_subset", "param_hull", "srac",
]  # fmt: skip


def param_hull(sep: Sep | Sequence[Sep], p_box: Any, eps: float, presplit: int = 0,
               max_boxes: int = 1 << 20) -> Batch:  # fmt: skip
    """Hull of the part of ``[p]`` that ``sep`` does not exclude, paved down to width ``eps``.

    A paver (Algorithm 2.1) that only keeps what the hull needs: boxes proved in the set and boxes
    narrower than ``eps`` enlarge the running hull ``H``; the strips ``[x_out] \\ [x_in]`` proved inside
    enlarge it too; a live box inside ``H`` is dropped (it cannot enlarge the hull). Every ``p`` that
    ``sep`` does not prove outside stays in the result: the contraction is sound.

    Args:
        sep: a separator of the feasible parameter set, or a sequence of separators of sets whose
            intersection it is: they run one after the other, each on what the previous ones kept
            (rows excluded early skip the later, costlier separators).
        p_box: the initial box ``[p]``.
        eps: width ``w∞`` under which a box is no longer bisected (``> 0``).
        presplit: bisect ``[p]`` this many times before the first separator call (larger batches).
        max_boxes: guard on the number of boxes of one generation.

    Returns:
        ``(lo, hi)`` of shape ``(q,)``; ``[+inf, -inf]`` everywhere when all of ``[p]`` is excluded.

    Raises:
        ValueError: on a bad box, ``eps <= 0``, or a generation over ``max_boxes``.
    """
    seps = [sep] if isinstance(sep, Sep) else list(sep)
    if not seps or not all(isinstance(x, Sep) for x in seps):
        raise ValueError(f"sep: expected a Sep or a non-empty sequence of Sep, got {sep!r}")
    plo, phi = bounded_box(p_box, "p_box")
    if not (isinstance(eps, (int, float, np.floating)) and np.isfinite(eps) and eps > 0):
        raise ValueError(f"eps: must be a positive finite number, got {eps!r}")
    lo, hi = plo[None].copy(), phi[None].copy()
    for _ in range(presplit):
        (a, b), (c, d) = bisect(lo, hi)
        lo, hi = np.concatenate([a, c]), np.concatenate([b, d])
    h_lo, h_hi = np.full(plo.size, np.inf), np.full(plo.size, -np.inf)
    while lo.shape[0]:
        if lo.shape[0] > max_boxes:
            raise ValueError(f"max_boxes: a generation holds {lo.shape[0]} boxes; raise eps or max_boxes")
        xin, xout = _separate_seq(seps, lo, hi)
        live = ~empty_rows(*xout)
        proved = live & empty_rows(*xin)  # all of [x] is feasible
        fin = proved | (live & (width_inf(*xout) < eps))
        parts_lo, parts_hi = [xout[0][fin]], [xout[1][fin]]
        # [x_out] \ [x_in] is proved feasible: its slabs {x_k < x_in_k⁻}, {x_k > x_in_k⁺} join the hull
        part = live & ~empty_rows(*xin)
        for k in range(plo.size):
            for side in (0, 1):
                cut = (xin[0][:, k] > xout[0][:, k]) if side == 0 else (xin[1][:, k] < xout[1][:, k])
                m = part & cut
                slo, shi = xout[0][m].copy(), xout[1][m].copy()
                if side == 0:
                    shi[:, k] = xin[0][m, k]
                else:
                    slo[:, k] = xin[1][m, k]
                parts_lo.append(slo)
                parts_hi.append(shi)
        cat_lo, cat_hi = np.concatenate(parts_lo), np.concatenate(parts_hi)
        if cat_lo.shape[0]:
            h_lo, h_hi = np.minimum(h_lo, cat_lo.min(axis=0)), np.maximum(h_hi, cat_hi.max(axis=0))
        inside = ((xout[0] >= h_lo) & (xout[1] <= h_hi)).all(axis=1)
        rest = live & ~fin & ~inside
        (a, b), (c, d) = bisect(xout[0][rest], xout[1][rest])
        lo, hi = np.concatenate([a, c]), np.concatenate([b, d])
    h_lo, h_hi = normalize_empty(h_lo[None], h_hi[None])
    return h_lo[0], h_hi[0]


def _separate_seq(seps: list[Sep], lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
    """``S₁ ∩ S₂ ∩ …`` applied in sequence: ``S_k`` separates the ``x_out`` kept by ``S_{k-1}``.

    ``x_out`` is the last outer box (a point removed by any ``S_k`` is outside its set); ``x_in`` the
    hull of the inner boxes within it (a point of ``x_out`` outside every ``x_in,k`` is in every set).
    """
    xin = (np.full_like(lo, np.inf), np.full_like(hi, -np.inf))
    xout = (lo, hi)
    for s in seps:
        rows = np.flatnonzero(~empty_rows(*xout))
        if rows.size == 0:
            break
        i, o = s.separate(xout[0][rows], xout[1][rows])
        i = inter_batch(normalize_empty(*i), (xout[0][rows], xout[1][rows]))
        o = inter_batch(normalize_empty(*o), (xout[0][rows], xout[1][rows]))
        ilo, ihi = xin[0].copy(), xin[1].copy()
        ilo[rows], ihi[rows] = np.minimum(ilo[rows], i[0]), np.maximum(ihi[rows], i[1])
        olo, ohi = np.full_like(lo, np.inf), np.full_like(hi, -np.inf)
        olo[rows], ohi[rows] = o
        xout = (olo, ohi)
        xin = inter_batch((ilo, ihi), xout)
    return xin, xout


def _box(b: Batch) -> IntervalArray:
    return IntervalArray._raw(b[0].copy(), b[1].copy())


def ctc_param_subset(p_box: Any, a: ThickSep, b: ThickSep, f: Transformation, a_box: Any, eps: float,
                     eps_p: float, presplit: int = 0, **proj_kw: Any) -> Batch:  # fmt: skip
    """``C_f⊂([p], [A], [B]) = [p] ∩ ⟦{p | f_p(A⁻) ⊂ B⁺}⟧`` (Prop. 5.4, Eq. 5.49, 5.54).

    Args:
        p_box: the parameter box ``[p]``.
        a, b: the thick sets ``[A]``, ``[B]``.
        f: the transform ``f(a, p)`` (see :func:`~.registration.transform_function`; ``f.q`` or ``q=``).
        a_box: a bounded box for the projection over ``a`` (sound even if it misses part of ``A⁻``:
            fewer constraints, a larger set).
        eps: splitting width of ``a_box``; eps_p: paving width of ``[p]``.
        presplit: initial bisections of ``[p]``; ``**proj_kw``: ``max_splits``, ``max_pairs``, ``presplit``
            (of ``a_box``) or ``q`` for the registration separator.

    Returns:
        The contracted box ``(lo, hi)`` (``[+inf, -inf]`` when no ``p`` is feasible).
    """
    return param_hull(sep_inclusion(a.lower, b.upper, f, a_box, eps, **proj_kw), p_box, eps_p, presplit)


def ctc_param_equal(p_box: Any, a: ThickSep, b: ThickSep, f: Transformation, f_inv: Transformation,
                    a_box: Any, b_box: Any, eps: float, eps_p: float, presplit: int = 0,
                    **proj_kw: Any) -> Batch:  # fmt: skip
    """``C_f= = C_f⊂([p], [A], [B]) ∩ C_f⁻¹⊂([p], [B], [A])`` for bijective ``f_p`` (Remark 5.7, Eq. 5.56).

    Both inclusions ``f_p(A⁻) ⊂ B⁺`` and ``f_p⁻¹(B⁻) ⊂ A⁺`` are separated together and ``[p]`` is paved
    once (the hull of their intersection is tighter than the intersection of their hulls).
    ``f_inv(b, p) = f_p⁻¹(b)`` and ``b_box`` play for ``B`` the roles of ``f`` and ``a_box``.
    """
    seps = [sep_inclusion(a.lower, b.upper, f, a_box, eps, **proj_kw),
            sep_inclusion(b.lower, a.upper, f_inv, b_box, eps, **proj_kw)]  # fmt: skip
    return param_hull(seps, p_box, eps_p, presplit)


def ctc_param_meets(p_box: Any, a: ThickSep, b: ThickSep, f: Transformation, a_box: Any, eps: float,
                    eps_p: float, presplit: int = 0, **proj_kw: Any) -> Batch:  # fmt: skip
    """``C_f≠([p]) = [p] ∩ ⟦proj_p{(A⁺ × R^q) ∩ f⁻¹(B⁺)}⟧`` for ``f_p(A) ∩ B ≠ ∅`` (Prop. 5.5, Eq. 5.61).

    ``a_box`` must contain ``A⁺``: the projection only sees ``a ∈ a_box`` (a smaller box could drop a
    feasible ``p``). Arguments as for :func:`ctc_param_subset`.
    """
    return param_hull(sep_intersection(a.upper, b.upper, f, a_box, eps, **proj_kw), p_box, eps_p, presplit)


def ctc_image_equal(a: ThickSep, b: ThickSep, t: Transform) -> tuple[ThickSep, ThickSep]:
    """Minimal contractor of ``f(A) = B`` for a bijection ``f`` (Prop. 5.2, Eq. 5.47).

    Returns:
        ``([A⁻ ∪ f⁻¹(B⁻), A⁺ ∩ f⁻¹(B⁺)], [B⁻ ∪ f(A⁻), B⁺ ∩ f(A⁺)])``.
    """
    a2, _ = ctc_equal(a, thick_image(b, t.inverse()))
    b2, _ = ctc_equal(b, thick_image(a, t))
    return a2, b2


def ctc_image_param(a: ThickSep, b: ThickSep, f: Transformation, f_inv: Transformation, p_box: Any, *,
                    n: int, eps: float, equal: bool = True, q: int | None = None
                    ) -> tuple[ThickSep, ThickSep]:  # fmt: skip
    """Carving by ``f_p(A) = B`` (or ``⊂``), ``p ∈ [p]``, ``f_p`` bijective (Prop. 5.3, Eq. 5.48).

    ``F⁻¹([B]) = [∩_p f_p⁻¹(B⁻), ∪_p f_p⁻¹(B⁺)]`` and ``F([A]) = [∩_p f_p(A⁻), ∪_p f_p(A⁺)]`` (Theorem 5.1,
    Eq. 5.40–5.41, by projection over ``[p]``); then Prop. 5.1: for ``f_p(A) ⊂ B`` (``equal=False``)
    ``[A⁻, A⁺ ∩ F⁻¹(B)⁺]`` and ``[B⁻ ∪ F(A)⁻, B⁺]``, for ``f_p(A) = B`` the lattice meets
    ``[A] ⊓ F⁻¹([B])`` and ``[B] ⊓ F([A])``.

    Args:
        a, b: ``[A]``, ``[B]`` on ``Rⁿ``; f, f_inv: ``f(a, p)`` and ``f_inv(b, p) = f_p⁻¹(b)``.
        p_box: the (contracted) parameter box; n: the dimension; eps: projection width over ``[p]``.
    """
    plo, _ = bounded_box(p_box, "p_box")
    q = plo.size if q is None else q
    fz, gz = transform_function(f, n, q, n), transform_function(f_inv, n, q, n)
    pre_b = thick_inverse_proj(fz, b.lower, b.upper, p_box, n=n, eps=eps)  # F⁻¹([B])
    img_a = thick_inverse_proj(gz, a.lower, a.upper, p_box, n=n, eps=eps)  # F([A]) = G⁻¹([A])
    if equal:
        return ctc_equal(a, pre_b)[0], ctc_equal(b, img_a)[0]
    return ctc_subset(a, pre_b)[0], ctc_subset(img_a, b)[1]


@dataclass
class SRACResult:
    """Result of :func:`srac`: the contracted ``p`` box, thick sets, and whether ``[p]`` became empty."""

    p: Batch
    a: ThickSep
    b: ThickSep
    empty: bool
    stats: dict[str, Any] = field(default_factory=dict)


def srac(f: Transformation, f_inv: Transformation, p_box: Any, a: ThickSep, b: ThickSep, a_box: Any,
         b_box: Any, *, eps: float, eps_p: float, eps_carve: float | None = None, presplit: int = 0,
         **proj_kw: Any) -> SRACResult:  # fmt: skip
    """Shape registration and carving, Algorithm 5.1, for ``f_p(A) = B`` with ``f_p`` bijective.

    1. ``[p] := C_f=([p], [A], [B])`` (Prop. 5.4, Remark 5.7, :func:`ctc_param_equal`);
    2. ``([A], [B]) := C_f[p]([A], [B])`` (Prop. 5.1–5.3, :func:`ctc_image_param` with ``equal=True``).

    Args:
        f, f_inv: ``f(a, p)`` and its inverse ``f_inv(b, p)``; a, b: ``[A]``, ``[B]``.
        p_box: the initial ``[p]``; a_box, b_box: boxes of the projections over ``A⁻`` and ``B⁻``.
        eps: projection width over ``a_box``/``b_box``; eps_p: paving width of ``[p]``; eps_carve:
            projection width over ``[p]`` in the carving (default ``eps_p``).
        presplit, proj_kw: see :func:`ctc_param_equal`.

    Returns:
        :class:`SRACResult`. When ``[p]`` is empty the network has no solution and ``a``, ``b`` are
        returned unchanged with ``empty=True``.
    """
    p = ctc_param_equal(p_box, a, b, f, f_inv, a_box, b_box, eps, eps_p, presplit, **proj_kw)
    if empty_rows(p[0][None], p[1][None])[0]:
        return SRACResult(p, a, b, True)
    n = bounded_box(a_box, "a_box")[0].size
    a2, b2 = ctc_image_param(a, b, f, f_inv, _box(p), n=n, eps=eps_p if eps_carve is None else eps_carve,
                             q=p[0].size)  # fmt: skip
    return SRACResult(p, a2, b2, False)
