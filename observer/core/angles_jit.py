"""Compiled angle primitive: which axis directions ``m·π/2`` an angle range may hold.

The extrema of ``cos`` and ``sin`` over ``[a, b]``, and the extent of a circular sector of that angle range,
are reached at its ends or at the axis directions inside it: ``+x`` at ``θ = 2kπ``, ``+y`` at
``π/2 + 2kπ``, ``-x`` at ``π + 2kπ`` and ``-y`` at ``-π/2 + 2kπ``. :func:`axes_in` says which of the four
may lie in the range; the enclosures of ``cos``/``sin`` (:func:`.online.pose_jit.cos_sin`) and the bounding
boxes of sectors (the online filter's cone windows, the ground-truth coverage's scan boxes) all take it
from here.

>>> axes_in(-0.1, 0.1), axes_in(0.1, 3.2), axes_in(0.0, 7.0)
((True, False, False, False), (False, True, True, False), (True, True, True, True))
"""

from __future__ import annotations

import math

from digslam.observer.core.rounding import HALF_PI_DOWN, HALF_PI_UP
from digslam.observer.core.scalar_jit import njit

__all__ = ["axes_in", "sector_box"]


@njit
def axes_in(a: float, b: float) -> tuple[bool, bool, bool, bool]:
    """``(east, north, west, south)``: whether a multiple ``m·π/2`` with ``m ≡ 0, 1, 2, 3 (mod 4)`` may lie
    in ``[a, b]`` (the directions ``+x``, ``+y``, ``-x``, ``-y``).

    Rigorous, never a missed direction: a direction reported False has no multiple in ``[a, b]``. The
    candidates ``m`` run over ``floor(a / HALF_PI_UP) - 1 ... floor(b / HALF_PI_DOWN) + 1``
    (:data:`~.rounding.HALF_PI_DOWN` ``< π/2 <`` :data:`~.rounding.HALF_PI_UP`; the margin of one covers
    the rounding of the quotients), and ``m·π/2`` is tested as the float ``p = m·HALF_PI_DOWN``, which is
    within ``|m|(π/2 - HALF_PI_DOWN)`` plus half an ulp, about ``2⁻⁵²|p|``, of it, against
    ``[a - ε, b + ε]`` with ``ε = 10⁻¹⁵|p| + 10⁻³⁰⁰``, which covers that error and the rounding of
    ``a - ε``, ``b + ε`` with room to spare (``m = 0`` is exact). A direction may thus be reported when one
    of its multiples lies within ``ε`` outside the range: a bound computed with it only grows.

    A range of more than 8 candidates spans more than a full turn: every direction lies in it. So does an
    end that is not finite (nothing is known of the range).
    """
    if not (math.isfinite(a) and math.isfinite(b)):
        return True, True, True, True
    f0, f1 = math.floor(a / HALF_PI_UP) - 1.0, math.floor(b / HALF_PI_DOWN) + 1.0
    if f1 - f0 > 8.0:
        return True, True, True, True
    east = north = west = south = False
    for m in range(int(f0), int(f1) + 1):
        p = m * HALF_PI_DOWN
        eps = abs(p) * 1e-15 + 1e-300
        if a - eps <= p <= b + eps:
            q = m % 4
            if q == 0:
                east = True
            elif q == 1:
                north = True
            elif q == 2:
                west = True
            else:
                south = True
    return east, north, west, south


@njit(forceinline=True)
def sector_box(r: float, a0: float, a1: float, c0: float, s0: float, c1: float, s1: float
               ) -> tuple[float, float, float, float]:  # fmt: skip
    """``(x_lo, x_hi, y_lo, y_hi)``: the bounding box, relative to its apex, of the circular sector of radius
    ``r >= 0`` over the angles ``[a0, a1]``, given ``(c0, s0)`` and ``(c1, s1)``, the cosines and sines (as
    computed by the caller) of its two ends: the apex, the two edge ends and the axis points ``r·(±1, 0)``,
    ``r·(0, ±1)`` of the directions :func:`axes_in` reports inside the range (a caller pads for the
    rounding of ``r·c``, ``r·s`` and of its ends)."""
    xlo, xhi = min(0.0, r * c0, r * c1), max(0.0, r * c0, r * c1)
    ylo, yhi = min(0.0, r * s0, r * s1), max(0.0, r * s0, r * s1)
    east, north, west, south = axes_in(a0, a1)
    if east:
        xhi = max(xhi, r)
    if north:
        yhi = max(yhi, r)
    if west:
        xlo = min(xlo, -r)
    if south:
        ylo = min(ylo, -r)
    return xlo, xhi, ylo, yhi
