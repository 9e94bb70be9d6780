"""Compiled pose kernels of the online Dig-SLAM filter: the tube prediction (Eq. 6.23) and the impact
contractor on the cells of one pose box (Eq. 6.22), outward rounded with :mod:`.jit`.

* :func:`predict` is one step of the tube: ``ψ_k ∈ ([ψ_{k-1}] + [dt]·[ω_k]) ∩ [compass]``, the heading over
  the slice ``[t_{k-1}, t_k]`` (both ends reachable, the gyro bounding the drift), and
  ``x_k ∈ x_{k-1} + [dt]·[v_k]·(cos, sin)([ψ] on the slice)``; every correctly rounded operation is
  stepped one ulp outward, ``cos``/``sin`` enclosed by :func:`cos_sin`.
* :func:`impact_bound_q` is the radius of the impact constraint, q-relaxed (§2.6.2) when the filter allows
  ``q`` outliers per step: the ``(q + 1)``-th smallest upper range.
* :func:`clearance_cells` bounds ``dist(p, comp M⁻)`` from below for the cells of a pose box: the centre
  distance ``D`` to the nearest not-free cell of a window (the ring around the window counts as not free),
  then ``D(1 - EDT_SLACK) - diag`` (triangle inequality; the slack covers the rounding, as in
  :meth:`.digmap.DigMap.clearance_lower`). :func:`contract` keeps the hull of the feasible cells.

>>> cl, ch, sl, sh = cos_sin(-0.1, 0.1)
>>> bool(cl < math.cos(0.1) and ch >= 1.0 and sl < -math.sin(0.1) and sh > math.sin(0.1))
True
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.rounding import HALF_PI_DOWN, HALF_PI_UP
from digslam.observer.core.scalar_jit import dn, njit, up
from digslam.observer.online.dig_jit import window

__all__ = ["cos_sin", "predict", "clearance_cells", "contract", "impact_bound", "impact_bound_q"]

#: Absolute widening of a libm ``cos``/``sin`` value (``|v| <= 1``): 4 ulps of 1 plus the subtraction's.
TRIG_PAD = 2e-15


@njit(inline="always")
def _mul(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """Outward-rounded product of two finite intervals."""
    p, q, r, s = al * bl, al * bh, ah * bl, ah * bh
    return dn(min(p, q, r, s)), up(max(p, q, r, s))


@njit
def cos_sin(a: float, b: float) -> tuple[float, float, float, float]:
    """Enclosures ``(cos⁻, cos⁺, sin⁻, sin⁺)`` over ``[a, b]``: endpoints widened, plus every extremum
    ``m·π/2`` that may lie in ``[a, b]`` (slack on the float multiple of ``π/2``)."""
    if not (math.isfinite(a) and math.isfinite(b)):
        return -1.0, 1.0, -1.0, 1.0
    f0, f1 = math.floor(a / HALF_PI_UP) - 1.0, math.floor(b / HALF_PI_DOWN) + 1.0
    if f1 - f0 > 8.0:
        return -1.0, 1.0, -1.0, 1.0
    ca, cb, sa, sb = math.cos(a), math.cos(b), math.sin(a), math.sin(b)
    c0, c1 = min(ca, cb) - TRIG_PAD, max(ca, cb) + TRIG_PAD
    s0, s1 = min(sa, sb) - TRIG_PAD, max(sa, sb) + TRIG_PAD
    for m in range(int(f0), int(f1) + 1):
        p = m * HALF_PI_DOWN
        eps = abs(p) * 1e-15 + 1e-300
        if a - eps <= p <= b + eps:
            q = m % 4
            if q == 0:
                c1 = 1.0
            elif q == 1:
                s1 = 1.0
            elif q == 2:
                c0 = -1.0
            else:
                s0 = -1.0
    return max(c0, -1.0), min(c1, 1.0), max(s0, -1.0), min(s1, 1.0)


@njit
def predict(
    lo0: float,
    lo1: float,
    hi0: float,
    hi1: float,
    h0l: float,
    h0h: float,
    dt: float,
    yaw_lo: float,
    yaw_hi: float,
    comp_lo: float,
    comp_hi: float,
    v_lo: float,
    v_hi: float,
) -> tuple[bool, float, float, float, float, float, float, float, float, float, float]:  # noqa: E501
    """One tube step (Eq. 6.23, heading fused with the compass, Eq. 6.12).

    Returns ``(ok, ψ⁻, ψ⁺, x⁻, y⁻, x⁺, y⁺, d_x⁻, d_y⁻, d_x⁺, d_y⁺)`` with ``d`` the displacement box;
    ``ok`` False when the heading or its slice is empty (the data contradict their bounds).
    """
    dtl, dth = dn(dt), up(dt)
    wl, wh = _mul(dtl, dth, yaw_lo, yaw_hi)
    hl, hh = max(comp_lo, dn(h0l + wl)), min(comp_hi, up(h0h + wh))
    zl, zh = min(wl, 0.0), max(wh, 0.0)
    sl, sh = max(dn(h0l + zl), dn(hl - zh)), min(up(h0h + zh), up(hh - zl))
    nan = math.nan
    if not (hl <= hh and sl <= sh):
        return False, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan
    cl, ch, snl, snh = cos_sin(sl, sh)
    a, b = _mul(v_lo, v_hi, cl, ch)
    d0l, d0h = _mul(dtl, dth, a, b)
    a, b = _mul(v_lo, v_hi, snl, snh)
    d1l, d1h = _mul(dtl, dth, a, b)
    return True, hl, hh, dn(lo0 + d0l), dn(lo1 + d1l), up(hi0 + d0h), up(hi1 + d1h), d0l, d1l, d0h, d1h


@njit
def clearance_cells(free: np.ndarray, b0: int, b1: int, a0: int, a1: int, w0: int, w1: int, v0: int, v1: int,
                    dx: float, dy: float, keep: float, off: float) -> np.ndarray:  # fmt: skip
    """Lower bounds ``(b1 - b0, a1 - a0)`` on ``dist(p, comp M⁻)`` for the cells ``[b0:b1, a0:a1]``, taking
    the cells of ``comp M⁻`` from the window ``[w0:w1, v0:v1]`` (which holds them) and its ring.

    ``keep = 1 - EDT_SLACK`` and ``off = diag + EDT_SLACK·span`` as in :meth:`.digmap.DigMap.clearance_lower`.
    """
    rows, cols, n = _not_free(free, w0, w1, v0, v1)
    out = np.zeros((b1 - b0, a1 - a0))
    for i in range(b0, b1):
        pr = i - w0
        for j in range(a0, a1):
            if not free[i, j]:
                continue
            pc = j - v0
            d2 = math.inf
            for k in range(n):
                ey, ex = (pr - rows[k]) * dy, (pc - cols[k]) * dx
                d2 = min(d2, ey * ey + ex * ex)
            ring = min(min(pr + 1, w1 - w0 - pr) * dy, min(pc + 1, v1 - v0 - pc) * dx)
            d = min(math.sqrt(d2), ring)
            out[i - b0, j - a0] = max(dn(d * keep - off), 0.0)
    return out


@njit
def _not_free(free: np.ndarray, w0: int, w1: int, v0: int, v1: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Rows and columns (relative to the window) of the cells of ``[w0:w1, v0:v1]`` not in ``M⁻``."""
    n = 0
    rows, cols = np.empty((w1 - w0) * (v1 - v0), np.int64), np.empty((w1 - w0) * (v1 - v0), np.int64)
    for i in range(w0, w1):
        for j in range(v0, v1):
            if not free[i, j]:
                rows[n], cols[n] = i - w0, j - v0
                n += 1
    return rows, cols, n


