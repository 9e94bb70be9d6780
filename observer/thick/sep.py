"""Thick separators ``{S_in, S_?, S_out}`` and their algebra (thesis §5.3, Eq. 5.8–5.25).

A thick set ``[X] = [X⁻, X⁺]`` (Eq. 5.4) splits space into the clear zone ``X⁻``, the penumbra
``X⁺ \\ X⁻`` and the dark zone ``complement(X⁺)``. A :class:`ThickSep` is built from two classical
separators ``S⁻`` (for ``X⁻``) and ``S⁺`` (for ``X⁺``) as in Eq. 5.19, and the operations of §5.2.3
act on the pair of bounds, e.g. the extension intersection (Eq. 5.8, 5.16):

>>> from digslam.observer import Box, SepBox
>>> a = ThickSep(SepBox(Box([(0, 1), (0, 1)])), SepBox(Box([(0, 2), (0, 2)])))
>>> b = ThickSep(SepBox(Box([(0.5, 3), (0, 1)])), SepBox(Box([(0.5, 3), (0, 2)])))
>>> import numpy as np
>>> (a & b).classify(np.array([[0.6, 0.1], [1.2, 1.2]]), np.array([[0.9, 0.9], [1.8, 1.8]])).tolist()
[1, 2]
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core.boxes import empty_rows, normalize_empty
from digslam.observer.core.types import Batch
from digslam.observer.sets.separators import Sep, SepInter, SepNot, SepQInter, SepUnion
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA, UNKNOWN


class ThickSep:
    """Thick separator ``[S] = {S⁻_out, S⁻_in ∪ S⁺_out, S⁺_in}`` of ``[X⁻, X⁺]`` (Eq. 5.18–5.19).

    Args:
        sep_lower: separator of the lower bound ``X⁻`` (the clear zone).
        sep_upper: separator of the upper bound ``X⁺`` (``X⁻ ⊂ X⁺`` is required).
    """

    def __init__(self, sep_lower: Sep, sep_upper: Sep) -> None:
        if not isinstance(sep_lower, Sep) or not isinstance(sep_upper, Sep):
            raise TypeError(f"ThickSep: expected two Sep, got {type(sep_lower)} and {type(sep_upper)}")
        n = {s.n for s in (sep_lower, sep_upper) if s.n is not None}
        if len(n) > 1:
            raise ValueError(f"ThickSep: bounds of mismatched dimensions {sorted(n)}")
        self.lower, self.upper, self.n = sep_lower, sep_upper, (n.pop() if n else None)

    def _bounds(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch, Batch, Batch]:
        lo, hi = np.atleast_2d(np.asarray(lo, np.float64)), np.atleast_2d(np.asarray(hi, np.float64))
        (li, lout), (ui, uout) = self.lower.separate(lo, hi), self.upper.separate(lo, hi)
        li, lout, ui, uout = (normalize_empty(*b) for b in (li, lout, ui, uout))
        # a box proved inside X⁻ (S⁻_in empty) and outside X⁺ (S⁺_out empty): X⁻ ⊄ X⁺
        bad = empty_rows(*li) & empty_rows(*uout) & ~empty_rows(lo, hi)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise ValueError(
                f"ThickSep: lower bound not inside upper bound: box {k} "
                f"[{lo[k].tolist()}, {hi[k].tolist()}] is proved in X⁻ and outside X⁺"
            )
        return li, lout, ui, uout

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch, Batch]:
        """Contract a batch into ``(x_in, x_?, x_out)`` (Eq. 5.18–5.22).

        ``x_in = S⁻_out([x])`` keeps ``[x] ∩ X⁻`` (what it removes is proved not clear);
        ``x_? = S⁻_in([x]) ∩ S⁺_out([x])`` (Eq. 5.22) keeps ``[x] ∩ (X⁺ \\ X⁻)``; ``x_out = S⁺_in([x])`` keeps
        ``[x] \\ X⁺``. Their hull is ``[x]``. Empty rows are ``[+inf, -inf]``.

        Raises:
            ValueError: where a box is proved in ``X⁻`` and outside ``X⁺`` (inconsistent bounds).
        """
        li, lout, ui, uout = self._bounds(lo, hi)
        # Eq. 5.22: X? = comp(X⁻) ∩ X⁺, so intersecting S⁻_in and S⁺_out is sound and tighter
        xq = normalize_empty(*_inter(li, uout))
        return lout, xq, ui

    def classify(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """``int8`` status per box: ``1`` clear (``⊂ X⁻``), ``-1`` dark (``∩ X⁺ = ∅``),
        ``2`` penumbra (``⊂ X⁺ \\ X⁻``), ``0`` unknown."""
        li, lout, ui, uout = self._bounds(lo, hi)
        st = np.full(li[0].shape[0], UNKNOWN, dtype=np.int8)
        st[empty_rows(*lout) & empty_rows(*ui)] = PENUMBRA
        st[empty_rows(*li)] = CLEAR
        st[empty_rows(*uout)] = DARK
        return st

    # ---- thick algebra (Eq. 5.8–5.17, 5.23–5.25) on the bound separators ----
    def __and__(self, other: ThickSep) -> ThickSep:
        """Extension intersection ``[X⁻ ∩ Y⁻, X⁺ ∩ Y⁺]`` (Eq. 5.8, 5.16, 5.23)."""
        return ThickSep(SepInter(self.lower, other.lower), SepInter(self.upper, other.upper))

    def __or__(self, other: ThickSep) -> ThickSep:
        """Extension union ``[X⁻ ∪ Y⁻, X⁺ ∪ Y⁺]`` (Eq. 5.9, 5.17)."""
        return ThickSep(SepUnion(self.lower, other.lower), SepUnion(self.upper, other.upper))

    def __invert__(self) -> ThickSep:
        """Complement ``[comp(X⁺), comp(X⁻)]`` (Eq. 5.7 with the anti-monotone complement)."""
        return ThickSep(SepNot(self.upper), SepNot(self.lower))

    def __sub__(self, other: ThickSep) -> ThickSep:
        """Restriction ``[A⁻ \\ B⁺, A⁺ \\ B⁻]`` (Eq. 5.11)."""
        return ThickSep(SepInter(self.lower, SepNot(other.upper)), SepInter(self.upper, SepNot(other.lower)))

    def meet(self, other: ThickSep) -> ThickSep:
        """Lattice intersection ``[X] ⊓ [Y] = [X⁻ ∪ Y⁻, X⁺ ∩ Y⁺]`` (Eq. 5.3, 5.16)."""
        return ThickSep(SepUnion(self.lower, other.lower), SepInter(self.upper, other.upper))

    def join(self, other: ThickSep) -> ThickSep:
        """Lattice hull ``[X] ⊔ [Y] = [X⁻ ∩ Y⁻, X⁺ ∪ Y⁺]`` (Eq. 5.3, 5.17)."""
        return ThickSep(SepInter(self.lower, other.lower), SepUnion(self.upper, other.upper))


def _inter(a: Batch, b: Batch) -> Batch:
    return np.maximum(a[0], b[0]), np.minimum(a[1], b[1])


def thick_relaxed_intersection(seps: list[ThickSep], q: int) -> ThickSep:
    """q-relaxed intersection ``[∩^{q} X_i⁻, ∩^{q} X_i⁺]`` (monotone, so Eq. 5.7 acts on bounds)."""
    if not seps or not 0 <= q < len(seps):
        raise ValueError(f"thick_relaxed_intersection: need 0 <= q < {len(seps)}, got q={q}")
    return ThickSep(SepQInter([s.lower for s in seps], q), SepQInter([s.upper for s in seps], q))


def thick_classify_grid(x0: Any, tsep: ThickSep, shape: tuple[int, int]) -> np.ndarray:
    """Classify the cells of an ``(ny, nx)`` grid over a 2-d box into clear/penumbra/dark.

    Same cell layout as :func:`observer.regular.classify_grid` (row 0 is the top, largest ``y``).

    Returns:
        ``int8 (ny, nx)``: ``1`` clear, ``2`` penumbra, ``-1`` dark, ``0`` unknown.
    """
    lo0, hi0 = x0.pair if hasattr(x0, "pair") else x0
    lo0, hi0 = np.asarray(lo0, dtype=np.float64), np.asarray(hi0, dtype=np.float64)
    ny, nx = shape
    if lo0.shape != (2,) or nx < 1 or ny < 1:
        raise ValueError(f"thick_classify_grid: need a 2-d box and a positive shape, got {lo0.shape} {shape}")
    xs, ys = np.linspace(lo0[0], hi0[0], nx + 1), np.linspace(hi0[1], lo0[1], ny + 1)
    gx, gy = np.meshgrid(np.arange(nx), np.arange(ny))
    lo = np.stack([xs[gx.ravel()], ys[gy.ravel() + 1]], axis=1)
    hi = np.stack([xs[gx.ravel() + 1], ys[gy.ravel()]], axis=1)
    return tsep.classify(lo, hi).reshape(ny, nx)


__all__ = ["ThickSep", "thick_classify_grid",
           "thick_relaxed_intersection"]  # fmt: skip
