"""Compiled cell kernels of the online Dig-SLAM filter: digging ``M⁻`` (thesis §6.4, Eq. 6.21).

One step of :class:`~.online.OnlineDigSlam` touches the cells within sensor reach of the pose box ``[x]``.
These kernels loop over those cells in machine code, each bound outward rounded with :mod:`.jit`.
:func:`dig_cells` digs ``M⁻ := M⁻ ∪ g⁻¹_{[x]}(Z⁻)`` for one reading: a cell is dug when its relative box
``c - [x]`` (outward rounded) lies strictly inside the open disk ``ρ < r`` (farthest corner, squared
distance rounded up) and, for a cone, inside the narrowed cone ``θ ∈ [θ₁, θ₂]`` with ``θ₁ = ψ⁺ + α - γ``,
``θ₂ = ψ⁻ + α + γ`` (rounded inwards): for an aperture at most ``π`` that cone is
``{cross(e₁, p) >= 0} ∩ {cross(p, e₂) >= 0}``, bounded below on the box with interval products and ``e_k``
enclosed by widened ``cos``/``sin``; a wider cone is covered by two cones of aperture ``π⁻``. These are
the proofs of :meth:`.digmap.DigMap.dig_sectors` and :meth:`~.digmap.DigMap.dig_disks`; every dug cell is
also certainly sensed. The possibly sensed zone is in :mod:`.online_jit_mark`.

In the q-relaxed mode of the filter (at most ``q`` outliers among the readings of one step, thesis §2.6.2,
Eq. 2.54) a reading does not dig: :func:`_dig` with a reading stamp ``sid > 0`` counts, per cell, the readings
of the step that prove it free, and :func:`.online_jit_mark.dig_and_mark_q` digs the cells counted
``q + 1`` times (one of them at least is an inlier).

Skipping a cell never makes a false claim here (it is just not dug), so the windows are float estimates
padded by two cells; every claim is proved cell by cell.

>>> from digslam.observer.slam.grid import Grid
>>> g = Grid((-2.0, -2.0), (2.0, 2.0), (8, 8))
>>> free, sure = np.zeros(g.shape, bool), np.zeros(g.shape, bool)
>>> dig_cells(free, sure, g.xs, g.ys, -g.ys, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, np.pi, 1.2, True)
>>> free.astype(int)[3:5].tolist()            # an omni disk of radius 1.2 around the origin
[[0, 0, 1, 1, 1, 1, 0, 0], [0, 0, 1, 1, 1, 1, 0, 0]]
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.rounding import PI_DOWN
from digslam.observer.core.scalar_jit import (
    add_dn,
    add_up,
    dn,
    mul_dn,
    mul_up,
    njit,
    sub_dn,
    sub_up,
    up,
    wdn,
    wup,
)

__all__ = ["dig_cells", "dig_batch", "window"]


@njit(inline="always")
def _plo(al: float, ah: float, bl: float, bh: float) -> float:
    """Lower bound of ``[a]·[b]`` (finite): each product is within half an ulp, so one :func:`.jit.dn`
    step of the smallest bounds them all."""
    return dn(min(al * bl, al * bh, ah * bl, ah * bh))


@njit(inline="always")
def _phi(al: float, ah: float, bl: float, bh: float) -> float:
    """Upper bound of ``[a]·[b]`` (finite)."""
    return up(max(al * bl, al * bh, ah * bl, ah * bh))


@njit
def _edge(t: float) -> tuple[float, float, float, float]:
    """Enclosures ``(cos⁻, cos⁺, sin⁻, sin⁺)`` of the edge direction ``e(t)`` (libm widened)."""
    c, s = math.cos(t), math.sin(t)
    return wdn(c), wup(c), wdn(s), wup(s)


@njit
def _count(a: np.ndarray, v: float, strict: bool) -> int:
    """Number of entries of the increasing ``a`` that are ``< v`` (``<= v`` unless ``strict``): bisection."""
    lo, hi = 0, a.size
    while lo < hi:
        mid = (lo + hi) // 2
        if a[mid] < v or (not strict and a[mid] == v):
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit
def window(xs: np.ndarray, nys: np.ndarray, x0: float, y0: float, x1: float, y1: float
           ) -> tuple[int, int, int, int]:  # fmt: skip
    """Rows ``r0:r1`` and columns ``c0:c1`` of the cells meeting the closed box (``nys = -ys``)."""
    nx, ny = xs.size - 1, nys.size - 1
    c0 = min(max(_count(xs, x0, True) - 1, 0), nx)
    c1 = min(max(_count(xs, x1, False), c0), nx)
    r0 = min(max(_count(nys, -y1, True) - 1, 0), ny)
    r1 = min(max(_count(nys, -y0, False), r0), ny)
    return r0, r1, c0, c1


@njit
def _cone_window(xs: np.ndarray, nys: np.ndarray, lo0: float, lo1: float, hi0: float, hi1: float,
                 t1: float, t2: float, r: float, pad: float, c1: float, s1: float, c2: float, s2: float
                 ) -> tuple[int, int, int, int]:  # fmt: skip
    """Cells meeting the bounding box of ``[x] + {ρ <= r, θ ∈ [t1, t2]}`` (``t2 - t1 <= 2π``) plus ``pad``.

    The extreme points are the apex, the two edge ends ``r (c_k, s_k)`` (``cos``, ``sin`` of ``t_k`` within
    ``10⁻¹⁵``) and the axis points ``m π/2`` inside ``[t1, t2]``; ``pad`` (two cells) covers the rounding of
    these values and of the float multiples of ``π/2``.
    """
    ax0, ax1 = min(0.0, r * c1, r * c2), max(0.0, r * c1, r * c2)
    ay0, ay1 = min(0.0, r * s1, r * s2), max(0.0, r * s1, r * s2)
    m = math.floor(t1 / (0.5 * math.pi)) + 1.0
    for _ in range(5):
        if m * (0.5 * math.pi) <= t2:
            q = int(m % 4.0)  # the axis point (1, 0), (0, 1), (-1, 0) or (0, -1)
            if q == 0:
                ax1 = max(ax1, r)
            elif q == 1:
                ay1 = max(ay1, r)
            elif q == 2:
                ax0 = min(ax0, -r)
            else:
                ay0 = min(ay0, -r)
        m += 1.0
    return window(xs, nys, lo0 + ax0 - pad, lo1 + ay0 - pad, hi0 + ax1 + pad, hi1 + ay1 + pad)


@njit
def _axes(xs: np.ndarray, ys: np.ndarray, lo0: float, lo1: float, hi0: float, hi1: float, r0: int, r1: int,
          c0: int, c1: int) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Per column ``c0:c1`` and per row ``r0:r1`` of the relative boxes ``c - [x]`` (outward rounded): the
    lower and upper bounds, the farthest squared distance (rounded up) and the nearest (rounded down).

    Shared by every reading of one pose box: each cell test then only compares these bounds.
    """
    ax, ay = np.empty((4, c1 - c0)), np.empty((4, r1 - r0))
    for j in range(c0, c1):
        lo, hi = sub_dn(xs[j], hi0), sub_up(xs[j + 1], lo0)
        far, near = max(-lo, hi), max(lo, -hi, 0.0)
        k = j - c0
        ax[0, k], ax[1, k], ax[2, k], ax[3, k] = lo, hi, mul_up(far, far), mul_dn(near, near)
    for i in range(r0, r1):
        lo, hi = sub_dn(ys[i + 1], hi1), sub_up(ys[i], lo1)
        far, near = max(-lo, hi), max(lo, -hi, 0.0)
        k = i - r0
        ay[0, k], ay[1, k], ay[2, k], ay[3, k] = lo, hi, mul_up(far, far), mul_dn(near, near)
    return ax, ay