@njit
def _feasible(free: np.ndarray, i: int, j: int, r_hi: float, w0: int, w1: int, v0: int, v1: int, dx: float,
              dy: float, keep: float, off: float) -> bool:  # fmt: skip
    """Whether cell ``(i, j)`` may hold a pose: its :func:`clearance_cells` bound is ``<= r⁺``.

    The bound is monotone in the distance, so the cell is feasible iff the ring or one not-free cell of the
    window is near enough; only the cells within the generous radius ``(r⁺ + off) / keep · (1 + 10⁻⁹)`` of
    its centre can be, and each candidate is decided by the exact bound of :func:`clearance_cells`.
    """
    if not free[i, j]:
        return True
    pr, pc = i - w0, j - v0
    ring = min(min(pr + 1, w1 - w0 - pr) * dy, min(pc + 1, v1 - v0 - pc) * dx)
    if max(dn(ring * keep - off), 0.0) <= r_hi:
        return True
    rad = (r_hi + off) / keep * (1.0 + 1e-9)
    t = rad * rad
    kr = int(rad / dy) + 1
    for di in range(max(-kr, w0 - i), min(kr, w1 - 1 - i) + 1):
        ey = di * dy
        rem = t - ey * ey
        if rem < 0.0:
            continue
        kc = int(math.sqrt(rem) / dx) + 1
        for dj in range(max(-kc, v0 - j), min(kc, v1 - 1 - j) + 1):
            if not free[i + di, j + dj]:
                ex = dj * dx
                if max(dn(math.sqrt(ey * ey + ex * ex) * keep - off), 0.0) <= r_hi:
                    return True
    return False


