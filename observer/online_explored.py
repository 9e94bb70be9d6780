"""Windowed kernels of the online Dig-SLAM filter (thesis §6.4, Eq. 6.21–6.22; explored zone of App. B).

Each step of the online filter only touches the cells within sensor reach of the current pose box.
:class:`WindowDigMap` is a :class:`~.digmap.DigMap` whose digging merges its runs on a window only, with a
clearance lower bound computed on a window (:meth:`WindowDigMap.clearance_window`: cells outside the
window count as *not* free, which only lowers distances, so the bound stays a lower bound; for the few
cells of a pose box, :meth:`WindowDigMap.clearance_cells` takes the same minimum directly) and the impact
contractor of Eq. 6.22 for one pose box (:meth:`WindowDigMap.contract_box`).

:func:`mark_possibly_sensed` grows the outer explored zone ``Z⁺`` (Eq. B.5): a cell is marked unless it is
*proved* to miss every sensed sector ``x + R(ψ)·{ρ <= r⁺, |θ - α| <= γ}`` for ``x ∈ [x]``, ``ψ ∈ [ψ]``:
either its relative box ``c - [x]`` (outward rounded) misses the closed disk ``ρ <= r⁺``, or, for a cone of
aperture at most ``π/2``, it lies strictly on the outer side of one of the cone's edges, or of an axis
that bounds the cone. The certainly sensed cells (``Z⁻``) are exactly the dug cells: a cell is dug when it
lies in ``x + Z⁻`` for every pose (:meth:`DigMap.dig_disks`, :meth:`DigMap.dig_sectors`).

Rounding (both kernels). The pair tests evaluate in round-to-nearest and compare against a margin that
bounds every error: with ``u = 2⁻⁵³``, the differences ``xs[i] - x`` are within ``u|·|`` of the exact
ones, libm's ``cos``/``sin`` within :data:`~.rounding.LIBM_ULPS` ulps (``<= 5·10⁻¹⁶`` absolute), and a
form ``c·p_y - s·p_x`` over the box ``c - [x]`` is off by at most ``(4u + 5·10⁻¹⁶)(M_x + M_y) <
MARGIN·(M_x + M_y)`` with ``M`` the largest coordinate magnitudes; squared distances carry a relative error
``< MARGIN``. Signs of rounded differences are exact (rounding is monotone). The heading angles are
rounded outward with :func:`~.rounding.step_down` / :func:`~.rounding.step_up`.

>>> g = Grid((-2.0, -2.0), (2.0, 2.0), (8, 8))
>>> maybe = np.zeros(g.shape, bool)
>>> mark_possibly_sensed(g, maybe, np.zeros(2), np.zeros(2), 0.0, 0.0, np.array([0.0]),
...                      np.array([np.pi / 8]), np.array([1.2]))
>>> maybe.astype(int)[3:5].tolist()          # a cone towards +x from the origin
[[0, 0, 0, 1, 1, 1, 1, 0], [0, 0, 0, 1, 1, 1, 1, 0]]
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right

import numpy as np
from scipy.ndimage import distance_transform_edt

from . import rounding as rnd
from .digmap import EDT_SLACK, DigMap, _ragged
from .grid import Grid

__all__ = ["WindowDigMap", "mark_possibly_sensed", "MARGIN"]

#: Relative margin of the round-to-nearest pair tests (covers ~900 unit roundoffs, see the module docstring).
MARGIN = 1e-13
_TINY = 1e-300
#: Above this many (pose cell, not-free cell) pairs, :meth:`WindowDigMap.clearance_cells` uses the EDT.
CELLS_PAIRS = 1 << 16


def _cone_window(grid: Grid, lo: np.ndarray, hi: np.ndarray, th1: np.ndarray, th2: np.ndarray,
                 r: np.ndarray) -> tuple[np.ndarray, ...]:  # fmt: skip
    """Cells meeting the bounding box of each cone ``[x] + {ρ <= r, θ ∈ [θ₁, θ₂]}`` plus two cells."""
    k = (np.floor(th1 / (np.pi / 2))[:, None] + np.arange(1, 5)[None, :]) * (np.pi / 2)
    cand = np.concatenate([th1[:, None], th2[:, None], np.where(k <= th2[:, None], k, th1[:, None])], 1)
    cx, cy = np.cos(cand) * r[:, None], np.sin(cand) * r[:, None]
    pad = 2.0 * max(grid.cell_size)
    w_lo = lo + np.stack([np.minimum(cx.min(1), 0), np.minimum(cy.min(1), 0)], axis=1) - pad
    w_hi = hi + np.stack([np.maximum(cx.max(1), 0), np.maximum(cy.max(1), 0)], axis=1) + pad
    return grid.window(w_lo, w_hi)


class WindowDigMap(DigMap):
    """A :class:`DigMap` whose per-step operations stay inside a window of the grid.

    Digging a sonar cone tests only the cells of its window not already dug, with the margin tests of the
    module docstring (the same claims as :meth:`DigMap.dig_sectors`: every point of the cell lies in the
    cone, strictly inside the open disk, for every pose of the box).
    """

    def __init__(self, grid: Grid) -> None:
        super().__init__(grid)
        self._xs, self._nys = grid.xs.tolist(), (-grid.ys).tolist()

    def win(self, lo: np.ndarray, hi: np.ndarray) -> tuple[int, int, int, int]:
        """:meth:`Grid.window` of one box ``(2,)``, as Python ints (bisection on the exact cell bounds)."""
        ny, nx = self.grid.shape
        c0 = min(max(bisect_left(self._xs, float(lo[0])) - 1, 0), nx)
        c1 = min(max(bisect_right(self._xs, float(hi[0])), c0), nx)
        r0 = min(max(bisect_left(self._nys, -float(hi[1])) - 1, 0), ny)
        r1 = min(max(bisect_right(self._nys, -float(lo[1])), r0), ny)
        return r0, r1, c0, c1

    def dig_disks(self, pos_lo: np.ndarray, pos_hi: np.ndarray, r: np.ndarray) -> None:
        """:meth:`DigMap.dig_disks` with the margin tests of the module docstring, on the hull window.

        Row ``j`` of a disk holds the columns ``i`` with ``xs[i+1] < x⁻ + s`` and ``xs[i] > x⁺ - s``,
        ``s = sqrt(r² - m_y²)`` (``m_y`` the row's farthest vertical distance); ``s`` and the two sums are
        moved inwards by the margin.
        """
        lo, hi, r = self._check(pos_lo, pos_hi, r)
        ok = np.all(np.isfinite(lo) & np.isfinite(hi) & (lo <= hi), axis=1) & np.isfinite(r) & (r > 0)
        lo, hi, r = lo[ok], hi[ok], r[ok]
        if not r.size:
            return
        g = self.grid
        rm = float(r.max())
        r0, r1, c0, c1 = self.win(lo.min(0) - rm, hi.max(0) + rm)
        ys = g.ys[r0 : r1 + 1]
        my = np.maximum(ys[None, :-1] - lo[:, 1:2], hi[:, 1:2] - ys[None, 1:])  # (N, rows)
        s2 = (r * r * (1 - MARGIN))[:, None] - my * my * (1 + MARGIN)
        s = np.sqrt(np.maximum(s2, 0.0)) * (1 - MARGIN)
        a = (lo[:, :1] + s) - MARGIN * (np.abs(lo[:, :1]) + s)  # <= x⁻ + s
        b = (hi[:, :1] - s) + MARGIN * (np.abs(hi[:, :1]) + s)  # >= x⁺ - s
        c_hi = np.searchsorted(g.xs, a, side="left") - 1  # columns i with xs[i+1] < a
        c_lo = np.searchsorted(g.xs, b, side="right")  # columns i with xs[i] > b
        cols = np.arange(c0, c1)[None, None, :]
        inside = (s2 > 0)[:, :, None] & (cols >= c_lo[:, :, None]) & (cols < c_hi[:, :, None])
        self.free[r0:r1, c0:c1] |= inside.any(axis=0)

    def dig_sectors(self, pos_lo: np.ndarray, pos_hi: np.ndarray, psi_lo: np.ndarray, psi_hi: np.ndarray,
                    alpha: np.ndarray, gamma: np.ndarray, r: np.ndarray) -> None:  # fmt: skip
        """:meth:`DigMap.dig_sectors` (same narrowed cones ``θ₁ = ψ⁺ + α - γ``, ``θ₂ = ψ⁻ + α + γ``, rounded
        inwards by one-ulp steps; a cone wider than ``π`` split in two) on the cells not yet dug."""
        lo, hi, r = self._check(pos_lo, pos_hi, r)
        psi_lo, psi_hi, alpha, gamma = (np.asarray(v, dtype=np.float64).ravel() for v in
                                        (psi_lo, psi_hi, alpha, gamma))  # fmt: skip
        if not (psi_lo.shape == psi_hi.shape == alpha.shape == gamma.shape == r.shape):
            raise ValueError("psi_lo, psi_hi, alpha, gamma: expected one value per pose box")
        up, down = rnd.step_up, rnd.step_down
        th1, th2 = up(up(psi_hi + alpha) - gamma), down(down(psi_lo + alpha) + gamma)
        ok = np.all(np.isfinite(lo) & np.isfinite(hi) & (lo <= hi), axis=1) & np.isfinite(r) & (r > 0)
        ok &= np.isfinite(th1) & np.isfinite(th2) & (th1 <= th2)
        wide = ok & (up(th2 - th1) > rnd.PI_DOWN)
        if wide.any():  # [θ₁, θ₁ + π⁻] and [θ₂ - π⁻, θ₂], both inside [θ₁, θ₂]
            a1 = np.concatenate([th1[ok], up(th2[wide] - rnd.PI_DOWN)])
            a2 = np.concatenate([np.where(wide, down(th1 + rnd.PI_DOWN), th2)[ok], th2[wide]])
            sel = np.concatenate([np.flatnonzero(ok), np.flatnonzero(wide)])
            self._dig_cones(lo[sel], hi[sel], a1, a2, r[sel])
        else:
            self._dig_cones(lo[ok], hi[ok], th1[ok], th2[ok], r[ok])

    def _dig_cones(
        self, lo: np.ndarray, hi: np.ndarray, th1: np.ndarray, th2: np.ndarray, r: np.ndarray
    ) -> None:
        if not r.size:
            return
        g = self.grid
        if np.all(lo == lo[0]) and np.all(hi == hi[0]):  # one pose box (the filter's case): dense pairs
            rm = float(r.max())
            r0, r1, c0, c1 = self.win(lo[0] - rm, hi[0] + rm)
            row, col = np.nonzero(~self.free[r0:r1, c0:c1])
            row, col = row + r0, col + c0
            owner = None
            blo, bhi, rr = lo[:1], hi[:1], r[:, None]
        else:  # several boxes: ragged pairs over each cone's window
            w0, w1, v0, v1 = _cone_window(g, lo, hi, th1, th2, r)
            nc = np.maximum(v1 - v0, 1)
            owner, off = _ragged((w1 - w0) * (v1 - v0))
            row, col = w0[owner] + off // nc[owner], v0[owner] + off % nc[owner]
            keep = np.flatnonzero(~self.free[row, col])
            owner, row, col = owner[keep], row[keep], col[keep]
            blo, bhi, rr = lo[owner], hi[owner], r[owner]
        dxl, dyl = g.xs[col] - bhi[:, 0], g.ys[row + 1] - bhi[:, 1]
        dxh, dyh = g.xs[col + 1] - blo[:, 0], g.ys[row] - blo[:, 1]
        fx, fy = np.maximum(-dxl, dxh), np.maximum(-dyl, dyh)
        good = (fx * fx + fy * fy) * (1 + MARGIN) < (rr * rr) * (1 - MARGIN)  # (N, M) dense, (M,) ragged
        if owner is None:
            m = np.flatnonzero(good.any(axis=0))
            row, col, dxl, dyl, dxh, dyh, fx, fy = (v[m] for v in (row, col, dxl, dyl, dxh, dyh, fx, fy))
            good = good[:, m]
            c1_, s1_, c2_, s2_ = (f(t)[:, None] for t in (th1, th2) for f in (np.cos, np.sin))
        else:
            c1_, s1_, c2_, s2_ = (f(t)[owner] for t in (th1, th2) for f in (np.cos, np.sin))
        tol = MARGIN * (fx + fy)
        # min over the box of cross(e₁, p) = cos θ₁ p_y - sin θ₁ p_x and of cross(p, e₂)
        good &= np.minimum(c1_ * dyl, c1_ * dyh) - np.maximum(s1_ * dxl, s1_ * dxh) >= tol
        good &= np.minimum(s2_ * dxl, s2_ * dxh) - np.maximum(c2_ * dyl, c2_ * dyh) >= tol
        if owner is None:
            good = good.any(axis=0)
        self.free[row[good], col[good]] = True

    def clearance_window(self, r0: int, r1: int, c0: int, c1: int) -> np.ndarray:
        """Lower bound on ``dist(p, comp M⁻)`` for the cells ``[r0:r1, c0:c1]`` (see :meth:`clearance_lower`).

        The cells around the window are taken as not free: for a cell of the window, clamping the index of
        any cell outside it onto that ring moves it no farther, so the distance transform only decreases.
        """
        dx, dy = self.grid.cell_size
        pad = np.zeros((r1 - r0 + 2, c1 - c0 + 2), dtype=bool)
        sub = self.free[r0:r1, c0:c1]
        pad[1:-1, 1:-1] = sub
        d = distance_transform_edt(pad, sampling=(dy, dx))[1:-1, 1:-1]
        diag = float(np.hypot(dx, dy)) * (1 + EDT_SLACK)
        span = max(self.grid.hi[0] - self.grid.lo[0], self.grid.hi[1] - self.grid.lo[1])
        low = rnd.step_down(d * (1 - EDT_SLACK) - (diag + EDT_SLACK * span))
        return np.where(sub, np.maximum(low, 0.0), 0.0)

    def clearance_cells(self, b0: int, b1: int, a0: int, a1: int, window: tuple[int, int, int, int]
                        ) -> np.ndarray:  # fmt: skip
        """:meth:`clearance_window` of ``window`` restricted to the cells ``[b0:b1, a0:a1]`` (inside it).

        For a few cells (a pose box) the centre distance ``D`` to the nearest not-free cell of the window
        (or of the ring around it, straight across) is a direct minimum over those cells, with the same
        bound ``D(1 - EDT_SLACK) - diag`` as the distance transform; many cells use the transform.
        """
        w0, w1, v0, v1 = window
        sub = self.free[w0:w1, v0:v1]
        nr, nc = np.nonzero(~sub)
        if (b1 - b0) * (a1 - a0) * (nr.size + 1) > CELLS_PAIRS:
            return self.clearance_window(w0, w1, v0, v1)[b0 - w0 : b1 - w0, a0 - v0 : a1 - v0]
        dx, dy = self.grid.cell_size
        pr, pc = np.arange(b0 - w0, b1 - w0)[:, None, None], np.arange(a0 - v0, a1 - v0)[None, :, None]
        d2 = np.min(((pr - nr) * dy) ** 2 + ((pc - nc) * dx) ** 2, axis=2, initial=np.inf)
        ring = np.minimum(np.minimum(pr[..., 0] + 1, w1 - w0 - pr[..., 0]) * dy,
                          np.minimum(pc[..., 0] + 1, v1 - v0 - pc[..., 0]) * dx)  # fmt: skip
        d = np.minimum(np.sqrt(d2), ring)
        diag = float(np.hypot(dx, dy)) * (1 + EDT_SLACK)
        span = max(self.grid.hi[0] - self.grid.lo[0], self.grid.hi[1] - self.grid.lo[1])
        low = rnd.step_down(d * (1 - EDT_SLACK) - (diag + EDT_SLACK * span))
        return np.where(sub[b0 - w0 : b1 - w0, a0 - v0 : a1 - v0], np.maximum(low, 0.0), 0.0)

    def contract_box(self, lo: np.ndarray, hi: np.ndarray, r_hi: float) -> tuple[np.ndarray, np.ndarray]:
        """Eq. 6.22 for one pose box: keep the hull of the cells with ``clearance <= r⁺`` (exact cell bounds).

        Returns the box unchanged when it leaves the frame or ``r⁺`` is infinite, and ``[+inf, -inf]``
        when no cell of the box is feasible.
        """
        g = self.grid
        if not (np.isfinite(r_hi) and np.all(lo >= g.lo) and np.all(hi <= g.hi) and np.all(lo <= hi)):
            return lo, hi
        b0, b1, a0, a1 = self.win(lo, hi)
        reach = float(r_hi) + 2.0 * max(g.cell_size)
        w0, w1, v0, v1 = self.win(lo - reach, hi + reach)
        feas = self.clearance_cells(b0, b1, a0, a1, (w0, w1, v0, v1)) <= r_hi
        rows, cols = np.flatnonzero(feas.any(axis=1)), np.flatnonzero(feas.any(axis=0))
        if not rows.size:
            return np.full(2, np.inf), np.full(2, -np.inf)
        lo = np.array([max(lo[0], g.xs[a0 + cols[0]]), max(lo[1], g.ys[b0 + rows[-1] + 1])])
        hi = np.array([min(hi[0], g.xs[a0 + cols[-1] + 1]), min(hi[1], g.ys[b0 + rows[0]])])
        return lo, hi


def mark_possibly_sensed(
    grid: Grid,
    maybe: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    psi_lo: float,
    psi_hi: float,
    alpha: np.ndarray,
    gamma: np.ndarray,
    r_hi: np.ndarray,
) -> None:
    """Mark in ``maybe`` (in place) every cell not proved outside all the sensed sectors of one pose box.

    Args:
        grid: the cells of ``maybe``.
        maybe: ``(ny, nx)`` bool, the cells possibly sensed so far (only cells still False are tested).
        lo, hi: ``(2,)`` the pose box.
        psi_lo, psi_hi: the heading interval.
        alpha, gamma, r_hi: ``(n,)`` cone directions, half-apertures and sensed ranges ``r⁺``.
    """
    ok = np.isfinite(r_hi) & (r_hi > 0)
    alpha, gamma, r_hi = alpha[ok], gamma[ok], r_hi[ok]
    if not r_hi.size:
        return
    reach = float(r_hi.max())
    (R0,), (R1,), (C0,), (C1,) = grid.window((lo - reach)[None], (hi + reach)[None])
    rows, cols = np.nonzero(~maybe[R0:R1, C0:C1])
    rows, cols = rows + R0, cols + C0
    dxl, dxh = grid.xs[cols] - hi[0], grid.xs[cols + 1] - lo[0]
    dyl, dyh = grid.ys[rows + 1] - hi[1], grid.ys[rows] - lo[1]
    mx, my = np.maximum(np.maximum(dxl, -dxh), 0.0), np.maximum(np.maximum(dyl, -dyh), 0.0)
    near2 = (mx * mx + my * my) * (1 - MARGIN)  # <= the exact squared distance from 0 to c - [x]
    r2 = (r_hi * r_hi) * (1 + MARGIN) + _TINY
    sel = np.flatnonzero(near2 <= r2.max())  # cells within reach of some sensor
    rows, cols, dxl, dxh, dyl, dyh, near2 = (a[sel] for a in (rows, cols, dxl, dxh, dyl, dyh, near2))
    th1 = rnd.step_down(rnd.step_down(psi_lo + alpha) - gamma)
    th2 = rnd.step_up(rnd.step_up(psi_hi + alpha) + gamma)
    is_narrow = rnd.step_up(th2 - th1) <= rnd.HALF_PI_DOWN
    if not is_narrow.all():  # disk-only sensors first: their cells need no cone test
        wide = np.any(near2[None, :] <= r2[~is_narrow, None], axis=0)
        maybe[rows[wide], cols[wide]] = True
        rows, cols, dxl, dxh, dyl, dyh, near2 = (a[~wide] for a in (rows, cols, dxl, dxh, dyl, dyh, near2))
        alpha, r2, th1, th2 = alpha[is_narrow], r2[is_narrow], th1[is_narrow], th2[is_narrow]
    hit = near2[None, :] <= r2[:, None]
    if alpha.size and rows.size:
        tol = MARGIN * (np.maximum(-dxl, dxh) + np.maximum(-dyl, dyh))
        c1, s1, c2, s2 = (f(t)[:, None] for t in (th1, th2) for f in (np.cos, np.sin))
        # max over the box of cross(e₁, p) < 0, or of cross(p, e₂) < 0: strictly outside an edge
        out = np.maximum(c1 * dyl, c1 * dyh) - np.minimum(s1 * dxl, s1 * dxh) < -tol
        out |= np.maximum(s2 * dxl, s2 * dxh) - np.minimum(c2 * dyl, c2 * dyh) < -tol
        # a cone of aperture < π whose two edges lie in a closed half-plane lies in it (cos, sin ± 5e-16)
        e = 1e-15
        out |= ((c1 >= e) & (c2 >= e)) & (dxh < 0) | ((c1 <= -e) & (c2 <= -e)) & (dxl > 0)
        out |= ((s1 >= e) & (s2 >= e)) & (dyh < 0) | ((s1 <= -e) & (s2 <= -e)) & (dyl > 0)
        hit &= ~out
    mark = hit.any(axis=0)
    maybe[rows[mark], cols[mark]] = True
