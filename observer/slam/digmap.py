"""The dig zone ``M⁻`` on a grid and the impact contractor ``C_g^≠`` (thesis §6.4.1, Eq. 6.19–6.22).

A range reading ``y ∈ [y⁻, y⁺]`` taken from a pose ``x ∈ [x]`` gives two shapes (§6.2.3.2, Fig. 6.9): the
free zone ``Z⁻`` (an open disk of radius ``y⁻``, or a sector for a sonar cone) and the impact zone ``ΔZ``
(the ring or arc ``ρ ∈ [y]``). Eq. 6.21 digs ``M⁻ := M⁻ ∪ g⁻¹_{[x]}(Z⁻)``: a cell joins ``M⁻`` when it lies
inside ``x + Z⁻`` for *every* pose of the box, which :meth:`DigMap.dig_disks` and
:meth:`DigMap.dig_sectors` prove with outward rounding. Eq. 6.22 contracts the pose box with
``ΔZ ∩ g_x(comp M) ≠ ∅``: since ``comp M ⊂ comp M⁻``, the true pose satisfies
``dist(x, comp M⁻) <= y⁺``; :meth:`DigMap.contract_impacts` removes the cells where that is proved false,
using the lower bound :meth:`DigMap.clearance_lower` on the distance from each cell to ``comp M⁻``.

>>> g = Grid((-2.0, -2.0), (2.0, 2.0), (40, 40))
>>> m = DigMap(g)
>>> m.dig_disks(np.array([[-0.01, -0.01]]), np.array([[0.01, 0.01]]), np.array([1.0]))
>>> bool(m.free[20, 20]), bool(m.free[20, 39])                  # near the robot / 1.9 m away
(True, False)
>>> lo, hi = m.contract_impacts(np.array([[0.3, -0.1]]), np.array([[0.95, 0.1]]), np.array([0.2]))
>>> np.round(lo, 6).tolist(), hi.tolist()   # poses farther than 0.2 m from comp(M⁻) are removed
([[0.6, -0.1]], [[0.95, 0.1]])
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.record.grid import Grid

#: Pairs of (sector, cell) tested at once by :meth:`DigMap.dig_sectors` (memory bound).
PAIR_CHUNK = 1 << 20
#: Cells gathered at once by :meth:`DigMap.contract_impacts` (memory bound).
CONTRACT_CHUNK = 1 << 22
#: Relative slack that covers the floating-point error of the distance transform (see clearance_lower).
EDT_SLACK = 1e-12


def _ragged(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``owner, offset`` of the flat expansion of ``counts[i]`` items per owner ``i``."""
    owner = np.repeat(np.arange(counts.size), counts)
    start = np.cumsum(counts) - counts
    return owner, np.arange(owner.size) - start[owner]


