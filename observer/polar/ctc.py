"""Minimal polar contractor for ``(x, y) = (ρ cos θ, ρ sin θ)`` (thesis §3.2.3, Eq. 3.22–3.34).

The set is ``Π = {(x, y, ρ, θ) | (x, y) = π(ρ, θ)}`` (Eq. 3.22) and the contractor returns, for every
box ``[p] = [x]×[y]×[ρ]×[θ]``, the hull ``⟦Π ∩ [p]⟧`` up to outward rounding (Theorem 3.1, Eq. 3.28).

How. The thesis builds ``C_Π`` from ``C_Π₀`` on the base octant ``x, y, ρ ≥ 0, θ ∈ [0, π/4]`` and the
box-conservative symmetries of Prop. 3.4. On the base octant every coordinate is monotone along every
boundary piece of ``[x]×[y] ∩ π([ρ]×[θ])``, so the hull is reached at vertices of that region; the
symmetries σ₁–σ₃ only add the points where a piece crosses an octant border with an extremum (the
axes). We therefore take the hull of the region's candidate extreme points in all octants at once (box
corners, box edges ∩ circles ``|p| = ρ±``, box edges ∩ rays ``θ±``, rays ∩ circles, circles ∩ axes,
feet of the edges on the axes, the origin), each enclosed by outward interval arithmetic, kept when it
may lie in the region and clipped to ``[p]``. That is exactly the union hull of Eq. 3.34: ``σ₄``
(``ρ < 0``) is applied explicitly, and ``γ`` (``θ + 2kπ``) by lifting every candidate angle to the
smallest and the largest representative in ``[θ]`` with a rigorous enclosure of ``2kπ``. θ of any width
works; beyond ``|θ| > 2⁵⁰`` (or unbounded) θ is left as is.

At ``ρ = 0``. ``Π`` holds the origin with every angle, ``(0, 0, 0, θ)`` for all ``θ`` (Eq. 3.22: the
polar map sends ``(0, θ)`` to the origin), so a box whose only points of ``Π`` are at the origin keeps
them: ``[-1, 1]² × {0} × [0, 1]`` contracts to ``{0}³ × [0, 1]``, and ``[θ]`` is not contracted there.
codac's ``CtcPolar`` reads θ as ``atan2(y, x)``, undefined at the origin, and returns the empty box on
such a box; that drops points of ``Π`` (a robot standing on its landmark, range 0, any bearing), so this
contractor keeps them (``tests/peer``, case ``CtcPolar_origin``).

A box unbounded in both ``[ρ]`` and ``[x]×[y]`` is returned after the sound clipping
``|x|, |y| <= ρ <= |(x, y)|`` only (no candidate can be enclosed at infinity).

:class:`CtcPolar` runs this construction compiled (:mod:`digslam.observer.core.polar_jit`, one loop over
the boxes in machine code); its numpy oracle lives with the tests (``tests/polar_oracle.py``).

>>> c = CtcPolar()
>>> lo, hi = c.contract(np.array([[1.0, 1.0, 0.0, -10.0]]), np.array([[2.0, 2.0, 10.0, 10.0]]))
>>> [round(float(v), 6) for v in lo[0]], [round(float(v), 6) for v in hi[0]]  # θ: atan ½ - 2π, atan 2 + 2π
([1.0, 1.0, 1.414214, -5.819538], [2.0, 2.0, 2.828427, 7.390334])
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core.polar_jit import ctc_polar_batch
from digslam.observer.core.types import Batch
from digslam.observer.sets.contractors import Ctc


class CtcPolar(Ctc):
    """Minimal contractor for ``Π = {(x, y, ρ, θ) | x = ρ cos θ, y = ρ sin θ}`` (Eq. 3.22, 3.34).

    Acts on batches ``(N, 4)`` with columns ``(x, y, ρ, θ)``. Each face of a non-empty result touches
    ``Π`` (up to outward rounding), for ``ρ`` of any sign and ``θ`` of any width; the origin belongs to
    ``Π`` with every ``θ`` (see the module docstring, "At ρ = 0"). The work is one call
    of the compiled kernel :func:`digslam.observer.core.polar_jit.ctc_polar_batch`.

    Args:
        need_theta: when False, θ is kept as given and only ``x, y, ρ`` are contracted (minimally):
            what :class:`~.sep.SepPiInv` needs, at a fraction of the cost.
    """

    n = 4

    def __init__(self, need_theta: bool = True) -> None:
        self.need_theta = bool(need_theta)

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        if lo.ndim != 2 or lo.shape[1] != 4:
            raise ValueError(f"CtcPolar: boxes must have shape (N, 4) = (x, y, ρ, θ), got {lo.shape}")
        lo, hi = np.ascontiguousarray(lo, dtype=np.float64), np.ascontiguousarray(hi, dtype=np.float64)
        return ctc_polar_batch(lo, hi, self.need_theta)


__all__ = [
    "CtcPolar",
]
