"""The one unicycle arc of the project, in a stable form, with a proved bound on its floating-point error.

**What the truth is.** A piece of motion of duration ``τ`` (a float, exact) runs at a constant speed ``v``
(a float, exact) while the heading moves *linearly* from ``θ₀`` to ``θ₁`` (two floats, exact): the true yaw
rate is the real number ``(θ₁ − θ₀)/τ``, and the position follows ``ẋ = v (cos ψ, sin ψ)`` exactly, so that

    x₁ = x₀ + v τ sinc(Δ/2) (cos(θ₀ + Δ/2), sin(θ₀ + Δ/2)),   Δ = θ₁ − θ₀,   sinc(u) = sin(u)/u.      (A)

The simulator chooses ``θ₁ = fl(θ₀ + ω τ)`` from the commanded ``ω``, so the heading it stores *is* the
true heading, at every piece end, exactly; only the position is computed. (A) is the chord form: the chord
``2 (v/ω) sin(ωτ/2)`` along ``θ₀ + ωτ/2`` written without ``v/ω``. The classic form
``x₀ + v/ω (sin(θ₀ + ωτ) − sin θ₀)`` cancels catastrophically for small ``|ω|`` (an error of about
``1e-16 v/|ω|``: 1e-4 m at ``ω = 2e-12``); (A) has no cancellation for any ``Δ``, subnormal or zero included.

**Error bound** (:func:`arc_move`). Write ``u = 2⁻⁵³``, ``η = 2⁻¹⁰⁷⁴`` (the subnormal spacing) and ``L`` the
libm error in ulps (:data:`~digslam.observer.core.rounding.LIBM_ULPS`). Every rounded operation ``r = fl(a ∘
b)``
obeys ``|r − a ∘ b| ≤ 2u|r| + η``; libm's ``sin``/``cos`` of a value in ``[−1, 1]`` err by at most ``2Lu``.
With computed ``d = fl(θ₁ − θ₀)``, ``h = d/2``, ``m = fl(θ₀ + h)``, ``a = fl(v τ)``:

* ``|h − Δ/2| ≤ e_h = u|d| + 2η``;
* ``sinc``: for ``|h| < 2⁻¹⁰`` the series ``1 − h²/6 + h⁴/120`` (truncation ``h⁶/5040 < 2⁻⁷²``, five
  roundings of terms ``≤ 1``), else ``sin(h)/h``; either way ``|s − sinc(Δ/2)| ≤ e_s = (2L + 12)u + e_h/2``
  (``|sinc'| ≤ 1/2``);
* ``|m − (θ₀ + Δ/2)| ≤ e_m = 2u|m| + η + e_h``, so each of ``cos m``, ``sin m`` is within
  ``e_c = 2Lu + e_m`` of the exact direction's component (``|cos'| ≤ 1``);
* the products ``a``, ``a s``, ``a s cos m`` add ``8u|vτ|`` and ``4η``; the final sum ``fl(x₀ + dx)`` adds
  ``2u|x₁| + η``.

So each coordinate of (A) is computed within ``E = |vτ| (e_s + e_c + 8u) + 2u max(|x₁|, |y₁|) + 8η`` of the
exact value *from the same start point*. Starting from a start point that is itself within ``E₀`` of the
truth, the result is within ``E₀ + E``: the heading is exact, so position errors add and never compound
through the direction. The simulator carries this running sum (``pose_error``) over the whole episode: a
bound of the accumulated state, whatever the actions (``ω = 0``, subnormal, the largest yaw rate, long
episodes with an unwrapped heading: ``|θ₀|`` enters ``e_m`` linearly). ``E`` is evaluated with upward
rounding and doubled, so the bound is itself rigorous. ``tests/envs/sim/test_arc.py`` checks it against a
200-bit reference, with hypothesis over tiny, huge, subnormal and sign-alternating yaw rates.

Example (a tiny yaw rate: the chord form keeps full accuracy):
    >>> x, y, th, err = advance(0.0, 0.0, 1.0, 1.0, 2e-12, 0.1)
    >>> abs(x - 0.1 * math.cos(1.0 + 1e-13)) < 1e-17, err < 1e-15
    (True, True)
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.rounding import LIBM_ULPS
from digslam.observer.core.scalar_jit import add_up, div_dn, div_up, mul_up, njit, sub_dn, sub_up

_U = 2.0**-53
_ETA = 5e-324
_ES0 = (2 * LIBM_ULPS + 12) * _U
_EC0 = 2 * LIBM_ULPS * _U


@njit
def arc_move(x: float, y: float, th0: float, th1: float, v: float, tau: float) -> tuple[float, float, float]:
    """Position after a piece of (A) and the bound ``E`` on each coordinate's error; see the module.

    Returns ``(x₁, y₁, E)``. A piece that does not move (``v = 0`` or ``τ = 0``) returns the start
    exactly, ``E = 0``.
    """
    if v == 0.0 or tau == 0.0:
        return x, y, 0.0
    a = v * tau
    d = th1 - th0
    h = 0.5 * d
    if abs(h) < 2.0**-10:
        h2 = h * h
        s = 1.0 - h2 * (1.0 / 6.0 - h2 * (1.0 / 120.0))
    else:
        s = math.sin(h) / h
    m = th0 + h
    k = a * s
    x1 = x + k * math.cos(m)
    y1 = y + k * math.sin(m)
    e_h = add_up(mul_up(_U, abs(d)), 2 * _ETA)
    e_s = add_up(_ES0, 0.5 * e_h)
    e_c = add_up(add_up(_EC0, mul_up(2 * _U, abs(m))), add_up(_ETA, e_h))
    big = mul_up(abs(a), add_up(add_up(e_s, e_c), 8 * _U))
    tail = add_up(mul_up(2 * _U, max(abs(x1), abs(y1))), 8 * _ETA)
    return x1, y1, 2.0 * add_up(big, tail)


@njit
def advance(x: float, y: float, th: float, v: float, w: float,
            tau: float) -> tuple[float, float, float, float]:  # fmt: skip
    """One piece at commanded ``(v, w)`` for ``tau`` s: ``(x₁, y₁, θ₁, E)`` with ``θ₁ = fl(θ + w τ)`` exact
    by definition (the true yaw rate is ``(θ₁ − θ)/τ``, :func:`yaw_rate_bounds`)."""
    th1 = th + w * tau
    x1, y1, e = arc_move(x, y, th, th1, v, tau)
    return x1, y1, th1, e


@njit
def yaw_rate_bounds(th0: float, th1: float, tau: float) -> tuple[float, float]:
    """Outward bounds of the true yaw rate ``(θ₁ − θ₀)/τ`` of a piece (``tau > 0``)."""
    d_lo, d_hi = sub_dn(th1, th0), sub_up(th1, th0)
    if d_lo == 0.0 and d_hi == 0.0:  # no turn: exactly 0
        return 0.0, 0.0
    return div_dn(d_lo, tau), div_up(d_hi, tau)


def arc(pose: np.ndarray, v: float, w: float, tau: float) -> np.ndarray:
    """The pose ``(x, y, θ)`` after ``tau`` s at commanded ``(v, w)`` from ``pose``: (A) with
    ``θ₁ = fl(θ + w τ)`` (plain floats; the error bound is :func:`arc_bounded`'s)."""
    return arc_bounded(pose, v, w, tau)[0]


def arc_bounded(pose: np.ndarray, v: float, w: float, tau: float) -> tuple[np.ndarray, float]:
    """:func:`arc` and the bound ``E`` on the error of its position (the heading is exact)."""
    x, y, th = (float(c) for c in pose)
    x1, y1, th1, e = advance(x, y, th, float(v), float(w), float(tau))
    return np.array([x1, y1, th1]), float(e)


def exact_duration(t0: float, t1: float) -> float:
    """``t1 − t0`` when it is a float exactly (record times are consecutive floats, Sterbenz's lemma), so
    that the pieces of a step last exactly the time between its records; ValueError otherwise."""
    a, b = float(t1), -float(t0)
    tau = a + b
    t = tau - a
    err = (a - (tau - t)) + (b - t)  # TwoSum: the exact a + b - tau
    if err != 0.0 or not tau > 0 or not math.isfinite(tau):
        raise ValueError(f"t: the step from {t0!r} to {t1!r} has no exact positive float duration")
    return tau


__all__ = ["advance", "arc", "arc_bounded", "arc_move", "exact_duration", "yaw_rate_bounds"]
