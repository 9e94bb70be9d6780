"""Online Dig-SLAM filter (thesis §6.4, Algorithm 6.3 as a filter): guarantees against the simulator's truth."""

from __future__ import annotations

import math

import numpy as np
import pytest
from ground_truth import assert_free

from digslam.envs.config import NoiseConfig
from digslam.envs.sim.generators import ThesisRoom
from digslam.envs.sim.missions import loop_mission
from digslam.envs.sim.sensors import SensorSuite
from digslam.observer.online.observer import OnlineConfig, OnlineDigSlam
from digslam.observer.online.pose_jit import cos_sin
from digslam.observer.online.smoother import dig_slam
from digslam.observer.online.window import WindowDigMap, mark_possibly_sensed
from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord
from digslam.observer.slam.digmap import DigMap
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA

CELL = 0.1
GRID = Grid.from_cell_size((-10.0, -10.0), (10.0, 10.0), CELL)
OMNI = SensorSuite(np.array([0.0]), np.array([math.pi]), np.array([6.0]))
SONARS = SensorSuite(np.arange(8) * math.pi / 4, np.full(8, math.pi / 12), np.full(8, 5.0))
BOTH = SensorSuite(np.r_[SONARS.alpha, 0.0], np.r_[SONARS.gamma, math.pi], np.r_[SONARS.r_max, 5.0])


def run(rec: MissionRecord, x0: np.ndarray, config: OnlineConfig | None = None, truth: np.ndarray | None = None,
        pad: float = 0.0) -> tuple[OnlineDigSlam, np.ndarray, np.ndarray]:  # fmt: skip
    """Filter a whole mission; the pose boxes of every step; truth checked in the box at every step."""
    f = OnlineDigSlam(GRID, config)
    f.reset(x0 - pad, x0 + pad, rec[0])
    lo, hi = [f.pose_lo.copy()], [f.pose_hi.copy()]
    for k in range(1, len(rec)):
        f.update(rec[k])
        assert f.consistent, f"inconsistent at step {k}"
        if truth is not None:
            assert np.all((f.pose_lo <= truth[k, :2]) & (truth[k, :2] <= f.pose_hi)), f"truth left box {k}"
            assert f.heading_lo <= truth[k, 2] <= f.heading_hi, f"truth left the heading at {k}"
        lo.append(f.pose_lo.copy())
        hi.append(f.pose_hi.copy())
    assert f.steps == len(rec)
    return f, np.array(lo), np.array(hi)


def sensed_points(world: object, suite: SensorSuite, truth: np.ndarray, rng: np.random.Generator,
                  per: int = 12, every: int = 5) -> np.ndarray:  # fmt: skip
    """Points truly sensed: within the true range (``r_max`` when no echo) in each true cone."""
    out = []
    for k in range(0, len(truth), every):
        d = suite.true_ranges(world, truth[k, :3])
        d = np.where(np.isfinite(d), d, suite.r_max)
        rho = d[:, None] * np.sqrt(rng.random((suite.n, per)))
        rho[:, 0] = d  # the impact distance itself
        th = truth[k, 2] + suite.alpha[:, None] + suite.gamma[:, None] * rng.uniform(-1, 1, (suite.n, per))
        out.append(
            np.stack([truth[k, 0] + rho * np.cos(th), truth[k, 1] + rho * np.sin(th)], -1).reshape(-1, 2)
        )
    return np.concatenate(out)


