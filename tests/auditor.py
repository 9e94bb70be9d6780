"""An independent auditor of the guaranteed observer's claims, step by step, against an exact ground truth.

Nothing of ``digslam.observer`` is used for the truth: the exact pose and the exact ranges come from
:mod:`premise` (mpmath arcs from ``truth.pieces``, brute-force cone distances from ``world.edges``), and
the geometry below (cell/edge intersection, even-odd point location, cone/box distances) is written here.
The env and its wrapper are only what is audited: their ``info`` (``pose_box (2, 2)``, ``heading_box (2,)``,
``dig``, ``clear``, ``explored`` on the wrapper's grid, row 0 at the top, cell ``(r, c)`` being
``[xs[c], xs[c+1]] x [ys[r+1], ys[r]]`` with the grid's boundary arrays) and the coverage figures.

Checked at every step while the observer is consistent (a valid premise must never make it inconsistent):

1. the exact position lies in the pose box and the exact heading in the heading box (exact comparisons);
2. no dug or clear cell meets an obstacle: no world edge meets the closed cell box (exact rational test on the
   cells near an edge, a float distance test with a wide margin elsewhere), the box lies in the world frame
   and its centre is free by the even-odd rule over all edges;
3. every clear cell (and every cell coded CLEAR) was seen: sample points of the cell (corners, edge midpoints,
   centre, random points) each lie within some step's true sensed region, the closed cone at the exact pose
   below ``min(true range, r_max)`` (float test with a margin, then an exact mpmath test for the rest);
4. no dark cell was seen: each step's true sensed region misses every dark cell (the nearest point of
   ``cell ∩ cone`` from the exact pose is no nearer than ``min(true range, r_max)``; float screening with
   an inclusive margin, exact mpmath confirmation); a cell that turns dark again is checked against every
   earlier step;
5. certified coverage never exceeds ground-truth coverage.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

import mpmath
import numpy as np
from premise import PREC, PremiseChecker

CLEAR_CODE, DARK_CODE = 1, -1
#: Float margin (m) below which a float decision is re-taken exactly.
EPS = 1e-9


class GuaranteeBreach(AssertionError):
    """A false claim of the observer (or a premise violation, see :class:`premise.PremiseViolation`)."""


def _box_edge_fraction(lo: tuple[float, float], hi: tuple[float, float], e: np.ndarray) -> bool:
    """Exact: does the closed segment ``e`` meet the closed box ``[lo, hi]`` (Liang-Barsky in rationals)?"""
    p = (Fraction(float(e[0])), Fraction(float(e[1])))
    d = (Fraction(float(e[2])) - p[0], Fraction(float(e[3])) - p[1])
    t0, t1 = Fraction(0), Fraction(1)
    for k in (0, 1):
        lk, hk = Fraction(float(lo[k])), Fraction(float(hi[k]))
        if d[k] == 0:
            if not lk <= p[k] <= hk:
                return False
            continue
        a, b = (lk - p[k]) / d[k], (hk - p[k]) / d[k]
        t0, t1 = max(t0, min(a, b)), min(t1, max(a, b))
        if t0 > t1:
            return False
    return True


def _seg_dist(px: np.ndarray, py: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Float distance ``(N,)`` from points to their nearest edge of ``e`` (``(E, 4)``), chunked."""
    out = np.full(px.shape, np.inf)
    for s in range(0, len(e), 256):
        f = e[s : s + 256]
        ax, ay = f[None, :, 0] - px[:, None], f[None, :, 1] - py[:, None]
        dx, dy = (f[:, 2] - f[:, 0])[None], (f[:, 3] - f[:, 1])[None]
        dd = dx * dx + dy * dy
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(dd > 0, np.clip(-(ax * dx + ay * dy) / dd, 0.0, 1.0), 0.0)
        out = np.minimum(out, np.hypot(ax + t * dx, ay + t * dy).min(axis=1))
    return out


