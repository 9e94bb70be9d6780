"""Explored zone with headings: sonar sectors (patch) and sweep exploration (thesis App. B, Eq. B.2–B.3,
Theorems B.1–B.2, tests B.12 and B.15).

* Sectors (Example 1): ``V(x, ψ) = {z : |z - x| < r, bearing(z - x) - ψ - α ∈ [-γ, γ] mod 2π}`` with
  ``r ∈ [r_lo, r_hi]``, ``ψ ∈ [ψ](t_i)``. The radius part reuses the separable disk tests of
  :mod:`.explored`; the bearing part is proved on the flat batch of the (time, cell) pairs they leave.
  Radius claims hold for the open and the closed disk; the angular limits are closed (Eq. B.2) and no
  clear or dark claim relies on the apex ``z = x``.
* Sweep (Example 2): ``V(x, ψ) = {x + s n(ψ) : s ∈ [s_lo, s_hi]}``, ``n(ψ) = (sin ψ, -cos ψ)`` the right
  of the heading, sensed continuously. With ``φ = u(ψ)·(z - x)`` (along track, ``u = (cos ψ, sin ψ)``)
  and ``s = n(ψ)·(z - x)``, Theorem B.1 proves a cell clear when ``φ`` has opposite signs on
  ``[x](t_i)`` and ``[x](t_{i+1})`` and ``s ∈ [s_lo, s_hi]`` on the *gate* ``[x]([t_i, t_{i+1}])``; the
  dark test B.15 asks ``0 ∉ [φ]`` or ``[s] ∩ [s_lo, s_hi] = ∅`` on every gate. Penumbra is not proved
  for sweeps (cells are clear, dark or unknown).

>>> from digslam.observer.record.grid import Grid
>>> g = Grid((-3.0, -3.0), (3.0, 3.0), (6, 6))
>>> pos = np.array([[0.0, 0.0]])      # a sonar pie of ±60° facing east, heading in [-0.1, 0.1]
>>> st = explored_sectors_grid(g, pos - 0.1, pos + 0.1, -0.1, 0.1, 0.0, np.pi / 3, 2.9, 3.2)
>>> st[2:4].tolist()
[[-1, -1, 0, 0, 1, 0], [-1, -1, 0, 0, 1, 0]]
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core import trig
from digslam.observer.record.grid import Grid
from digslam.observer.slam.explored import (
    BLOCK,
    check_interval,
    check_tube,
    codes,
    pair_test,
    row_intervals,
)
from digslam.observer.thick.cells import CLEAR, DARK, UNKNOWN

__all__ = ["explored_sectors_grid", "explored_sweep_grid", "sweep_gates"]

_PI2 = (rnd.TWO_PI_DOWN, rnd.TWO_PI_UP)


def box_arc(dlo: np.ndarray, dhi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Outward arc ``[a, b]`` (``b - a < π`` up to rounding) of the bearings of ``(P, 2)`` boxes, and a
    mask of the boxes that hold the origin (arc meaningless there)."""
    l1, h1 = trig.atan2((dlo[:, 1], dhi[:, 1]), (dlo[:, 0], dhi[:, 0]))
    l2, h2 = trig.atan2((-dhi[:, 1], -dlo[:, 1]), (-dhi[:, 0], -dlo[:, 0]))
    l2, h2 = rnd.add_down(l2, rnd.PI_DOWN), rnd.add_up(h2, rnd.PI_UP)  # bearing(-d) + π
    first = (h1 - l1) <= (h2 - l2)
    zero = np.asarray(((dlo <= 0) & (dhi >= 0)).all(1))
    return np.where(first, l1, l2), np.where(first, h1, h2), zero


def _two_pi_k(k: np.ndarray, up: bool) -> np.ndarray:
    if up:
        return rnd.mul_up(k, np.where(k >= 0, _PI2[1], _PI2[0]))
    return rnd.mul_down(k, np.where(k >= 0, _PI2[0], _PI2[1]))