def cell_of(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    col = np.searchsorted(GRID.xs, points[:, 0], side="right") - 1
    row = np.searchsorted(-GRID.ys, -points[:, 1], side="right") - 1
    return np.clip(row, 0, GRID.shape[0] - 1), np.clip(col, 0, GRID.shape[1] - 1)


@pytest.mark.parametrize(
    ("suite", "model", "seed", "jitter", "window", "pad"),
    [(OMNI, "uniform", 0, 0.0, 0, 0.0), (BOTH, "adversarial", 1, 0.3, 0, 0.0), (SONARS, "biased", 2, 0.2, 0, 0.3),
     (BOTH, "uniform", 3, 0.0, 6, 0.0), (OMNI, "adversarial", 4, 0.3, 3, 0.5)],
)  # fmt: skip
def test_guarantees_against_ground_truth(suite, model, seed, jitter, window, pad):
    world = ThesisRoom(jitter=jitter).generate(seed)
    rec, truth = loop_mission(world, suite=suite, duration=30.0, noise=NoiseConfig(model=model), seed=seed)
    f, _, _ = run(rec, truth[0, :2], OnlineConfig(smoothing_window=window), truth, pad)
    rng = np.random.default_rng(seed)
    assert_free(f.dig.free, world, GRID, rng, 2000)
    assert_free(f.clear_mask(), world, GRID, rng, 2000)
    assert f.dig.free.sum() * CELL**2 > 10.0  # it dug a real area
    # every truly sensed point is in a possibly-sensed (non-dark) cell
    row, col = cell_of(sensed_points(world, suite, truth, rng))
    assert np.all(f.sensed_maybe[row, col]), "a truly sensed point lies in a dark cell"
    codes = f.explored()
    assert np.array_equal(codes == CLEAR, f.sensed_sure) and np.all(f.sensed_maybe[f.sensed_sure])
    assert np.array_equal(codes == DARK, ~f.sensed_maybe)
    assert np.array_equal(codes == PENUMBRA, f.sensed_maybe & ~f.sensed_sure)
    assert (codes == DARK).any() and (codes == PENUMBRA).any()


def test_consistent_with_the_offline_observer():
    world = ThesisRoom().generate(5)
    rec, truth = loop_mission(world, suite=OMNI, duration=40.0, seed=5)
    f, lo, hi = run(rec, truth[0, :2])
    off = dig_slam(rec, GRID, truth[0, :2], truth[0, :2])
    assert off.consistent
    # online boxes contain the offline gates (both outward rounded: containment up to rounding slack)
    slack = 1e-9
    assert np.all(lo <= off.tube.gate_lo + slack) and np.all(off.tube.gate_hi <= hi + slack)
    assert not np.any(f.dig.free & ~off.dig.free)
    assert f.dig.free.sum() > 0.5 * off.dig.free.sum()
    no_impacts, lo2, hi2 = run(rec, truth[0, :2], OnlineConfig(impacts=False))
    assert np.all(lo2 <= lo) and np.all(hi <= hi2)  # the impact contractor only shrinks


def test_gross_outlier_is_reported_as_an_inconsistency():
    world = ThesisRoom().generate(0)
    rec, truth = loop_mission(world, suite=OMNI, duration=35.0, seed=6)
    d = rec.as_dict()
    rng = d["range"].copy()
    k = 300
    rng[k, 0] = rng[k, 0] + 3.0  # reported 3 m farther than the truth: contradicts the next readings
    d["range"] = rng
    bad = MissionRecord(**d)
    f = OnlineDigSlam(GRID)
    f.reset(truth[0, :2], truth[0, :2], bad[0])
    for j in range(1, len(bad)):
        f.update(bad[j])
    assert not f.consistent and f.inconsistent_step is not None and 300 <= f.inconsistent_step <= 310
    assert np.all(f.pose_lo == np.inf) and np.all(f.pose_hi == -np.inf)
    steps = f.steps
    f.update(bad[-1])  # does nothing once inconsistent
    assert f.steps == steps and not f.consistent


def test_memory_stays_bounded():
    rec, truth = loop_mission(suite=OMNI, duration=20.0, seed=7)
    f = OnlineDigSlam(GRID, OnlineConfig(smoothing_window=4))
    f.reset(truth[0, :2], truth[0, :2], rec[0])

    def sizes() -> dict[str, int]:
        return {k: (v.nbytes if isinstance(v, np.ndarray) else len(v)) for k, v in vars(f).items()
                if isinstance(v, np.ndarray | list) or k == "_ring"} | {"dig": f.dig.free.nbytes}  # fmt: skip

    for j in range(1, 60):
        f.update(rec[j])
    first = sizes()
    for j in range(60, len(rec)):
        f.update(rec[j])
    assert sizes() == first and len(f._ring) == 5


def test_windowed_kernels_agree_with_digmap():
    g = Grid((-10.0, -10.0), (10.0, 10.0), (128, 128))
    rng = np.random.default_rng(1)
    for _ in range(40):
        n = int(rng.integers(1, 4))
        lo = rng.uniform(-8, 8, (n, 2))
        hi, r = lo + rng.uniform(0, 0.5, (n, 2)), rng.uniform(0.1, 5, n)
        if _ % 2:  # one box for every cone (the filter's dense path)
            lo, hi = np.repeat(lo[:1], n, 0), np.repeat(hi[:1], n, 0)
        psi = rng.uniform(-4, 4, n)
        args = (
            psi,
            psi + rng.uniform(0, 0.5, n),
            rng.uniform(-3, 3, n),
            rng.choice([0.2, 1.0, 2.0, np.pi], n),
            r,
        )
        a, b = DigMap(g), WindowDigMap(g)
        a.dig_disks(lo, hi, r)
        b.dig_disks(lo, hi, r)
        a.dig_sectors(lo, hi, *args)
        b.dig_sectors(lo, hi, *args)
        assert not np.any(b.free & ~a.free) and (a.free & ~b.free).sum() <= 2
        # the windowed clearance is a lower bound of the full one (cells outside count as not free)
        w = b.win(lo[0] - 3.0, hi[0] + 3.0)
        cw = b.clearance_window(*w)
        assert np.all(cw <= b.clearance_lower()[w[0] : w[1], w[2] : w[3]])
        p = b.win(lo[0], hi[0])  # the direct minimum over a few cells: the same bound
        cells = b.clearance_cells(*p, w)
        assert np.allclose(cells, cw[p[0] - w[0] : p[1] - w[0], p[2] - w[2] : p[3] - w[2]], rtol=0, atol=1e-9)


def test_possibly_sensed_contains_every_sensed_point():
    g = Grid((-4.0, -4.0), (4.0, 4.0), (64, 64))
    rng = np.random.default_rng(2)
    for _ in range(40):
        lo = rng.uniform(-1, 1, 2)
        hi = lo + rng.uniform(0, 0.4, 2)
        psi_lo = rng.uniform(-7, 7)
        psi_hi = psi_lo + rng.choice([0.0, 0.05, 1.0])
        alpha, gamma = rng.uniform(-3, 3, 3), rng.choice([0.05, np.pi / 12, 1.0, np.pi], 3)
        r = rng.uniform(0.2, 3.0, 3)
        maybe = np.zeros(g.shape, bool)
        mark_possibly_sensed(g, maybe, lo, hi, psi_lo, psi_hi, alpha, gamma, r)
        m = 4000
        x = lo + (hi - lo) * rng.random((m, 2))
        s = rng.integers(0, 3, m)
        th = rng.uniform(psi_lo, psi_hi, m) + alpha[s] + gamma[s] * rng.uniform(-1, 1, m)
        rho = r[s] * np.sqrt(rng.random(m))
        row, col = (np.clip(v, 0, 63) for v in (np.searchsorted(-g.ys, -(x[:, 1] + rho * np.sin(th))) - 1,
                                                 np.searchsorted(g.xs, x[:, 0] + rho * np.cos(th)) - 1))  # fmt: skip
        assert np.all(maybe[row, col])
        assert maybe.sum() < g.n_cells  # and it proves some cells dark


def test_cos_sin_enclosures():
    rng = np.random.default_rng(0)
    a = np.concatenate([rng.uniform(-20, 20, 300), np.arange(-12, 13) * math.pi / 2])
    for lo, w in zip(a, rng.choice([0.0, 1e-3, 0.3, 2.0], a.size), strict=True):
        hi = lo + w
        cl, ch, sl, sh = cos_sin(lo, hi)
        x = np.linspace(lo, hi, 101)
        assert (
            cl <= np.cos(x).min()
            and np.cos(x).max() <= ch
            and sl <= np.sin(x).min()
            and np.sin(x).max() <= sh
        )
        assert ch - cl <= (np.cos(x).max() - np.cos(x).min()) + 0.02 * w + 1e-14  # and not loose


def test_bad_input():
    rec, truth = loop_mission(suite=OMNI, duration=1.0, seed=0)
    with pytest.raises(ValueError, match="grid"):
        OnlineDigSlam("grid")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="cell_size"):
        Grid.from_cell_size((-1.0, -1.0), (1.0, 1.0), 0.0)
    with pytest.raises(ValueError, match="unknown"):
        OnlineConfig.from_dict({"smoothing": 3})
    with pytest.raises(ValueError, match="smoothing_window"):
        OnlineConfig(smoothing_window=-1)
    f = OnlineDigSlam(GRID)
    with pytest.raises(ValueError, match="reset"):
        f.update(rec[1])
    with pytest.raises(ValueError, match="x0_lo"):
        f.reset([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], rec[0])
    with pytest.raises(ValueError, match="x0_lo"):
        f.reset([50.0, 0.0], [50.0, 0.0], rec[0])  # outside the grid's frame
    with pytest.raises(ValueError, match="first"):
        f.reset(truth[0, :2], truth[0, :2], rec)
    f.reset(truth[0, :2], truth[0, :2], rec[0])
    with pytest.raises(ValueError, match="rec"):
        f.update(rec)  # a stacked record
    with pytest.raises(ValueError, match="rec"):
        f.update(rec[0])  # time does not increase
    f.update(rec[1])
    assert f.consistent and f.steps == 2 and f.last_update_seconds > 0