def even_odd_free(px: np.ndarray, py: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Even-odd rule with half-open vertices: True where a rightward ray crosses an odd number of edges
    (only reliable for points well away from every edge, which is how it is used)."""
    out = np.zeros(px.shape, dtype=bool)
    for s in range(0, len(px), 512):
        x, y = px[s : s + 512, None], py[s : s + 512, None]
        x1, y1, x2, y2 = (e[None, :, k] for k in range(4))
        straddle = (y1 > y) != (y2 > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
        out[s : s + 512] = (np.count_nonzero(straddle & (xc > x), axis=1) % 2) == 1
    return out


class Auditor:
    """Audits one episode of a certified-coverage env (``DigCoverageEnv`` or ``GuaranteedObserver``).

    Args:
        env: The wrapped env (its ``grid`` and ``unwrapped.world`` are read once per :meth:`reset`).
        samples: Random sample points per clear cell (besides corners, edge midpoints and centre).
        max_outliers: Passed to the premise checker.
    """

    def __init__(self, env: Any, samples: int = 4, max_outliers: int | None = None, seed: int = 0) -> None:
        self.env, self.samples, self.max_outliers = env, samples, max_outliers
        self.rng = np.random.default_rng(seed)
        self.log: list[str] = []

    # --- episode ---------------------------------------------------------------------------------------
    def reset(self, info: dict[str, Any]) -> None:
        world = self.env.unwrapped.world
        self.edges = np.ascontiguousarray(world.edges, dtype=np.float64).reshape(-1, 4)
        self.frame = tuple(float(v) for v in world.frame)
        g = self.env.get_wrapper_attr("grid")
        self.xs, self.ys = np.asarray(g.xs, dtype=np.float64), np.asarray(g.ys, dtype=np.float64)
        self.shape = (len(self.ys) - 1, len(self.xs) - 1)
        self.premise = PremiseChecker(self.edges, dense=False, max_outliers=self.max_outliers)
        self.free_ok = np.zeros(self.shape, dtype=bool)  # verified obstacle-free
        self.seen_ok = np.zeros(self.shape, dtype=bool)  # verified entirely seen
        self.prev_dark: np.ndarray | None = None
        self.k = 0
        rec = info["record"]
        self.alpha, self.gamma, self.r_max = (np.asarray(getattr(rec, n), dtype=np.float64)
                                              for n in ("alpha", "gamma", "r_max"))  # fmt: skip
        self.premise.reset(info["record"], info["truth"])
        self._check(info)

    def step(self, info: dict[str, Any]) -> None:
        self.k += 1
        self.premise.step(info["record"], info["truth"])
        self._check(info)

    def fail(self, msg: str) -> None:
        raise GuaranteeBreach(f"step {self.k}: {msg}")

    # --- checks ----------------------------------------------------------------------------------------
    def _check(self, info: dict[str, Any]) -> None:
        if not info["consistent"]:
            self.fail(f"the observer reports an inconsistency (step {info['inconsistent_step']}) although "
                      "every record satisfies the premise")  # fmt: skip
        ex = self.premise.exact_poses[-1]
        box, hb = np.asarray(info["pose_box"], np.float64), np.asarray(info["heading_box"], np.float64)
        with mpmath.workprec(PREC):
            inside = all(mpmath.mpf(float(box[0, i])) <= c <= mpmath.mpf(float(box[1, i]))
                         for i, c in enumerate((ex.x, ex.y)))  # fmt: skip
        if not inside:
            self.fail(f"exact position ({mpmath.nstr(ex.x, 20)}, {mpmath.nstr(ex.y, 20)}) outside the pose box "
                      f"{box.tolist()}")  # fmt: skip
        if not hb[0] <= ex.th <= hb[1]:
            self.fail(f"exact heading {ex.th!r} outside the heading box {hb.tolist()}")
        sets = info if "dig" in info else self.env.get_wrapper_attr("sets")()  # info_sets: the info's copies
        dig, clear = np.asarray(sets["dig"], bool), np.asarray(sets["clear"], bool)
        explored = np.asarray(sets["explored"])
        for name, m in (("dig", dig), ("clear", clear), ("explored", explored)):
            if m.shape != self.shape:
                self.fail(f"info[{name!r}] has shape {m.shape}, the grid {self.shape}")
        self._check_free(dig | clear)
        self._check_seen(clear | (explored == CLEAR_CODE))
        self._check_dark(explored == DARK_CODE)
        cert, true = float(info["certified_coverage"]), float(info["true_coverage"])
        if not cert <= true:
            self.fail(f"certified coverage {cert} exceeds the ground-truth coverage {true}")

    def cell_boxes(self, rows: np.ndarray, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lo = np.stack([self.xs[cols], self.ys[rows + 1]], axis=1)
        hi = np.stack([self.xs[cols + 1], self.ys[rows]], axis=1)
        return lo, hi

    def _check_free(self, claimed: np.ndarray) -> None:
        rows, cols = np.nonzero(claimed & ~self.free_ok)
        if not rows.size:
            return
        lo, hi = self.cell_boxes(rows, cols)
        f = self.frame
        out = (lo[:, 0] < f[0]) | (lo[:, 1] < f[1]) | (hi[:, 0] > f[2]) | (hi[:, 1] > f[3])
        if out.any():
            i = int(np.nonzero(out)[0][0])
            self.fail(f"cell {(int(rows[i]), int(cols[i]))} {lo[i].tolist()}..{hi[i].tolist()} claimed free "
                      f"reaches outside the world frame {f}")  # fmt: skip
        ctr = 0.5 * (lo + hi)
        half = 0.5 * np.hypot(hi[:, 0] - lo[:, 0], hi[:, 1] - lo[:, 1])
        d = _seg_dist(ctr[:, 0], ctr[:, 1], self.edges) if len(self.edges) else np.full(len(ctr), np.inf)
        near = np.nonzero(~(d > half * (1 + 1e-9) + EPS))[0]
        e = self.edges
        for i in near:
            cand = np.nonzero((np.minimum(e[:, 0], e[:, 2]) <= hi[i, 0]) & (np.maximum(e[:, 0], e[:, 2]) >= lo[i, 0])
                              & (np.minimum(e[:, 1], e[:, 3]) <= hi[i, 1])
                              & (np.maximum(e[:, 1], e[:, 3]) >= lo[i, 1]))[0]  # fmt: skip
            for k in cand:
                if _box_edge_fraction(tuple(lo[i]), tuple(hi[i]), e[k]):
                    self.fail(f"cell {(int(rows[i]), int(cols[i]))} [{lo[i, 0]!r}, {hi[i, 0]!r}] x "
                              f"[{lo[i, 1]!r}, {hi[i, 1]!r}] claimed free meets the edge {e[k].tolist()}")  # fmt: skip
        # no edge meets any of these boxes: each box is wholly free or wholly obstacle, as its centre
        free = even_odd_free(ctr[:, 0], ctr[:, 1], e)
        if not free.all():
            i = int(np.nonzero(~free)[0][0])
            self.fail(f"cell {(int(rows[i]), int(cols[i]))} {lo[i].tolist()}..{hi[i].tolist()} claimed free "
                      "lies inside an obstacle")  # fmt: skip
        self.free_ok[rows, cols] = True

    def _sensors(self, j: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Step ``j``'s float pose, cone directions, half-apertures and sensed radii ``min(range, r_max)``."""
        p = self.premise.poses[j]
        return p, p[2] + self.alpha, self.gamma, np.minimum(self.premise.ranges[j], self.r_max)

    def _seen_float(self, pts: np.ndarray, j: int) -> np.ndarray:
        """Points certainly (with margin) in step ``j``'s true sensed region."""
        p, phi, gam, rho = self._sensors(j)
        v = pts - p[:2]
        r = np.hypot(v[:, 0], v[:, 1])
        ang = np.arctan2(v[:, 1], v[:, 0])
        ok = np.zeros(len(pts), dtype=bool)
        for s in range(len(phi)):
            inr = r < rho[s] - EPS
            if gam[s] >= math.pi:
                ok |= inr
            else:
                da = np.abs(np.mod(ang - phi[s] + math.pi, 2 * math.pi) - math.pi)
                ok |= inr & (da <= gam[s] - EPS)
        return ok

    def _seen_exact(self, q: tuple[float, float]) -> bool:
        """Exact: does the point lie in some step's closed true sensed region?"""
        alpha, gamma, r_max = self.alpha, self.gamma, self.r_max
        with mpmath.workprec(PREC):
            qx, qy = mpmath.mpf(q[0]), mpmath.mpf(q[1])
            for ex, ranges in zip(self.premise.exact_poses, self.premise.exact_ranges, strict=True):
                vx, vy = qx - ex.x, qy - ex.y
                r = mpmath.sqrt(vx * vx + vy * vy)
                for s in range(len(alpha)):
                    rho = min(ranges[s], mpmath.mpf(float(r_max[s])))
                    if not r <= rho:
                        continue
                    if gamma[s] >= math.pi:
                        return True
                    phi = mpmath.mpf(ex.th) + mpmath.mpf(float(alpha[s]))
                    if mpmath.cos(phi) * vx + mpmath.sin(phi) * vy >= r * mpmath.cos(
                        mpmath.mpf(float(gamma[s]))
                    ):
                        return True
        return False

    def _check_seen(self, claimed: np.ndarray) -> None:
        rows, cols = np.nonzero(claimed & ~self.seen_ok)
        if not rows.size:
            return
        lo, hi = self.cell_boxes(rows, cols)
        fr = [(0, 0), (1, 0), (0, 1), (1, 1), (0.5, 0), (0.5, 1), (0, 0.5), (1, 0.5), (0.5, 0.5)]
        fr += [tuple(u) for u in self.rng.uniform(size=(self.samples, 2))]
        u = np.array(fr)
        pts = lo[:, None, :] + u[None, :, :] * (hi - lo)[:, None, :]  # (N, P, 2)
        flat = pts.reshape(-1, 2)
        todo = np.ones(len(flat), dtype=bool)
        for j in range(len(self.premise.poses) - 1, -1, -1):
            idx = np.nonzero(todo)[0]
            if not idx.size:
                break
            todo[idx[self._seen_float(flat[idx], j)]] = False
        for i in np.nonzero(todo)[0]:
            if not self._seen_exact((float(flat[i, 0]), float(flat[i, 1]))):
                c = i // len(u)
                self.fail(f"clear cell {(int(rows[c]), int(cols[c]))} {lo[c].tolist()}..{hi[c].tolist()}: its "
                          f"point {flat[i].tolist()} was never seen")  # fmt: skip
        self.seen_ok[rows, cols] = True

    def _check_dark(self, dark: np.ndarray) -> None:
        steps = [len(self.premise.poses) - 1]
        if self.prev_dark is not None:
            again = dark & ~self.prev_dark
            if again.any():
                self.log.append(
                    f"step {self.k}: {int(again.sum())} cells turned dark again; checked against all steps"
                )
                for j in range(len(self.premise.poses) - 1):
                    self._dark_step(again, j)
        self.prev_dark = dark.copy()
        for j in steps:
            self._dark_step(dark, j)

    def _dark_step(self, dark: np.ndarray, j: int) -> None:
        p, phi, gam, rho = self._sensors(j)
        reach = float(rho.max())
        if not reach > 0:
            return
        x0, x1 = (
            np.searchsorted(self.xs, p[0] - reach - 1) - 1,
            np.searchsorted(self.xs, p[0] + reach + 1) + 1,
        )
        r0 = np.searchsorted(-self.ys, -(p[1] + reach + 1)) - 1
        r1 = np.searchsorted(-self.ys, -(p[1] - reach - 1)) + 1
        ny, nx = self.shape
        r0, r1, x0, x1 = max(r0, 0), min(r1, ny), max(x0, 0), min(x1, nx)
        rr, cc = np.nonzero(dark[r0:r1, x0:x1])
        if not rr.size:
            return
        rows, cols = rr + r0, cc + x0
        lo, hi = self.cell_boxes(rows, cols)
        clamp = np.clip(p[:2], lo, hi)
        dc = np.hypot(*(clamp - p[:2]).T)
        keep = dc < reach + EPS
        if not keep.any():
            return
        rows, cols, lo, hi = rows[keep], cols[keep], lo[keep], hi[keep]
        m = _box_cone_min_float(p[:2], lo, hi, phi, gam, rho)  # (N, S): nearest point of box ∩ cone
        sus = np.nonzero((m < rho[None, :] + EPS).any(axis=1))[0]
        for i in sus:
            for s in np.nonzero(m[i] < rho + EPS)[0]:
                if self._dark_seen_exact(j, s, lo[i], hi[i]):
                    self.fail(f"dark cell {(int(rows[i]), int(cols[i]))} {lo[i].tolist()}..{hi[i].tolist()} "
                              f"was seen by sensor {s} at step {j}")  # fmt: skip

    def _dark_seen_exact(self, j: int, s: int, lo: np.ndarray, hi: np.ndarray) -> bool:
        """Exact: does the closed box meet step ``j``'s open sensed region of sensor ``s``?"""
        alpha, gamma, r_max = self.alpha, self.gamma, self.r_max
        ex = self.premise.exact_poses[j]
        with mpmath.workprec(PREC):
            rho = min(self.premise.exact_ranges[j][s], mpmath.mpf(float(r_max[s])))
            m = _box_cone_min_exact(ex.x, ex.y, mpmath.mpf(ex.th) + mpmath.mpf(float(alpha[s])),
                                    float(gamma[s]), lo, hi)  # fmt: skip
            return bool(m < rho)


def grid_cell_boxes(grid: Any, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The closed boxes ``(lo, hi)`` (each ``(m, 2)``) of the cells set in ``mask`` on ``grid`` (a
    :class:`~digslam.observer.record.grid.Grid`: row 0 at the top)."""
    r, c = np.nonzero(mask)
    return np.stack([grid.xs[c], grid.ys[r + 1]], 1), np.stack([grid.xs[c + 1], grid.ys[r]], 1)


def assert_cells_free(grid: Any, mask: np.ndarray, world: Any) -> None:
    """No obstacle point in any cell of ``mask``: no edge of ``world`` meets the closed box (exact near the
    edges), the box lies in the world's frame, and its centre is free by the even-odd rule (no edge meets the
    box, so it is wholly free or wholly not)."""
    lo, hi = grid_cell_boxes(grid, mask)
    f, e = world.frame, world.edges
    assert np.all((lo[:, 0] >= f[0]) & (lo[:, 1] >= f[1]) & (hi[:, 0] <= f[2]) & (hi[:, 1] <= f[3]))
    ctr = 0.5 * (lo + hi)
    half = 0.5 * np.hypot(*(hi - lo).T)
    for i in np.flatnonzero(~(_seg_dist(ctr[:, 0], ctr[:, 1], e) > half * (1 + 1e-9) + 1e-9)):
        near = np.all(
            (np.minimum(e[:, :2], e[:, 2:]) <= hi[i]) & (np.maximum(e[:, :2], e[:, 2:]) >= lo[i]), axis=1
        )
        for k in np.flatnonzero(near):
            assert not _box_edge_fraction(tuple(lo[i]), tuple(hi[i]), e[k]), f"cell {lo[i]} meets edge {e[k]}"
    free = even_odd_free(ctr[:, 0], ctr[:, 1], e)
    assert free.all(), f"cell {lo[int(np.argmin(free))]} claimed free lies inside an obstacle"


def _box_cone_min_float(p: np.ndarray, lo: np.ndarray, hi: np.ndarray, phi: np.ndarray, gam: np.ndarray,
                        rho: np.ndarray) -> np.ndarray:  # fmt: skip
    """``(N, S)`` float distance from ``p`` to the nearest point of ``box ∩ cone_s`` (``inf`` if empty),
    computed over a superset of the cone (an inclusive angular margin), so it never exceeds the exact value
    by more than rounding."""
    n = len(lo)
    cl = np.clip(p, lo, hi)
    corners = np.stack([lo, np.c_[hi[:, 0], lo[:, 1]], hi, np.c_[lo[:, 0], hi[:, 1]]], axis=1)
    fx = np.clip(p[0], lo[:, 0], hi[:, 0])
    fy = np.clip(p[1], lo[:, 1], hi[:, 1])
    feet = np.stack(
        [np.c_[fx, lo[:, 1]], np.c_[fx, hi[:, 1]], np.c_[lo[:, 0], fy], np.c_[hi[:, 0], fy]], axis=1
    )
    cand = np.concatenate([cl[:, None], corners, feet], axis=1) - p  # (N, 9, 2)
    r = np.hypot(cand[..., 0], cand[..., 1])
    ang = np.arctan2(cand[..., 1], cand[..., 0])
    out = np.full((n, len(phi)), np.inf)
    for s in range(len(phi)):
        if not rho[s] > 0:
            continue
        if gam[s] >= math.pi:
            out[:, s] = r[:, 0]
            continue
        da = np.abs(np.mod(ang - phi[s] + math.pi, 2 * math.pi) - math.pi)
        inc = (da <= gam[s] + 1e-7) | (r < EPS)
        best = np.where(inc, r, np.inf).min(axis=1)
        for sg in (-1.0, 1.0):
            w = np.array([math.cos(phi[s] + sg * gam[s]), math.sin(phi[s] + sg * gam[s])])
            t0, t1 = np.zeros(n), np.full(n, np.inf)
            for k in (0, 1):
                if w[k] == 0:
                    bad = (p[k] < lo[:, k]) | (p[k] > hi[:, k])
                    t0 = np.where(bad, np.inf, t0)
                    continue
                a, b = (lo[:, k] - p[k]) / w[k], (hi[:, k] - p[k]) / w[k]
                t0, t1 = np.maximum(t0, np.minimum(a, b)), np.minimum(t1, np.maximum(a, b))
            best = np.minimum(best, np.where(t0 <= t1 + EPS, t0 * (1 - 1e-12), np.inf))
        out[:, s] = best
    return out


def _box_cone_min_exact(px: Any, py: Any, phi: Any, gamma: float, lo: np.ndarray, hi: np.ndarray) -> Any:
    """Exact (mp) distance from ``(px, py)`` to the nearest point of ``[lo, hi] ∩ closed cone`` (``inf`` if
    empty): the minimum over the clamped point, the corners and the feet on the box's sides that lie in the
    cone, and the entry points of the cone's boundary rays into the box."""
    L = [mpmath.mpf(float(lo[0])), mpmath.mpf(float(lo[1]))]
    H = [mpmath.mpf(float(hi[0])), mpmath.mpf(float(hi[1]))]
    P = [px, py]
    cl = [min(max(P[k], L[k]), H[k]) for k in (0, 1)]
    cand = [cl, [L[0], L[1]], [H[0], L[1]], [H[0], H[1]], [L[0], H[1]],
            [cl[0], L[1]], [cl[0], H[1]], [L[0], cl[1]], [H[0], cl[1]]]  # fmt: skip
    whole = gamma >= math.pi
    ux, uy, cg = mpmath.cos(phi), mpmath.sin(phi), mpmath.cos(mpmath.mpf(gamma))
    best = mpmath.inf
    for qx, qy in cand:
        vx, vy = qx - px, qy - py
        r = mpmath.sqrt(vx * vx + vy * vy)
        if whole or ux * vx + uy * vy >= r * cg:
            best = min(best, r)
    if whole:
        return best
    for sg in (-1, 1):
        a = phi + sg * mpmath.mpf(gamma)
        w = [mpmath.cos(a), mpmath.sin(a)]
        t0, t1, ok = mpmath.mpf(0), mpmath.inf, True
        for k in (0, 1):
            if w[k] == 0:
                ok &= L[k] <= P[k] <= H[k]
                continue
            u, v = (L[k] - P[k]) / w[k], (H[k] - P[k]) / w[k]
            t0, t1 = max(t0, min(u, v)), min(t1, max(u, v))
        if ok and t0 <= t1:
            best = min(best, t0)
    return best


def audit_episode(env: Any, seed: int, actions: Any, max_outliers: int | None = None) -> Auditor:
    """Reset ``env`` with ``seed``, run ``actions`` (float64) and audit every step; returns the auditor."""
    _, info = env.reset(seed=seed)
    aud = Auditor(env, max_outliers=max_outliers, seed=seed)
    aud.reset(info)
    for a in actions:
        _, _, term, trunc, info = env.step(np.asarray(a, dtype=np.float64))
        aud.step(info)
        if term or trunc:
            break
    return aud


#: Yaw actions that stress the arc: tiny, subnormal, huge-but-valid.
TINY_YAWS = (1e-12, -1e-12, 2e-12, -2e-12, 1e-9, -1e-9, 1e-6, 5e-324, -5e-324, 2.2e-308, -2.2e-308, 1e-3)


def random_actions(rng: np.random.Generator, n: int) -> np.ndarray:
    """``(n, 2)`` float64 actions of a random policy mixing uniform actions, straight runs with tiny yaw
    actions, sign-alternating tiny yaws, spins in place and full-speed runs (into walls), in sticky bursts."""
    out = np.empty((n, 2))
    k = 0
    while k < n:
        mode, run = int(rng.integers(6)), int(rng.integers(1, 12))
        for i in range(k, min(k + run, n)):
            if mode == 0:
                out[i] = rng.uniform(-1, 1, 2)
            elif mode == 1:
                out[i] = (rng.choice([1.0, 0.5, -1.0]), rng.choice(TINY_YAWS))
            elif mode == 2:
                y = rng.choice(TINY_YAWS)
                out[i] = (1.0, y if (i - k) % 2 == 0 else -y)
            elif mode == 3:
                out[i] = (0.0, rng.choice([1.0, -1.0, 0.5]))
            elif mode == 4:
                out[i] = (1.0, 0.0)
            else:
                out[i] = (rng.uniform(-1, 1), rng.choice([1.0, -1.0]))
        k += run
    return out