class DigMap:
    """``M⁻`` as a boolean grid (True = proved free), grown by digging, never shrunk.

    Args:
        grid: the cells; every claim is about whole cells, so it is guaranteed at cell level.
    """

    def __init__(self, grid: Grid) -> None:
        if not isinstance(grid, Grid):
            raise TypeError(f"grid: expected a Grid, got {type(grid).__name__}")
        self.grid = grid
        self.free = np.zeros(grid.shape, dtype=bool)

    # ------------------------------------------------------------------ digging (Eq. 6.21)
    def dig_disks(self, pos_lo: np.ndarray, pos_hi: np.ndarray, r: np.ndarray) -> None:
        """Dig the cells inside the open disk ``D(x, r_i)`` for every ``x`` in box ``i``.

        A cell ``c`` is inside for every pose iff the farthest distance between the pose box and ``c`` is
        below ``r``. That set of cells is convex, so each row is one run of columns, found in closed form:
        with ``m_y`` the row's farthest vertical distance (rounded up) and ``s = sqrt(r² - m_y²)`` (rounded
        down), column ``i`` qualifies iff ``xs[i+1] < x⁻ + s`` and ``xs[i] > x⁺ - s`` (rounded inwards;
        every operation is bounded by a one-ulp step of its round-to-nearest result).
        Runs are merged with one difference array: no loop over boxes or cells.

        Args:
            pos_lo, pos_hi: ``(N, 2)`` pose boxes (empty or unbounded rows are skipped).
            r: ``(N,)`` free radii ``y⁻`` (non-positive or non-finite entries dig nothing).
        """
        lo, hi, r = self._check(pos_lo, pos_hi, r)
        ok = np.all(np.isfinite(lo) & np.isfinite(hi) & (lo <= hi), axis=1) & np.isfinite(r) & (r > 0)
        lo, hi, r = lo[ok], hi[ok], r[ok]
        if not r.size:
            return
        g = self.grid
        ny, nx = g.shape
        r0, r1, _, _ = g.window(lo - r[:, None], hi + r[:, None])
        owner, off = _ragged(r1 - r0)
        row = r0[owner] + off
        b_lo, b_hi = lo[owner], hi[owner]
        # one-ulp steps bound each correctly rounded operation (rounding.step_up / step_down)
        my = rnd.step_up(np.maximum(g.ys[row] - b_lo[:, 1], b_hi[:, 1] - g.ys[row + 1]))
        s2 = rnd.step_down(rnd.step_down(r * r)[owner] - rnd.step_up(my * my))
        s = rnd.step_down(np.sqrt(np.maximum(s2, 0.0)))
        c_hi = Grid.count_below(g.xs, rnd.step_down(b_lo[:, 0] + s), strict=True) - 1
        c_lo = Grid.count_below(g.xs, rnd.step_up(b_hi[:, 0] - s), strict=False)
        c_lo, c_hi = np.clip(c_lo, 0, nx), np.clip(c_hi, 0, nx)
        run = (s2 > 0) & (c_lo < c_hi)
        self._add_runs(row[run], c_lo[run], c_hi[run])

    def dig_sectors(
        self,
        pos_lo: np.ndarray,
        pos_hi: np.ndarray,
        psi_lo: np.ndarray,
        psi_hi: np.ndarray,
        alpha: np.ndarray,
        gamma: np.ndarray,
        r: np.ndarray,
    ) -> None:
        """Dig the cells inside the sonar sector ``x + R(ψ)·{ρ < r, |θ - α| <= γ}`` for every pose.

        For every heading ``ψ ∈ [ψ]`` the sector contains the narrowed cone ``θ ∈ [θ₁, θ₂]`` with
        ``θ₁ = ψ⁺ + α - γ`` (rounded up) and ``θ₂ = ψ⁻ + α + γ`` (rounded down). A cone of aperture at most
        ``π`` cut by the open disk is convex, so the relative box ``c - [x]`` (outward rounded) lies in it iff
        its four corners do: ``|p| < r`` and ``cross(e₁, p) >= 0 <= cross(p, e₂)`` with ``e_k`` enclosed by
        outward-rounded cosines and sines. A wider cone is covered by two overlapping cones of aperture
        ``π`` (a cell inside either is inside the sector).

        Args:
            pos_lo, pos_hi: ``(N, 2)`` pose boxes.
            psi_lo, psi_hi: ``(N,)`` heading intervals.
            alpha, gamma: ``(N,)`` cone directions (relative to the heading) and half-apertures.
            r: ``(N,)`` free ranges ``y⁻``.
        """
        lo, hi, r = self._check(pos_lo, pos_hi, r)
        psi_lo, psi_hi, alpha, gamma = (np.asarray(v, dtype=np.float64).ravel() for v in
                                        (psi_lo, psi_hi, alpha, gamma))  # fmt: skip
        if not (psi_lo.shape == psi_hi.shape == alpha.shape == gamma.shape == r.shape):
            raise ValueError("psi_lo, psi_hi, alpha, gamma: expected one value per pose box")
        th1 = rnd.sub_up(rnd.add_up(psi_hi, alpha), gamma)
        th2 = rnd.add_down(rnd.add_down(psi_lo, alpha), gamma)
        ok = np.all(np.isfinite(lo) & np.isfinite(hi) & (lo <= hi), axis=1) & np.isfinite(r) & (r > 0)
        ok &= np.isfinite(th1) & np.isfinite(th2) & (th1 <= th2)
        wide = ok & (rnd.sub_up(th2, th1) > rnd.PI_DOWN)
        # a wide cone: [θ₁, θ₁ + π⁻] and [θ₂ - π⁻, θ₂], both inside [θ₁, θ₂]
        a1 = np.concatenate([th1[ok], rnd.sub_up(th2[wide], rnd.PI_DOWN)])
        a2 = np.concatenate([np.where(wide, rnd.add_down(th1, rnd.PI_DOWN), th2)[ok], th2[wide]])
        sel = np.concatenate([np.flatnonzero(ok), np.flatnonzero(wide)])
        self._dig_cones(lo[sel], hi[sel], a1, a2, r[sel])

    def _dig_cones(
        self, lo: np.ndarray, hi: np.ndarray, th1: np.ndarray, th2: np.ndarray, r: np.ndarray
    ) -> None:
        if not r.size:
            return
        g = self.grid
        # window: bounding box of the cone's points 0, r e(θ₁), r e(θ₂) and the axis points inside [θ₁, θ₂]
        k = (np.floor(th1 / (np.pi / 2))[:, None] + np.arange(1, 5)[None, :]) * (np.pi / 2)
        cand = np.concatenate([th1[:, None], th2[:, None], np.where(k <= th2[:, None], k, th1[:, None])], 1)
        cx, cy = np.cos(cand) * r[:, None], np.sin(cand) * r[:, None]
        pad = 2.0 * max(g.cell_size)
        w_lo = lo + np.stack([np.minimum(cx.min(1), 0), np.minimum(cy.min(1), 0)], axis=1) - pad
        w_hi = hi + np.stack([np.maximum(cx.max(1), 0), np.maximum(cy.max(1), 0)], axis=1) + pad
        r0, r1, c0, c1 = g.window(w_lo, w_hi)
        nc = c1 - c0
        e = [(rnd.widen_down(f(t)), rnd.widen_up(f(t))) for t in (th1, th2) for f in (np.cos, np.sin)]
        r2 = rnd.step_down(r * r)
        owner_all, off_all = _ragged((r1 - r0) * nc)
        # one-ulp steps bound each correctly rounded operation (rounding.step_up / step_down)
        up, down = rnd.step_up, rnd.step_down
        for s in range(0, owner_all.size, PAIR_CHUNK):
            owner, off = owner_all[s : s + PAIR_CHUNK], off_all[s : s + PAIR_CHUNK]
            row, col = r0[owner] + off // nc[owner], c0[owner] + off % nc[owner]
            # relative box c - [x], outward; the disk test first, on its farthest corner
            blo, bhi = lo[owner], hi[owner]
            dxl, dyl = down(g.xs[col] - bhi[:, 0]), down(g.ys[row + 1] - bhi[:, 1])
            dxh, dyh = up(g.xs[col + 1] - blo[:, 0]), up(g.ys[row] - blo[:, 1])
            fx, fy = np.maximum(-dxl, dxh), np.maximum(-dyl, dyh)
            keep = np.flatnonzero(up(up(fx * fx) + up(fy * fy)) < r2[owner])
            owner, row, col = owner[keep], row[keep], col[keep]
            dxl, dyl, dxh, dyh = dxl[keep], dyl[keep], dxh[keep], dyh[keep]
            (c1l, c1h), (s1l, s1h), (c2l, c2h), (s2l, s2h) = ((a[owner], b[owner]) for a, b in e)
            good = np.ones(owner.size, dtype=bool)
            for px in (dxl, dxh):
                for py in (dyl, dyh):
                    # cross(e₁, p) = cos θ₁ py - sin θ₁ px >= 0 and cross(p, e₂) = px sin θ₂ - py cos θ₂ >= 0
                    x1 = down(down(np.minimum(c1l * py, c1h * py)) - up(np.maximum(s1l * px, s1h * px)))
                    x2 = down(down(np.minimum(s2l * px, s2h * px)) - up(np.maximum(c2l * py, c2h * py)))
                    good &= (x1 >= 0) & (x2 >= 0)
            self.free[row[good], col[good]] = True

    def _add_runs(self, row: np.ndarray, c_lo: np.ndarray, c_hi: np.ndarray) -> None:
        ny, nx = self.grid.shape
        w = nx + 1
        idx = np.concatenate([row * w + c_lo, row * w + c_hi])
        val = np.concatenate([np.ones(row.size), -np.ones(row.size)])
        cover = np.cumsum(np.bincount(idx, weights=val, minlength=ny * w).reshape(ny, w)[:, :nx], axis=1)
        self.free |= cover > 0.5

    @staticmethod
    def _check(pos_lo: np.ndarray, pos_hi: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, ...]:
        lo, hi = np.atleast_2d(np.asarray(pos_lo, np.float64)), np.atleast_2d(np.asarray(pos_hi, np.float64))
        r = np.asarray(r, dtype=np.float64).ravel()
        if lo.shape != hi.shape or lo.ndim != 2 or lo.shape[1] != 2 or r.shape != (lo.shape[0],):
            raise ValueError(f"pos_lo, pos_hi, r: expected (N, 2), (N, 2), (N,), got {lo.shape}, {hi.shape}, "
                             f"{r.shape}")  # fmt: skip
        return lo, hi, r

    # ------------------------------------------------------------------ impacts (Eq. 6.22)
    def clearance_lower(self) -> np.ndarray:
        """Lower bound ``(ny, nx)`` on ``dist(p, comp M⁻)`` for every point ``p`` of each cell.

        ``comp M⁻`` is the union of the cells not in ``M⁻`` and of everything outside the frame (covered by
        a ring of padding cells). The exact Euclidean distance transform gives the centre-to-centre distance
        ``D`` to the nearest such cell; any two points of two cells are at least ``D - |(dx, dy)|`` apart
        (triangle inequality), so ``D - |(dx, dy)|`` bounds the distance from below. ``EDT_SLACK`` covers the
        transform's own rounding and the ulp-level spread of the cell sizes.
        """
        from scipy.ndimage import distance_transform_edt

        ny, nx = self.grid.shape
        dx, dy = self.grid.cell_size
        pad = np.zeros((ny + 2, nx + 2), dtype=bool)
        pad[1:-1, 1:-1] = self.free
        d = distance_transform_edt(pad, sampling=(dy, dx))[1:-1, 1:-1]
        diag = float(np.hypot(dx, dy)) * (1 + EDT_SLACK)
        span = max(self.grid.hi[0] - self.grid.lo[0], self.grid.hi[1] - self.grid.lo[1])
        low = rnd.sub_down(d * (1 - EDT_SLACK), np.full_like(d, diag + EDT_SLACK * span))
        return np.where(self.free, np.maximum(low, 0.0), 0.0)

    def contract_impacts(
        self, pos_lo: np.ndarray, pos_hi: np.ndarray, r_hi: np.ndarray, clearance: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Contract pose boxes with ``dist(x, comp M⁻) <= y⁺`` (Eq. 6.22 relaxed to the disk ``y⁺``).

        The cells of each box whose clearance lower bound exceeds ``y⁺`` hold no feasible pose; the box is
        replaced by its intersection with the hull of the other cells. A box with no feasible cell becomes
        empty (``[+inf, -inf]``): the data contradict their bounds. Boxes not inside the frame, or with an
        infinite ``y⁺`` (no echo), are returned unchanged.

        Args:
            pos_lo, pos_hi: ``(N, 2)`` pose boxes.
            r_hi: ``(N,)`` upper range bounds ``y⁺`` (for a sonar cone this drops the bearing: still sound).
            clearance: a precomputed :meth:`clearance_lower` (recomputed when None).

        Returns:
            The contracted ``(lo, hi)``.
        """
        lo, hi, r_hi = self._check(pos_lo, pos_hi, r_hi)
        lo, hi = lo.copy(), hi.copy()
        g = self.grid
        dlow = self.clearance_lower() if clearance is None else clearance
        act = np.flatnonzero(np.all((lo >= g.lo) & (hi <= g.hi) & (lo <= hi), axis=1) & np.isfinite(r_hi))
        if not act.size:
            return lo, hi
        r0, r1, c0, c1 = g.window(lo[act], hi[act])
        nr, nc = r1 - r0, c1 - c0
        # windows padded to powers of two: a handful of buckets, each a few dense gathers
        br = 1 << np.ceil(np.log2(np.maximum(nr, 1))).astype(np.int64)
        bc = 1 << np.ceil(np.log2(np.maximum(nc, 1))).astype(np.int64)
        keys, inv = np.unique(br * (1 << 32) + bc, return_inverse=True)
        for key_i, key in enumerate(keys.tolist()):
            wr, wc = key >> 32, key & ((1 << 32) - 1)
            members = np.flatnonzero(inv == key_i)
            step = max(1, CONTRACT_CHUNK // (wr * wc))
            for s in range(0, members.size, step):
                idx = members[s : s + step]
                self._contract_chunk(lo, hi, act[idx], r0[idx], c0[idx], nr[idx], nc[idx], wr, wc, dlow, r_hi)
        return lo, hi

    # the body of contract_impacts' loop over chunks of boxes, on its arrays (untyped: eleven of them)
    def _contract_chunk(self, lo, hi, box, r0, c0, nr, nc, wr, wc, dlow, r_hi) -> None:  # type: ignore[no-untyped-def]
        g = self.grid
        ny, nx = g.shape
        ar, ac = np.arange(wr), np.arange(wc)
        vr, vc = ar[None, :] < nr[:, None], ac[None, :] < nc[:, None]
        rows, cols = np.minimum(r0[:, None] + ar, ny - 1), np.minimum(c0[:, None] + ac, nx - 1)
        feas = dlow[rows[:, :, None], cols[:, None, :]] <= r_hi[box][:, None, None]
        feas &= vr[:, :, None] & vc[:, None, :]
        rany, cany = feas.any(axis=2), feas.any(axis=1)
        none = ~rany.any(axis=1)
        fr, lr = np.argmax(rany, axis=1), wr - 1 - np.argmax(rany[:, ::-1], axis=1)
        fc, lc = np.argmax(cany, axis=1), wc - 1 - np.argmax(cany[:, ::-1], axis=1)
        lo[box, 0] = np.maximum(lo[box, 0], g.xs[c0 + fc])
        hi[box, 0] = np.minimum(hi[box, 0], g.xs[np.minimum(c0 + lc + 1, nx)])
        hi[box, 1] = np.minimum(hi[box, 1], g.ys[r0 + fr])
        lo[box, 1] = np.maximum(lo[box, 1], g.ys[np.minimum(r0 + lr + 1, ny)])
        dead = box[none]
        lo[dead], hi[dead] = np.inf, -np.inf


__all__ = ["DigMap", "EDT_SLACK"]
