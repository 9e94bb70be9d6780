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

__all__ = ["axes_in"]


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
