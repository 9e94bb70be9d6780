"""Array kernels of the differential contractor ``C_d/dt`` on sliced tubes (thesis §2.5.4, Eq. 2.76).

The tube lives on a time grid ``t_0 < ... < t_T``: gates ``[x_k]`` (boxes at ``t_k``) and slices
``[s_k]`` (envelopes over ``[t_k, t_{k+1}]``), with ``ẋ = u`` and ``u(τ) ∈ [u_k]`` for ``τ`` in slice ``k``
(Remark 2.12: ``[u]`` is a parameter, never contracted). Over slice ``k`` the increment
``Δ_k = x(t_{k+1}) - x(t_k) = ∫ u`` lies in ``[d_k] = [dt_k]·[u_k]`` (``[dt_k]`` encloses the exact
``t_{k+1} - t_k``), so the gates obey the chain of difference constraints
``x_{k+1} ∈ x_k + [d_k]``. Per coordinate, the forward pass for the lower bounds

    ``L_0 = c_0,   L_{k+1} = max(c_{k+1}, L_k + d_k)``        (c: the gate lower bounds, d: d_lo)

is a max-plus recurrence with the closed form ``L_k = max_{j<=k} (c_j + S_k - S_j)``,
``S_k = Σ_{i<k} d_i``, which numpy evaluates without a loop over time (:func:`maxplus_lower`).

**Soundness** (every bound is a guaranteed lower bound of the exact value). Let ``x`` be a trajectory
with ``x(t_j) >= c_j`` and increments ``Δ_i >= d_i``. For every ``j <= k`` with no ``d_i = -∞`` in between,
``x(t_k) = x(t_j) + Σ_{j<=i<k} Δ_i >= c_j + S_k - S_j`` in exact arithmetic.
Prefix sums (:func:`cumsum_enclosure`): numpy's ``cumsum`` gives ``ŝ``; when its steps are the
sequential ``ŝ_{i+1} = fl(ŝ_i + d_i)`` (checked), TwoSum gives each step's exact error ``e_i`` with
``ŝ_i + d_i = ŝ_{i+1} + e_i``, so ``S_k = ŝ_k + Σ_{i<k} e_i`` exactly (telescoping). A float sum ``ĉ_k`` of
``k`` terms is within ``γ_{k-1} Σ|e_i|`` of the exact one, any order, additions having no underflow
error (Higham, Accuracy and Stability, Eq. 4.4; ``γ_m = mu/(1-mu)``, ``u = 2⁻⁵³``); with the computed
``P̂_k ≈ Σ|e_i|`` (``P_k <= P̂_k/(1-γ_{k-1})``), ``ρ_k = k·2⁻⁵²·P̂_k`` rounded up bounds it for ``k <= 2⁵⁰``.
So ``S_k ∈ [ŝ_k + ĉ_k - ρ_k, ŝ_k + ĉ_k + ρ_k]``, every operation rounded outward: exact when the
sums are exact, a few ulps wide otherwise. (Were ``cumsum`` not sequential, the same bound is applied
to ``ŝ`` and ``Σ|d_i|`` directly.) Overflow gives ``S⁻ = -∞``, ``S⁺ = +∞``, which only loses contraction.
Then ``c_j + S_k - S_j >= A_j + S⁻_k`` with ``A_j = sub_down(c_j, S⁺_j) <= c_j - S⁺_j``, and since
``add_down`` is monotone, ``max_j add_down(A_j, S⁻_k) = add_down(max_{j<=k} A_j, S⁻_k)`` is a lower
bound of ``x(t_k)``: a running maximum (``np.maximum.accumulate``). Where some ``d_i = -∞`` (unbounded
input) the chain is cut: the maximum runs over the segment since the last cut only (a sparse table
of range maxima, exact). The result differs from the sequential rounded recurrence by a few ulps.
The upper bounds and the backward pass (``x_k ∈ x_{k+1} - [d_k]``) are the same kernel on negated
and reversed arrays; slices use ``x(τ) ∈ x_k + [0, dt_k]·[u_k]`` and ``x(τ) ∈ x_{k+1} - [0, dt_k]·[u_k]``.

>>> c = np.array([[0.0], [-np.inf], [5.0], [-np.inf]])     # lower bounds of 4 gates
>>> d = np.array([[1.0], [1.0], [-2.0]])                   # lower bounds of the 3 increments
>>> maxplus_lower(c, d).ravel().tolist()
[0.0, 1.0, 5.0, 3.0]
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core import arith, trig
from digslam.observer.core import rounding as rnd
from digslam.observer.core.types import Pair

_INF = np.inf


def _cumsum_radius(a: np.ndarray, s: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Rounded-up bound ``k·2⁻⁵²·Σ|a_i|`` of ``|s_k - Σ_{i<k} a_i|`` for ``s = cumsum(a)``."""
    p = np.zeros_like(s)
    np.cumsum(np.abs(a), axis=0, out=p[1:])
    return np.where(p == 0, 0.0, rnd.next_up(k * p))  # k exact: fl(k·p) within ½ ulp (or 2⁻¹⁰⁷⁵) of k·p


