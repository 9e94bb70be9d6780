"""Images, Cartesian products and Minkowski sums of thick sets (thesis §5.2.3, Eq. 5.10, 5.12, 5.13).

Each operation is monotone for ``⊂``, so it acts on the two bounds of ``[X] = [X⁻, X⁺]`` (Eq. 5.7) and
the result is a :class:`~.sep.ThickSep` built on the classical separators of the bounds:

* image by a bijection ``f``: ``f([A]) = [f(A⁻), f(A⁺)]`` (Eq. 5.13) with :class:`~.transforms.SepTransform`;
* image by a bijection ``f_p`` with an uncertain ``p ∈ [p]``: ``[∩_p f_p(A⁻), ∪_p f_p(A⁺)]``, the
  inversion by ``f_p⁻¹`` of §5.4.3 (Eq. 5.40–5.41) with projections;
* Cartesian product ``[A] × [B] = [A⁻ × B⁻, A⁺ × B⁺]`` (Eq. 5.10): cylinders (``SepOnDims``);
* Minkowski sum ``[A] ⊕ [B] = [A⁻ ⊕ B⁻, A⁺ ⊕ B⁺]`` (Eq. 5.12) with :class:`~.minkowski.SepMinkowskiSum`.

>>> from digslam.observer import Box, SepBox
>>> a = ThickSep(SepBox(Box([(0, 1)])), SepBox(Box([(0, 2)])))
>>> b = ThickSep(SepBox(Box([(5, 6)])), SepBox(Box([(4, 6)])))
>>> ab = thick_product(a, b)            # [[0,1]×[5,6], [0,2]×[4,6]]
>>> lo, hi = np.array([[0.2, 5.2], [1.5, 4.5], [3.0, 5.0]]), np.array([[0.8, 5.8], [1.9, 4.9], [4.0, 6.0]])
>>> ab.classify(lo, hi).tolist()
[1, 2, -1]
>>> s = thick_minkowski_sum(a, b, [(0, 2)], eps=0.05)   # [[5, 7], [4, 8]]
>>> s.classify(np.array([[5.2], [4.2], [8.5]]), np.array([[6.8], [4.8], [9.0]])).tolist()
[1, 2, -1]
"""

from __future__ import annotations

from typing import Any

from digslam.observer.sets.minkowski import SepMinkowskiSum
from digslam.observer.sets.projection import SepOnDims, bounded_box
from digslam.observer.sets.registration import Transformation, transform_function
from digslam.observer.sets.separators import Sep, SepInter
from digslam.observer.sets.transforms import SepTransform, Transform
from digslam.observer.thick.inversion import thick_inverse_proj
from digslam.observer.thick.sep import ThickSep

__all__ = ["thick_image", "thick_image_param", "thick_minkowski_sum", "thick_product"]


def _check(ts: Any, name: str) -> ThickSep:
    if not isinstance(ts, ThickSep):
        raise TypeError(f"{name}: expected a ThickSep, got {type(ts).__name__}")
    return ts


def thick_image(a: ThickSep, t: Transform) -> ThickSep:
    """``f([A]) = [f(A⁻), f(A⁺)]`` for a bijection ``f`` given with its inverse (Eq. 5.13).

    The bound separators are ``f(S) = {f ∘ S_in ∘ f⁻¹, f ∘ S_out ∘ f⁻¹}`` (Eq. 3.10): sound for every
    bijection, minimal when ``f`` is box-conservative (Prop. 3.3).

    Raises:
        TypeError: if ``a`` is not a ThickSep or ``t`` not a :class:`~.transforms.Transform`.
        ValueError: on a dimension mismatch.
    """
    _check(a, "a")
    if not isinstance(t, Transform):
        raise TypeError(f"t: expected a Transform (a bijection with its inverse), got {type(t).__name__}")
    return ThickSep(SepTransform(a.lower, t), SepTransform(a.upper, t))