@pytest.mark.parametrize("window", [0, 4])
def test_lateral_slip_stays_in_the_pose_box(window):
    """``x' = R(psi) v`` with ``v_2 != 0`` (Eq. 3.59, 6.12, B.20): a robot sliding sideways at 0.3 m/s while
    it turns stays in the pose box at every step (exact truth, :mod:`slip_mission`), and the online boxes
    hold the offline gates; the unicycle model (``lateral`` forced to ``[0, 0]``) loses it."""
    from slip_mission import N, inside, mission, truth

    rec = mission()
    f, lo, hi = run(rec, np.zeros(2), OnlineConfig(smoothing_window=window))
    assert all(inside(lo[k], hi[k], float(rec.t[k])) for k in range(N))
    assert f.heading_lo <= truth(float(rec.t[-1]))[2] <= f.heading_hi
    assert float(np.max(hi - lo)) < 0.5  # the guarantee is not vacuous
    off = dig_slam(rec, GRID, [0.0, 0.0], [0.0, 0.0])
    assert off.consistent and np.all(lo <= off.tube.gate_lo + 1e-9) and np.all(off.tube.gate_hi <= hi + 1e-9)
    _, lo0, hi0 = run(mission(lateral=False), np.zeros(2), OnlineConfig(smoothing_window=window))
    out = [k for k in range(N) if not inside(lo0[k], hi0[k], float(rec.t[k]))]
    assert out and out[-1] == N - 1
