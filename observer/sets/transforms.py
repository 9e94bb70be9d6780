"""Images of contractors and separators by bijections, and unions of symmetries (thesis §3.2.1).

``f(C) = f ∘ C ∘ f⁻¹`` (Eq. 3.6) and ``f(S) = {f ∘ S_in ∘ f⁻¹, f ∘ S_out ∘ f⁻¹}`` (Eq. 3.10) for a
bijection ``f: Rⁿ → Rⁿ`` given with its inverse. With outward inclusion functions the result is sound
for every bijection; it is minimal when ``f`` is box-conservative and ``C``/``S`` is (Prop. 3.3,
Corollary 2): coordinate permutations, reflections, monotone maps of each coordinate, rotations by
``kπ/2``. ``symmetric_union`` builds ``(I ⊔ f¹ ⊔ … ⊔ fᵏ)(S)`` for ``X ∪ f(X) ∪ …`` (Eq. 3.7, Cor. 1).

>>> quarter = Transform(Function(lambda x: (-x[1], x[0])), Function(lambda y: (y[1], -y[0])))  # rotation π/2
>>> s = symmetric_union(SepBox(Box([(1, 2), (-0.5, 0.5)])), quarter, 3)     # four arms of a cross
>>> xin, xout = s(Box([(-0.2, 0.2), (1.2, 1.8)]))                          # the upper arm
>>> bool(xin.is_empty().all())
True

Beware: ``f`` must be a bijection of the whole space with ``f⁻¹`` its exact inverse everywhere. A map
such as ``(√(3 - x₂), x₁)`` is a bijection only between half-planes; outside them the result is wrong.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core.boxes import normalize_empty
from digslam.observer.core.types import Batch
from digslam.observer.expr.expr import Function
from digslam.observer.sets.contractors import Ctc
from digslam.observer.sets.separators import Sep, SepUnion, inter_batch


class Transform:
    """A bijection ``f: Rⁿ → Rⁿ`` with its inverse, both as :class:`~.expr.Function`.

    Raises:
        ValueError: if either function is not ``Rⁿ → Rⁿ`` for the same ``n``.
    """

    def __init__(self, f: Function | Any, f_inv: Function | Any) -> None:
        self.f = f if isinstance(f, Function) else Function(f)
        self.f_inv = f_inv if isinstance(f_inv, Function) else Function(f_inv)
        for name, g in (("f", self.f), ("f_inv", self.f_inv)):
            if g.n != g.m:
                raise ValueError(f"{name}: a bijection maps Rⁿ to Rⁿ, got R^{g.n} -> R^{g.m}")
        if self.f.n != self.f_inv.n:
            raise ValueError(f"f_inv: dimension {self.f_inv.n} differs from f's {self.f.n}")
        self.n = self.f.n

    def image(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        """``[f]([x])`` on a batch (empty rows stay empty)."""
        return _eval(self.f, lo, hi)

    def preimage(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        """``[f⁻¹]([x])`` on a batch."""
        return _eval(self.f_inv, lo, hi)

    def inverse(self) -> Transform:
        return Transform(self.f_inv, self.f)

    def power(self, k: int) -> list[Transform]:
        """``[f¹, …, fᵏ]`` as chains of this transform."""
        return [_Chain(self, j) for j in range(1, k + 1)]


def _eval(f: Function, lo: np.ndarray, hi: np.ndarray) -> Batch:
    r = f.eval((lo, hi))
    rlo, rhi = r.lo, r.hi
    if rlo.ndim == 1:
        rlo, rhi = rlo[:, None], rhi[:, None]
    return normalize_empty(rlo, rhi)


class _Chain(Transform):
    """``fᵏ`` applied as ``k`` successive evaluations (no symbolic composition)."""

    def __init__(self, base: Transform, k: int) -> None:
        self.f, self.f_inv, self.n, self.base, self.k = base.f, base.f_inv, base.n, base, k

    def image(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        for _ in range(self.k):
            lo, hi = self.base.image(lo, hi)
        return lo, hi

    def preimage(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        for _ in range(self.k):
            lo, hi = self.base.preimage(lo, hi)
        return lo, hi


class CtcTransform(Ctc):
    """``f(C) = f ∘ C ∘ f⁻¹`` (Def. 3.2, Eq. 3.6), intersected with the input box."""

    def __init__(self, ctc: Ctc, t: Transform) -> None:
        if ctc.n is not None and ctc.n != t.n:
            raise ValueError(f"t: transform of dimension {t.n} for a contractor of dimension {ctc.n}")
        self.ctc, self.t, self.n = ctc, t, t.n

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        y = self.t.preimage(lo, hi)
        return inter_batch(self.t.image(*normalize_empty(*self.ctc.contract(*y))), (lo, hi))


class SepTransform(Sep):
    """``f(S) = {f ∘ S_in ∘ f⁻¹, f ∘ S_out ∘ f⁻¹}`` (Corollary 2, Eq. 3.10): a separator of ``f(X)``."""

    def __init__(self, sep: Sep, t: Transform) -> None:
        if sep.n is not None and sep.n != t.n:
            raise ValueError(f"t: transform of dimension {t.n} for a separator of dimension {sep.n}")
        self.sep, self.t, self.n = sep, t, t.n

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        yin, yout = self.sep.separate(*self.t.preimage(lo, hi))
        xin = inter_batch(self.t.image(*normalize_empty(*yin)), (lo, hi))
        xout = inter_batch(self.t.image(*normalize_empty(*yout)), (lo, hi))
        return xin, xout


def symmetric_union(sep: Sep, t: Transform, k: int) -> Sep:
    """Separator of ``X ∪ f(X) ∪ … ∪ fᵏ(X)`` (Eq. 3.7, Corollary 1 for separators)."""
    if k < 0:
        raise ValueError(f"k: number of powers must be >= 0, got {k}")
    return SepUnion(sep, *(SepTransform(sep, p) for p in t.power(k))) if k else sep


__all__ = [
    "CtcTransform",
    "SepTransform",
    "Transform",
    "symmetric_union",
]
