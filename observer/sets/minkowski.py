"""Minkowski difference and sum separators (thesis §4.3, Def. 4.3–4.4, Prop. 4.1–4.2).

* Difference (Eq. 4.27–4.29): ``B ⊖ A = {p | A + p ⊂ B}`` is the registration of ``A`` into ``B`` by
  the translation ``f(a, p) = a + p``: ``S_B ⊖ S_A = ~proj_p{(S_A × S_Rⁿ) ∩ f⁻¹(~S_B)}`` (Eq. 4.28).
* Sum (Eq. 4.30–4.32): ``A ⊕ B = ~(~B ⊖ -A)``, so ``S_A ⊕ S_B = ~(~S_B ⊖ -S_A)`` (Eq. 4.31), where
  ``-S_A`` is the separator of ``-A`` (``S_A`` inverted through ``x ↦ -x``, Theorem 2.1).

``A`` (the shape projected out) must lie in the bounded box ``a_box``; ``B`` may be unbounded.

>>> from digslam.observer import Box, SepBox
>>> d = SepMinkowskiDiff(SepBox(Box([(0, 3)])), SepBox(Box([(-0.5, 0.5)])), [(-0.5, 0.5)], eps=0.05)
>>> (ilo, ihi), (olo, ohi) = d.separate(np.array([[1.0], [2.8]]), np.array([[2.0], [3.5]]))
>>> bool(ilo[0, 0] > ihi[0, 0]), bool(olo[1, 0] > ohi[1, 0])   # [0,3] ⊖ [-½,½] = [½, 2.5]
(True, True)
>>> s = SepMinkowskiSum(SepBox(Box([(-0.5, 0.5)])), SepBox(Box([(0, 3)])), [(-0.5, 0.5)], eps=0.05)
>>> (ilo, ihi), (olo, ohi) = s.separate(np.array([[-0.4], [3.6]]), np.array([[3.4], [4.0]]))
>>> bool(ilo[0, 0] > ihi[0, 0]), bool(olo[1, 0] > ohi[1, 0])   # [-½,½] ⊕ [0,3] = [-½, 3.5]
(True, True)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core.types import Batch
from digslam.observer.expr.expr import Function
from digslam.observer.sets.projection import bounded_box
from digslam.observer.sets.registration import SepRegistration, translation
from digslam.observer.sets.sep_inverse import SepInverse
from digslam.observer.sets.separators import Sep, SepNot

__all__ = ["SepMinkowskiDiff", "SepMinkowskiSum", "sep_negate"]


def sep_negate(sep: Sep, n: int | None = None) -> Sep:
    """Separator of ``-X = {-x | x ∈ X}`` from one of ``X`` (``SepInverse`` of ``x ↦ -x``, exact).

    Raises:
        ValueError: when the dimension is unknown (``sep.n`` is None and no ``n``) or inconsistent.
    """
    n = sep.n if n is None else n
    if n is None or n < 1 or (sep.n is not None and sep.n != n):
        raise ValueError(f"n: need the dimension of the separator (got n={n}, sep.n={sep.n})")
    return SepInverse(Function(lambda x: tuple(-x[i] for i in range(n)), n=n), sep)


class SepMinkowskiDiff(Sep):
    """``S_B ⊖ S_A``, a separator of ``B ⊖ A = {p | A + p ⊂ B}`` (Prop. 4.1, Eq. 4.28).

    Args:
        sep_b: separator of ``B ⊂ Rⁿ``.
        sep_a: separator of ``A ⊂ Rⁿ``.
        a_box: a bounded box containing ``A`` (``n`` intervals).
        eps: splitting width of ``a_box`` in the projection (:class:`~.projection.SepProj`).
        **proj_kw: ``max_splits``, ``max_pairs`` of :class:`~.projection.SepProj`.

    Raises:
        ValueError: on mismatched dimensions.
    """

    def __init__(self, sep_b: Sep, sep_a: Sep, a_box: Any, eps: float, **proj_kw: Any) -> None:
        n = bounded_box(a_box, "a_box")[0].size
        if sep_b.n is not None and sep_b.n != n:
            raise ValueError(f"sep_b: dimension {sep_b.n}, but a_box has dimension {n}")
        self.reg = SepRegistration(sep_a, sep_b, translation(n), a_box, eps, "inclusion", **proj_kw)
        self.n = n

    @property
    def proj(self) -> Any:
        """The underlying :class:`~.projection.SepProj` (work counters)."""
        return self.reg.proj

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        return self.reg.separate(lo, hi)


class SepMinkowskiSum(Sep):
    """``S_A ⊕ S_B = ~(~S_B ⊖ -S_A)``, a separator of ``A ⊕ B = {a + b}`` (Prop. 4.2, Eq. 4.31).

    Args:
        sep_a: separator of ``A ⊂ Rⁿ`` (projected out: it must be bounded).
        sep_b: separator of ``B ⊂ Rⁿ``.
        a_box: a bounded box containing ``A``.
        eps, proj_kw: see :class:`SepMinkowskiDiff`.

    Raises:
        ValueError: on mismatched dimensions.
    """

    def __init__(self, sep_a: Sep, sep_b: Sep, a_box: Any, eps: float, **proj_kw: Any) -> None:
        alo, ahi = bounded_box(a_box, "a_box")
        n = alo.size
        if sep_a.n is not None and sep_a.n != n:
            raise ValueError(f"sep_a: dimension {sep_a.n}, but a_box has dimension {n}")
        neg_box = np.stack([-ahi, -alo], axis=1)  # the box of -A
        self.diff = SepMinkowskiDiff(SepNot(sep_b), sep_negate(sep_a, n), neg_box, eps, **proj_kw)
        self.n = n

    @property
    def proj(self) -> Any:
        """The underlying :class:`~.projection.SepProj` (work counters)."""
        return self.diff.proj

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        xin, xout = self.diff.separate(lo, hi)
        return xout, xin
