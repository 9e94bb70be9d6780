"""Compiled guard and bounds of the pymunk robot (:mod:`.robot`, ``dynamics="pymunk"``): the premise check of
each substep and rigorous hulls of the body-frame velocity and yaw rate over a step, with the substep
durations they rest on.

**Substep durations** (:func:`substep_times`). A step of ``dt`` seconds (a float, the exact time between two
records) runs ``S`` pymunk substeps with boundaries ``s_0 = 0``, ``s_j = fl(fl(j dt) / S)`` for
``0 < j < S`` and ``s_S = dt``, and durations ``τ_j = fl(s_{j+1} − s_j)``. Every ``τ_j`` is the exact
difference, positive, and the ``τ_j`` sum exactly to ``dt``, provided ``dt / S ≥ 2⁻¹⁰²¹`` (no underflow;
checked). Proof, with ``u = 2⁻⁵³`` and every value normal, so that each rounding has relative error ``≤ u``
and scaling by 2 is exact:

* ``τ_0 = s_1 − 0`` is exact; for ``S = 1`` that is all, ``τ_0 = dt``.
* ``S = 2``: ``s_1 = fl(dt/2) = dt/2`` exactly, so ``τ_1 = dt − dt/2`` is exact.
* ``S ≥ 3``, ``j = 1``: ``s_2 = fl(fl(2 dt)/S) = fl(2 dt/S) = 2 s_1``, so ``s_1 ≤ s_2 ≤ 2 s_1`` and
  ``s_2 − s_1`` is exact by Sterbenz's lemma (``y/2 ≤ x ≤ 2y`` makes ``x − y`` a float).
* ``S ≥ 3``, ``2 ≤ j ≤ S − 1``: ``s_j ≥ (j dt/S)(1 − u)²`` and ``s_{j+1} ≤ ((j+1) dt/S)(1 + u)²`` (for
  ``j + 1 = S``, ``s_S = dt`` itself), so ``s_{j+1}/s_j ≤ (3/2)((1 + u)/(1 − u))² < 2``; rounding is
  monotone, so ``s_j ≤ s_{j+1}``, and ``(j + 1)(1 − u)² > j (1 + u)²`` makes it strict. Sterbenz again.

The sum of exact differences telescopes to ``s_S − s_0 = dt``.

**The truth between substeps.** pymunk integrates the robot; after substep ``j`` the simulator reads back
the body's position ``p_{j+1}`` and angle ``a_{j+1}`` (floats). The true trajectory is *defined* as the
piecewise-linear path through these stored states: over ``[s_j, s_{j+1}]`` the position moves from ``p_j``
to ``p_{j+1}`` at the constant velocity ``u_j = (p_{j+1} − p_j)/τ_j`` and the heading moves linearly from
``a_j`` to ``a_{j+1}`` at the yaw rate ``(a_{j+1} − a_j)/τ_j``. These are real numbers, exact by definition;
the stored pose after the step *is* the true pose (``pose_error = 0``) and its heading is ``a_S``. The
body-frame velocity is ``v(t) = R(−ψ(t)) u_j`` (forward ``v_1``, leftward ``v_2``), so
``ẋ = R(ψ) v`` holds at every instant but the ``S + 1`` substep boundaries.

**Bounds** (:func:`step_bounds`). Over substep ``j`` let ``m = fl(a_j + fl(a_{j+1} − a_j)/2)`` (any float
will do) and ``ψ = m + e`` with ``e ∈ [e⁻, e⁺] = [min(a_j, a_{j+1}) − m, max(a_j, a_{j+1}) − m]``
(outward-rounded), ``h = max(|e⁻|, |e⁺|)``. Then ``v = R(−e) w`` with ``w = R(−m) u_j``:

    v_1 = cos e · w_1 + sin e · w_2,    v_2 = cos e · w_2 − sin e · w_1,
    w_1 = cos m · u_x + sin m · u_y,    w_2 = cos m · u_y − sin m · u_x.

Each factor is enclosed rigorously: ``u_j`` by the outward-rounded differences divided outward by ``τ_j``
(exactly ``[0, 0]`` when the coordinate did not change); ``cos m``, ``sin m`` by libm widened by
:data:`~digslam.observer.core.rounding.LIBM_ULPS` ulps (:func:`~digslam.observer.core.scalar_jit.wdn`,
:func:`~digslam.observer.core.scalar_jit.wup`), clipped to ``[−1, 1]``; ``cos e ∈ [1 − h²/2, 1]``
(``cos e ≥ 1 − e²/2`` for every real ``e``) and ``sin e ∈ [min(e⁻, 0), max(e⁺, 0)]`` (``sin e`` has the
sign of ``e`` and ``|sin e| ≤ |e|`` for ``|e| ≤ π``; ``[−1, 1]`` for both when ``h > 3``); the products and
sums by the outward-rounded interval operations of :mod:`digslam.observer.core.scalar_jit`. The yaw rate is
:func:`.arc_jit.yaw_rate_bounds`. The step's hulls are the hulls of the substeps': they contain ``v_1(t)``,
``v_2(t)`` and ``ψ'(t)`` at every instant of the step, and the heading over the step lies in the hull of the
``a_j``. Writing ``v`` through the mid-heading ``m`` keeps the speed tight (``|e| ≤ ω τ / 2``: the forward
bound widens by ``h²/2 |w_1| + 2 h |w_2|``); the lateral bound is at least ``±h |w_1|`` wide, which is the
truth: the chord direction is fixed over a substep while the heading turns.

**The mean velocity in the start frame** (rows 3 and 4 of :func:`step_bounds`: the odometry increment).
The hulls above span every change of velocity within the step, so with inertia (a step that starts at rest
and ends at full speed) they are as wide as the change itself, and the position bound they give,
``dt R([ψ]) [v]``, grows by ``dt`` times that width every step. A robot's odometry also reports what it
integrated over the step: the body-frame velocity rotated by the relative heading its gyro measured,

    v̄ = (1/dt) ∫ R(ψ(t) − ψ(t_0)) v(t) dt = (1/dt) R(−a_0) (p_S − p_0),

the displacement over the step in the body frame at its start, per second (``∫ R(ψ) v dt = p_S − p_0``:
the path is continuous). It does not widen when the velocity changes within the step. Enclosed from the
stored floats: ``p_S − p_0`` outward, ``cos a_0``, ``sin a_0`` by libm widened, the rotation's products and
sums and the division by ``dt = Σ τ_j`` (an exact float sum: its partial sums are the ``s_j``)
outward-rounded. The observer turns it into ``x_k − x_{k−1} ∈ [dt] R([ψ_{k−1}]) [v̄]``
(:func:`digslam.observer.online.pose_jit.mean_displacement`).

**The premise guard** (:func:`substep_clear`). The observer digs the robot's disc of radius ``r`` along its
path, so the disc centred anywhere on the segment ``p_j → p_{j+1}`` must keep off every obstacle:
``dist(P, E) ≥ r`` for the segment ``P`` and every wall edge ``E``. For segments that do not cross,
``dist(P, E)`` is the least of the four endpoint-to-segment distances ``δ_0, δ_1`` (of ``P``'s ends to
``E``) and ``δ_2, δ_3`` (of ``E``'s ends to ``P``). Each is computed in floats by
:func:`.geometry_jit.segment_distance` (``a = s_0 − q``, ``d = s_1 − s_0``, the clamped foot
``t̃``, ``|a + t̃ d|``) and lowered by ``64 u (|a|₁ + |d|₁) + 2⁻⁴⁰``. That margin dominates the float
error: the exact distance ``δ`` satisfies ``δ ≥ |A + t̃ D| − |t̃ − t*| |D|`` (triangle inequality, ``t*`` the
exact foot), ``|t̃ − t*| |D| ≤ 12 u |A|`` (numerator and denominator of the foot within ``≈ 5.3 u`` relative
to ``|A||D|`` and ``|D|²``; clamping is 1-Lipschitz), the computed point is within ``≈ 3.1 u (|A|₁ + |D|₁)``
of ``A + t̃ D`` and the norm adds ``≈ 3 u`` relative: ``24 u (|a|₁ + |d|₁)`` in all; ``2⁻⁴⁰`` m covers every
underflow (a foot lost to ``|d|² = 0``, subnormal products). The segments cannot meet when
``|P| < δ_0 + δ_1`` or ``|E| < δ_2 + δ_3`` (a common point ``c`` splits ``P`` into ``|p_j c| ≥ δ_0`` and
``|c p_{j+1}| ≥ δ_1``, and likewise ``E``), which settles every substep shorter than ``2 r``; otherwise an
orientation test with error bounds (Shewchuk's, doubled) must prove them apart, else the substep counts as
blocked (this also catches tunnelling through thin walls). Edges whose bounding box lies farther than
``r + |P|`` from ``p_j`` (widened by ``2⁻²⁰``) are skipped: no point of ``P`` comes within ``r`` of them.
The simulator's fast path (:func:`free_radius`, one call a step) proves a radius ``ρ`` around the step's start
within which the disc keeps off every wall; a substep whose two ends lie within ``ρ`` of the start (an L1
norm, rounded upward) is clear, the disc being convex, so :func:`substep_clear` runs only near walls.

Example (a disc of radius 0.2 moving 0.05 m towards a wall 0.26 m ahead: clear; 0.07 m: blocked):
    >>> import numpy as np
    >>> from digslam.envs.sim.geometry_jit import edge_boxes
    >>> edges = np.array([[0.26, -1.0, 0.26, 1.0]])
    >>> substep_clear(0.0, 0.0, 0.05, 0.0, 0.2, edges, edge_boxes(edges))
    True
    >>> substep_clear(0.0, 0.0, 0.07, 0.0, 0.2, edges, edge_boxes(edges))
    False
    >>> from fractions import Fraction
    >>> taus = substep_times(0.1, 3)
    >>> taus.tolist(), sum(Fraction(t) for t in taus) == Fraction(0.1)
    ([0.03333333333333333, 0.03333333333333333, 0.03333333333333334], True)
"""