def cumsum_enclosure(d: np.ndarray) -> Pair:
    """Floats ``S⁻ <= S <= S⁺`` around the exact prefix sums ``S_k = Σ_{i<k} d_i`` (``S_0 = 0``).

    Compensated: the exact rounding errors of the ``cumsum`` steps are summed again, so the enclosure
    is exact when the sums are, and otherwise a few ulps wide (proof in the module docstring).

    Args:
        d: ``(T, n)`` finite floats.

    Returns:
        ``(S⁻, S⁺)`` of shape ``(T+1, n)``; ``(-∞, +∞)`` where a sum overflows.
    """
    T, n = d.shape
    if T >= 2**50:
        raise ValueError(f"d: {T} terms is beyond the error bound's range (2**50)")
    s = np.zeros((T + 1, n))
    k = np.arange(T + 1, dtype=np.float64)[:, None] * 2.0**-52
    with np.errstate(over="ignore", invalid="ignore"):
        np.cumsum(d, axis=0, out=s[1:])
        r = s[:-1] + d  # the step cumsum took, when it sums sequentially
        if np.array_equal(r, s[1:]):
            e = (s[:-1] - (r - (r - s[:-1]))) + (d - (r - s[:-1]))  # TwoSum: s_i + d_i = s_{i+1} + e_i
            c = np.zeros_like(s)
            np.cumsum(e, axis=0, out=c[1:])
            rad = _cumsum_radius(e, c, k)
            lo = rnd.add_down(s, rnd.sub_down(c, rad))
            hi = rnd.add_up(s, rnd.add_up(c, rad))
        else:  # another summation order: the a-priori bound of recursive summation
            rad = _cumsum_radius(d, s, k)
            lo, hi = rnd.sub_down(s, rad), rnd.add_up(s, rad)
    bad = ~(np.isfinite(lo) & np.isfinite(hi))
    if bad.any():
        lo, hi = np.where(bad, -_INF, lo), np.where(bad, _INF, hi)
    return lo, hi


def _segment_max(a: np.ndarray, cut: np.ndarray) -> np.ndarray:
    """``m_k = max(a_j : s_k <= j <= k)`` with ``s_k`` the last segment start ``<= k`` (``cut[i]``: a
    segment starts at ``i + 1``), column by column, by a sparse table of range maxima (exact)."""
    T1, n = a.shape
    idx = np.arange(T1)[:, None]
    mark = np.zeros((T1, n), dtype=bool)
    mark[0] = True
    mark[1:] = cut
    start = np.maximum.accumulate(np.where(mark, idx, 0), axis=0)
    table = [a]
    w = 1
    while 2 * w <= T1:  # log2(T) levels: table[l][i] = max a[i : i + 2**l]
        prev = table[-1]
        nxt = prev.copy()
        nxt[: T1 - w] = np.maximum(prev[: T1 - w], prev[w:])
        table.append(nxt)
        w *= 2
    tab = np.stack(table)
    length = idx - start + 1
    lev = np.frexp(length.astype(np.float64))[1] - 1  # floor(log2(length))
    cols = np.broadcast_to(np.arange(n), (T1, n))
    return np.maximum(tab[lev, start, cols], tab[lev, idx - (1 << lev) + 1, cols])