def thick_image_param(a: ThickSep, f_inv: Transformation, p_box: Any, *, n: int, eps: float,
                      q: int | None = None) -> ThickSep:  # fmt: skip
    """``f_[p]([A]) = [∩_{p∈[p]} f_p(A⁻), ∪_{p∈[p]} f_p(A⁺)]`` for bijections ``f_p`` (Eq. 5.13, 5.40–5.41).

    With ``g_p = f_p⁻¹``, ``f_p(A) = g_p⁻¹(A)``: the bounds are the uncertain inversion of ``[A]`` by
    ``g`` (:func:`~.inversion.thick_inverse_proj`), projections over ``[p]``.

    Args:
        a: the thick set ``[A]`` (on ``Rⁿ``).
        f_inv: the inverse ``g(y, p) = f_p⁻¹(y)``: a callable ``g(y, p)`` on sequences of expressions (with
            ``q`` given or ``g.q``), or a :class:`~.expr.Function` of ``z = (y, p)``.
        p_box: the parameter box ``[p]`` (``q`` bounded intervals).
        n: the dimension of the space.
        eps: parameter splitting width of the projections.

    Raises:
        ValueError: on a bad parameter box or a transform of the wrong dimension.
    """
    _check(a, "a")
    plo, _ = bounded_box(p_box, "p_box")
    q = plo.size if q is None else q
    if plo.size != q:
        raise ValueError(f"p_box: {plo.size} intervals for a parameter of dimension {q}")
    g = transform_function(f_inv, n, q, n)
    return thick_inverse_proj(g, a.lower, a.upper, p_box, n=n, eps=eps)


def _dim(s: Sep, n: int | None, name: str) -> int:
    d = s.n if n is None else n
    if d is None or d < 1 or (s.n is not None and s.n != d):
        raise ValueError(f"{name}: dimension unknown or inconsistent (given {n}, separator has {s.n})")
    return int(d)


def thick_product(a: ThickSep, b: ThickSep, n_a: int | None = None, n_b: int | None = None) -> ThickSep:
    """Cartesian product ``[A] × [B] = [A⁻ × B⁻, A⁺ × B⁺]`` on ``R^(n_a + n_b)`` (Eq. 5.10).

    ``X × Y = (X × R^{n_b}) ∩ (R^{n_a} × Y)``: each bound is the intersection of two cylinders.

    Args:
        a, b: the thick sets; ``n_a``, ``n_b`` their dimensions when their separators do not know them.

    Raises:
        TypeError: if ``a`` or ``b`` is not a ThickSep.
        ValueError: when a dimension is unknown or inconsistent.
    """
    _check(a, "a"), _check(b, "b")
    na, nb = _dim(a.upper, n_a, "n_a"), _dim(b.upper, n_b, "n_b")
    n = na + nb

    def prod(x: Sep, y: Sep) -> Sep:
        return SepInter(SepOnDims(x, range(na), n), SepOnDims(y, range(na, n), n))

    return ThickSep(prod(a.lower, b.lower), prod(a.upper, b.upper))


def thick_minkowski_sum(a: ThickSep, b: ThickSep, a_box: Any, eps: float, **proj_kw: Any) -> ThickSep:
    """Minkowski sum ``[A] ⊕ [B] = [A⁻ ⊕ B⁻, A⁺ ⊕ B⁺]`` (Eq. 5.5, 5.12).

    Args:
        a, b: the thick sets (same dimension ``n``).
        a_box: a bounded box containing ``A⁺`` (hence ``A⁻``): the projections run over it.
        eps: splitting width of ``a_box`` (:class:`~.projection.SepProj`).
        **proj_kw: ``max_splits``, ``max_pairs``, ``presplit`` of the projections.

    Raises:
        TypeError: if ``a`` or ``b`` is not a ThickSep.
        ValueError: on mismatched dimensions or a bad ``a_box``.
    """
    _check(a, "a"), _check(b, "b")
    return ThickSep(SepMinkowskiSum(a.lower, b.lower, a_box, eps, **proj_kw),
                    SepMinkowskiSum(a.upper, b.upper, a_box, eps, **proj_kw))  # fmt: skip