from __future__ import annotations

import math

import numpy as np

from digslam.envs.sim.arc_jit import yaw_rate_bounds
from digslam.envs.sim.geometry_jit import edge_near, segment_distance
from digslam.observer.core.scalar_jit import (
    add_dn,
    add_up,
    div_dn,
    div_up,
    iadd,
    imul,
    isub,
    mul_up,
    njit,
    sub_dn,
    sub_up,
    wdn,
    wup,
)

_U = 2.0**-53
_FLOOR = 2.0**-40  # m: covers every underflow term of the guard's error bound
_REACH = 1.0 + 2.0**-20  # widening of the edge pre-filter's reach


def substep_times(dt: float, substeps: int) -> np.ndarray:
    """The substep durations ``τ_j = s_{j+1} − s_j`` of a step of ``dt`` seconds (see the module): exact
    float differences, positive, summing exactly to ``dt``; ValueError when ``dt / substeps`` underflows."""
    n, dt = int(substeps), float(dt)
    if not (1 <= n <= 2**20):
        raise ValueError(f"substeps: must be an integer in [1, 2**20], got {substeps!r}")
    if not (math.isfinite(dt) and dt / n >= 2.0**-1021):
        raise ValueError(f"dt: must be finite with dt / substeps >= 2**-1021, got {dt!r}")
    s = [j * dt / n for j in range(n)] + [dt]
    return np.array([s[j + 1] - s[j] for j in range(n)])