def arc_inside(a: np.ndarray, b: np.ndarray, t1: np.ndarray, t2: np.ndarray) -> np.ndarray:
    """Proof that ``[a, b] ⊂ [t1, t2] + 2πk`` for some integer ``k`` (``t1`` an upper bound of the
    cone start, ``t2`` a lower bound of its end)."""
    ok = rnd.sub_down(t2, t1) >= _PI2[1]
    k0 = np.floor((a - t1) / _PI2[0])
    for dk in (-1.0, 0.0, 1.0):  # the float guess of k may be one off
        k = k0 + dk
        ok |= (a >= rnd.add_up(t1, _two_pi_k(k, True))) & (b <= rnd.add_down(t2, _two_pi_k(k, False)))
    return ok


def arc_disjoint(a: np.ndarray, b: np.ndarray, p1: np.ndarray, p2: np.ndarray) -> np.ndarray:
    """Proof that ``[a, b] ∩ ([p1, p2] + 2πk) = ∅`` for every ``k`` (``[p1, p2]`` an outer bound,
    empty when ``p1 > p2``)."""
    ok = p1 > p2
    k0 = np.floor((a - p2) / _PI2[0])
    for dk in (-1.0, 0.0, 1.0):
        k = k0 + dk
        ok |= (rnd.add_up(p2, _two_pi_k(k, True)) < a) & (b < rnd.add_down(p1, _two_pi_k(k + 1, False)))
    return ok