@njit
def contract(free: np.ndarray, xs: np.ndarray, ys: np.ndarray, nys: np.ndarray, lo0: float, lo1: float,
             hi0: float, hi1: float, r_hi: float, dx: float, dy: float, keep: float, off: float
             ) -> tuple[float, float, float, float]:  # fmt: skip
    """Eq. 6.22 on the cells of the box ``[lo, hi]``: the box cut to the hull of the cells with clearance
    ``<= r⁺`` (:func:`_feasible` on the window ``[x] ± (r⁺ + 2 cells)``; exact cell bounds);
    ``(inf, inf, -inf, -inf)`` when none is."""
    b0, b1, a0, a1 = window(xs, nys, lo0, lo1, hi0, hi1)
    reach = r_hi + 2.0 * max(dx, dy)
    w0, w1, v0, v1 = window(xs, nys, lo0 - reach, lo1 - reach, hi0 + reach, hi1 + reach)
    rmin, rmax, cmin, cmax = b1, -1, a1, -1
    for i in range(b0, b1):
        for j in range(a0, a1):
            if _feasible(free, i, j, r_hi, w0, w1, v0, v1, dx, dy, keep, off):
                rmin, rmax = min(rmin, i - b0), max(rmax, i - b0)
                cmin, cmax = min(cmin, j - a0), max(cmax, j - a0)
    if rmax < 0:
        return math.inf, math.inf, -math.inf, -math.inf
    return (max(lo0, xs[a0 + cmin]), max(lo1, ys[b0 + rmax + 1]), min(hi0, xs[a0 + cmax + 1]),
            min(hi1, ys[b0 + rmin]))  # fmt: skip


@njit
def impact_bound(no_echo: np.ndarray, rng: np.ndarray) -> float:
    """Smallest upper range bound over the echoing sensors (``inf`` if none echoed)."""
    out = math.inf
    for k in range(no_echo.size):
        if not no_echo[k]:
            out = min(out, rng[k, 1])
    return out


@njit
def impact_bound_q(no_echo: np.ndarray, rng: np.ndarray, q: int) -> float:
    """Radius of the q-relaxed impact constraint (Eq. 6.22 under thesis §2.6.2, Eq. 2.54): the ``(q + 1)``-th
    smallest upper range bound over the echoing sensors (``inf`` if fewer than ``q + 1`` echoed).

    Each echo ``k`` says an obstacle point lies within ``y_k⁺`` of the position, hence (outside ``M⁻``)
    ``dist(x, comp M⁻) <= y_k⁺``. These sets are nested in ``y_k⁺``, so the points that satisfy all but at
    most ``q`` of them, the q-relaxed intersection, are exactly ``dist(x, comp M⁻) <= y⁺_(q+1)``: with at
    most ``q`` false echoes one of the ``q + 1`` smallest is true. ``q = 0`` is :func:`impact_bound`.
    """
    if q == 0:
        return impact_bound(no_echo, rng)
    best = np.full(q + 1, math.inf)  # the q + 1 smallest so far, increasing
    for k in range(no_echo.size):
        v = rng[k, 1]
        if no_echo[k] or not v < best[q]:
            continue
        j = q
        while j > 0 and best[j - 1] > v:
            best[j] = best[j - 1]
            j -= 1
        best[j] = v
    return best[q]
