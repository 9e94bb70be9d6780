"""Uncertain set inversion with a parametric function (thesis §5.4.3, Eq. 5.39–5.41).

For ``f: (x, p) ↦ f_p(x)`` with ``p ∈ [p]`` and a thick target ``[Y⁻, Y⁺]``:

* ``X⁻ = {x | ∀p ∈ [p], f_p(x) ∈ Y⁻} = comp(proj_x{(x, p) | f_p(x) ∉ Y⁻})`` (Eq. 5.40);
* ``X⁺ = {x | ∃p ∈ [p], f_p(x) ∈ Y⁺} = proj_x{(x, p) | f_p(x) ∈ Y⁺}`` (Eq. 5.41),

both separated with :class:`~.projection.SepProj`. :func:`thick_inverse_classical` is the classical
alternative (``p`` kept as the interval ``[p]`` inside the inclusion function), which cannot prove
boxes in the penumbra and adds pessimism (Fig. 5.7b).

>>> from digslam.observer import Box
>>> y, p = Box([(0, 1)]), Box([(0, 0.5)])  # x + p ∈ [0, 1]: X⁻ = [0, 0.5], X⁺ = [-0.5, 1]
>>> ts = thick_inverse_proj(lambda z: [z[0] + z[1]], y, y, p, n=1, eps=0.01)
>>> import numpy as np
>>> ts.classify(np.array([[0.2], [-0.4], [2.5]]), np.array([[0.3], [-0.1], [2.6]])).tolist()
[1, 2, -1]
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from digslam.observer.core.boxes import normalize_empty
from digslam.observer.core.interval import IntervalArray
from digslam.observer.core.types import Batch
from digslam.observer.expr.expr import Function
from digslam.observer.sets.projection import SepProj
from digslam.observer.sets.sep_inverse import SepInverse
from digslam.observer.sets.separators import Sep, SepNot
from digslam.observer.thick.sep import ThickSep


def _pair(box: Any, name: str) -> Batch:
    if isinstance(box, IntervalArray):
        lo, hi = box.pair
    else:
        arr = np.asarray(box, float).reshape(-1, 2)
        lo, hi = arr[:, 0], arr[:, 1]
    lo, hi = np.atleast_1d(np.asarray(lo, np.float64)), np.atleast_1d(np.asarray(hi, np.float64))
    if lo.ndim != 1 or np.any(lo > hi) or not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise ValueError(f"{name}: expected one bounded non-empty box, got {lo.tolist()} {hi.tolist()}")
    return lo, hi


class SepFixedParam(Sep):
    """Separator on ``x`` of ``Z`` on ``(x, p)`` with ``p`` held as the whole interval box ``[p]``.

    ``x_in`` (resp. ``x_out``) is the ``x``-part of ``S_Z``'s ``x_in`` (resp. ``x_out``) on
    ``[x] × [p]``: it keeps every ``x`` with some ``p`` outside (resp. inside) ``Z``, so the same
    separator is consistent with both ``X⁻`` (Eq. 5.40) and ``X⁺`` (Eq. 5.41), pessimistically.
    """

    def __init__(self, sep: Sep, p_box: Any, n: int) -> None:
        self.sep, self.p, self.n = sep, _pair(p_box, "p_box"), n

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        k = lo.shape[0]
        zlo = np.concatenate([lo, np.broadcast_to(self.p[0], (k, self.p[0].size))], axis=1)
        zhi = np.concatenate([hi, np.broadcast_to(self.p[1], (k, self.p[1].size))], axis=1)
        (ilo, ihi), (olo, ohi) = self.sep.separate(zlo, zhi)
        n = self.n
        return normalize_empty(ilo[:, :n], ihi[:, :n]), normalize_empty(olo[:, :n], ohi[:, :n])


def thick_inverse_proj(f: Function | Callable[..., Any], y_lower: Any, y_upper: Any, p_box: Any = None, *,
                       n: int, eps: float, p: Any = None) -> ThickSep:  # fmt: skip
    """Thick separator of ``[X⁻, X⁺]`` of Eq. 5.40–5.41 via projection.

    Args:
        f: callable or :class:`~.expr.Function` of ``z = (x₁..xₙ, p₁..p_q)``.
        y_lower, y_upper: boxes (or separators) for ``Y⁻ ⊂ Y⁺``.
        p_box: the parameter box ``[p]`` (``q`` intervals); ``p`` is an alias.
        n: dimension of ``x`` (the first ``n`` coordinates of ``z``).
        eps: parameter resolution of the projections.

    Raises:
        ValueError: on a missing/bad parameter box or dimension mismatch.
    """
    p_box = p if p_box is None else p_box
    if p_box is None:
        raise ValueError("thick_inverse_proj: a parameter box p_box is required")
    kept = list(range(n))
    upper = SepProj(SepInverse(f, y_upper), kept, p_box, eps)
    lower = SepNot(SepProj(SepNot(SepInverse(f, y_lower)), kept, p_box, eps))
    return ThickSep(lower, upper)


def thick_inverse_classical(
    f: Function | Callable[..., Any], y_lower: Any, y_upper: Any, p_box: Any, *, n: int
) -> ThickSep:
    """Classical thick separator: ``[p]`` stays an interval inside ``f`` (Fig. 5.7b)."""
    lower = SepFixedParam(SepInverse(f, y_lower), p_box, n)
    return ThickSep(lower, SepFixedParam(SepInverse(f, y_upper), p_box, n))


__all__ = ["SepFixedParam", "thick_inverse_classical", "thick_inverse_proj"]