@njit(inline="always")
def _dist_lo(qx: float, qy: float, x0: float, y0: float, x1: float, y1: float) -> float:
    """A lower bound of the distance from the point ``q`` to the segment ``s0 → s1`` (floats, see the
    module)."""
    ax, ay, dx, dy = x0 - qx, y0 - qy, x1 - x0, y1 - y0
    margin = add_up(mul_up(64.0 * _U, ((abs(ax) + abs(ay)) + (abs(dx) + abs(dy))) * (1.0 + 4.0 * _U)), _FLOOR)
    return sub_dn(segment_distance(ax, ay, dx, dy), margin)


@njit(inline="always")
def _orient(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> int:
    """The sign of the orientation ``(b − a) × (c − a)``: ``±1`` when proved, 0 when it may be 0."""
    l = (bx - ax) * (cy - ay)
    r = (by - ay) * (cx - ax)
    det = l - r
    err = 8.0 * _U * (abs(l) + abs(r)) + _FLOOR * _FLOOR
    if det > err:
        return 1
    if det < -err:
        return -1
    return 0


@njit(inline="always")
def _apart(
    x0: float, y0: float, x1: float, y1: float, ex0: float, ey0: float, ex1: float, ey1: float
) -> bool:
    """Whether the segments ``p0 p1`` and ``e0 e1`` are proved not to cross (one's endpoints strictly on
    one side of the other's line)."""
    o1 = _orient(ex0, ey0, ex1, ey1, x0, y0)
    o2 = _orient(ex0, ey0, ex1, ey1, x1, y1)
    if o1 * o2 > 0:
        return True
    o3 = _orient(x0, y0, x1, y1, ex0, ey0)
    o4 = _orient(x0, y0, x1, y1, ex1, ey1)
    return o3 * o4 > 0


@njit
def substep_clear(x0: float, y0: float, x1: float, y1: float, radius: float, edges: np.ndarray,
                  bbox: np.ndarray) -> bool:  # fmt: skip
    """Whether the disc of radius ``radius`` centred anywhere on the segment ``(x0, y0) → (x1, y1)`` is proved
    to keep off every edge of ``edges (E, 4)`` (bounding boxes ``bbox``, :func:`.geometry_jit.edge_boxes`):
    the premise guard of one substep (see the module)."""
    length = add_up((abs(x1 - x0) + abs(y1 - y0)) * (1.0 + 4.0 * _U), _FLOOR)  # >= |P|
    reach = (radius + length) * _REACH
    reach2 = reach * reach * _REACH
    for k in range(edges.shape[0]):
        if not edge_near(bbox, k, x0, y0, reach2):
            continue
        ex0, ey0, ex1, ey1 = edges[k, 0], edges[k, 1], edges[k, 2], edges[k, 3]
        d0, d1 = _dist_lo(x0, y0, ex0, ey0, ex1, ey1), _dist_lo(x1, y1, ex0, ey0, ex1, ey1)
        if not (d0 >= radius and d1 >= radius):
            return False
        d2, d3 = _dist_lo(ex0, ey0, x0, y0, x1, y1), _dist_lo(ex1, ey1, x0, y0, x1, y1)
        if not (d2 >= radius and d3 >= radius):
            return False
        if add_dn(d0, d1) > length:  # the segments cannot meet (see the module)
            continue
        edge = add_up((abs(ex1 - ex0) + abs(ey1 - ey0)) * (1.0 + 4.0 * _U), _FLOOR)  # >= |E|
        if not add_dn(d2, d3) > edge and not _apart(x0, y0, x1, y1, ex0, ey0, ex1, ey1):
            return False
    return True


@njit
def free_radius(
    x: float, y: float, radius: float, reach: float, edges: np.ndarray, bbox: np.ndarray
) -> float:
    """A radius ``ρ ≤ reach`` such that the disc of radius ``radius`` centred anywhere within ``ρ`` of
    ``(x, y)`` keeps off every edge: a lower bound of ``dist((x, y), edges) − radius``, capped at ``reach``
    (edges whose bounding box lies farther than ``radius + reach`` are skipped, widened by ``2⁻²⁰``). The
    simulator's fast path: a substep whose two ends lie within ``ρ`` of the step's start is clear (the disc
    of that radius is convex), so :func:`substep_clear` runs only near walls."""
    r = (radius + reach) * _REACH
    reach2 = r * r * _REACH
    best = reach
    for k in range(edges.shape[0]):
        if edge_near(bbox, k, x, y, reach2):
            best = min(
                best, sub_dn(_dist_lo(x, y, edges[k, 0], edges[k, 1], edges[k, 2], edges[k, 3]), radius)
            )
    return best


@njit(inline="always")
def _rate(d_lo: float, d_hi: float, tau: float) -> tuple[float, float]:
    """Outward bounds of ``d / τ`` for ``d ∈ [d_lo, d_hi]``, ``τ > 0``; exactly 0 for ``d = 0``."""
    if d_lo == 0.0 and d_hi == 0.0:
        return 0.0, 0.0
    return div_dn(d_lo, tau), div_up(d_hi, tau)


@njit(inline="always")
def _cos_sin(m: float) -> tuple[float, float, float, float]:
    """Rigorous ``[cos m]``, ``[sin m]`` (libm widened, clipped to ``[−1, 1]``; exact at ``m = 0``)."""
    if m == 0.0:
        return 1.0, 1.0, 0.0, 0.0
    c, s = math.cos(m), math.sin(m)
    return max(wdn(c), -1.0), min(wup(c), 1.0), max(wdn(s), -1.0), min(wup(s), 1.0)


@njit(inline="always")
def _unrotate(xl: float, xh: float, yl: float, yh: float, cl: float, ch: float, sl: float, sh: float
              ) -> tuple[float, float, float, float]:  # fmt: skip
    """Outward bounds of ``R(−m) (x, y) = (cos m · x + sin m · y, cos m · y − sin m · x)`` for
    ``x ∈ [xl, xh]``, ``y ∈ [yl, yh]``, ``cos m ∈ [cl, ch]``, ``sin m ∈ [sl, sh]``."""
    pl, ph = imul(xl, xh, cl, ch)
    ql, qh = imul(yl, yh, sl, sh)
    al, ah = iadd(pl, ph, ql, qh)
    pl, ph = imul(yl, yh, cl, ch)
    ql, qh = imul(xl, xh, sl, sh)
    bl, bh = isub(pl, ph, ql, qh)
    return al, ah, bl, bh


@njit
def step_bounds(states: np.ndarray, taus: np.ndarray, out: np.ndarray) -> None:
    """Rigorous bounds over a step, written into ``out (5, 2)`` (``[lo, hi]`` rows): the hulls of the true
    forward velocity ``v_1``, leftward velocity ``v_2`` and yaw rate at every instant, then the mean velocity
    ``(v̄_1, v̄_2)`` over the step in the body frame at its start (``[0, 0]`` twice for no substep); from the
    stored states ``(S + 1, 3)`` (``x, y, angle`` before the step and after each substep) and the durations
    ``τ (S,)`` (see the module)."""
    if out.shape[0] != 5 or out.shape[1] != 2 or states.shape[0] != taus.shape[0] + 1:
        raise ValueError("step_bounds: expected out (5, 2) and states (S + 1, 3) for taus (S,)")
    lo1, hi1, lo2, hi2 = math.inf, -math.inf, math.inf, -math.inf
    wlo, whi = math.inf, -math.inf
    m1l, m1h, m2l, m2h = 0.0, 0.0, 0.0, 0.0
    dt = 0.0
    for j in range(taus.shape[0]):
        tau = taus[j]
        dt += tau  # exact (see the module)
        x0, y0, a0 = states[j, 0], states[j, 1], states[j, 2]
        x1, y1, a1 = states[j + 1, 0], states[j + 1, 1], states[j + 1, 2]
        uxl, uxh = _rate(sub_dn(x1, x0), sub_up(x1, x0), tau)
        uyl, uyh = _rate(sub_dn(y1, y0), sub_up(y1, y0), tau)
        m = a0 + 0.5 * (a1 - a0)
        el, eh = sub_dn(min(a0, a1), m), sub_up(max(a0, a1), m)
        h = max(abs(el), abs(eh))
        if h <= 3.0:
            cel, ceh = max(sub_dn(1.0, mul_up(0.5, mul_up(h, h))), -1.0), 1.0
            sel, seh = min(el, 0.0), max(eh, 0.0)
        else:
            cel, ceh, sel, seh = -1.0, 1.0, -1.0, 1.0
        cl, ch, sl, sh = _cos_sin(m)
        w1l, w1h, w2l, w2h = _unrotate(uxl, uxh, uyl, uyh, cl, ch, sl, sh)
        v1l, v1h, v2l, v2h = _unrotate(w1l, w1h, w2l, w2h, cel, ceh, sel, seh)
        lo1, hi1, lo2, hi2 = min(lo1, v1l), max(hi1, v1h), min(lo2, v2l), max(hi2, v2h)
        yl, yh = yaw_rate_bounds(a0, a1, tau)
        wlo, whi = min(wlo, yl), max(whi, yh)
    out[0, 0], out[0, 1], out[1, 0], out[1, 1], out[2, 0], out[2, 1] = lo1, hi1, lo2, hi2, wlo, whi
    n = taus.shape[0]
    if dt > 0.0:  # the mean velocity in the start frame, R(-a_0) (p_S - p_0) / dt (see the module)
        dxl, dxh = sub_dn(states[n, 0], states[0, 0]), sub_up(states[n, 0], states[0, 0])
        dyl, dyh = sub_dn(states[n, 1], states[0, 1]), sub_up(states[n, 1], states[0, 1])
        cl, ch, sl, sh = _cos_sin(states[0, 2])
        w1l, w1h, w2l, w2h = _unrotate(dxl, dxh, dyl, dyh, cl, ch, sl, sh)
        (m1l, m1h), (m2l, m2h) = _rate(w1l, w1h, dt), _rate(w2l, w2h, dt)
    out[3, 0], out[3, 1], out[4, 0], out[4, 1] = m1l, m1h, m2l, m2h


@njit
def step_bounds_free(states: np.ndarray, taus: np.ndarray, out: np.ndarray, radius: float, reach: float,
                     edges: np.ndarray, bbox: np.ndarray) -> float:  # fmt: skip
    """:func:`step_bounds` into ``out``, then :func:`free_radius` around the step's end ``states[-1]``: the
    simulator's one compiled call after a step, which leaves the next step's fast path ready."""
    step_bounds(states, taus, out)
    n = states.shape[0] - 1
    return free_radius(states[n, 0], states[n, 1], radius, reach, edges, bbox)


__all__ = [
    "free_radius",
    "step_bounds",
    "step_bounds_free",
    "substep_clear",
    "substep_times",
]
