"""Shape registration as a projection (thesis §4.2.2, Eq. 4.11–4.20).

Given shapes ``A ⊂ Rⁿ``, ``B ⊂ Rᵐ`` with separators ``S_A``, ``S_B`` and a transform
``f: Rⁿ × R^q → Rᵐ, (a, p) ↦ f(a, p)`` (Eq. 4.11), the parameters that map ``A`` into ``B`` are

``P_⊂ = {p | f(A, p) ⊂ B} = ~proj_p{(A × R^q) ∩ f⁻¹(~B)}`` (Eq. 4.13–4.15), with the separator
``S_P = ~proj_p{(S_A × S_{R^q}) ∩ f⁻¹(~S_B)}`` (Eq. 4.16), and those for which ``f(A, p)`` meets ``B``

``P_≠ = {p | f(A, p) ∩ B ≠ ∅} = proj_p{(A × R^q) ∩ f⁻¹(B)}`` (Remark 4.1, Eq. 4.19–4.20: the
complement of ``P_= = {p | f(A, p) ⊂ ~B}``).

The projection runs over ``a`` in a bounded box ``a_box`` that must contain ``A`` (the projection
only sees ``a ∈ a_box``). ``f`` is traced on ``z = (a₁..aₙ, p₁..p_q)``; ready-made transforms are
:func:`translation`, :func:`rigid2d` and :func:`scaling`.

>>> from digslam.observer import Box, SepBox
>>> inside = SepRegistration(SepBox(Box([(0, 1)])), SepBox(Box([(0, 3)])), translation(1), [(0, 1)], 0.05)
>>> (ilo, ihi), (olo, ohi) = inside.separate(np.array([[0.5], [2.5]]), np.array([[1.5], [3.0]]))
>>> bool(ilo[0, 0] > ihi[0, 0]), bool(olo[1, 0] > ohi[1, 0])   # [0,1] + p ⊂ [0,3] iff p ∈ [0, 2]
(True, True)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, TypeAlias

import numpy as np

from digslam.observer.core.interval import IntervalArray
from digslam.observer.core.types import Batch
from digslam.observer.expr.expr import Expr, Function
from digslam.observer.sets.projection import SepOnDims, SepProj, bounded_box
from digslam.observer.sets.sep_inverse import SepInverse
from digslam.observer.sets.separators import Sep, SepInter, SepNot

__all__ = [
    "ParamTransform", "Transformation", "SepRegistration", "sep_inclusion", "sep_intersection", "sep_cone",
    "translation", "rigid2d", "scaling", "transform_function",
]  # fmt: skip

#: a parametric transformation ``f(a, p)`` on expressions: the point ``a`` moved by the parameter ``p``
ParamTransform = Callable[[Sequence[Expr], Sequence[Expr]], Any]
#: what the registration separators take as ``f``: a :data:`ParamTransform` (with ``q`` given, or
#: ``f.q``) or a :class:`~digslam.observer.expr.expr.Function` of ``z = (a, p)``
Transformation: TypeAlias = ParamTransform | Function


def translation(n: int) -> ParamTransform:
    """``f(a, p) = a + p`` on ``Rⁿ`` (the Minkowski case, Prop. 4.1): ``q = n``."""
    if n < 1:
        raise ValueError(f"n: dimension must be >= 1, got {n}")

    def f(a: Sequence[Expr], p: Sequence[Expr]) -> tuple[Expr, ...]:
        return tuple(a[i] + p[i] for i in range(n))

    f.q = n  # type: ignore[attr-defined]  # the parameter count rides on f (transform_function reads f.q)
    return f


def rigid2d() -> ParamTransform:
    """``f(a, (x, y, θ)) = R(θ) a + (x, y)``: rotation then translation in the plane (``q = 3``)."""
    from digslam.observer.expr.ops import cos, sin

    def f(a: Sequence[Expr], p: Sequence[Expr]) -> tuple[Expr, ...]:
        c, s = cos(p[2]), sin(p[2])
        return (a[0] * c - a[1] * s + p[0], a[0] * s + a[1] * c + p[1])

    f.q = 3  # type: ignore[attr-defined]  # as in translation
    return f


def scaling() -> ParamTransform:
    """``f(a, d) = d · a`` (the sonar simulation of §4.2.3, Eq. 4.22): ``q = 1``, any ``n``."""

    def f(a: Sequence[Expr], p: Sequence[Expr]) -> tuple[Expr, ...]:
        return tuple(p[0] * ai for ai in a)

    f.q = 1  # type: ignore[attr-defined]  # as in translation
    return f


def transform_function(f: Transformation, n: int, q: int, m: int | None) -> Function:
    """``f`` as a :class:`Function` of ``z = (a, p) ∈ R^(n+q)``, checked to have ``m`` outputs.

    Args:
        f: a :class:`Function` of ``n + q`` variables, or a callable ``f(a, p)`` taking the sequences
            ``a`` (``n`` expressions) and ``p`` (``q`` expressions) and returning ``m`` expressions.
        n, q: the dimensions of ``A`` and of the parameter.
        m: the dimension of ``B`` (None: unchecked).

    Raises:
        ValueError: when ``f`` does not map ``R^(n+q)`` to ``R^m`` (a transform of the wrong dimension).
    """
    if isinstance(f, Function):
        fn = f
    else:
        if not callable(f):
            raise ValueError(f"f: expected a Function or a callable f(a, p), got {type(f).__name__}")

        def fz(z: Any) -> Any:
            return f([z[i] for i in range(n)], [z[n + i] for i in range(q)])

        try:
            fn = Function(fz, n=n + q)
        except (IndexError, ValueError) as e:
            raise ValueError(f"f: cannot trace the transform on a ∈ R^{n}, p ∈ R^{q}: {e}") from e
    if fn.n != n + q:
        raise ValueError(f"f: the transform takes {fn.n} variables, expected n + q = {n} + {q}")
    if m is not None and fn.m != m:
        raise ValueError(f"f: the transform has {fn.m} outputs but B has dimension {m}")
    return fn


class SepRegistration(Sep):
    """Separator of ``{p | f(A, p) ⊂ B}`` (Eq. 4.16) or of ``{p | f(A, p) ∩ B ≠ ∅}`` (Eq. 4.19–4.20).

    Args:
        sep_a: separator of ``A ⊂ Rⁿ`` (the shape being moved).
        sep_b: separator of ``B ⊂ Rᵐ``.
        f: the transform, see :func:`transform_function`; a callable may carry its parameter dimension
            as ``f.q`` (the ready-made ones do), otherwise pass ``q``.
        a_box: a bounded box containing ``A`` (``n`` intervals), the domain of the projection.
        eps: width under which the splits of ``a_box`` are not bisected (:class:`SepProj`).
        mode: ``"inclusion"`` for ``P_⊂`` or ``"intersection"`` for ``P_≠``.
        q: the parameter dimension (default ``f.q``, or the dimension left by a :class:`Function`).
        **proj_kw: ``max_splits``, ``max_pairs`` of :class:`SepProj`.

    Raises:
        ValueError: on a transform or box of the wrong dimension, or an unknown ``mode``.

    Attributes:
        proj: the underlying :class:`SepProj` (its ``calls`` and ``pairs`` count the work done).
    """

    def __init__(
        self,
        sep_a: Sep,
        sep_b: Sep,
        f: Transformation,
        a_box: Any,
        eps: float,
        mode: str = "inclusion",
        q: int | None = None,
        **proj_kw: Any,
    ) -> None:
        if mode not in ("inclusion", "intersection"):
            raise ValueError(f"mode: expected 'inclusion' or 'intersection', got {mode!r}")
        alo, ahi = bounded_box(a_box, "a_box")
        n = alo.size
        if sep_a.n is not None and sep_a.n != n:
            raise ValueError(f"a_box: dimension {n}, but sep_a has dimension {sep_a.n}")
        if q is None:
            q = getattr(f, "q", None)
            if q is None and isinstance(f, Function):
                q = f.n - n
            if q is None:
                raise ValueError("q: the parameter dimension is unknown: pass q= or give f a q attribute")
        if q < 1:
            raise ValueError(f"q: the parameter dimension must be >= 1, got {q}")
        self.f = transform_function(f, n, int(q), sep_b.n)
        self.mode, self.n, self.dim_a = mode, int(q), n
        target = SepNot(sep_b) if mode == "inclusion" else sep_b
        z = SepInter(SepOnDims(sep_a, range(n), n + q), SepInverse(self.f, target))  # (S_A × S_Rq) ∩ f⁻¹(·)
        self.proj = SepProj(z, range(n, n + q), IntervalArray._raw(alo, ahi), eps, **proj_kw)
        self.sep: Sep = SepNot(self.proj) if mode == "inclusion" else self.proj

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        return self.sep.separate(lo, hi)


def sep_inclusion(sep_a: Sep, sep_b: Sep, f: Transformation, a_box: Any, eps: float, **kw: Any) -> Sep:
    """Separator of ``{p | f(A, p) ⊂ B}`` (Eq. 4.13, 4.16); see :class:`SepRegistration`."""
    return SepRegistration(sep_a, sep_b, f, a_box, eps, mode="inclusion", **kw)


def sep_intersection(sep_a: Sep, sep_b: Sep, f: Transformation, a_box: Any, eps: float, **kw: Any) -> Sep:
    """Separator of ``{p | f(A, p) ∩ B ≠ ∅}`` (Eq. 4.19–4.20); see :class:`SepRegistration`."""
    return SepRegistration(sep_a, sep_b, f, a_box, eps, mode="intersection", **kw)


def sep_cone(r: Any, direction: Any, half_aperture: Any) -> Sep:
    """Separator of the pie ``{a ∈ R² | |a| ∈ [r], atan2(a₂, a₁) ∈ [α - γ, α + γ]}`` (Eq. 4.23, 4.33).

    A forward-backward separator (Theorem 2.1): the intersection of a ring ``|a|² ∈ [r]²`` with the two
    half-planes bounding the sector, whose normals ``(cos, sin)`` of the exact angles are enclosed by
    outward-rounded intervals. It is sound for the exact pie, not minimal (the polar separators of
    Ch. 3 are). ``r`` with a zero lower bound gives the full sector (a free sector ``S_i``).

    Args:
        r: range interval ``[r⁻, r⁺]`` (a pair or an Interval), ``0 <= r⁻ <= r⁺ < ∞``.
        direction: ``α`` (a float, or an Interval enclosing an exact angle such as ``π/4``).
        half_aperture: ``γ`` (float or Interval), ``0 < γ < π/2``.

    Raises:
        ValueError: on a negative or empty range, or an aperture ``2γ`` not in ``(0, π)``.
    """
    from digslam.observer.core import arith, trig
    from digslam.observer.core import rounding as rnd
    from digslam.observer.core.interval import Interval

    def pair(v: Any, name: str) -> tuple[float, float]:
        if isinstance(v, IntervalArray):
            return float(v.lo), float(v.hi)
        a = np.atleast_1d(np.asarray(v, dtype=np.float64)).ravel()
        if a.size not in (1, 2) or np.isnan(a).any():
            raise ValueError(f"{name}: expected a number or an interval, got {v!r}")
        return float(a[0]), float(a[-1])

    rlo, rhi = pair(r, "r")
    if not (0 <= rlo <= rhi < np.inf):
        raise ValueError(f"r: range interval must satisfy 0 <= r⁻ <= r⁺ < inf, got [{rlo}, {rhi}]")
    alo, ahi = pair(direction, "direction")
    glo, ghi = pair(half_aperture, "half_aperture")
    if not (0 < glo <= ghi < rnd.HALF_PI_DOWN) or not (np.isfinite(alo) and np.isfinite(ahi) and alo <= ahi):
        raise ValueError(f"half_aperture: the cone aperture 2γ must lie in (0, π), got γ ∈ [{glo}, {ghi}]")
    one = (np.array([alo]), np.array([ahi]))
    gam = (np.array([glo]), np.array([ghi]))
    lo_ang, hi_ang = arith.sub(one, gam), arith.add(one, gam)  # α - γ, α + γ enclosed

    def cs(t: tuple[np.ndarray, np.ndarray]) -> tuple[Any, Any]:
        c, s = trig.cos(t), trig.sin(t)
        return Interval(c[0][0], c[1][0]), Interval(s[0][0], s[1][0])

    c1, s1 = cs(lo_ang)
    c2, s2 = cs(hi_ang)
    r2lo = -np.inf if rlo == 0 else float(rnd.mul_down(np.float64(rlo), np.float64(rlo)))
    r2hi = float(rnd.mul_up(np.float64(rhi), np.float64(rhi)))
    ring = SepInverse(Function(lambda a: a[0] ** 2 + a[1] ** 2), Interval(r2lo, r2hi))
    # left of the ray α - γ and right of the ray α + γ (2γ < π)
    wedge = SepInverse(Function(lambda a: (a[1] * c1 - a[0] * s1, a[0] * s2 - a[1] * c2)),
                       IntervalArray([0.0, 0.0], [np.inf, np.inf]))  # fmt: skip
    return SepInter(ring, wedge)
