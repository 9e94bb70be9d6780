"""Thick inclusion functions (thesis App. A, Theorem A.1).

For bound functions ``f⁻ ≤ f⁺`` the thick function ``⟦f⟧(x) = ⟦f⁻(x), f⁺(x)⟧`` has the thick inclusion
``⟦f⟧([x]) = ⟦[f⁻]([x]), [f⁺]([x])⟧`` (Theorem A.1). :meth:`ThickFunction.from_parametric` builds it
from ``f(x, p)``, ``p ∈ [p]``: ``f⁻(x) = min_p f(x, p)``, ``f⁺(x) = max_p f(x, p)``, enclosed with
``[f]([x], [p])`` and ``[f]([x], mid [p])``. Two closed forms give the exact ranges of the bounds:
:meth:`ThickFunction.linear` (``[A] x``, Eq. A.40) and :meth:`ThickFunction.sqdist`
(``‖x − m‖²``, ``m ∈ [m]``: the thick disk of test-case 1 and the marks of Eq. A.49).

Example:
    >>> import numpy as np
    >>> from digslam.observer import Function
    >>> tf = ThickFunction(Function(lambda x: x[0] - 1), Function(lambda x: x[0] + 1))
    >>> a = tf.eval(np.array([[0.0]]), np.array([[1.0]]))
    >>> b = tf.eval(np.array([[0.0]]), np.array([[0.0]]))
    >>> (a & b).as_tuple()
    ((-1.0, 0.0), (1.0, 1.0))
    >>> d = ThickFunction.sqdist([[0.0, 0.0]], [[1.0, 1.0]])  # ‖x − m‖², m ∈ [0,1]²
    >>> d.eval(np.array([[2.0, 0.0]]), np.array([[3.0, 0.0]])).as_tuple()  # f⁻ ∈ [1,4], f⁺ ∈ [5,10]
    ((1.0, 4.0), (5.0, 10.0))
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from digslam.observer.core import arith
from digslam.observer.core import rounding as rnd
from digslam.observer.core.boxes import validate_batch
from digslam.observer.expr.expr import Function
from digslam.observer.thick.interval import ThickIntervalArray


class ThickFunction:
    """Thick inclusion function ``⟦f⟧`` (Theorem A.1).

    Args:
        f_minus: lower bound function ``f⁻`` (a :class:`Function`, ``n`` inputs).
        f_plus: upper bound function ``f⁺`` (same input dimension).

    Attributes:
        n: input dimension.
        approx: ``None``, or a fast evaluator ``(lo, hi) -> ((lb f⁻, ub f⁻, lb f⁺, ub f⁺), k)``, four
            ``(N, m)`` arrays computed in round-to-nearest
            for a thick function with values ``≥ 0``. Its bounds ``A`` approximate the exact range bounds
            ``e ≥ 0`` with ``A ≤ e·(1+u)ᵏ + η`` for the lower ends ``lb[f⁻]``, ``lb[f⁺]`` and
            ``A ≥ e·(1−u)ᵏ − η`` for the upper ends ``ub[f⁻]``, ``ub[f⁺]`` (``u = 2⁻⁵³``, ``η = 2⁻¹⁰⁷⁰``;
            ``+inf`` only where ``e`` exceeds the largest float). :class:`~.sivia.ThickInverse`
            then moves the thresholds of ``Y`` once instead of rounding every bound (a forward error
            bound, Higham, *Accuracy and Stability of Numerical Algorithms*, §3.1).
    """

    def __init__(
        self, f_minus: Function | None, f_plus: Function | None, *, _evaluator: Callable | None = None
    ) -> None:
        if _evaluator is None and (f_minus is None or f_plus is None or f_minus.n != f_plus.n):
            raise ValueError("ThickFunction needs two Functions f-, f+ of the same input dimension")
        self.f_minus, self.f_plus, self._evaluator = f_minus, f_plus, _evaluator
        self.n = f_minus.n if f_minus is not None else None
        self.approx: Callable | None = None

    @classmethod
    def from_parametric(cls, f: Function, p_lo, p_hi) -> ThickFunction:
        """Thick function of ``f(x, p)``, ``p ∈ [p_lo, p_hi]``; the last ``len(p_lo)`` inputs are ``p``."""
        p_lo, p_hi = np.atleast_1d(np.asarray(p_lo, float)), np.atleast_1d(np.asarray(p_hi, float))
        if p_lo.shape != p_hi.shape or np.any(p_lo > p_hi):
            raise ValueError("parameter box [p] must be non-empty with matching shapes")
        k, p_mid = p_lo.size, 0.5 * (p_lo + p_hi)

        def ev(lo: np.ndarray, hi: np.ndarray) -> ThickIntervalArray:
            n_rows = lo.shape[0]
            full = f.eval(
                (
                    np.hstack([lo, np.broadcast_to(p_lo, (n_rows, k))]),
                    np.hstack([hi, np.broadcast_to(p_hi, (n_rows, k))]),
                )
            )
            mid = f.eval(
                (
                    np.hstack([lo, np.broadcast_to(p_mid, (n_rows, k))]),
                    np.hstack([hi, np.broadcast_to(p_mid, (n_rows, k))]),
                )
            )
            # f⁻([x]) ⊂ [lb f([x],[p]), ub f([x],p_mid)]; f⁺([x]) ⊂ [lb f([x],p_mid), ub f([x],[p])].
            return ThickIntervalArray(full.lo, mid.hi, mid.lo, full.hi, check=False)

        obj = cls(None, None, _evaluator=ev)
        obj.n = f.n - k
        return obj

    @classmethod
    def from_evaluator(cls, n: int, evaluator: Callable[[np.ndarray, np.ndarray], ThickIntervalArray]
                       ) -> ThickFunction:  # fmt: skip
        """Wrap ``evaluator(lo, hi) -> ⟦[f⁻]([x]), [f⁺]([x])⟧`` on ``(N, n)`` batches; it must satisfy
        Eq. A.26 (``a ∈ [x] ⇒ [f](a) ∈ ⟦f⟧([x])``) with outward rounding."""
        if not (isinstance(n, (int, np.integer)) and n >= 1) or not callable(evaluator):
            raise ValueError(f"n, evaluator: expected a positive dimension and a callable, got {n!r}")
        obj = cls(None, None, _evaluator=evaluator)
        obj.n = int(n)
        return obj

    @classmethod
    def linear(cls, a_lo, a_hi) -> ThickFunction:
        """Thick function ``x ↦ A x``, ``A ∈ [A]`` (interval linear system, Eq. A.40).

        ``f⁻ᵢ(x) = Σⱼ min(a⁻ᵢⱼ xⱼ, a⁺ᵢⱼ xⱼ)`` and ``f⁺ᵢ(x) = Σⱼ max(a⁻ᵢⱼ xⱼ, a⁺ᵢⱼ xⱼ)``: each term is
        piecewise linear in ``xⱼ`` with its kink at ``0``, so its range on ``[xⱼ]`` is reached at the
        endpoints or at ``0``; the sums of the ranges are exact (separable), rounded outward.

        Raises:
            ValueError: if ``a_lo``, ``a_hi`` are not finite ``(m, n)`` matrices with ``a_lo <= a_hi``.
        """
        a_lo, a_hi = np.atleast_2d(np.asarray(a_lo, float)), np.atleast_2d(np.asarray(a_hi, float))
        if (
            a_lo.shape != a_hi.shape
            or a_lo.ndim != 2
            or not np.all(a_lo <= a_hi)
            or not np.isfinite(a_lo).all()
            or not np.isfinite(a_hi).all()
        ):
            raise ValueError(f"a_lo, a_hi: expected finite (m, n) matrices, a_lo <= a_hi, got {a_lo.shape}")

        def ev(lo: np.ndarray, hi: np.ndarray) -> ThickIntervalArray:
            p, q = lo[:, None, :], hi[:, None, :]  # (N, 1, n) against (m, n)
            al, ah = a_lo[None], a_hi[None]
            prod = arith.mul((al, ah), (p, q))  # lb: min of f⁻ terms, ub: max of f⁺ terms
            zero = (p <= 0) & (q >= 0)
            # ub of min(a⁻t, a⁺t) on [p, q]: endpoints, or 0 at the kink; lb of max(a⁻t, a⁺t) likewise
            ub_min = np.maximum(
                np.minimum(rnd.mul_up(al, p), rnd.mul_up(ah, p)),
                np.minimum(rnd.mul_up(al, q), rnd.mul_up(ah, q)),
            )
            lb_max = np.minimum(
                np.maximum(rnd.mul_down(al, p), rnd.mul_down(ah, p)),
                np.maximum(rnd.mul_down(al, q), rnd.mul_down(ah, q)),
            )
            ub_min, lb_max = (
                np.where(zero, np.maximum(ub_min, 0.0), ub_min),
                np.where(zero, np.minimum(lb_max, 0.0), lb_max),
            )
            return ThickIntervalArray(
                _sum(prod[0], False),
                _sum(ub_min, True),
                _sum(lb_max, False),
                _sum(prod[1], True),
                check=False,
            )

        obj = cls(None, None, _evaluator=ev)
        obj.n = a_lo.shape[1]
        return obj

    @classmethod
    def sqdist(cls, m_lo, m_hi) -> ThickFunction:
        """Thick function ``x ↦ (‖x − m_k‖²)_k`` with uncertain points ``m_k ∈ [m_k]`` (rows of ``(K, n)``).

        ``f⁻_k(x) = d(x, [m_k])²`` and ``f⁺_k(x) = max_{m ∈ [m_k]} ‖x − m‖²`` are sums over the coordinates,
        so their ranges on a box are sums of 1-d ranges: with ``[x_j] = [a, b]``, ``[m_j] = [c, d]``,
        ``d(t, [c, d]) ∈ [max(c−b, a−d, 0), max(c−a, b−d, 0)]`` and
        ``max(t−c, d−t) ∈ [max(d−b, a−c, (d−c)/2), max(b−c, d−a)]``. :attr:`approx` evaluates the same
        closed form in round-to-nearest (one subtraction, one square, ``n−1`` additions per bound:
        ``k = n + 3`` covers them); :meth:`eval` rounds every operation outward.

        Raises:
            ValueError: if ``m_lo``, ``m_hi`` are not finite ``(K, n)`` arrays with ``m_lo <= m_hi``.
        """
        c, d = np.atleast_2d(np.asarray(m_lo, float)), np.atleast_2d(np.asarray(m_hi, float))
        if (
            c.shape != d.shape
            or c.ndim != 2
            or not np.all(c <= d)
            or not np.isfinite(c).all()
            or not np.isfinite(d).all()
        ):
            raise ValueError(f"m_lo, m_hi: expected finite (K, n) arrays with m_lo <= m_hi, got {c.shape}")
        half_lo = rnd.mul_down(rnd.sub_down(d, c), 0.5)  # ≤ (d − c)/2, for the lower bound of f⁺ only
        half = np.maximum(half_lo, 0.0)
        n = c.shape[1]

        def ev(lo: np.ndarray, hi: np.ndarray) -> ThickIntervalArray:
            a, b = lo[:, None, :], hi[:, None, :]  # (N, 1, n) against (K, n)
            ll = np.maximum(np.maximum(rnd.sub_down(c, b), rnd.sub_down(a, d)), 0.0)
            lh = np.maximum(np.maximum(rnd.sub_up(c, a), rnd.sub_up(b, d)), 0.0)
            hl = np.maximum(np.maximum(rnd.sub_down(d, b), rnd.sub_down(a, c)), half)
            hh = np.maximum(rnd.sub_up(b, c), rnd.sub_up(d, a))
            sq = [rnd.mul_down(ll, ll), rnd.mul_up(lh, lh), rnd.mul_down(hl, hl), rnd.mul_up(hh, hh)]
            return ThickIntervalArray(
                _sum(sq[0], False), _sum(sq[1], True), _sum(sq[2], False), _sum(sq[3], True), check=False
            )

        neg_half = -half

        def approx(lo: np.ndarray, hi: np.ndarray) -> tuple[tuple[np.ndarray, ...], int]:
            acc: list[np.ndarray] = []
            cj: float | np.ndarray
            dj: float | np.ndarray
            hj: float | np.ndarray
            one = c.shape[0] == 1  # one uncertain point: 1-d columns against scalars (faster)
            for j in range(n):  # loop over the coordinates, each on the whole batch (N, K)
                if one:
                    a, b = lo[:, j], hi[:, j]
                    cj, dj, hj = float(c[0, j]), float(d[0, j]), float(neg_half[0, j])
                else:
                    a, b, cj, dj, hj = lo[:, j : j + 1], hi[:, j : j + 1], c[:, j], d[:, j], neg_half[:, j]
                p, q, r, t = cj - b, a - dj, cj - a, b - dj  # fl(d − b) = −fl(b − d): signs fold in
                terms = (np.maximum(np.maximum(p, q), 0.0), np.maximum(np.maximum(r, t), 0.0),
                         np.minimum(np.minimum(r, t), hj), np.minimum(p, q))  # fmt: skip
                sq = [np.multiply(v, v, out=v) for v in terms]
                acc = sq if not acc else [np.add(s, q, out=s) for s, q in zip(acc, sq, strict=True)]
            return tuple(v.reshape(lo.shape[0], -1) for v in acc), n + 3

        obj = cls(None, None, _evaluator=ev)
        obj.n, obj.approx = n, approx
        return obj

    def eval(self, lo: np.ndarray, hi: np.ndarray) -> ThickIntervalArray:
        """``⟦[f⁻]([x]), [f⁺]([x])⟧`` on a batch ``(N, n)`` of boxes (Theorem A.1)."""
        lo, hi = validate_batch(np.asarray(lo, float), np.asarray(hi, float), "boxes", self.n)
        if self._evaluator is not None:
            return self._evaluator(lo, hi)
        assert self.f_minus is not None and self.f_plus is not None  # __init__: both, or an evaluator
        a, b = self.f_minus.eval((lo, hi)), self.f_plus.eval((lo, hi))
        return ThickIntervalArray(a.lo, a.hi, b.lo, b.hi, check=False)


def _sum(v: np.ndarray, up: bool) -> np.ndarray:
    """Sum over the last axis rounded down (``up=False``) or up."""
    add = rnd.add_up if up else rnd.add_down
    s = v[..., 0]
    for j in range(1, v.shape[-1]):
        s = add(s, v[..., j])
    return s


__all__ = [
    "ThickFunction",
]
