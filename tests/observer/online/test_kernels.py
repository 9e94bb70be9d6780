"""Compiled kernels of the online filter against numpy oracles and the truth.

The oracles are numpy implementations of the same tests in round-to-nearest, against the relative margin
``MARGIN``. The compiled kernels prove every claim with outward rounding, so
they may differ from the oracles only at cell borders (a few cells): the dug cells are those of the rigorous
offline :class:`DigMap`; the compiled possibly-sensed zone can be a few cells tighter than the oracle's (it
also uses the sector's bounding box). Soundness is checked by sampling against exact geometry and by the
shared ground-truth checks of a whole mission.
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from ground_truth import assert_free
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.envs.config import NoiseConfig
from digslam.envs.dig_coverage.maps_jit import fill_map, observer_sets, three_state
from digslam.envs.sim.generators import ThesisRoom
from digslam.envs.sim.missions import loop_mission
from digslam.envs.sim.sensors import SensorSuite
from digslam.observer.core import rounding as rnd
from digslam.observer.online.dig_types import PoseBox, StepRecord
from digslam.observer.online.observer import OnlineDigSlam
from digslam.observer.online.pose_jit import TRIG_PAD, cos_sin, predict, rotate
from digslam.observer.online.window import WindowDigMap, mark_possibly_sensed
from digslam.observer.record.grid import Grid
from digslam.observer.slam.digmap import EDT_SLACK, DigMap
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA

G = Grid((-6.0, -6.0), (6.0, 6.0), (96, 96))
PI_40 = Fraction("3.1415926535897932384626433832795028841971")  # π to 40 digits
#: Relative margin of the oracles' round-to-nearest pair tests.
MARGIN = 1e-13


# ------------------------------------------------------------------ numpy oracles
def oracle_dig_disk(free: np.ndarray, lo: np.ndarray, hi: np.ndarray, r: float) -> None:
    ys = G.ys
    my = np.maximum(ys[:-1] - lo[1], hi[1] - ys[1:])
    s2 = r * r * (1 - MARGIN) - my * my * (1 + MARGIN)
    s = np.sqrt(np.maximum(s2, 0.0)) * (1 - MARGIN)
    a = (lo[0] + s) - MARGIN * (abs(lo[0]) + s)
    b = (hi[0] - s) + MARGIN * (abs(hi[0]) + s)
    c_hi, c_lo = np.searchsorted(G.xs, a, side="left") - 1, np.searchsorted(G.xs, b, side="right")
    cols = np.arange(G.shape[1])[None, :]
    free |= (s2 > 0)[:, None] & (cols >= c_lo[:, None]) & (cols < c_hi[:, None])


def oracle_dig_cone(
    free: np.ndarray, lo: np.ndarray, hi: np.ndarray, th1: float, th2: float, r: float
) -> None:
    row, col = np.nonzero(~free)
    dxl, dyl = G.xs[col] - hi[0], G.ys[row + 1] - hi[1]
    dxh, dyh = G.xs[col + 1] - lo[0], G.ys[row] - lo[1]
    fx, fy = np.maximum(-dxl, dxh), np.maximum(-dyl, dyh)
    good = (fx * fx + fy * fy) * (1 + MARGIN) < (r * r) * (1 - MARGIN)
    tol = MARGIN * (fx + fy)
    c1, s1, c2, s2 = math.cos(th1), math.sin(th1), math.cos(th2), math.sin(th2)
    good &= np.minimum(c1 * dyl, c1 * dyh) - np.maximum(s1 * dxl, s1 * dxh) >= tol
    good &= np.minimum(s2 * dxl, s2 * dxh) - np.maximum(c2 * dyl, c2 * dyh) >= tol
    free[row[good], col[good]] = True


def oracle_dig_sector(free, lo, hi, psi_lo, psi_hi, alpha, gamma, r) -> None:  # noqa: ANN001
    up, down = rnd.step_up, rnd.step_down
    th1, th2 = float(up(up(psi_hi + alpha) - gamma)), float(down(down(psi_lo + alpha) + gamma))
    if th1 > th2:
        return
    if float(up(th2 - th1)) > rnd.PI_DOWN:
        oracle_dig_cone(free, lo, hi, th1, float(down(th1 + rnd.PI_DOWN)), r)
        oracle_dig_cone(free, lo, hi, float(up(th2 - rnd.PI_DOWN)), th2, r)
    else:
        oracle_dig_cone(free, lo, hi, th1, th2, r)


def oracle_mark(maybe, lo, hi, psi_lo, psi_hi, alpha, gamma, r_hi) -> None:  # noqa: ANN001
    rows, cols = np.nonzero(~maybe)
    dxl, dxh = G.xs[cols] - hi[0], G.xs[cols + 1] - lo[0]
    dyl, dyh = G.ys[rows + 1] - hi[1], G.ys[rows] - lo[1]
    mx, my = np.maximum(np.maximum(dxl, -dxh), 0.0), np.maximum(np.maximum(dyl, -dyh), 0.0)
    near2 = (mx * mx + my * my) * (1 - MARGIN)
    r2 = (r_hi * r_hi) * (1 + MARGIN) + 1e-300
    th1 = rnd.step_down(rnd.step_down(psi_lo + alpha) - gamma)
    th2 = rnd.step_up(rnd.step_up(psi_hi + alpha) + gamma)
    narrow = rnd.step_up(th2 - th1) <= rnd.HALF_PI_DOWN
    hit = near2[None, :] <= r2[:, None]
    tol = MARGIN * (np.maximum(-dxl, dxh) + np.maximum(-dyl, dyh))
    c1, s1, c2, s2 = (f(t)[:, None] for t in (th1, th2) for f in (np.cos, np.sin))
    out = np.maximum(c1 * dyl, c1 * dyh) - np.minimum(s1 * dxl, s1 * dxh) < -tol
    out |= np.maximum(s2 * dxl, s2 * dxh) - np.minimum(c2 * dyl, c2 * dyh) < -tol
    e = 1e-15
    out |= ((c1 >= e) & (c2 >= e)) & (dxh < 0) | ((c1 <= -e) & (c2 <= -e)) & (dxl > 0)
    out |= ((s1 >= e) & (s2 >= e)) & (dyh < 0) | ((s1 <= -e) & (s2 <= -e)) & (dyl > 0)
    hit &= ~(out & narrow[:, None])
    mark = hit.any(axis=0)
    maybe[rows[mark], cols[mark]] = True


def oracle_clearance_cells(free, b0, b1, a0, a1, window) -> np.ndarray:  # noqa: ANN001
    w0, w1, v0, v1 = window
    sub = free[w0:w1, v0:v1]
    nr, nc = np.nonzero(~sub)
    dx, dy = G.cell_size
    pr, pc = np.arange(b0 - w0, b1 - w0)[:, None, None], np.arange(a0 - v0, a1 - v0)[None, :, None]
    d2 = np.min(((pr - nr) * dy) ** 2 + ((pc - nc) * dx) ** 2, axis=2, initial=np.inf)
    ring = np.minimum(np.minimum(pr[..., 0] + 1, w1 - w0 - pr[..., 0]) * dy,
                      np.minimum(pc[..., 0] + 1, v1 - v0 - pc[..., 0]) * dx)  # fmt: skip
    d = np.minimum(np.sqrt(d2), ring)
    diag = float(np.hypot(dx, dy)) * (1 + EDT_SLACK)
    low = rnd.step_down(d * (1 - EDT_SLACK) - (diag + EDT_SLACK * 12.0))
    return np.where(sub[b0 - w0 : b1 - w0, a0 - v0 : a1 - v0], np.maximum(low, 0.0), 0.0)


def oracle_contract(m: WindowDigMap, lo: np.ndarray, hi: np.ndarray, r_hi: float) -> tuple[np.ndarray, ...]:
    b0, b1, a0, a1 = m.win(lo, hi)
    reach = r_hi + 2.0 * max(G.cell_size)
    feas = oracle_clearance_cells(m.free, b0, b1, a0, a1, m.win(lo - reach, hi + reach)) <= r_hi
    rows, cols = np.flatnonzero(feas.any(axis=1)), np.flatnonzero(feas.any(axis=0))
    if not rows.size:
        return np.full(2, np.inf), np.full(2, -np.inf)
    return (np.array([max(lo[0], G.xs[a0 + cols[0]]), max(lo[1], G.ys[b0 + rows[-1] + 1])]),
            np.array([min(hi[0], G.xs[a0 + cols[-1] + 1]), min(hi[1], G.ys[b0 + rows[0]])]))  # fmt: skip


# ------------------------------------------------------------------ exact checks by sampling
def _cell_points(rows: np.ndarray, cols: np.ndarray, rng: np.random.Generator, k: int) -> np.ndarray:
    lo, hi = G.cell_boxes(rows, cols)
    u = rng.random((k, rows.size, 2))
    u[0], u[1] = 0.0, 1.0  # two corners
    return lo + (hi - lo) * u  # (k, cells, 2)


def _random_reading(rng: np.random.Generator) -> tuple:
    lo = rng.uniform(-3, 3, 2)
    hi = lo + rng.uniform(0, 0.6, 2)
    psi_lo = rng.uniform(-7, 7)
    psi_hi = psi_lo + rng.choice([0.0, 0.05, 0.5])
    alpha, gamma = rng.uniform(-3.2, 3.2), rng.choice([0.05, np.pi / 12, 0.7, 2.0, np.pi])
    return lo, hi, psi_lo, psi_hi, alpha, gamma, rng.uniform(0.2, 3.5)


@pytest.mark.parametrize("seed", range(3))
def test_dig_agrees_with_the_numpy_oracle_and_is_sound(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(25):
        lo, hi, psi_lo, psi_hi, alpha, gamma, r = _random_reading(rng)
        ref, exact, jit = np.zeros(G.shape, bool), DigMap(G), WindowDigMap(G)
        if gamma == np.pi and rng.random() < 0.5:  # the omni disk
            oracle_dig_disk(ref, lo, hi, r)
            exact.dig_disks(lo[None], hi[None], [r])
            jit.dig_disks(lo[None], hi[None], [r])
            sector = None
        else:
            oracle_dig_sector(ref, lo, hi, psi_lo, psi_hi, alpha, gamma, r)
            args = ([psi_lo], [psi_hi], [alpha], [gamma], [r])
            exact.dig_sectors(lo[None], hi[None], *args)
            jit.dig_sectors(lo[None], hi[None], *args)
            sector = (psi_lo, psi_hi, alpha, gamma)
        got = jit.free
        assert (got & ~ref).sum() <= 2 and (ref & ~got).sum() <= 2  # equal up to cell borders
        assert not np.any(got & ~exact.free)  # never more than the rigorous offline DigMap proves
        rows, cols = np.nonzero(got)
        if not rows.size:
            continue
        # every point of a dug cell is strictly within r of every pose, inside the sector for every heading
        p = _cell_points(rows, cols, rng, 6)
        x = lo + (hi - lo) * rng.random((6, 1, 2))
        d = p - x
        assert np.all(np.hypot(d[..., 0], d[..., 1]) < r)
        if sector is not None:
            psi = rng.uniform(psi_lo, psi_hi, (6, 1))
            off = np.angle(np.exp(1j * (np.arctan2(d[..., 1], d[..., 0]) - psi - alpha)))
            assert np.all(np.abs(off) <= gamma + 1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_possibly_sensed_contains_the_oracle_and_every_sensed_point(seed: int) -> None:
    rng = np.random.default_rng(10 + seed)
    for _ in range(25):
        lo, hi, psi_lo, psi_hi, _, _, _ = _random_reading(rng)
        alpha, gamma = rng.uniform(-3.2, 3.2, 3), rng.choice([0.05, np.pi / 12, 1.0, np.pi], 3)
        r = rng.uniform(0.2, 3.5, 3)
        ref, got = np.zeros(G.shape, bool), np.zeros(G.shape, bool)
        oracle_mark(ref, lo, hi, psi_lo, psi_hi, alpha, gamma, r)
        mark_possibly_sensed(G, got, lo, hi, psi_lo, psi_hi, alpha, gamma, r)
        assert (ref & ~got).sum() <= 3 and (got & ~ref).sum() <= 3  # equal up to cell borders
        # the cells the compiled kernel proves dark and the oracle does not: proved by the sector's bounding
        # box (apex, arc ends, axis points), which the oracle did not use; check them with dense samples
        only = ref & ~got
        m = 40000 if only.any() else 4000
        x = lo + (hi - lo) * rng.random((m, 2))
        s = rng.integers(0, 3, m)
        th = rng.uniform(psi_lo, psi_hi, m) + alpha[s] + gamma[s] * rng.uniform(-1, 1, m)
        rho = r[s] * np.sqrt(rng.random(m))
        rho[:50] = r[s[:50]]  # on the arc
        px, py = x[:, 0] + rho * np.cos(th), x[:, 1] + rho * np.sin(th)
        col = np.clip(np.searchsorted(G.xs, px) - 1, 0, G.shape[1] - 1)
        row = np.clip(np.searchsorted(-G.ys, -py) - 1, 0, G.shape[0] - 1)
        assert np.all(got[row, col]) and not np.any(only[row, col])


def test_contraction_equals_the_oracle() -> None:
    rng = np.random.default_rng(3)
    for _ in range(30):
        m = WindowDigMap(G)
        c = rng.uniform(-3, 3, (4, 2))
        m.dig_disks(c - 0.2, c + 0.2, rng.uniform(0.5, 2.5, 4))
        lo = rng.uniform(-3, 3, 2)
        hi = lo + rng.uniform(0, 1.0, 2)
        r_hi = float(rng.uniform(0.0, 2.0))
        a, b = m.contract_box(lo, hi, r_hi), oracle_contract(m, lo, hi, r_hi)
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
        w = m.win(lo - 3.0, hi + 3.0)
        p = m.win(lo, hi)
        ref = oracle_clearance_cells(m.free, *p, w)
        assert np.allclose(m.clearance_cells(*p, w), ref, rtol=0, atol=1e-12)


def _old_predict(lo, hi, h0l, h0h, dt, yl, yh, cl_, ch_, vl, vh):  # noqa: ANN001, ANN202
    dn, up = (lambda v: math.nextafter(v, -math.inf)), (lambda v: math.nextafter(v, math.inf))

    def mul(al, ah, bl, bh):  # noqa: ANN001, ANN202
        p = (al * bl, al * bh, ah * bl, ah * bh)
        return dn(min(p)), up(max(p))

    dtl, dth = dn(dt), up(dt)
    wl, wh = mul(dtl, dth, yl, yh)
    hl, hh = max(cl_, dn(h0l + wl)), min(ch_, up(h0h + wh))
    zl, zh = min(wl, 0.0), max(wh, 0.0)
    sl, sh = max(dn(h0l + zl), dn(hl - zh)), min(up(h0h + zh), up(hh - zl))
    c0, c1, s0, s1 = cos_sin(sl, sh)
    d = [mul(dtl, dth, *mul(vl, vh, c0, c1)), mul(dtl, dth, *mul(vl, vh, s0, s1))]
    return hl, hh, dn(lo[0] + d[0][0]), dn(lo[1] + d[1][0]), up(hi[0] + d[0][1]), up(hi[1] + d[1][1])


def _step(dt: float, yaw: tuple, comp: tuple, speed: tuple, n: int = 0, lateral: tuple = (0.0, 0.0)
          ) -> StepRecord:  # fmt: skip
    """A :class:`StepRecord` with these odometry intervals (a unicycle by default) and ``n`` dummy readings."""
    z = np.zeros(n)
    return StepRecord(dt, np.array(speed, float), np.array(lateral, float), np.array(yaw, float),
                      np.array(comp, float), z, z, z, np.zeros((n, 2)), np.zeros(n, bool))  # fmt: skip


def _old_cos_sin(a: float, b: float) -> tuple[float, float, float, float]:
    """The former loop of :func:`cos_sin` (before :func:`~digslam.observer.core.angles_jit.axes_in`)."""
    if not (math.isfinite(a) and math.isfinite(b)):
        return -1.0, 1.0, -1.0, 1.0
    f0, f1 = math.floor(a / rnd.HALF_PI_UP) - 1.0, math.floor(b / rnd.HALF_PI_DOWN) + 1.0
    if f1 - f0 > 8.0:
        return -1.0, 1.0, -1.0, 1.0
    ca, cb, sa, sb = math.cos(a), math.cos(b), math.sin(a), math.sin(b)
    c0, c1 = min(ca, cb) - TRIG_PAD, max(ca, cb) + TRIG_PAD
    s0, s1 = min(sa, sb) - TRIG_PAD, max(sa, sb) + TRIG_PAD
    for m in range(int(f0), int(f1) + 1):
        p = m * rnd.HALF_PI_DOWN
        eps = abs(p) * 1e-15 + 1e-300
        if a - eps <= p <= b + eps:
            c1, s1, c0, s0 = (1.0, s1, c0, s0) if m % 4 == 0 else (c1, 1.0, c0, s0) if m % 4 == 1 else (
                (c1, s1, -1.0, s0) if m % 4 == 2 else (c1, s1, c0, -1.0))  # fmt: skip
    return max(c0, -1.0), min(c1, 1.0), max(s0, -1.0), min(s1, 1.0)


def test_cos_sin_is_the_former_loop_and_axes_in_never_misses_an_axis() -> None:
    from digslam.observer.core.angles_jit import axes_in

    rng = np.random.default_rng(12)
    q = np.arange(-40, 41) * (math.pi / 2)
    ends = np.concatenate([rng.uniform(-30, 30, 400), q, np.nextafter(q, np.inf), np.nextafter(q, -np.inf)])
    for a in ends:
        for w in (0.0, 1e-12, 0.3, 1.6, 3.2, 6.3, 20.0):
            b = a + w
            assert cos_sin(a, b) == _old_cos_sin(a, b)
            got = axes_in(a, b)
            # exact reals m·π/2 in [a, b] (Fraction arithmetic on π to 40 digits is plenty here)
            for m in range(math.floor(a / (math.pi / 2)) - 2, math.floor(b / (math.pi / 2)) + 3):
                p = m * (PI_40 / 2)
                if Fraction(a) <= p <= Fraction(b):
                    assert got[m % 4], (a, b, m)
    assert axes_in(np.nan, 1.0) == (True,) * 4 and axes_in(0.0, np.inf) == (True,) * 4


def test_grid_frame_gives_the_grid_s_cell_size_and_frame_exactly() -> None:
    from digslam.observer.online.dig_jit import cell_size, in_frame
    from digslam.observer.online.window import grid_frame

    rng = np.random.default_rng(14)
    for _ in range(200):
        lo = rng.uniform(-50, 50, 2)
        hi = lo + rng.uniform(1e-3, 80, 2)
        g = Grid(lo, hi, tuple(int(v) for v in rng.integers(1, 300, 2)))
        f = grid_frame(g)
        assert cell_size(f) == g.cell_size
        (x0, y0), (x1, y1) = g.lo, g.hi
        assert in_frame(f, x0, y0, x1, y1) and not in_frame(f, np.nextafter(x0, -np.inf), y0, x1, y1)
        assert not in_frame(f, x0, y0, x1, np.nextafter(y1, np.inf)) and not in_frame(f, x1, y0, x0, y1)


def test_window_is_the_former_bisection() -> None:
    from digslam.observer.core.grid_jit import window

    def count(a, v, strict):  # noqa: ANN001, ANN202
        lo, hi = 0, a.size
        while lo < hi:
            mid = (lo + hi) // 2
            if a[mid] < v or (not strict and a[mid] == v):
                lo = mid + 1
            else:
                hi = mid
        return lo

    def old(xs, nys, x0, y0, x1, y1):  # noqa: ANN001, ANN202
        nx, ny = xs.size - 1, nys.size - 1
        c0 = min(max(count(xs, x0, True) - 1, 0), nx)
        c1 = min(max(count(xs, x1, False), c0), nx)
        r0 = min(max(count(nys, -y1, True) - 1, 0), ny)
        r1 = min(max(count(nys, -y0, False), r0), ny)
        return r0, r1, c0, c1

    g = Grid((-2.0, -1.0), (2.0, 3.0), (8, 5))
    xs, nys = np.array(g.xs), np.array(-g.ys)
    vals = np.concatenate([xs, -nys, [-9.0, 9.0, np.inf, -np.inf, np.nan, 0.1, -0.3, 2.2]])
    rng = np.random.default_rng(13)
    for _ in range(3000):
        x0, y0, x1, y1 = rng.choice(vals, 4)
        assert window(xs, nys, x0, y0, x1, y1) == old(xs, nys, x0, y0, x1, y1)


def test_predict_equals_the_scalar_python_step_and_encloses_the_motion() -> None:
    rng = np.random.default_rng(4)
    for _ in range(200):
        lo = rng.uniform(-5, 5, 2)
        hi = lo + rng.uniform(0, 0.3, 2)
        h0l = rng.uniform(-7, 7)
        h0h, dt = h0l + rng.uniform(0, 0.2), rng.uniform(0.01, 0.2)
        yl = rng.uniform(-1, 1)
        vl = rng.uniform(-0.2, 1.0)
        args = (h0l, h0h, dt, yl, yl + 0.05, -np.inf, np.inf, vl, vl + 0.05)
        ok, box, _ = predict(
            PoseBox(lo[0], lo[1], hi[0], hi[1], h0l, h0h),
            _step(dt, (yl, yl + 0.05), (-np.inf, np.inf), (vl, vl + 0.05)),
        )
        x0, y0, x1, y1, hl, hh = box
        assert ok and (hl, hh, x0, y0, x1, y1) == _old_predict(lo, hi, *args)
        # a constant-rate motion from a pose of the box stays in the predicted box
        t = np.linspace(0, dt, 9)
        for _k in range(5):
            w, v, h = rng.uniform(yl, yl + 0.05), rng.uniform(vl, vl + 0.05), rng.uniform(h0l, h0h)
            x = lo + (hi - lo) * rng.random(2)
            ang = h + w * t
            end = x + v * np.array([np.trapezoid(np.cos(ang), t), np.trapezoid(np.sin(ang), t)])
            assert x0 - 1e-6 <= end[0] <= x1 + 1e-6 and y0 - 1e-6 <= end[1] <= y1 + 1e-6
            assert hl <= h + w * dt <= hh


def test_a_mission_passes_the_ground_truth_checks() -> None:
    suite = SensorSuite(np.r_[np.arange(8) * math.pi / 4, 0.0], np.r_[np.full(8, math.pi / 12), math.pi],
                        np.full(9, 5.0))  # fmt: skip
    world = ThesisRoom(jitter=0.2).generate(3)
    rec, truth = loop_mission(
        world, suite=suite, duration=15.0, noise=NoiseConfig(model="adversarial"), seed=3
    )
    grid = Grid.from_cell_size((-10.0, -10.0), (10.0, 10.0), 0.15625)
    f = OnlineDigSlam(grid)
    f.reset(truth[0, :2], truth[0, :2], rec[0])
    rng = np.random.default_rng(0)
    for k in range(1, len(rec)):
        f.update(rec[k])
        assert f.consistent
        assert np.all((f.pose_lo <= truth[k, :2]) & (truth[k, :2] <= f.pose_hi))
        assert f.heading_lo <= truth[k, 2] <= f.heading_hi
        if k % 10 == 0:  # every truly sensed point lies in the explored outer set
            d = suite.true_ranges(world, truth[k, :3])
            d = np.where(np.isfinite(d), d, suite.r_max)[:, None] * np.sqrt(rng.random((suite.n, 20)))
            th = truth[k, 2] + suite.alpha[:, None] + suite.gamma[:, None] * rng.uniform(-1, 1, (suite.n, 20))
            px, py = (truth[k, 0] + d * np.cos(th)).ravel(), (truth[k, 1] + d * np.sin(th)).ravel()
            col = np.clip(np.searchsorted(grid.xs, px) - 1, 0, grid.shape[1] - 1)
            row = np.clip(np.searchsorted(-grid.ys, -py) - 1, 0, grid.shape[0] - 1)
            assert np.all(f.sensed_maybe[row, col])
    assert_free(f.dig.free, world, grid, rng, 2000)
    assert_free(f.clear_mask(), world, grid, rng, 2000)
    assert f.dig.free.sum() > 100


def test_observer_sets_and_map_kernels_match_numpy() -> None:
    rng = np.random.default_rng(5)
    sure, maybe, free, reach = (rng.random((40, 40)) < p for p in (0.3, 0.6, 0.7, 0.8))
    maybe |= sure
    explored, clear, dark = np.empty((40, 40), np.int8), np.empty((40, 40), bool), np.empty((40, 40), bool)
    n = observer_sets(sure, maybe, free, reach, explored, clear, dark)
    ref = np.where(sure, CLEAR, np.where(maybe, PENUMBRA, DARK))
    assert np.array_equal(explored, ref) and np.array_equal(clear, sure & free)
    assert np.array_equal(dark, ~maybe) and n == int(np.sum(sure & free & reach))
    for m in (40, 36, 20, 64):
        img = np.zeros((3, m, m), np.uint8)
        fill_map(clear, dark, img)
        s = (np.arange(m) * 40) // m
        e = np.maximum(np.append(s[1:], 40), s + 1)
        c = np.array([[clear[s[i] : e[i], s[j] : e[j]].all() for j in range(m)] for i in range(m)])
        d = np.array([[dark[s[i] : e[i], s[j] : e[j]].all() for j in range(m)] for i in range(m)])
        assert np.array_equal(img[0] > 0, c) and np.array_equal(img[2] > 0, d) and np.all(img.sum(0) == 255)
        assert all(
            np.array_equal(a, b) for a, b in zip(three_state(clear, dark, m), (c, ~(c | d), d), strict=True)
        )
    with pytest.raises(ValueError, match="C-contiguous"):
        observer_sets(sure, maybe, free, reach, explored, clear[:, ::2], dark)


@pytest.mark.parametrize("window", [0, 3])
def test_wrapper_sets_kept_up_to_date_equal_the_filter_sets(window: int) -> None:
    from digslam.envs.dig_coverage.config import ObserverConfig
    from digslam.envs.dig_coverage.maps_jit import three_state as ts
    from digslam.envs.dig_coverage.wrapper import GuaranteedObserver
    from digslam.envs.explore.env import ExploreEnv
    from digslam.observer.online.observer import OnlineConfig

    cfg = ObserverConfig(map_size=48, info_sets=True, online=OnlineConfig(smoothing_window=window))
    env = GuaranteedObserver(ExploreEnv(world="rocks"), config=cfg)
    rng = np.random.default_rng(window)
    for episode in range(2):
        obs, info = env.reset(seed=episode)
        for k in range(60):
            f = env.filter
            assert np.array_equal(info["explored"], f.explored()) and np.array_equal(
                info["clear"], f.clear_mask()
            )
            assert round(info["certified_coverage"] * env.n_reachable) == np.sum(
                f.clear_mask() & env.reachable
            )
            c, p, d = ts(f.clear_mask(), f.explored() == DARK, 48)
            assert np.array_equal(obs["map"][0] > 0, c) and np.array_equal(obs["map"][2] > 0, d)
            if k % 20 == 0:
                info["clear"][:] = True  # the agent's copies are its own
            a = np.array([rng.uniform(0.3, 1.0), rng.uniform(-1, 1)], np.float32)
            obs, _, _, _, info = env.step(a)


def test_dig_and_mark_window_holds_every_changed_cell_and_filter_step_matches_the_kernels() -> None:
    from digslam.observer.online.dig_types import CellSets
    from digslam.observer.online.mark_jit import dig_and_mark
    from digslam.observer.online.pose_jit import contract, impact_bound
    from digslam.observer.online.step_jit import filter_step

    g = Grid((-4.0, -4.0), (4.0, 4.0), (64, 64))
    d = WindowDigMap(g)
    rng = np.random.default_rng(11)
    free, sure, maybe = (np.zeros(g.shape, bool) for _ in range(3))
    alpha = np.array([0.0, 1.0, -2.0, np.pi / 2, 0.0])
    gamma = np.array([0.3, 0.2, 0.4, 0.26, np.pi])
    r_max = np.full(5, 3.0)
    lo, hi, h = np.array([-0.1, -0.2]), np.array([0.1, 0.0]), (-0.05, 0.05)
    for _ in range(40):
        rg = np.sort(rng.uniform(0.2, 3.5, (5, 2)), axis=1)
        no_echo = rg[:, 0] > 3.0
        rg[no_echo] = [3.0, np.inf]
        yaw, comp, speed = np.array([-0.3, 0.3]), np.array([h[0] - 0.1, h[1] + 0.1]), np.array([0.4, 0.6])
        f0, s0, m0 = free.copy(), sure.copy(), maybe.copy()
        step = StepRecord(0.1, speed, np.zeros(2), yaw, comp, alpha, gamma, r_max, rg, no_echo)
        # the fused step equals predict + Eq. 6.22 + dig_and_mark called one by one
        ok, box, disp = predict(PoseBox(lo[0], lo[1], hi[0], hi[1], h[0], h[1]), step)
        assert ok
        x0, y0, x1, y1, hl, hh = box
        rb = impact_bound(no_echo, rg)
        if math.isfinite(rb):
            x0, y0, x1, y1 = contract(f0, d.frame, x0, y0, x1, y1, rb)
        new = (lo.copy(), hi.copy(), np.array(h))
        cells = CellSets(free, sure, maybe, np.zeros((2, 1, 1), np.int32), np.zeros(1, np.int32))
        code, *win, shift = filter_step(cells, d.frame, step, *new, True)
        if not x0 <= x1 or not y0 <= y1:  # the random ranges contradict the dug cells: start again
            assert code == 1
            lo, hi, h = np.array([-0.1, -0.2]), np.array([0.1, 0.0]), (-0.05, 0.05)
            free[:], sure[:], maybe[:] = False, False, False
            continue
        assert code == 0 and [*np.concatenate(new).tolist(), *shift] == [x0, y0, x1, y1, hl, hh, *disp]
        f1, s1, m1 = f0.copy(), s0.copy(), m0.copy()
        c1 = CellSets(f1, s1, m1, np.zeros((2, 1, 1), np.int32), np.zeros(1, np.int32))
        assert dig_and_mark(c1, d.frame, PoseBox(x0, y0, x1, y1, hl, hh), step, True) == tuple(win)
        assert np.array_equal(f1, free) and np.array_equal(s1, sure) and np.array_equal(m1, maybe)
        changed = (free != f0) | (sure != s0) | (maybe != m0)
        r0, r1, c0, c1 = win
        outside = changed.copy()
        outside[r0:r1, c0:c1] = False
        assert not outside.any() and (changed.any() or (r0 >= r1 or c0 >= c1))
        if changed.any():  # the smallest such window
            rows, cols = np.nonzero(changed)
            assert (r0, r1, c0, c1) == (rows.min(), rows.max() + 1, cols.min(), cols.max() + 1)
        lo, hi, h = new[0].copy(), new[1].copy(), (new[2][0], new[2][1])
        lo, hi = np.clip(lo, -3.0, 3.0), np.clip(np.maximum(hi, lo), -3.0, 3.0)


def test_observe_matches_its_pieces() -> None:
    from digslam.envs.dig_coverage.maps_jit import MapPlanes, pixel_blocks, pixel_range, sets_and_map
    from digslam.envs.dig_coverage.observe_jit import map_context, observe
    from digslam.observer.core.grid_jit import window

    rng = np.random.default_rng(6)
    for n, m in ((40, 36), (30, 64), (64, 64)):
        g = Grid((-2.0, -2.0), (2.0, 2.0), (n, n))
        sure, maybe, free, reach = (rng.random((n, n)) < p for p in (0.3, 0.6, 0.7, 0.8))
        maybe |= sure
        planes = np.zeros((4, n, n), np.uint8)
        planes[3] = reach
        explored, clear, dark = (np.zeros((n, n), t) for t in (np.int8, bool, bool))
        base, ref_base = np.zeros((3, m, m), np.uint8), np.zeros((3, m, m), np.uint8)
        lo, hi = np.sort(rng.uniform(-2.0, 2.0, (2, 2)), axis=0)
        img, state = np.empty((4, m, m), np.uint8), np.empty(11, np.float32)
        win = (3, n - 5, 2, n // 2)
        ref = sets_and_map(sure, maybe, free, reach, explored, clear, dark, ref_base, win)
        snap = np.empty((3, n, n), np.uint8)
        maps = map_context((sure, maybe, free), MapPlanes(*planes), base, g.xs, -g.ys, 100.0)
        got = observe(maps, lo, hi, (0.1, 0.3), win, 7, 5, img, state, snap)
        assert np.array_equal(snap[:2], planes[:2]) and np.array_equal(snap[2], free)
        assert got == ref + 5 and np.array_equal(base, ref_base) and np.array_equal(img[:3], ref_base)
        assert np.array_equal(planes[0].view(np.int8)[3 : n - 5, 2 : n // 2], explored[3 : n - 5, 2 : n // 2])
        r0, r1, c0, c1 = window(g.xs, -g.ys, lo[0], lo[1], hi[0], hi[1])
        p0, p1 = pixel_range(r0, r1, n, m)
        q0, q1 = pixel_range(c0, c1, n, m)
        foot = np.zeros((m, m), np.uint8)
        foot[p0:p1, q0:q1] = 255
        assert np.array_equal(img[3], foot) and np.array(pixel_blocks((n, n), m)).shape == (4, m)
        want = [lo[0] / 2, lo[1] / 2, hi[0] / 2, hi[1] / 2, math.cos(0.2), math.sin(0.2), 0.1 / math.pi,
                math.tanh(max(hi - lo)), 0.07, np.count_nonzero(planes[1]) / (n * n), 1.0]  # fmt: skip
        assert np.array_equal(state, np.array(want, np.float32))


@settings(max_examples=200, deadline=None)
@given(
    v1=st.tuples(st.floats(-3, 5), st.floats(0, 3)),
    v2=st.tuples(st.floats(-2, 2), st.floats(0, 2)),
    psi=st.tuples(st.floats(-20, 20), st.floats(0, 7)),
    seed=st.integers(0, 2**32 - 1),
)
def test_rotate_contains_the_rotated_velocities(v1: tuple, v2: tuple, psi: tuple, seed: int) -> None:
    """The compiled enclosure of ``R([psi]) [v]`` (Eq. 3.59, 6.12, B.20) holds ``R(psi) v`` for sampled
    ``psi``, ``v = (v_1, v_2)`` (the corners included; mpmath at 40 digits)."""
    import mpmath

    v1l, v1h, v2l, v2h = v1[0], v1[0] + v1[1], v2[0], v2[0] + v2[1]
    pl, ph = psi[0], psi[0] + psi[1]
    u0l, u0h, u1l, u1h = rotate(v1l, v1h, v2l, v2h, *cos_sin(pl, ph))
    rng = np.random.default_rng(seed)
    pts = [(a, b, p) for a in (v1l, v1h) for b in (v2l, v2h) for p in (pl, ph)]
    pts += list(zip(rng.uniform(v1l, v1h, 16), rng.uniform(v2l, v2h, 16), rng.uniform(pl, ph, 16)))
    with mpmath.workdps(40):
        for a, b, p in pts:
            if not (v1l <= a <= v1h and v2l <= b <= v2h and pl <= p <= ph):
                continue
            c, s = mpmath.cos(mpmath.mpf(p)), mpmath.sin(mpmath.mpf(p))
            a_, b_ = mpmath.mpf(a), mpmath.mpf(b)
            assert mpmath.mpf(u0l) <= a_ * c - b_ * s <= mpmath.mpf(u0h), (a, b, p)
            assert mpmath.mpf(u1l) <= a_ * s + b_ * c <= mpmath.mpf(u1h), (a, b, p)


def test_rotate_without_lateral_is_the_unicycle_product() -> None:
    """``[v_2] = [0, 0]``: :func:`rotate` is the unicycle's ``[v_1]·[c]``, ``[v_1]·[s]`` to the bit (what
    keeps every unicycle step of the filter unchanged); with ``v_2`` it encloses them, signs of zero
    included, and an unbounded ``v_2`` gives unbounded bounds, never NaN."""
    from digslam.observer.core.scalar_jit import imul_hi, imul_lo

    rng = np.random.default_rng(21)
    for _ in range(500):
        vl = float(rng.choice([0.0, -0.5, rng.uniform(-2, 2)]))
        vh = vl + float(rng.choice([0.0, rng.uniform(0, 1)]))
        pl = rng.uniform(-7, 7)
        cs = cos_sin(pl, pl + rng.uniform(0, 2))
        uni = (imul_lo(vl, vh, cs[0], cs[1]), imul_hi(vl, vh, cs[0], cs[1]), imul_lo(vl, vh, cs[2], cs[3]),
               imul_hi(vl, vh, cs[2], cs[3]))  # fmt: skip
        got = rotate(vl, vh, 0.0, 0.0, *cs)
        assert np.array(got).tobytes() == np.array(uni).tobytes()
        w = rotate(vl, vh, -0.1, 0.2, *cs)
        assert w[0] <= got[0] and got[1] <= w[1] and w[2] <= got[2] and got[3] <= w[3]
    inf = rotate(1.0, 1.0, -np.inf, np.inf, 0.5, 0.6, -0.1, 0.1)
    assert inf == (-np.inf, np.inf, -np.inf, np.inf)


def test_predict_with_lateral_slip_encloses_the_motion() -> None:
    """A constant-rate motion with sideways slip from a pose of the prior box, ``x' = R(psi) v`` (Eq. 3.59,
    6.12, B.20; exact closed form in mpmath), ends in the predicted box."""
    import mpmath

    rng = np.random.default_rng(22)
    for _ in range(200):
        lo = rng.uniform(-5, 5, 2)
        hi = lo + rng.uniform(0, 0.3, 2)
        h0l = rng.uniform(-7, 7)
        h0h, dt = h0l + rng.uniform(0, 0.2), rng.uniform(0.01, 0.3)
        yl, vl, ll = rng.uniform(-1, 1), rng.uniform(-0.2, 1.0), rng.uniform(-0.5, 0.5)
        step = _step(dt, (yl, yl + 0.05), (-np.inf, np.inf), (vl, vl + 0.05), lateral=(ll, ll + 0.05))
        ok, box, d = predict(PoseBox(lo[0], lo[1], hi[0], hi[1], h0l, h0h), step)
        assert ok
        x0, y0, x1, y1, hl, hh = box
        with mpmath.workdps(40):
            for _k in range(5):
                w, v, u = (mpmath.mpf(rng.uniform(a, a + 0.05)) for a in (yl, vl, ll))
                h = mpmath.mpf(rng.uniform(h0l, h0h))
                if w == 0:
                    continue
                x = [mpmath.mpf(a) for a in lo + (hi - lo) * rng.random(2)]
                e = h + w * mpmath.mpf(dt)
                ds, dc = mpmath.sin(e) - mpmath.sin(h), mpmath.cos(e) - mpmath.cos(h)
                end = (x[0] + (v * ds + u * dc) / w, x[1] + (u * ds - v * dc) / w)
                assert mpmath.mpf(x0) <= end[0] <= mpmath.mpf(x1), (lo, hi, dt)
                assert mpmath.mpf(y0) <= end[1] <= mpmath.mpf(y1), (lo, hi, dt)
                assert mpmath.mpf(hl) <= e <= mpmath.mpf(hh)


def test_the_odometry_increment_bounds_the_step_exactly_and_tightly() -> None:
    """A robot that turns at 1 rad/s while it speeds up from rest (a speed hull of [0, 1] m/s): the hull
    model alone gives a displacement about 0.1 m wide; the increment ``mean_velocity`` (the displacement in
    the start frame, per second) keeps it within the heading's and the noise's widths, and the exact
    displacement (mpmath) stays inside. A contradicting increment empties the box."""
    from digslam.observer.online.dig_types import PoseBox

    rng = np.random.default_rng(31)
    for _ in range(300):
        th0, dt = rng.uniform(-20, 20), rng.choice([0.1, 0.05, 1e-3])
        f, lat = rng.uniform(0.0, 1.4), rng.uniform(-0.4, 0.4)  # the body-frame velocity, held over the step
        dx = dt * (math.cos(th0) * f - math.sin(th0) * lat)  # the end (floats: the truth by definition)
        dy = dt * (math.sin(th0) * f + math.cos(th0) * lat)
        prior = PoseBox(-1e-3, -1e-3, 1e-3, 1e-3, th0 - 1e-3, th0 + 1e-3)
        with mpmath.workprec(200):
            c, s = mpmath.cos(mpmath.mpf(th0)), mpmath.sin(mpmath.mpf(th0))
            m = [(c * dx + s * dy) / mpmath.mpf(dt), (c * dy - s * dx) / mpmath.mpf(dt)]
        noise = 1e-3
        mv = np.array([[float(v) - noise, float(v) + noise] for v in m])
        step = _step(dt, (-1.0, 1.0), (th0 - 2.0, th0 + 2.0), (-0.01, 1.5), lateral=(-0.5, 0.5))
        ok, wide, _ = predict(prior, step)
        ok2, box, d = predict(prior, step._replace(mean_velocity=mv))
        assert ok and ok2
        # the truth: the start is the prior's centre (0, 0) at heading th0, the end is (dx, dy)
        assert box.x_lo <= dx <= box.x_hi and box.y_lo <= dy <= box.y_hi
        assert box.x_hi - box.x_lo <= wide.x_hi - wide.x_lo and box.y_hi - box.y_lo <= wide.y_hi - wide.y_lo
        # the widths: the prior's, the noise's and the heading's (natural interval form of R([psi]) [v])
        assert box.x_hi - box.x_lo < 2e-3 + 2.01 * noise * dt * 1.42 + 2.01e-3 * (f + abs(lat)) * dt + 1e-12
        far = mv + 1.0  # an increment 1 m/s off: outside the hull model's displacement
        ok3, _, _ = predict(prior, step._replace(mean_velocity=far * 10))
        assert not ok3
    assert _step(0.1, (0, 0), (0, 0), (0, 0)).mean_velocity.tolist() == [[-math.inf, math.inf]] * 2