@njit
def _dig_cone(free: np.ndarray, sure: np.ndarray, xs: np.ndarray, nys: np.ndarray, lo0: float, lo1: float,
              hi0: float, hi1: float, t1: float, t2: float, r: float, disk: bool, ax: np.ndarray,
              ay: np.ndarray, R0: int, C0: int, cnt: np.ndarray, lst: np.ndarray, sid: int
              ) -> tuple[int, int, int, int]:  # fmt: skip
    """Dig the cells inside ``[x] + {ρ < r, θ ∈ [t1, t2]}`` (``disk``: the whole disk), ``t2 - t1 <= π``;
    ``ax``, ``ay``: :func:`_axes` of a window from row ``R0``, column ``C0`` holding the reading's window.
    Returns the window ``(r0, r1, c0, c1)`` of the cells it dug (empty: ``r0 >= r1``).

    ``sid = 0`` digs (sets ``free`` and ``sure``). ``sid > 0`` (the q-relaxed mode, :func:`_dig` of reading
    ``sid - 1``) only counts: each proved cell not yet in ``M⁻`` gets ``cnt[0] += 1`` once per reading
    (``cnt[1]`` holds the reading that counted it last, so the two halves of a wide cone count once), a cell
    counted for the first time in the step is appended to the list ``lst`` (``lst[0]`` its length, then
    flat indices ``i·nx + j``), and the window returned is that of the counted cells; ``cnt`` is then
    ``(2, ny, nx)`` and ``lst`` ``(ny·nx + 1,)``, else both unused.

    The bounds that depend on the column only (``p_x`` terms) or on the row only (``p_y`` terms) are
    computed once; each cell then compares them. A comparison ``a ≥ b`` of two bounds is exact, and so is
    ``fl(a + b) < c`` for a float ``c`` (round-to-nearest is monotone): no rounding is lost.
    """
    pad = 2.0 * max(xs[1] - xs[0], -nys[1] + nys[0])
    c1l, c1h, s1l, s1h = _edge(t1)
    c2l, c2h, s2l, s2h = _edge(t2)
    if disk:
        r0, r1, c0, c1 = window(xs, nys, lo0 - r - pad, lo1 - r - pad, hi0 + r + pad, hi1 + r + pad)
    else:
        r0, r1, c0, c1 = _cone_window(xs, nys, lo0, lo1, hi0, hi1, t1, t2, r, pad, c1l, s1l, c2l, s2l)
    r0, r1 = max(r0, R0), min(r1, R0 + ay.shape[1])
    c0, c1 = max(c0, C0), min(c1, C0 + ax.shape[1])
    if r0 >= r1 or c0 >= c1:
        return 0, 0, 0, 0
    r2 = mul_dn(r, r)
    u0, u1, v0, v1 = r1, r0, c1, c0  # the window of the dug cells
    n = c1 - c0
    sx1, sx2 = np.zeros(n), np.zeros(n)
    xl, xh, fx2 = ax[0, c0 - C0 : c1 - C0], ax[1, c0 - C0 : c1 - C0], ax[2, c0 - C0 : c1 - C0]
    if not disk:
        for k in range(n):
            sx1[k], sx2[k] = _phi(s1l, s1h, xl[k], xh[k]), _plo(s2l, s2h, xl[k], xh[k])
    for i in range(r0, r1):
        fy2 = ay[2, i - R0]
        if not fy2 < r2:
            continue
        cy1 = cy2 = 0.0
        if not disk:
            dyl, dyh = ay[0, i - R0], ay[1, i - R0]
            cy1, cy2 = _plo(c1l, c1h, dyl, dyh), _phi(c2l, c2h, dyl, dyh)
        fr, sr = free[i, c0:c1], sure[i, c0:c1]  # row slices indexed from 0 (no wraparound checks)
        if sid:
            cc, cs = cnt[0, i, c0:c1], cnt[1, i, c0:c1]
        else:
            cc = cs = cnt[0, 0, 0:0]
        for k in range(n):
            if fr[k] or not fx2[k] + fy2 < r2:  # strictly inside the open disk, farthest corner
                continue
            # min over the box of cross(e₁, p) = cos θ₁ p_y - sin θ₁ p_x >= 0, and of cross(p, e₂) >= 0
            if disk or (cy1 >= sx1[k] and sx2[k] >= cy2):
                if sid:
                    if cs[k] == sid:  # already counted for this reading (the other half of its cone)
                        continue
                    cs[k] = sid
                    if cc[k] == 0:
                        m = lst[0] + 1
                        lst[0], lst[m] = m, i * free.shape[1] + c0 + k
                    cc[k] += 1
                else:
                    fr[k] = True
                    sr[k] = True
                u0, u1, v0, v1 = min(u0, i), max(u1, i + 1), min(v0, c0 + k), max(v1, c0 + k + 1)
    return u0, u1, v0, v1


