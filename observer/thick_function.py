"""Thick inclusion functions (thesis App. A, Theorem A.1).

For bound functions ``f⁻ ≤ f⁺`` the thick function ``⟦f⟧(x) = ⟦f⁻(x), f⁺(x)⟧`` has the thick inclusion
``⟦f⟧([x]) = ⟦[f⁻]([x]), [f⁺]([x])⟧`` (Theorem A.1). :meth:`ThickFunction.from_parametric` builds it
from ``f(x, p)``, ``p ∈ [p]``: ``f⁻(x) = min_p f(x, p)``, ``f⁺(x) = max_p f(x, p)``, enclosed with
``[f]([x], [p])`` and ``[f]([x], mid [p])``.

Example:
    >>> import numpy as np
    >>> from digslam.observer import Function
    >>> tf = ThickFunction(Function(lambda x: x[0] - 1), Function(lambda x: x[0] + 1))
    >>> a = tf.eval(np.array([[0.0]]), np.array([[1.0]]))
    >>> b = tf.eval(np.array([[0.0]]), np.array([[0.0]]))
    >>> (a & b).as_tuple()
    ((-1.0, 0.0), (1.0, 1.0))
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .boxes import validate_batch
from .expr import Function
from .thick_interval import ThickIntervalArray


class ThickFunction:
    """Thick inclusion function ``⟦f⟧`` (Theorem A.1).

    Args:
        f_minus: lower bound function ``f⁻`` (a :class:`Function`, ``n`` inputs).
        f_plus: upper bound function ``f⁺`` (same input dimension).
    """

    def __init__(self, f_minus: Function | None, f_plus: Function | None, *,
                 _evaluator: Callable | None = None) -> None:
        if _evaluator is None and (f_minus is None or f_plus is None or f_minus.n != f_plus.n):
            raise ValueError("ThickFunction needs two Functions f-, f+ of the same input dimension")
        self.f_minus, self.f_plus, self._evaluator = f_minus, f_plus, _evaluator
        self.n = f_minus.n if f_minus is not None else None

    @classmethod
    def from_parametric(cls, f: Function, p_lo, p_hi) -> ThickFunction:
        """Thick function of ``f(x, p)``, ``p ∈ [p_lo, p_hi]``; the last ``len(p_lo)`` inputs are ``p``."""
        p_lo, p_hi = np.atleast_1d(np.asarray(p_lo, float)), np.atleast_1d(np.asarray(p_hi, float))
        if p_lo.shape != p_hi.shape or np.any(p_lo > p_hi):
            raise ValueError("parameter box [p] must be non-empty with matching shapes")
        k, p_mid = p_lo.size, 0.5 * (p_lo + p_hi)

        def ev(lo: np.ndarray, hi: np.ndarray) -> ThickIntervalArray:
            n_rows = lo.shape[0]
            full = f.eval((np.hstack([lo, np.broadcast_to(p_lo, (n_rows, k))]),
                           np.hstack([hi, np.broadcast_to(p_hi, (n_rows, k))])))
            mid = f.eval((np.hstack([lo, np.broadcast_to(p_mid, (n_rows, k))]),
                          np.hstack([hi, np.broadcast_to(p_mid, (n_rows, k))])))
            # f⁻([x]) ⊂ [lb f([x],[p]), ub f([x],p_mid)]; f⁺([x]) ⊂ [lb f([x],p_mid), ub f([x],[p])].
            return ThickIntervalArray(full.lo, mid.hi, mid.lo, full.hi, check=False)

        obj = cls(None, None, _evaluator=ev)
        obj.n = f.n - k
        return obj

    def eval(self, lo: np.ndarray, hi: np.ndarray) -> ThickIntervalArray:
        """``⟦[f⁻]([x]), [f⁺]([x])⟧`` on a batch ``(N, n)`` of boxes (Theorem A.1)."""
        lo, hi = validate_batch(np.asarray(lo, float), np.asarray(hi, float), "boxes", self.n)
        if self._evaluator is not None:
            return self._evaluator(lo, hi)
        a, b = self.f_minus.eval((lo, hi)), self.f_plus.eval((lo, hi))
        return ThickIntervalArray(a.lo, a.hi, b.lo, b.hi, check=False)
