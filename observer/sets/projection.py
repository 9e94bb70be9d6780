"""Projection of separators (thesis §4.2.1, Def. 4.1–4.2, Theorem 4.1).

For ``Z ⊂ Rⁿ × Rᵖ`` and a domain ``[y] ⊂ Rᵖ``, the projection ``proj_x(Z) = {x | ∃ y ∈ [y], (x, y) ∈ Z}``
(Eq. 4.1) has the separator ``{∩_y ∂_x S_in([x], y), ∪_y ∂_x S_out([x], y)}`` (Eq. 4.2, Theorem 4.1).
:class:`SepProj` implements it with the Proj-union / Proj-intersection scheme of §4.2.1, vectorised:
every x box of the batch is paired with the parameter splits ``[y_i]`` of ``[y]``, and one generation
of all ``(box, split)`` pairs goes to the inner separator in a single call.

* Outer part ``x_out`` (Proj-union, Eq. 4.4–4.6): a point ``x`` is proved outside the projection only
  when *every* ``y ∈ [y]`` rejects it (``∀``). ``x_out`` is the hull, over a cover ``{[y_i]}`` of ``[y]``,
  of the x-projections of ``S_out([x] × [y_i])``. Splits whose ``S_out`` is empty are dropped, the
  others are bisected (their contracted y part) down to the width ``eps``.
* Inner part ``x_in`` (Proj-intersection, Eq. 4.7–4.10): a point ``x`` is proved in the projection as
  soon as *one* ``y`` proves ``(x, y) ∈ Z`` (``∃``). For each pair, ``S_in`` is run on ``[x] × [y_i]``
  and on ``[x] × {mid [y_i]}`` (the sampled points of §4.2.1); a pair proves all of ``[x]`` when
  ``S_in`` empties its box or contracts its y part (some ``y ∈ [y_i]`` then lies outside ``S_in``'s
  box, so ``(x, y) ∈ Z`` for every ``x``), and otherwise proves ``[x]`` minus the x-projection of its
  ``S_in`` box. ``x_in`` is the intersection of these projections over all pairs ever evaluated.

An x box is finished as soon as ``x_in`` is empty (all of it proved inside) or no split is left.
Stopping anywhere keeps both parts sound, so the refinement also stops at ``max_splits`` live splits
per box (wide boxes are better bisected by the paver than projected finely) and ``max_pairs`` per
generation. Both parts are only as good as ``S`` on thin boxes: ``Z`` should have a non-empty
interior for the sampled points to prove anything (§4.2.1).

>>> from digslam.observer import Box, Function, Interval, SepInverse
>>> disk = SepInverse(Function(lambda z: z[0] ** 2 + z[1] ** 2), Interval(0, 1))   # (x, y) ∈ unit disk
>>> shadow = SepProj(disk, [0], Box([(-2, 2)]), eps=0.05)                             # [-1, 1] on x
>>> (ilo, ihi), (olo, ohi) = shadow.separate(np.array([[-0.5], [1.5]]), np.array([[0.5], [2.0]]))
>>> bool(ilo[0, 0] > ihi[0, 0]), bool(olo[1, 0] > ohi[1, 0])   # first proved inside, second outside
(True, True)
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from digslam.observer.core.boxes import (
    bisect,
    empty_rows,
    midpoint,
    normalize_empty,
    validate_batch,
    width_inf,
)
from digslam.observer.core.interval import IntervalArray
from digslam.observer.core.types import Batch
from digslam.observer.sets.separators import Sep, inter_batch

__all__ = ["SepOnDims", "SepProj", "bounded_box"]


def _dims(dims: Sequence[int], n: int, name: str) -> np.ndarray:
    d = np.asarray(list(dims), dtype=np.int64)
    if d.ndim != 1 or d.size == 0:
        raise ValueError(f"{name}: expected a non-empty sequence of coordinate indices, got {dims!r}")
    if (d < 0).any() or (d >= n).any():
        raise ValueError(f"{name}: indices must lie in [0, {n}), got {d.tolist()}")
    if np.unique(d).size != d.size:
        raise ValueError(f"{name}: repeated index in {d.tolist()}")
    return d


def bounded_box(box: Any, name: str) -> Batch:
    """Bounds ``(lo, hi)`` of one non-empty bounded box (a parameter domain, which gets bisected): an
    :class:`IntervalArray` ``(p,)`` or an array-like of ``(lo, hi)`` pairs of shape ``(p, 2)``.

    Raises:
        ValueError: naming ``name``, on another shape, a NaN, an empty or an unbounded side.
    """
    if isinstance(box, IntervalArray):
        lo, hi = np.atleast_1d(box.lo), np.atleast_1d(box.hi)
    else:
        a = np.asarray(box, dtype=np.float64)
        if a.ndim != 2 or a.shape[1] != 2:
            raise ValueError(
                f"{name}: expected an IntervalArray or (lo, hi) pairs of shape (p, 2), got shape {a.shape}"
            )
        lo, hi = a[:, 0].copy(), a[:, 1].copy()
    if lo.ndim != 1:
        raise ValueError(f"{name}: expected one box of shape (p,), got {lo.shape}")
    if np.isnan(lo).any() or np.isnan(hi).any() or (lo > hi).any():
        raise ValueError(
            f"{name}: the box must be non-empty and NaN-free, got {lo.tolist()} .. {hi.tolist()}"
        )
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise ValueError(
            f"{name}: the parameter box must be bounded (it is bisected), got {lo.tolist()} .. {hi.tolist()}"
        )
    return lo, hi


class SepOnDims(Sep):
    """``S × S_{R^k}``: a separator ``sep`` of ``X ⊂ R^m`` acting on the coordinates ``dims`` of ``Rⁿ``.

    This is the cylinder ``{z ∈ Rⁿ | z[dims] ∈ X}`` used in Eq. 4.16 (``S_A × S_{R^p}``): the other
    coordinates are left untouched in both parts.

    Args:
        sep: the separator on ``R^m``.
        dims: the ``m`` coordinates of ``Rⁿ`` it acts on, in the order ``sep`` expects them.
        n: the dimension of the whole space.

    Raises:
        ValueError: on bad indices or when ``len(dims)`` differs from ``sep.n``.
    """

    def __init__(self, sep: Sep, dims: Sequence[int], n: int) -> None:
        self.dims = _dims(dims, n, "dims")
        if sep.n is not None and sep.n != self.dims.size:
            raise ValueError(f"dims: {self.dims.size} coordinates given for a separator of dimension {sep.n}")
        self.sep, self.n = sep, int(n)

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        res = []
        for blo, bhi in self.sep.separate(lo[:, self.dims], hi[:, self.dims]):
            blo, bhi = normalize_empty(blo, bhi)
            rlo, rhi = lo.copy(), hi.copy()
            rlo[:, self.dims], rhi[:, self.dims] = blo, bhi
            res.append(normalize_empty(rlo, rhi))
        return res[0], res[1]


class SepProj(Sep):
    """Separator of ``proj_x(Z) = {x | ∃ y ∈ [y], (x, y) ∈ Z}`` (Def. 4.2, Theorem 4.1, Eq. 4.2).

    Args:
        sep: a separator for ``Z`` on ``R^(n+p)``.
        dims_kept: the ``n`` coordinates of ``sep``'s space that are kept (``x``), in output order; the
            ``p`` others (in increasing order) are projected out.
        y_box: the parameter domain ``[y]`` (``p`` bounded intervals): an IntervalArray box or an
            array-like of ``(lo, hi)`` pairs of shape ``(p, 2)``.
        eps: parameter splits narrower than ``eps`` (``w∞``) are not bisected any further.
        max_splits: at most this many live splits per x box: a box whose splits would outgrow it is
            not refined further (the paver bisects it instead; wide boxes would otherwise bisect a
            whole region of ``[y]`` down to ``eps``).
        max_pairs: at most this many ``(box, split)`` pairs per generation: beyond it the refinement
            stops. Stopping early keeps the result sound, only less tight.
        presplit: the first generation already cuts ``[y]`` into ``2**presplit`` splits (successive
            bisections of the widest side): fewer generations when ``[y]`` is wide against ``eps``.
        fixpoint: when True, iterate the projection on its own results until they stall (§4.2.1: the
            Proj-union / Proj-intersection of [Chabert and Jaulin, 2009b] contract to a fixpoint):
            ``x_out ← S_out(x_out)`` and ``x_in ← S_in(x_in)``, each round on the boxes still shrinking
            by more than ``fixpoint_ratio`` of their perimeter, at most ``max_rounds`` rounds. A smaller
            ``[x]`` contracts every split further, so this is tighter, at the cost of more calls (one
            per round; ``benchmarks/bench_paver.py``, ``sepproj_fixpoint_*``, measures both). Off by
            default: inside a paver, bisecting the box pays more than contracting it again.
        fixpoint_ratio, max_rounds: the stopping rule of the fixpoint (as :class:`~.contractors.CtcFixPoint`).

    Raises:
        ValueError: on bad indices, a ``y_box`` whose dimension is not ``p``, or ``eps <= 0``.

    Attributes:
        calls, pairs: number of separator calls and of ``(box, split)`` pairs evaluated so far.
        rounds: number of projection passes so far (one per :meth:`separate` without ``fixpoint``).
    """

    def __init__(
        self, sep: Sep, dims_kept: Sequence[int], y_box: Any, eps: float, max_splits: int = 1024,
        max_pairs: int = 1 << 21, presplit: int = 0, fixpoint: bool = False, fixpoint_ratio: float = 1e-3,
        max_rounds: int = 50,
    ) -> None:  # fmt: skip
        ylo, yhi = bounded_box(y_box, "y_box")
        p = ylo.size
        nz = sep.n if sep.n is not None else len(list(dims_kept)) + p
        self.kept = _dims(dims_kept, nz, "dims_kept")
        if self.kept.size + p != nz:
            raise ValueError(
                f"y_box: {p} parameter intervals plus {self.kept.size} kept coordinates differ from the "
                f"separator dimension {nz}"
            )
        self.proj = np.setdiff1d(np.arange(nz), self.kept)
        if not (isinstance(eps, (int, float, np.integer, np.floating)) and np.isfinite(eps) and eps > 0):
            raise ValueError(f"eps: must be a positive finite number, got {eps!r}")
        if max_pairs < 1 or max_splits < 1:
            raise ValueError(f"max_splits, max_pairs: must be >= 1, got {max_splits}, {max_pairs}")
        self.sep, self.y, self.eps = sep, (ylo, yhi), float(eps)
        if not 0 <= presplit <= 16:
            raise ValueError(f"presplit: must lie in [0, 16], got {presplit}")
        self.max_splits, self.max_pairs, self.presplit = int(max_splits), int(max_pairs), int(presplit)
        if not 0.0 <= fixpoint_ratio < 1.0:
            raise ValueError(f"fixpoint_ratio: must lie in [0, 1), got {fixpoint_ratio}")
        if max_rounds < 1:
            raise ValueError(f"max_rounds: must be at least 1, got {max_rounds}")
        self.fixpoint, self.fixpoint_ratio = bool(fixpoint), float(fixpoint_ratio)
        self.max_rounds = int(max_rounds)
        self.n, self.nz = int(self.kept.size), int(nz)
        self.calls = self.pairs = self.rounds = 0

    def _lift(self, xlo: np.ndarray, xhi: np.ndarray, ylo: np.ndarray, yhi: np.ndarray) -> Batch:
        zlo = np.empty((xlo.shape[0], self.nz))
        zhi = np.empty_like(zlo)
        zlo[:, self.kept], zhi[:, self.kept] = xlo, xhi
        zlo[:, self.proj], zhi[:, self.proj] = ylo, yhi
        return zlo, zhi

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        lo, hi = normalize_empty(*validate_batch(lo, hi, "boxes", self.n))
        (ilo, ihi), (olo, ohi) = self._once(lo, hi)
        self.rounds += 1
        if not self.fixpoint:
            return (ilo, ihi), (olo, ohi)
        # each part is sound on its own: S_in(x_in) only removes points proved in the projection, and
        # S_out(x_out) only points proved outside it; both halves go in one batch per round
        prev = (np.concatenate([lo, lo]), np.concatenate([hi, hi]))
        cur_lo, cur_hi = np.concatenate([ilo, olo]), np.concatenate([ihi, ohi])
        n = lo.shape[0]
        for _ in range(self.max_rounds - 1):
            with np.errstate(invalid="ignore", over="ignore"):
                before = (prev[1] - prev[0]).sum(axis=1)
                after = (cur_hi - cur_lo).sum(axis=1)
                changed = (cur_lo != prev[0]).any(axis=1) | (cur_hi != prev[1]).any(axis=1)
                gain = before - after > self.fixpoint_ratio * before
                shrinking = np.where(np.isfinite(before), gain, changed)
            active = np.flatnonzero(shrinking & ~empty_rows(cur_lo, cur_hi))
            if active.size == 0:
                break
            prev = (cur_lo.copy(), cur_hi.copy())
            (ilo, ihi), (olo, ohi) = self._once(cur_lo[active], cur_hi[active])
            self.rounds += 1
            is_in = active < n
            cur_lo[active] = np.where(is_in[:, None], ilo, olo)
            cur_hi[active] = np.where(is_in[:, None], ihi, ohi)
        return normalize_empty(cur_lo[:n], cur_hi[:n]), normalize_empty(cur_lo[n:], cur_hi[n:])

    def _once(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        """One pass of Proj-union / Proj-intersection on a validated batch."""
        n_rows, kept, proj = lo.shape[0], self.kept, self.proj
        in_lo, in_hi = lo.copy(), hi.copy()  # running intersection of the inner projections
        out_lo, out_hi = np.full_like(lo, np.inf), np.full_like(hi, -np.inf)  # hull of finished splits
        owner = np.flatnonzero(~empty_rows(lo, hi))
        glo, ghi = self.y[0][None], self.y[1][None]
        for _ in range(self.presplit):  # a first grid of splits: fewer (overhead-bound) generations
            (alo, ahi), (blo, bhi) = bisect(glo, ghi)
            glo, ghi = np.concatenate([alo, blo]), np.concatenate([ahi, bhi])
        k = glo.shape[0]
        ylo, yhi = np.tile(glo, (owner.size, 1)), np.tile(ghi, (owner.size, 1))
        owner = np.repeat(owner, k)
        while owner.size:
            m = owner.size
            xlo, xhi = lo[owner], hi[owner]
            ymid = midpoint(ylo, yhi)
            zlo, zhi = self._lift(np.concatenate([xlo, xlo]), np.concatenate([xhi, xhi]),
                                  np.concatenate([ylo, ymid]), np.concatenate([yhi, ymid]))  # fmt: skip
            (ilo, ihi), (olo, ohi) = self.sep.separate(zlo, zhi)
            self.calls += 1
            self.pairs += 2 * m
            ilo, ihi = inter_batch(normalize_empty(ilo, ihi), (zlo, zhi))
            olo, ohi = inter_batch(normalize_empty(olo[:m], ohi[:m]), (zlo[:m], zhi[:m]))
            # inner (∃ y): a pair proves all of [x] if S_in empties its box or shrinks its y part
            shrunk = (ilo[:m][:, proj] > ylo).any(axis=1) | (ihi[:m][:, proj] < yhi).any(axis=1)
            all_box = empty_rows(ilo[:m], ihi[:m]) | shrunk
            all_pt = empty_rows(ilo[m:], ihi[m:])
            clo = np.maximum(ilo[:m][:, kept], ilo[m:][:, kept])
            chi = np.minimum(ihi[:m][:, kept], ihi[m:][:, kept])
            proved_all = all_box | all_pt
            clo[proved_all], chi[proved_all] = np.inf, -np.inf
            np.maximum.at(in_lo, owner, clo)
            np.minimum.at(in_hi, owner, chi)
            owner_done = empty_rows(in_lo, in_hi)
            # outer (a point goes only if every split rejects it): hull over the surviving splits
            alive = ~empty_rows(olo, ohi) & ~owner_done[owner]
            refine = alive & (width_inf(olo[:, proj], ohi[:, proj]) >= self.eps)
            # budget: a box whose splits would outgrow max_splits is left to the paver (bisect x instead)
            per_box = np.bincount(owner[refine], minlength=n_rows)
            refine &= 2 * per_box[owner] <= self.max_splits
            if 2 * np.count_nonzero(refine) > self.max_pairs:
                refine[:] = False
            fin = alive & ~refine
            np.minimum.at(out_lo, owner[fin], olo[fin][:, kept])
            np.maximum.at(out_hi, owner[fin], ohi[fin][:, kept])
            # bisect the contracted y part of the splits left: no point of Z is lost
            r = np.flatnonzero(refine)
            (alo, ahi), (blo, bhi) = bisect(olo[r][:, proj], ohi[r][:, proj])
            owner = np.concatenate([owner[r], owner[r]])
            ylo, yhi = np.concatenate([alo, blo]), np.concatenate([ahi, bhi])
        done = empty_rows(in_lo, in_hi)
        out_lo[done], out_hi[done] = lo[done], hi[done]
        xin = inter_batch(normalize_empty(in_lo, in_hi), (lo, hi))
        xout = inter_batch(normalize_empty(out_lo, out_hi), (lo, hi))
        return xin, xout