@njit
def _dig(free: np.ndarray, sure: np.ndarray, xs: np.ndarray, nys: np.ndarray, lo0: float, lo1: float,
         hi0: float, hi1: float, psi_lo: float, psi_hi: float, alpha: float, gamma: float, r: float,
         disk: bool, ax: np.ndarray, ay: np.ndarray, R0: int, C0: int, cnt: np.ndarray, lst: np.ndarray,
         sid: int) -> tuple[int, int, int, int]:  # fmt: skip
    """:func:`dig_cells` on shared :func:`_axes`; returns the window of the dug cells (:func:`_dig_cone`;
    ``sid > 0``: only count them in ``cnt`` and ``lst``, once for the reading ``sid``, the q-relaxed
    mode)."""
    if not (math.isfinite(r) and r > 0.0):
        return 0, 0, 0, 0
    if disk:
        return _dig_cone(free, sure, xs, nys, lo0, lo1, hi0, hi1, 0.0, 0.0, r, True, ax, ay, R0, C0, cnt,
                         lst, sid)  # fmt: skip
    t1, t2 = sub_up(add_up(psi_hi, alpha), gamma), add_dn(add_dn(psi_lo, alpha), gamma)
    if not (math.isfinite(t1) and math.isfinite(t2) and t1 <= t2):
        return 0, 0, 0, 0
    if sub_up(t2, t1) > PI_DOWN:  # [θ₁, θ₁ + π⁻] and [θ₂ - π⁻, θ₂], both inside [θ₁, θ₂]
        t3, t4 = add_dn(t1, PI_DOWN), sub_up(t2, PI_DOWN)
        a = _dig_cone(free, sure, xs, nys, lo0, lo1, hi0, hi1, t1, t3, r, False, ax, ay, R0, C0, cnt, lst,
                      sid)  # fmt: skip
        b = _dig_cone(free, sure, xs, nys, lo0, lo1, hi0, hi1, t4, t2, r, False, ax, ay, R0, C0, cnt, lst,
                      sid)  # fmt: skip
        return union(a, b)
    return _dig_cone(free, sure, xs, nys, lo0, lo1, hi0, hi1, t1, t2, r, False, ax, ay, R0, C0, cnt, lst, sid)


