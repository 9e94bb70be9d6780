"""Compiled pose kernels of the online Dig-SLAM filter: the tube prediction (Eq. 6.23) and the impact
contractor on the cells of one pose box (Eq. 6.22), outward rounded with
:mod:`digslam.observer.core.scalar_jit`.

* :func:`predict` is one step of the tube: ``ψ_k ∈ ([ψ_{k-1}] + [dt]·[ω_k]) ∩ [compass]``, the heading over
  the slice ``[t_{k-1}, t_k]`` (both ends reachable, the gyro bounding the drift), and
  ``x_k ∈ x_{k-1} + [dt]·R([ψ] on the slice)·[v_k]`` with the body-frame velocity ``v = (v_1, v_2)``
  (``x' = R(ψ) v``, Eq. 3.59, 6.12, B.20; the unicycle of Eq. 6.23 is ``v_2 = 0``): :func:`rotate` encloses
  ``R([ψ]) [v]``; every correctly rounded operation is stepped one ulp outward, ``cos``/``sin`` enclosed
  by :func:`cos_sin`. When the record also holds the odometry increment (``mean_velocity``: the velocity
  averaged over the step in the body frame at its start), the displacement is intersected with
  :func:`mean_displacement`'s, ``[dt]·R([ψ_{k-1}])·[v̄]``: it stays tight when the velocity changes within
  the step (inertia, contacts), where ``[v]`` is as wide as the change.
* :func:`impact_bound_q` is the radius of the impact constraint, q-relaxed (§2.6.2) when the filter allows
  ``q`` outliers per step: the ``(q + 1)``-th smallest upper range.
* :func:`clearance_cells` bounds ``dist(p, comp M⁻)`` from below for the cells of a pose box: the centre
  distance ``D`` to the nearest not-free cell of a window (the ring around the window counts as not free),
  then ``D(1 - EDT_SLACK) - diag`` (triangle inequality; the slack covers the rounding, as in
  :meth:`.digmap.DigMap.clearance_lower`). :func:`contract` keeps the hull of the feasible cells: a cell is
  feasible when some not-free cell of the window (or its ring) is near enough (:func:`_feasible`, the
  definition, run cell by cell in :func:`contract_cells`); :func:`contract` decides the same cells, to the
  bit: cell by cell while those searches stay cheap, then a row of the box at once, from the nearest
  not-free cell of each column of the window (the bound and the searched offsets are monotone in the row
  and column offsets), in about ``O(window)`` per box rather than a disk search per cell.

>>> cl, ch, sl, sh = cos_sin(-0.1, 0.1)
>>> bool(cl < math.cos(0.1) and ch >= 1.0 and sl < -math.sin(0.1) and sh > math.sin(0.1))
True
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.angles_jit import axes_in
from digslam.observer.core.grid_jit import window
from digslam.observer.core.scalar_jit import dn, iadd, imul, imul_hi, imul_lo, isub, njit, up
from digslam.observer.online.dig_jit import cell_size
from digslam.observer.online.dig_types import GridFrame, PoseBox, StepRecord

__all__ = [
    "cos_sin",
    "rotate",
    "mean_displacement",
    "predict",
    "clearance_cells",
    "contract",
    "contract_cells",
    "impact_bound",
    "impact_bound_q",
]

#: Absolute widening of a libm ``cos``/``sin`` value (``|v| <= 1``): 4 ulps of 1 plus the subtraction's.
TRIG_PAD = 2e-15

#: A row distance past every search radius (:func:`_nearest_rows`).
_FAR = 1 << 62
#: :func:`contract` searches cell by cell (:func:`_search`) until the cells looked at reach the window's
#: area over this, then decides the cells left a row at a time (the same cells either way).
CELL_SEARCHES = 1


@njit(forceinline=True)
def _mul(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """Outward-rounded product of two finite intervals
    (:func:`~digslam.observer.core.scalar_jit.imul_lo`, :func:`~digslam.observer.core.scalar_jit.imul_hi`)."""
    return imul_lo(al, ah, bl, bh), imul_hi(al, ah, bl, bh)


@njit
def cos_sin(a: float, b: float) -> tuple[float, float, float, float]:
    """Enclosures ``(cos⁻, cos⁺, sin⁻, sin⁺)`` over ``[a, b]``: the endpoints' values widened by
    :data:`TRIG_PAD`, and ``±1`` where an extremum ``m·π/2`` may lie in ``[a, b]``
    (:func:`~digslam.observer.core.angles_jit.axes_in`, which never misses one); ``[-1, 1]`` twice when an
    end is not finite."""
    if not (math.isfinite(a) and math.isfinite(b)):
        return -1.0, 1.0, -1.0, 1.0
    east, north, west, south = axes_in(a, b)
    if east and north and west and south:  # a full turn (or more)
        return -1.0, 1.0, -1.0, 1.0
    ca, cb, sa, sb = math.cos(a), math.cos(b), math.sin(a), math.sin(b)
    c0, c1 = min(ca, cb) - TRIG_PAD, max(ca, cb) + TRIG_PAD
    s0, s1 = min(sa, sb) - TRIG_PAD, max(sa, sb) + TRIG_PAD
    if east:
        c1 = 1.0
    if north:
        s1 = 1.0
    if west:
        c0 = -1.0
    if south:
        s0 = -1.0
    return max(c0, -1.0), min(c1, 1.0), max(s0, -1.0), min(s1, 1.0)


@njit
def rotate(v1l: float, v1h: float, v2l: float, v2h: float, cl: float, ch: float, sl: float, sh: float
           ) -> tuple[float, float, float, float]:  # fmt: skip
    """Enclosure ``(u_1⁻, u_1⁺, u_2⁻, u_2⁺)`` of ``{R(ψ) v : v ∈ [v_1] × [v_2], cos ψ ∈ [c], sin ψ ∈ [s]}``,
    ``R(ψ) v = (v_1 cos ψ - v_2 sin ψ, v_1 sin ψ + v_2 cos ψ)`` (Eq. 3.59, 6.12, B.20), with
    ``[c] = [cl, ch]``, ``[s] = [sl, sh]`` (:func:`cos_sin` of a heading interval).

    Natural interval form, outward rounded: each product is the 4-corner min/max rule (the forward terms
    by :func:`_mul`, the lateral ones by :func:`~digslam.observer.core.scalar_jit.imul`, which also takes
    ``0·∞ = 0``), each sum TwoSum-tight (:func:`~digslam.observer.core.scalar_jit.isub`,
    :func:`~digslam.observer.core.scalar_jit.iadd`: exact sums stay exact, others step one ulp outward).
    ``[v_2] = [0, 0]`` (a unicycle) returns the forward terms ``[v_1]·[c]``, ``[v_1]·[s]`` as they are, the
    unicycle step of Eq. 6.23 to the bit (``- [0, 0]·[s]`` is exactly zero).
    """
    a0l, a0h = _mul(v1l, v1h, cl, ch)
    a1l, a1h = _mul(v1l, v1h, sl, sh)
    if v2l == 0.0 and v2h == 0.0:
        return a0l, a0h, a1l, a1h
    b0l, b0h = imul(v2l, v2h, sl, sh)
    b1l, b1h = imul(v2l, v2h, cl, ch)
    u0l, u0h = isub(a0l, a0h, b0l, b0h)
    u1l, u1h = iadd(a1l, a1h, b1l, b1h)
    return u0l, u0h, u1l, u1h


@njit
def mean_displacement(p_lo: float, p_hi: float, dtl: float, dth: float, mv: np.ndarray
                      ) -> tuple[float, float, float, float]:  # fmt: skip
    """The step's displacement ``(d_x⁻, d_y⁻, d_x⁺, d_y⁺)`` from the odometry increment: the mean velocity
    ``[v̄] = mv (2, 2)`` over the step in the body frame at its start, ``v̄ = (1/dt) ∫ R(ψ(t) - ψ_{k-1}) v dt``
    (a DVL integrated with the gyro's relative rotation; :mod:`digslam.observer.record.mission`). Since
    ``x_k - x_{k-1} = ∫ R(ψ) v dt = R(ψ_{k-1}) dt v̄``, it lies in ``[dt]·R([ψ_{k-1}])·[v̄]`` with
    ``[ψ_{k-1}] = [p_lo, p_hi]`` and ``[dtl, dth] ∋ dt`` (:func:`rotate`, outward rounded)."""
    cl, ch, sl, sh = cos_sin(p_lo, p_hi)
    u0l, u0h, u1l, u1h = rotate(mv[0, 0], mv[0, 1], mv[1, 0], mv[1, 1], cl, ch, sl, sh)
    e0l, e0h = _mul(dtl, dth, u0l, u0h)
    e1l, e1h = _mul(dtl, dth, u1l, u1h)
    return e0l, e1l, e0h, e1h


@njit
def predict(prior: PoseBox, step: StepRecord
            ) -> tuple[bool, PoseBox, tuple[float, float, float, float]]:  # fmt: skip
    """One tube step from ``prior`` (``x' = R(ψ) v``, Eq. 3.59, 6.12, B.20; heading fused with the compass)
    with the odometry of ``step`` (its ``dt``, ``yaw_rate``, ``heading``, ``speed`` and ``lateral``):
    ``x_k ∈ x_{k-1} + [dt]·R([ψ])·[v]`` with ``[ψ]`` the heading over the whole slice and
    ``[v] = ([speed], [lateral])`` (:func:`rotate`); a unicycle step (``lateral = [0, 0]``) is Eq. 6.23's.
    A measured ``mean_velocity`` (all four bounds finite) intersects the displacement with
    :func:`mean_displacement`'s.

    Returns ``(ok, box, d)``: the predicted pose box (position and heading) and the displacement box
    ``d = (d_x⁻, d_y⁻, d_x⁺, d_y⁺)`` of the step; ``ok`` False (and NaNs) when the heading or its slice is
    empty (the data contradict their bounds).
    """
    dt, yaw, comp, v, lat = step.dt, step.yaw_rate, step.heading, step.speed, step.lateral
    dtl, dth = dn(dt), up(dt)
    wl, wh = _mul(dtl, dth, yaw[0], yaw[1])
    hl, hh = max(comp[0], dn(prior.psi_lo + wl)), min(comp[1], up(prior.psi_hi + wh))
    zl, zh = min(wl, 0.0), max(wh, 0.0)
    sl, sh = max(dn(prior.psi_lo + zl), dn(hl - zh)), min(up(prior.psi_hi + zh), up(hh - zl))
    nan = math.nan
    if not (hl <= hh and sl <= sh):
        return False, PoseBox(nan, nan, nan, nan, nan, nan), (nan, nan, nan, nan)
    cl, ch, snl, snh = cos_sin(sl, sh)
    u0l, u0h, u1l, u1h = rotate(v[0], v[1], lat[0], lat[1], cl, ch, snl, snh)
    d0l, d0h = _mul(dtl, dth, u0l, u0h)
    d1l, d1h = _mul(dtl, dth, u1l, u1h)
    mv = step.mean_velocity
    if (
        math.isfinite(mv[0, 0])
        and math.isfinite(mv[0, 1])
        and math.isfinite(mv[1, 0])
        and math.isfinite(mv[1, 1])
    ):
        e0l, e1l, e0h, e1h = mean_displacement(prior.psi_lo, prior.psi_hi, dtl, dth, mv)
        d0l, d0h, d1l, d1h = max(d0l, e0l), min(d0h, e0h), max(d1l, e1l), min(d1h, e1h)
        if not (d0l <= d0h and d1l <= d1h):
            return False, PoseBox(nan, nan, nan, nan, nan, nan), (nan, nan, nan, nan)
    box = PoseBox(
        dn(prior.x_lo + d0l), dn(prior.y_lo + d1l), up(prior.x_hi + d0h), up(prior.y_hi + d1h), hl, hh
    )
    return True, box, (d0l, d1l, d0h, d1h)


@njit
def clearance_cells(free: np.ndarray, grid: GridFrame, block: tuple[int, int, int, int],
                    win: tuple[int, int, int, int]) -> np.ndarray:  # fmt: skip
    """Lower bounds on ``dist(p, comp M⁻)`` for the cells ``block = (b0, b1, a0, a1)`` (rows ``b0:b1``,
    columns ``a0:a1``, the result's shape), taking the cells of ``comp M⁻`` from the window
    ``win = (w0, w1, v0, v1)`` (which holds them) and its ring.

    The bound is ``D·keep - off`` with ``D`` the centre distance to the nearest not-free cell and the
    constants of ``grid`` (:class:`.dig_types.GridFrame`), as in :meth:`.digmap.DigMap.clearance_lower`.
    """
    b0, b1, a0, a1 = block
    w0, w1, v0, v1 = win
    (dx, dy), keep, off = cell_size(grid), grid.keep, grid.off
    rows, cols, n = _not_free(free, win)
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
def _not_free(free: np.ndarray, win: tuple[int, int, int, int]) -> tuple[np.ndarray, np.ndarray, int]:
    """Rows and columns (relative to the window ``win``) of the cells of ``win`` not in ``M⁻``."""
    w0, w1, v0, v1 = win
    n = 0
    rows, cols = np.empty((w1 - w0) * (v1 - v0), np.int64), np.empty((w1 - w0) * (v1 - v0), np.int64)
    for i in range(w0, w1):
        for j in range(v0, v1):
            if not free[i, j]:
                rows[n], cols[n] = i - w0, j - v0
                n += 1
    return rows, cols, n


@njit
def _feasible(free: np.ndarray, i: int, j: int, r_hi: float, win: tuple[int, int, int, int], dx: float,
              dy: float, keep: float, off: float) -> bool:  # fmt: skip
    """Whether cell ``(i, j)`` may hold a pose: its :func:`clearance_cells` bound (on the window ``win``,
    cell size ``dx``, ``dy``, constants ``keep``, ``off`` of :class:`.dig_types.GridFrame`) is ``<= r⁺``.

    The bound is monotone in the distance, so the cell is feasible iff the ring or one not-free cell of the
    window is near enough; only the cells within the generous radius ``(r⁺ + off) / keep · (1 + 10⁻⁹)`` of
    its centre can be, and each candidate is decided by the exact bound of :func:`clearance_cells`
    (:func:`_search` with no budget).
    """
    return _search(free, i, j, r_hi, win, dx, dy, keep, off, _FAR)[0] == 1


@njit
def _search(free: np.ndarray, i: int, j: int, r_hi: float, win: tuple[int, int, int, int], dx: float,
            dy: float, keep: float, off: float, budget: int) -> tuple[int, int]:  # fmt: skip
    """:func:`_feasible`'s search, given up before a row of candidates would take it past ``budget`` cells.

    Returns:
        ``(decided, cells)``: 1 feasible, 0 not, -1 given up; and the number of candidate cells looked at.
    """
    if not free[i, j]:
        return 1, 0
    w0, w1, v0, v1 = win
    pr, pc = i - w0, j - v0
    ring = min(min(pr + 1, w1 - w0 - pr) * dy, min(pc + 1, v1 - v0 - pc) * dx)
    if max(dn(ring * keep - off), 0.0) <= r_hi:
        return 1, 0
    rad = (r_hi + off) / keep * (1.0 + 1e-9)
    t = rad * rad
    kr = int(rad / dy) + 1
    used = 0
    for di in range(max(-kr, w0 - i), min(kr, w1 - 1 - i) + 1):
        ey = di * dy
        rem = t - ey * ey
        if rem < 0.0:
            continue
        kc = int(math.sqrt(rem) / dx) + 1
        lo, hi = max(-kc, v0 - j), min(kc, v1 - 1 - j)
        used += max(hi - lo + 1, 0)
        if used > budget:
            return -1, used
        for dj in range(lo, hi + 1):
            if not free[i + di, j + dj]:
                ex = dj * dx
                if max(dn(math.sqrt(ey * ey + ex * ex) * keep - off), 0.0) <= r_hi:
                    return 1, used
    return 0, used


@njit
def _reach_rows(r_hi: float, dx: float, dy: float, keep: float, off: float, amax: int, mmax: int
                ) -> np.ndarray:  # fmt: skip
    """``T[m]`` for the column offsets ``m = 0..mmax``: the largest row offset ``a <= amax`` such that a
    not-free cell at offset ``(±a, ±m)`` makes a cell feasible in :func:`_feasible` (it is searched there and
    its clearance bound is ``<= r⁺``); -1 where none.

    :func:`_feasible` searches the offsets ``|di| <= kr`` with ``rem(|di|) = t - (di·dy)² >= 0`` and
    ``|dj| <= kc(|di|) = ⌊√rem / dx⌋ + 1``; both are monotone in ``|di|`` (each rounded operation is), so for
    a column offset ``m`` the searched rows are ``|di| <= D(m)``. The bound
    ``max(dn(√((di·dy)² + (dj·dx)²)·keep - off), 0)`` is nondecreasing in ``|di|`` and in ``|dj|`` (every
    operation is monotone: round-to-nearest, ``sqrt``, the product by ``keep > 0``, :func:`dn`), so the
    offsets that pass are ``|di| <= T(m)``, ``T`` nonincreasing; computed as a staircase."""
    rad = (r_hi + off) / keep * (1.0 + 1e-9)
    t = rad * rad
    q = rad / dy
    lim = amax if not q < amax else min(int(q) + 1, amax)  # min(kr, amax), without converting a huge q
    kc = np.full(lim + 1, -1, np.int64)
    for a in range(lim + 1):
        ey = a * dy
        rem = t - ey * ey
        if rem < 0.0:
            break
        s = math.sqrt(rem) / dx
        kc[a] = mmax if not s < mmax else min(int(s) + 1, mmax)
    out = np.full(mmax + 1, -1, np.int64)
    a = lim
    for m in range(mmax + 1):
        while a >= 0 and kc[a] < m:  # D(m): the rows searched at this column offset
            a -= 1
        ex = m * dx
        while a >= 0 and not _near(a * dy, ex, keep, off, r_hi):
            a -= 1
        if a < 0:
            break
        out[m] = a
    return out


@njit(forceinline=True)
def _near(ey: float, ex: float, keep: float, off: float, r_hi: float) -> bool:
    """Whether a not-free cell at the centre offset ``(ey, ex)`` is near enough: :func:`_feasible`'s test."""
    return max(dn(math.sqrt(ey * ey + ex * ex) * keep - off), 0.0) <= r_hi


@njit
def _spans(reach: np.ndarray) -> np.ndarray:
    """``S[h]`` for ``h = 0..reach[0]``: the largest column offset ``m`` with ``reach[m] >= h`` (``reach``
    nonincreasing, :func:`_reach_rows`): a not-free cell ``h`` rows away is near enough iff ``m <= S[h]``."""
    out = np.empty(max(reach[0] + 1, 0), np.int64)
    m = reach.size - 1
    for h in range(out.size):
        while reach[m] < h:
            m -= 1
        out[h] = m
    return out


@njit
def _nearest_rows(free: np.ndarray, win: tuple[int, int, int, int], b0: int, b1: int, a0: int, a1: int,
                  spans: np.ndarray) -> np.ndarray:  # fmt: skip
    """For the rows ``b0:b1`` and the columns ``v0:v1`` of ``win``: the row distance from each cell to the
    nearest not-free cell of its column inside the window (above, below or itself), exact where it is at
    most ``T[m]`` (:func:`_reach_rows`; ``spans`` is its :func:`_spans`), ``m`` the column's offset from the
    columns ``a0:a1``, and larger than that elsewhere."""
    w0, w1, v0, v1 = win
    nc, nb = v1 - v0, b1 - b0
    up, down = np.full((nb, nc), _FAR, np.int64), np.full(nc, _FAR, np.int64)
    for a in range(spans.size):  # the first not-free cell at or above row b0, at or below row b1 - 1
        c0, c1 = max(v0, a0 - spans[a]), min(v1, a1 + spans[a])
        if w0 <= b0 - a:
            for c in range(c0, c1):
                if up[0, c - v0] == _FAR and not free[b0 - a, c]:
                    up[0, c - v0] = a
        if b1 - 1 + a < w1:
            for c in range(c0, c1):
                if down[c - v0] == _FAR and not free[b1 - 1 + a, c]:
                    down[c - v0] = a
    for k in range(1, nb):  # then row by row inside the block, each from its neighbour
        for c in range(nc):
            up[k, c] = 0 if not free[b0 + k, v0 + c] else min(up[k - 1, c], _FAR - 1) + 1
    for k in range(nb - 1, -1, -1):
        for c in range(nc):
            if k < nb - 1:
                down[c] = 0 if not free[b0 + k, v0 + c] else min(down[c], _FAR - 1) + 1
            up[k, c] = min(up[k, c], down[c])
    return up


@njit
def contract_cells(free: np.ndarray, grid: GridFrame, x0: float, y0: float, x1: float, y1: float, r_hi: float
                   ) -> tuple[float, float, float, float]:  # fmt: skip
    """:func:`contract` by its definition, one :func:`_feasible` search per cell of the box (the same result
    to the bit; the reference of its tests)."""
    xs, nys = grid.xs, grid.nys
    b0, b1, a0, a1 = window(xs, nys, x0, y0, x1, y1)
    dx, dy = cell_size(grid)
    reach = r_hi + 2.0 * max(dx, dy)
    win = window(xs, nys, x0 - reach, y0 - reach, x1 + reach, y1 + reach)
    rmin, rmax, cmin, cmax = b1, -1, a1, -1
    for i in range(b0, b1):
        for j in range(a0, a1):
            if _feasible(free, i, j, r_hi, win, dx, dy, grid.keep, grid.off):
                rmin, rmax = min(rmin, i - b0), max(rmax, i - b0)
                cmin, cmax = min(cmin, j - a0), max(cmax, j - a0)
    return _hull(grid, x0, y0, x1, y1, b0, a0, rmin, rmax, cmin, cmax)


@njit(forceinline=True)
def _hull(grid: GridFrame, x0: float, y0: float, x1: float, y1: float, b0: int, a0: int, rmin: int, rmax: int,
          cmin: int, cmax: int) -> tuple[float, float, float, float]:  # fmt: skip
    """The box cut to the cells of rows ``b0 + rmin..b0 + rmax`` and columns ``a0 + cmin..a0 + cmax`` (exact
    cell bounds); ``(inf, inf, -inf, -inf)`` when ``rmax < 0`` (no cell)."""
    xs, ys = grid.xs, grid.ys
    if rmax < 0:
        return math.inf, math.inf, -math.inf, -math.inf
    return (max(x0, xs[a0 + cmin]), max(y0, ys[b0 + rmax + 1]), min(x1, xs[a0 + cmax + 1]),
            min(y1, ys[b0 + rmin]))  # fmt: skip


@njit
def contract(free: np.ndarray, grid: GridFrame, x0: float, y0: float, x1: float, y1: float, r_hi: float,
             share: int = CELL_SEARCHES) -> tuple[float, float, float, float]:  # fmt: skip
    """Eq. 6.22 on the cells of the position box ``[x0, x1] × [y0, y1]``: the box cut to the hull of the
    cells with clearance ``<= r⁺`` (:func:`_feasible` on the window ``[x] ± (r⁺ + 2 cells)``; exact cell
    bounds); ``(inf, inf, -inf, -inf)`` when none is.

    The cells are decided as :func:`_feasible` decides them, to the bit (:func:`contract_cells`): each by its
    own search (:func:`_search`, which often stops at a near not-free cell) until those searches have looked
    at ``1 / share`` of the window's cells (:data:`CELL_SEARCHES`), then the cells left a row of the box at
    once (``share`` past the window's area: at once from the start). A free cell ``(i, j)`` away from the
    window's ring is feasible iff some column ``c`` of the window has a not-free cell ``h`` rows from row
    ``i`` with ``|c - j| <= S[h]`` (:func:`_reach_rows`, :func:`_spans`), and only the nearest one of each
    column counts (:func:`_nearest_rows`); a sweep over the columns in each direction finds the cells so
    covered. Either way costs at most about the window's area per box.
    """
    xs, nys = grid.xs, grid.nys
    b0, b1, a0, a1 = window(xs, nys, x0, y0, x1, y1)
    dx, dy = cell_size(grid)
    reach = r_hi + 2.0 * max(dx, dy)
    win = window(xs, nys, x0 - reach, y0 - reach, x1 + reach, y1 + reach)
    w0, w1, v0, v1 = win
    keep, off = grid.keep, grid.off
    budget = (w1 - w0) * (v1 - v0) // share
    inside = w0 <= b0 and b1 <= w1 and v0 <= a0 and a1 <= v1
    search = False
    rmin, rmax, cmin, cmax = b1, -1, a1, -1  # the hull of the feasible cells, relative to (b0, a0)
    for k in range(b1 - b0):
        for m in range(a1 - a0):
            i, j = b0 + k, a0 + m
            if not inside:
                ok = _feasible(free, i, j, r_hi, win, dx, dy, keep, off)
            elif not search:  # each cell's own search first (it often stops early), within a budget
                code, used = _search(free, i, j, r_hi, win, dx, dy, keep, off, budget)
                ok, budget, search = code == 1, budget - used, code < 0
            else:  # past it: a not-free cell, or one near the window's ring; the rest below
                ok = _search(free, i, j, r_hi, win, dx, dy, keep, off, 0)[0] == 1
            if ok:
                rmin, rmax, cmin, cmax = min(rmin, k), max(rmax, k), min(cmin, m), max(cmax, m)
    if search:  # past the budget: the cells left are decided a row at a time
        spans = _spans(_reach_rows(r_hi, dx, dy, keep, off, w1 - w0 - 1, v1 - v0 - 1))
        near = _nearest_rows(free, win, b0, b1, a0, a1, spans)
        for k in range(b1 - b0):
            far = a0 - 1  # the farthest column covered from the left so far
            for c in range(v0, a1):
                h = near[k, c - v0]
                if h < spans.size:
                    far = max(far, c + spans[h])
                if c >= a0 and far >= c:
                    rmin, rmax, cmin, cmax = min(rmin, k), max(rmax, k), min(cmin, c - a0), max(cmax, c - a0)
            far = a1  # from the right
            for c in range(v1 - 1, a0 - 1, -1):
                h = near[k, c - v0]
                if h < spans.size:
                    far = min(far, c - spans[h])
                if c < a1 and far <= c:
                    rmin, rmax, cmin, cmax = min(rmin, k), max(rmax, k), min(cmin, c - a0), max(cmax, c - a0)
    return _hull(grid, x0, y0, x1, y1, b0, a0, rmin, rmax, cmin, cmax)


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
