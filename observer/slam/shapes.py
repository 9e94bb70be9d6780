"""Range readings as shapes in the robot frame (thesis §6.2.3.2, Fig. 6.9, §4.4 Eq. 4.33–4.36).

A reading ``y ∈ [y⁻, y⁺]`` of a sensor of direction ``α`` and half-aperture ``γ`` becomes the interval
shape ``[Z] = [Z⁻, R²]`` with the free zone ``Z⁻ = {ρ < y⁻, |θ - α| <= γ}`` (a disk for the
omnidirectional sensor, ``γ = π``, a sector for a sonar cone) and the impact zone
``ΔZ = {ρ ∈ [y⁻, y⁺], |θ - α| <= γ}`` (a ring or an arc). "No echo up to ``r_max``" (``[r_max, ∞]``) is a
free sector of radius ``r_max`` and no impact constraint. These separators act on ``(x, y)`` boxes of the
robot frame and feed the paver, registration and drawing; :class:`~.digmap.DigMap` implements the same
shapes in closed form on grids.

>>> import numpy as np
>>> free, impact = measurement_shapes(alpha=0.0, gamma=np.pi / 12, y=(2.0, 2.1))
>>> (ilo, ihi), (olo, ohi) = free.separate(np.array([[0.5, -0.05]]), np.array([[0.6, 0.05]]))
>>> bool(np.all(ilo > ihi))                      # that box is proved inside the free sector
True
>>> measurement_shapes(alpha=0.0, gamma=np.pi, y=(5.0, np.inf))[1] is None   # no echo: no impact
True
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.interval import Interval
from digslam.observer.expr.expr import Function
from digslam.observer.polar.sep import SepPiInv
from digslam.observer.sets.sep_inverse import SepInverse
from digslam.observer.sets.separators import Sep

_SQ = Function(lambda z: z[0] ** 2 + z[1] ** 2)


def _ring(r_lo: float, r_hi: float) -> Sep:
    """``{z : |z| ∈ [r_lo, r_hi]}`` through ``|z|² ∈ [r_lo², r_hi²]`` (outward rounded)."""
    lo = float(rnd.mul_down(np.float64(r_lo), np.float64(r_lo)))
    hi = float(rnd.mul_up(np.float64(r_hi), np.float64(r_hi))) if np.isfinite(r_hi) else np.inf
    return SepInverse(_SQ, Interval(lo, hi))


def free_zone(alpha: float, gamma: float, r: float) -> Sep:
    """Separator of ``Z⁻``: the disk (``γ >= π``) or sector of radius ``r`` (Eq. 4.33)."""
    _check(gamma, r, r)
    if gamma >= rnd.PI_DOWN:
        return _ring(0.0, r)
    return SepPiInv((0.0, r), (alpha - gamma, alpha + gamma))


def impact_zone(alpha: float, gamma: float, r_lo: float, r_hi: float) -> Sep | None:
    """Separator of ``ΔZ``: the ring or arc ``ρ ∈ [r_lo, r_hi]`` (Eq. 4.34), None for no echo."""
    _check(gamma, r_lo, r_hi)
    if not np.isfinite(r_hi):
        return None
    if gamma >= rnd.PI_DOWN:
        return _ring(r_lo, r_hi)
    return SepPiInv((r_lo, r_hi), (alpha - gamma, alpha + gamma))


def measurement_shapes(alpha: float, gamma: float, y: tuple[float, float]) -> tuple[Sep, Sep | None]:
    """``(Z⁻, ΔZ)`` of one reading ``y = (y⁻, y⁺)``; ``y⁺ = inf`` is "no echo up to ``y⁻``"."""
    return free_zone(alpha, gamma, y[0]), impact_zone(alpha, gamma, y[0], y[1])


def _check(gamma: float, r_lo: float, r_hi: float) -> None:
    if not (0 < gamma <= np.pi):
        raise ValueError(f"gamma: the half-aperture must be in (0, pi], got {gamma!r}")
    if not (0 <= r_lo <= r_hi) or np.isnan(r_lo) or not np.isfinite(r_lo):
        raise ValueError(f"y: expected a range interval 0 <= y⁻ <= y⁺ with a finite y⁻, got [{r_lo}, {r_hi}]")


__all__ = ["free_zone", "impact_zone", "measurement_shapes"]