@njit(inline="always")
def union(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
    """Smallest window ``(r0, r1, c0, c1)`` holding the windows ``a`` and ``b`` (empty: ``r0 >= r1`` or
    ``c0 >= c1``)."""
    if a[0] >= a[1] or a[2] >= a[3]:
        return b
    if b[0] >= b[1] or b[2] >= b[3]:
        return a
    return min(a[0], b[0]), max(a[1], b[1]), min(a[2], b[2]), max(a[3], b[3])


@njit
def _reach_axes(xs: np.ndarray, ys: np.ndarray, nys: np.ndarray, lo0: float, lo1: float, hi0: float,
                hi1: float, r: float) -> tuple[np.ndarray, np.ndarray, int, int]:  # fmt: skip
    """:func:`_axes` on the window of the box grown by ``r`` plus two cells (holds every reading's window
    of range ``<= r``)."""
    pad = 2.0 * max(xs[1] - xs[0], ys[0] - ys[1])
    r0, r1, c0, c1 = window(xs, nys, lo0 - r - pad, lo1 - r - pad, hi0 + r + pad, hi1 + r + pad)
    ax, ay = _axes(xs, ys, lo0, lo1, hi0, hi1, r0, r1, c0, c1)
    return ax, ay, r0, c0


@njit(inline="always")
def _box_ok(lo0: float, lo1: float, hi0: float, hi1: float) -> bool:
    return lo0 <= hi0 and lo1 <= hi1 and math.isfinite(lo0 + lo1 + hi0 + hi1)


@njit
def dig_cells(free: np.ndarray, sure: np.ndarray, xs: np.ndarray, ys: np.ndarray, nys: np.ndarray,
              lo0: float, lo1: float, hi0: float, hi1: float, psi_lo: float, psi_hi: float, alpha: float,
              gamma: float, r: float, disk: bool) -> None:  # fmt: skip
    """Eq. 6.21 for one reading (free range ``r``) from the pose box ``[lo, hi]``, heading ``[ψ]``.

    ``disk``: the omnidirectional sensor (the open disk; ``psi``, ``alpha``, ``gamma`` unused); empty boxes,
    ``r`` not finite or ``<= 0``, and empty narrowed cones dig nothing. ``free``, ``sure``: updated in place.
    """
    if not (_box_ok(lo0, lo1, hi0, hi1) and math.isfinite(r) and r > 0.0):
        return
    ax, ay, R0, C0 = _reach_axes(xs, ys, nys, lo0, lo1, hi0, hi1, r)
    _dig(free, sure, xs, nys, lo0, lo1, hi0, hi1, psi_lo, psi_hi, alpha, gamma, r, disk, ax, ay, R0, C0,
         np.zeros((2, 1, 1), np.int32), np.zeros(1, np.int32), 0)  # fmt: skip


@njit
def dig_batch(free: np.ndarray, sure: np.ndarray, xs: np.ndarray, ys: np.ndarray, nys: np.ndarray,
              lo: np.ndarray, hi: np.ndarray, psi_lo: np.ndarray, psi_hi: np.ndarray, alpha: np.ndarray,
              gamma: np.ndarray, r: np.ndarray, disk: np.ndarray) -> None:  # fmt: skip
    """:func:`dig_cells` for each row ``k`` of a batch (pose boxes ``(N, 2)``, the rest ``(N,)``)."""
    for k in range(r.size):
        dig_cells(free, sure, xs, ys, nys, lo[k, 0], lo[k, 1], hi[k, 0], hi[k, 1], psi_lo[k], psi_hi[k],
                  alpha[k], gamma[k], r[k], disk[k])  # fmt: skip