def maxplus_lower(c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Guaranteed lower bounds of ``L_0 = c_0, L_{k+1} = max(c_{k+1}, L_k + d_k)`` (exact reals).

    Args:
        c: ``(T+1, n)`` lower bounds, none ``+∞``.
        d: ``(T, n)`` lower bounds of the increments, none ``+∞`` (``-∞`` cuts the chain).

    Returns:
        ``(T+1, n)`` floats ``<= L_k`` and ``>= c_k`` (proof in the module docstring).
    """
    cut = d == -_INF
    s_lo, s_hi = cumsum_enclosure(np.where(cut, 0.0, d))
    with np.errstate(invalid="ignore"):
        a = rnd.sub_down(c, s_hi)
        m = _segment_max(a, cut) if cut.any() else np.maximum.accumulate(a, axis=0)
        low = rnd.add_down(s_lo, m)
    return np.fmax(c, low)  # fmax: a NaN (impossible by construction) would fall back to c


def increments(t: np.ndarray, u_lo: np.ndarray, u_hi: np.ndarray) -> Pair:
    """``[d_k] = [t_{k+1} - t_k]·[u_k]`` with the time step enclosed by outward rounding.

    ``[dt] > 0``, so each bound is one directed product: ``d⁻ = dt^∓·u⁻`` (``dt⁻`` when ``u⁻ >= 0``),
    ``d⁺ = dt^±·u⁺``; infinite ``u`` bounds stay infinite (``dt⁻ > 0``: ``t`` strictly increases).
    """
    dt_lo, dt_hi = rnd.sub_down(t[1:], t[:-1])[:, None], rnd.sub_up(t[1:], t[:-1])[:, None]
    with np.errstate(invalid="ignore"):
        d_lo = rnd.mul_down(np.where(u_lo >= 0, dt_lo, dt_hi), u_lo)
        d_hi = rnd.mul_up(np.where(u_hi >= 0, dt_hi, dt_lo), u_hi)
    return d_lo, d_hi


def _upper(c_hi: np.ndarray, d_hi: np.ndarray) -> np.ndarray:
    return -maxplus_lower(-c_hi, -d_hi) + 0.0


def _first(lo: np.ndarray, hi: np.ndarray) -> int | None:
    bad = (lo > hi).any(axis=1)
    return int(np.argmax(bad)) if bad.any() else None


def deriv_arrays(
    t: np.ndarray,
    gates: Pair,
    slices: Pair,
    u: Pair,
    forward: bool = True,
    backward: bool = True,
    increment: Pair | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int | None]:
    """``C_d/dt`` on arrays (non-empty inputs): returns ``(gate_lo, gate_hi, slice_lo, slice_hi, bad)``.

    ``increment`` (optional, ``(T, n)`` twice) bounds the gate increments ``x_{k+1} - x_k`` directly (e.g.
    an odometry increment): the gate passes use its intersection with ``[dt_k]·[u_k]``; the slices still
    use ``[0, dt_k]·[u_k]`` (an increment says nothing about the path inside the slice).
    ``bad`` is None, or the index of the first gate (or slice) found empty, in the order of the passes
    (gates against their slices, forward, backward, slices, gates): no trajectory is consistent.
    """
    (glo, ghi), (slo, shi) = gates, slices
    u_dlo, u_dhi = d_lo, d_hi = increments(t, *u)
    if increment is not None:
        d_lo, d_hi = np.maximum(d_lo, increment[0]), np.minimum(d_hi, increment[1])
        if (d_lo > d_hi).any():  # the increment contradicts the velocity: slice k, so gate k + 1
            return glo, ghi, slo, shi, _first(d_lo, d_hi) + 1  # type: ignore[operator]  # not None: a row is empty
    glo, ghi = glo.copy(), ghi.copy()  # gates inside both adjacent slices (slices are closed envelopes)
    glo[:-1], ghi[:-1] = np.maximum(glo[:-1], slo), np.minimum(ghi[:-1], shi)
    glo[1:], ghi[1:] = np.maximum(glo[1:], slo), np.minimum(ghi[1:], shi)
    if (glo > ghi).any():
        return glo, ghi, slo, shi, _first(glo, ghi)
    if forward:  # x_{k+1} &= x_k + [d_k]
        glo, ghi = maxplus_lower(glo, d_lo), _upper(ghi, d_hi)
        if (glo > ghi).any():
            return glo, ghi, slo, shi, _first(glo, ghi)
    if backward:  # x_k &= x_{k+1} - [d_k]
        glo = maxplus_lower(glo[::-1], -d_hi[::-1])[::-1]
        ghi = _upper(ghi[::-1], -d_lo[::-1])[::-1]
        if (glo > ghi).any():
            return glo, ghi, slo, shi, _first(glo, ghi)
    z_lo, z_hi = np.minimum(u_dlo, 0.0), np.maximum(u_dhi, 0.0)  # [0, dt]·[u] ⊂ hull(0, [d])
    with np.errstate(invalid="ignore"):
        slo = np.fmax(slo, np.fmax(rnd.add_down(glo[:-1], z_lo), rnd.sub_down(glo[1:], z_hi)))
        shi = np.fmin(shi, np.fmin(rnd.add_up(ghi[:-1], z_hi), rnd.sub_up(ghi[1:], z_lo)))
    if (slo > shi).any():
        return glo, ghi, slo, shi, _first(slo, shi)
    glo[:-1], ghi[:-1] = np.maximum(glo[:-1], slo), np.minimum(ghi[:-1], shi)
    glo[1:], ghi[1:] = np.maximum(glo[1:], slo), np.minimum(ghi[1:], shi)
    return glo, ghi, slo, shi, _first(glo, ghi)


def _interval_arrays(name: str, lo: object, hi: object) -> Pair:
    lo_a, hi_a = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    if lo_a.ndim == 2 and lo_a.shape[1:] == hi_a.shape[1:] == (1,):  # a 1-d tube's slices
        lo_a, hi_a = lo_a[:, 0], hi_a[:, 0]
    if lo_a.ndim != 1 or lo_a.shape != hi_a.shape:
        raise ValueError(f"{name}: expected lo and hi of one shape (T,), got {lo_a.shape} and {hi_a.shape}")
    if np.isnan(lo_a).any() or np.isnan(hi_a).any():
        raise ValueError(f"{name}: NaN bound")
    if (lo_a > hi_a).any():
        raise ValueError(f"{name}: lower bound above upper bound at index {int(np.argmax(lo_a > hi_a))}")
    return lo_a, hi_a


def unicycle_velocity(speed_lo: object, speed_hi: object, heading_lo: object, heading_hi: object) -> Pair:
    """Per-slice velocity boxes ``(T, 2)`` of ``ẋ = v (cos ψ, sin ψ)`` (Eq. 6.23, B.20 with a forward
    speed): ``[u_k] ⊃ {v (cos ψ, sin ψ) : v ∈ [v_k], ψ ∈ [ψ_k]}``, outward rounded.

    Args:
        speed_lo, speed_hi: ``(T,)`` speed over each slice.
        heading_lo, heading_hi: ``(T,)`` (or ``(T, 1)``) heading over each slice (a heading tube's
            ``slice_lo``, ``slice_hi``).
    """
    v = _interval_arrays("speed", speed_lo, speed_hi)
    psi = _interval_arrays("heading", heading_lo, heading_hi)
    if v[0].shape != psi[0].shape:
        raise ValueError(f"heading: shape {psi[0].shape} differs from speed's {v[0].shape}")
    u1, u2 = arith.mul(v, trig.cos(psi)), arith.mul(v, trig.sin(psi))
    return np.stack([u1[0], u2[0]], axis=1), np.stack([u1[1], u2[1]], axis=1)


def body_velocity(v_lo: object, v_hi: object, heading_lo: object, heading_hi: object) -> Pair:
    """``ẋ = R(ψ)·v`` (Eq. 3.59, 6.12, B.20) with ``v = (v_1, v_2)`` in the robot frame, per slice.

    ``[u_k] ⊃ {R(ψ) v : v ∈ [v_k], ψ ∈ [ψ_k]}`` by the natural inclusion function
    ``(v_1 cos ψ - v_2 sin ψ, v_1 sin ψ + v_2 cos ψ)``, outward rounded. A row with ``[v_2] = [0, 0]`` (a
    unicycle, which cannot slip sideways) is :func:`unicycle_velocity` to the bit: ``- [0, 0]·sin ψ`` is
    exactly zero, and dropping it keeps the signs of zero bounds (``x - (-0.0)`` turns a ``-0.0`` into
    ``+0.0``), so a unicycle record gives the unicycle's tube to the bit.

    Args:
        v_lo, v_hi: ``(T, 2)`` body-frame velocity over each slice.
        heading_lo, heading_hi: ``(T,)`` heading over each slice.

    Returns:
        ``(u_lo, u_hi)`` of shape ``(T, 2)``: ``(v_1 cos ψ - v_2 sin ψ, v_1 sin ψ + v_2 cos ψ)``.
    """
    vl, vh = np.asarray(v_lo, dtype=np.float64), np.asarray(v_hi, dtype=np.float64)
    if vl.ndim != 2 or vl.shape[1] != 2 or vl.shape != vh.shape:
        raise ValueError(f"v: expected lo and hi of shape (T, 2), got {vl.shape} and {vh.shape}")
    v1 = _interval_arrays("v", vl[:, 0], vh[:, 0])
    v2 = _interval_arrays("v", vl[:, 1], vh[:, 1])
    psi = _interval_arrays("heading", heading_lo, heading_hi)
    if psi[0].shape != v1[0].shape:
        raise ValueError(f"heading: shape {psi[0].shape} differs from v's {vl.shape}")
    c, s = trig.cos(psi), trig.sin(psi)
    a1, a2 = arith.mul(v1, c), arith.mul(v1, s)  # the unicycle terms (Eq. 6.23)
    uni = (v2[0] == 0) & (v2[1] == 0)
    if uni.all():
        u1, u2 = a1, a2
    else:
        u1 = arith.sub(a1, arith.mul(v2, s))
        u2 = arith.add(a2, arith.mul(v2, c))
        if uni.any():
            u1 = (np.where(uni, a1[0], u1[0]), np.where(uni, a1[1], u1[1]))
            u2 = (np.where(uni, a2[0], u2[0]), np.where(uni, a2[1], u2[1]))
    return np.stack([u1[0], u2[0]], axis=1), np.stack([u1[1], u2[1]], axis=1)


__all__ = [
    "body_velocity",
    "cumsum_enclosure",
    "deriv_arrays",
    "increments",
    "maxplus_lower",
    "unicycle_velocity",
]