def _pairs(ivals: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Expand row intervals ``(time, col, a, b)`` into flat ``(time, row, col)`` pairs."""
    ti, col, ra, rb = ivals
    n = rb - ra + 1
    start = np.repeat(np.cumsum(n) - n, n)
    rows = np.repeat(ra, n) + np.arange(int(n.sum())) - start
    return np.repeat(ti, n), rows, np.repeat(col, n)


def _blocks(cost: np.ndarray, budget: int = BLOCK) -> list[slice]:
    """Consecutive slices of the times whose summed ``cost`` stays near ``budget``."""
    cum, out, s = np.cumsum(cost), [], 0
    while s < cost.size:
        e = max(int(np.searchsorted(cum, (cum[s - 1] if s else 0) + budget, "right")), s + 1)
        out.append(slice(s, e))
        s = e
    return out


def _hit(grid: Grid, t: np.ndarray, r: np.ndarray, c: np.ndarray, ok: np.ndarray) -> np.ndarray:
    return np.bincount((r * grid.shape[1] + c)[ok], minlength=grid.n_cells).reshape(grid.shape) > 0


def explored_sectors_grid(grid: Grid, pos_lo: Any, pos_hi: Any, psi_lo: Any, psi_hi: Any, alpha: Any,
                          gamma: Any, r_lo: Any, r_hi: Any) -> np.ndarray:  # fmt: skip
    """Classify ``grid`` for sonar sectors (Example 1, Eq. B.2) over the tube ``[x](t_i) × [ψ](t_i)``.

    Args:
        pos_lo, pos_hi: ``(m, 2)`` position boxes; psi_lo, psi_hi: headings (scalars or ``(m,)``).
        alpha: sector axis relative to the heading; gamma: half-aperture in ``[0, π]`` (scalar or ``(m,)``).
        r_lo, r_hi: radius interval, ``0 <= r_lo <= r_hi``.

    Clear: one time proves ``max |z - x| < r_lo`` and the bearings of ``cell - [x]`` inside the cone of
    every heading. Dark: every time proves ``min |z - x| > r_hi`` or the bearings outside the cone of
    every heading. Penumbra: one time has a witness position ``x*`` (the point of ``[x]`` nearest the
    cell centre) seeing the whole cell for some heading, and every time proves no point certainly seen.
    """
    lo, hi = check_tube(pos_lo, pos_hi)
    m = lo.shape[0]
    rl, rh = check_interval(r_lo, r_hi, m, "r", nonneg=True)
    pl, ph = check_interval(psi_lo, psi_hi, m, "psi")
    al, _ = check_interval(alpha, alpha, m, "alpha")
    ga, _ = check_interval(gamma, gamma, m, "gamma", nonneg=True)
    if (ga > rnd.PI_UP).any():
        raise ValueError("gamma: the half-aperture must lie in [0, π]")
    # cones: certain = ∩_ψ (inner bounds t1 <= start, t2 >= end), possible = ∪_ψ (outer p1, p2)
    c1, c2 = rnd.sub_up(rnd.add_up(ph, al), ga), rnd.add_down(rnd.add_down(pl, al), ga)
    o1, o2 = rnd.sub_down(rnd.add_down(pl, al), ga), rnd.add_up(rnd.add_up(ph, al), ga)
    u1, u2 = rnd.sub_up(rnd.add_up(pl, al), ga), rnd.add_down(rnd.add_down(ph, al), ga)
    k1, k2 = rnd.sub_down(rnd.add_down(ph, al), ga), rnd.add_up(rnd.add_up(pl, al), ga)
    full_c = rnd.sub_down(c2, c1) >= _PI2[1]
    got = {k: np.zeros(grid.shape, bool) for k in ("clear", "notdark", "upper", "notout")}
    side = int(np.ceil(2 * (rh.max() + (hi - lo).max()) / min(grid.cell_size))) + 2
    step = max(1, BLOCK // (side * side))
    for s in range(0, m, step):  # blocks of many (time, cell) pairs
        sl = slice(s, min(m, s + step))
        blo, bhi = lo[sl], hi[sl]
        ivals = row_intervals(grid, blo, bhi, rl[sl], rh[sl])
        for test in ("clear", "dark", "outside"):
            t, r, c = _pairs(ivals[test])
            t = t + s
            clo = np.stack([grid.xs[c], grid.ys[r + 1]], 1)
            chi = np.stack([grid.xs[c + 1], grid.ys[r]], 1)
            dlo, dhi = rnd.sub_down(clo, hi[t]), rnd.sub_up(chi, lo[t])
            if test == "clear":  # radius proved on these pairs; now the bearings
                a, b, zero = box_arc(dlo, dhi)
                ok = full_c[t] | (~zero & arc_inside(a, b, c1[t], c2[t]))
                got["clear"] |= _hit(grid, t, r, c, ok)
                continue
            xs = np.clip(0.5 * (clo + chi), lo[t], hi[t])  # witness position in [x](t_i)
            wlo, whi = rnd.sub_down(clo, xs), rnd.sub_up(chi, xs)
            wa, wb, wzero = box_arc(wlo, whi)
            if test == "dark":  # pairs where the radius does not prove dark
                a, b, zero = box_arc(dlo, dhi)
                dark = ~zero & arc_disjoint(a, b, o1[t], o2[t])
                got["notdark"] |= _hit(grid, t, r, c, ~dark)
                far = np.maximum(np.abs(wlo), np.abs(whi))
                near = rnd.add_up(rnd.mul_up(far[:, 0], far[:, 0]), rnd.mul_up(far[:, 1], far[:, 1]))
                full_o = rnd.sub_down(u2, u1)[t] >= _PI2[1]
                up = full_o & pair_test("upper", clo, chi, lo[t], hi[t], rh[t])
                up |= (near < rnd.mul_down(rh[t], rh[t])) & ~wzero & arc_inside(wa, wb, u1[t], u2[t])
                got["upper"] |= _hit(grid, t, r, c, up)
            else:  # pairs where the radius does not prove the cell outside C_i
                out = ~wzero & arc_disjoint(wa, wb, k1[t], k2[t])
                got["notout"] |= _hit(grid, t, r, c, ~out)
    return codes(got["clear"], ~got["notdark"], got["upper"], ~got["notout"])


def sweep_gates(pos_lo: Any, pos_hi: Any, psi_lo: Any, psi_hi: Any, v_max: float, w_max: float,
                dt: Any) -> tuple[np.ndarray, ...]:  # fmt: skip
    """Enclosures of ``x`` and ``ψ`` on ``[t_i, t_{i+1}]`` from bounds on the speed ``|ẋ| <= v_max`` and
    the turn rate ``|ψ̇| <= w_max``: ``([x](t_i) ⊕ v dt) ∩ ([x](t_{i+1}) ⊕ v dt)`` (and alike for ψ).

    Returns ``(gate_lo, gate_hi, gate_psi_lo, gate_psi_hi)`` of shapes ``(m-1, 2)`` and ``(m-1,)``.
    """
    lo, hi = check_tube(pos_lo, pos_hi)
    m = lo.shape[0]
    pl, ph = check_interval(psi_lo, psi_hi, m, "psi")
    if not (np.isfinite(v_max) and v_max >= 0 and np.isfinite(w_max) and w_max >= 0):
        raise ValueError(f"v_max, w_max: must be finite and >= 0, got {v_max!r} {w_max!r}")
    d, _ = check_interval(dt, dt, m - 1, "dt", nonneg=True)
    dv, dw = rnd.mul_up(d, v_max)[:, None], rnd.mul_up(d, w_max)
    glo = np.maximum(rnd.sub_down(lo[:-1], dv), rnd.sub_down(lo[1:], dv))
    ghi = np.minimum(rnd.add_up(hi[:-1], dv), rnd.add_up(hi[1:], dv))
    gpl = np.maximum(rnd.sub_down(pl[:-1], dw), rnd.sub_down(pl[1:], dw))
    gph = np.minimum(rnd.add_up(ph[:-1], dw), rnd.add_up(ph[1:], dw))
    if (glo > ghi).any() or (gpl > gph).any():
        raise ValueError("v_max, w_max: too small for the tube (consecutive boxes cannot be joined)")
    return glo, ghi, gpl, gph


def _mul(a: tuple, b: tuple) -> tuple:
    """Interval product, each round-to-nearest bound stepped one ulp outward (``rounding.next_*``)."""
    p = (a[0] * b[0], a[0] * b[1], a[1] * b[0], a[1] * b[1])
    return rnd.next_down(np.minimum(np.minimum(p[0], p[1]), np.minimum(p[2], p[3]))), rnd.next_up(
        np.maximum(np.maximum(p[0], p[1]), np.maximum(p[2], p[3])))  # fmt: skip


def _proj(d: tuple, c: tuple, s: tuple, sign: float) -> tuple:
    """``[d_x]·c + sign·[d_y]·s`` (interval arithmetic, outward)."""
    dy = d[1] if sign > 0 else (-d[1][1], -d[1][0])
    x, y = _mul(d[0], c), _mul(dy, s)
    return rnd.next_down(x[0] + y[0]), rnd.next_up(x[1] + y[1])


def _diff(cell: tuple, blo: np.ndarray, bhi: np.ndarray) -> tuple:
    """``cell - box`` per axis, outward."""
    return tuple((rnd.next_down(cell[j][0] - bhi[:, j]), rnd.next_up(cell[j][1] - blo[:, j])) for j in (0, 1))


def explored_sweep_grid(grid: Grid, pos_lo: Any, pos_hi: Any, psi_lo: Any, psi_hi: Any, s_lo: float,
                        s_hi: float, gate_lo: Any, gate_hi: Any, gate_psi_lo: Any, gate_psi_hi: Any
                        ) -> np.ndarray:  # fmt: skip
    """Classify ``grid`` for sweep exploration (Example 2, Eq. B.3): clarity test B.12 on consecutive
    pairs ``(t_i, t_{i+1})`` and dark test B.15 on every gate (see the module docstring).

    Args:
        pos_lo, pos_hi, psi_lo, psi_hi: the tube at the sample times (``(m, 2)``, ``(m,)``).
        s_lo, s_hi: the signed cross-track offsets seen (``s > 0`` on the right), ``s_lo <= s_hi``.
        gate_lo, gate_hi, gate_psi_lo, gate_psi_hi: enclosures over ``[t_i, t_{i+1}]`` (``(m-1, 2)``,
            ``(m-1,)``), e.g. from :func:`sweep_gates`; the robot must be continuous inside them.

    Returns ``int8 (ny, nx)``: ``CLEAR``, ``DARK`` (over ``[t_1, t_m]``) or ``UNKNOWN``.
    """
    lo, hi = check_tube(pos_lo, pos_hi)
    m = lo.shape[0]
    if m < 2:
        raise ValueError("pos_lo, pos_hi: a sweep needs at least two times")
    pl, ph = check_interval(psi_lo, psi_hi, m, "psi")
    glo, ghi = check_tube(gate_lo, gate_hi, "gate")
    if glo.shape[0] != m - 1:
        raise ValueError(f"gate_lo, gate_hi: expected {m - 1} gates, got {glo.shape[0]}")
    gpl, gph = check_interval(gate_psi_lo, gate_psi_hi, m - 1, "gate_psi")
    sl_, sh_ = check_interval(s_lo, s_hi, 1, "s")
    smax = float(max(abs(sl_[0]), abs(sh_[0])))
    cs = [trig.cos((pl, ph)), trig.sin((pl, ph))]
    gcs = [trig.cos((gpl, gph)), trig.sin((gpl, gph))]
    seen, runs = np.zeros(grid.shape, bool), [(np.zeros(0, np.int64), np.zeros(0, bool), np.zeros(0, bool))]
    r0, r1, c0, c1 = grid.window(rnd.sub_down(glo, smax), rnd.add_up(ghi, smax))
    for blk in _blocks((r1 - r0) * (c1 - c0)):  # blocks of ~BLOCK (gate, cell) pairs
        sel = np.arange(blk.start, blk.stop)
        n = (r1 - r0)[sel], (c1 - c0)[sel]
        cnt = n[0] * n[1]
        t = np.repeat(sel, cnt)
        k = np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        r, c = r0[t] + k // np.repeat(n[1], cnt), c0[t] + k % np.repeat(n[1], cnt)
        cell = ((grid.xs[c], grid.xs[c + 1]), (grid.ys[r + 1], grid.ys[r]))
        dg = _diff(cell, glo[t], ghi[t])
        gc, gs = tuple(v[t] for v in gcs[0]), tuple(v[t] for v in gcs[1])
        phi_g, s_g = _proj(dg, gc, gs, 1.0), _proj(dg, gs, gc, -1.0)
        dark = (phi_g[0] > 0) | (phi_g[1] < 0) | (s_g[0] > sh_[0]) | (s_g[1] < sl_[0])
        seen[r[~dark], c[~dark]] = True
        ins = (s_g[0] >= sl_[0]) & (s_g[1] <= sh_[0])  # ψ ⊂ R⁻ on the whole gate
        t, r, c = t[ins], r[ins], c[ins]
        neg, pos = np.zeros(t.size, bool), np.zeros(t.size, bool)
        for j in (t, t + 1):  # the sign of φ at both ends of the gate
            cj, sj = tuple(v[j] for v in cs[0]), tuple(v[j] for v in cs[1])
            cellj = ((grid.xs[c], grid.xs[c + 1]), (grid.ys[r + 1], grid.ys[r]))
            ph_ = _proj(_diff(cellj, lo[j], hi[j]), cj, sj, 1.0)
            neg |= ph_[1] <= 0
            pos |= ph_[0] >= 0
        runs.append(((r * grid.shape[1] + c) * m + t, neg, pos))
    # Theorem B.1 over a window [t_i, t_j] of consecutive gates all with ψ ⊂ R⁻: a run of gates
    # (consecutive t for one cell) with φ proved <= 0 at one sample and >= 0 at another is clear
    key, neg, pos = (np.concatenate([x[k] for x in runs]) for k in range(3))
    order = np.argsort(key, kind="stable")
    key, neg, pos = key[order], neg[order], pos[order]
    run = np.cumsum(np.r_[True, np.diff(key) != 1][: key.size])
    both = (np.bincount(run, neg) > 0) & (np.bincount(run, pos) > 0)
    flat = np.zeros(grid.n_cells, bool)
    flat[(key // m)[both[run]]] = True
    clear = flat.reshape(grid.shape)
    st = np.full(grid.shape, UNKNOWN, np.int8)
    st[~seen] = DARK
    st[clear] = CLEAR
    return st
