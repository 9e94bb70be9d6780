"""Offline Dig-SLAM (thesis §6.4, Algorithm 6.3): guarantees against the simulator's ground truth, for
``dig_slam`` (the fixpoint of the filter's contractors) and ``thesis_dig_slam`` (the algorithm as written)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from ground_truth import assert_free

from digslam.envs.config import NoiseConfig
from digslam.envs.sim.arc_jit import arc
from digslam.envs.sim.generators import ThesisRoom
from digslam.envs.sim.missions import loop_mission
from digslam.envs.sim.sensors import SensorSuite
from digslam.observer.online.smoother import dig_slam
from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord
from digslam.observer.slam.digslam import DigSlamConfig, thesis_dig_slam

CELL = 0.1
GRID = Grid.from_cell_size((-10.0, -10.0), (10.0, 10.0), CELL)
OMNI = SensorSuite(np.array([0.0]), np.array([math.pi]), np.array([10.0]))
SONARS = SensorSuite(np.array([0.0, math.pi / 2, math.pi, -math.pi / 2]), np.full(4, math.pi / 12),
                     np.full(4, 4.0))  # fmt: skip
WORLDS: dict[int, object] = {}  # the world of each mission record, for the ground truth
BOTH = SensorSuite(np.r_[SONARS.alpha, 0.0], np.r_[SONARS.gamma, math.pi], np.r_[SONARS.r_max, 5.0])


def slice_points(truth: np.ndarray, dt: float, n: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """True positions at ``n`` times strictly inside every slice (exact arcs)."""
    ts, xs = [], []
    for j in range(1, n + 1):
        tau = dt * j / (n + 1)
        p = np.array([arc(truth[k, :3], truth[k, 3], truth[k, 4], tau) for k in range(len(truth) - 1)])
        ts.append(np.arange(len(truth) - 1) * dt + tau)
        xs.append(p[:, :2])
    return np.concatenate(ts), np.concatenate(xs)


@pytest.mark.parametrize("algo", [dig_slam, thesis_dig_slam], ids=["dig_slam", "thesis"])
@pytest.mark.parametrize(
    ("suite", "model", "seed", "jitter"),
    [(OMNI, "uniform", 0, 0.0), (OMNI, "adversarial", 1, 0.3), (BOTH, "uniform", 2, 0.2),
     (SONARS, "adversarial", 3, 0.0), (BOTH, "biased", 4, 0.3)],
)  # fmt: skip
def test_guarantees_against_ground_truth(suite, model, seed, jitter, algo):
    world = ThesisRoom(jitter=jitter).generate(seed)
    duration = 150.0 if suite is OMNI else 40.0  # sonar sectors cost more to dig
    rec, truth = loop_mission(
        world, suite=suite, duration=duration, noise=NoiseConfig(model=model), seed=seed
    )
    WORLDS[id(rec)] = world
    res = algo(rec, GRID, truth[0, :2], truth[0, :2])
    assert res.consistent and res.first_empty is None
    tube = res.tube
    # the true position is in the tube at every time: gates and inside every slice
    assert np.all((tube.gate_lo <= truth[:, :2]) & (truth[:, :2] <= tube.gate_hi)), "truth left a gate"
    ts, xs = slice_points(truth, 0.1)
    assert np.all(tube.contains(ts, xs)), "truth left a slice"
    assert np.all((tube.slice_lo <= xs[: len(truth) - 1]) & (xs[: len(truth) - 1] <= tube.slice_hi))
    assert_free(res.dig.free, world, GRID, np.random.default_rng(seed))
    assert res.dig.free.sum() * CELL**2 > 10.0  # it dug a real area
    assert_explored_sound(res.explored, rec, truth, suite, np.random.default_rng(seed))


def truly_sensed(p: np.ndarray, rec: MissionRecord, truth: np.ndarray, suite: SensorSuite) -> np.ndarray:
    """Points ``(P, 2)`` inside some true visible set: within the true range, in the true cone."""
    true_r = np.array([suite.true_ranges(WORLDS[id(rec)], pose) for pose in truth[:, :3]])
    true_r = np.where(np.isfinite(true_r), true_r, suite.r_max)  # (T, S)
    d = p[:, None, :] - truth[None, :, :2]  # (P, T, 2)
    rho = np.linalg.norm(d, axis=-1)
    ang = np.arctan2(d[..., 1], d[..., 0])
    seen = np.zeros(p.shape[0], dtype=bool)
    for s in range(suite.n):
        diff = np.abs((ang - truth[None, :, 2] - suite.alpha[s] + np.pi) % (2 * np.pi) - np.pi)
        seen |= ((rho <= true_r[None, :, s]) & (diff <= suite.gamma[s])).any(axis=1)
    return seen


def assert_explored_sound(st: np.ndarray, rec: MissionRecord, truth: np.ndarray, suite: SensorSuite,
                          rng: np.random.Generator) -> None:  # fmt: skip
    """Clear cells were truly sensed, dark cells never; every truly sensed point is in a non-dark cell."""
    from digslam.observer.thick.cells import CLEAR, DARK

    for code, want in ((CLEAR, True), (DARK, False)):
        rows, cols = np.nonzero(st == code)
        if rows.size == 0:
            continue
        pick = rng.choice(rows.size, min(rows.size, 150), replace=False)
        lo, hi = GRID.cell_boxes(rows[pick], cols[pick])
        pts = np.concatenate([lo + (hi - lo) * rng.random(lo.shape), lo, hi])
        assert np.all(truly_sensed(pts, rec, truth, suite) == want), f"a {code} cell is wrong"
    # truly sensed points: from random true poses, inside the true cone and range
    k = rng.integers(0, len(truth), 300)
    s = rng.integers(0, suite.n, 300)
    true_r = np.array([suite.true_ranges(WORLDS[id(rec)], truth[i, :3])[j] for i, j in zip(k, s)])
    rr = np.where(np.isfinite(true_r), true_r, suite.r_max[s]) * rng.random(300)
    th = truth[k, 2] + suite.alpha[s] + suite.gamma[s] * rng.uniform(-1, 1, 300)
    p = truth[k, :2] + rr[:, None] * np.c_[np.cos(th), np.sin(th)]
    inside = np.all((p > GRID.lo) & (p < GRID.hi), axis=1)
    lo, hi = GRID.cell_boxes()
    p = p[inside]
    col = np.searchsorted(GRID.xs, p[:, 0]) - 1
    row = np.searchsorted(-GRID.ys, -p[:, 1]) - 1
    assert np.all(st[row, col] != DARK), "a truly sensed point lies in a dark cell"


def test_tube_shrinks_relative_to_dead_reckoning():
    rec, truth = loop_mission(duration=400.0, seed=5)
    res = dig_slam(rec, GRID, truth[0, :2], truth[0, :2])
    assert res.consistent
    final, dr = res.tube.widths(), res.dead_reckoning
    assert final[-1] < 0.5 * dr[-1]
    assert np.all(final <= dr + 1e-12)
    assert len(res.widths) == res.iterations >= 2
    no_impacts = dig_slam(rec, GRID, truth[0, :2], truth[0, :2], DigSlamConfig(impacts=False))
    assert np.allclose(no_impacts.tube.widths(), dr)


def test_inconsistent_reading_is_reported():
    world = ThesisRoom().generate(0)
    rec, truth = loop_mission(world, duration=60.0, seed=6)
    d = rec.as_dict()
    rng = d["range"].copy()
    k = 300
    rng[k, 0] = rng[k, 0] + 3.0  # reported 3 m farther than the truth: contradicts the neighbours
    d["range"] = rng
    bad = MissionRecord(**d)
    res = dig_slam(bad, GRID, truth[0, :2], truth[0, :2])
    assert not res.consistent
    assert res.first_empty is not None and res.tube is None and res.dig is None


def test_record_round_trip_gives_the_same_result(tmp_path):
    rec, truth = loop_mission(duration=30.0, seed=7)
    rec.save_npz(tmp_path / "mission.npz")
    again = MissionRecord.load_npz(tmp_path / "mission.npz")
    a = dig_slam(rec, GRID, truth[0, :2], truth[0, :2])
    b = dig_slam(again, GRID, truth[0, :2], truth[0, :2])
    assert np.array_equal(a.tube.gate_lo, b.tube.gate_lo) and np.array_equal(a.dig.free, b.dig.free)


def test_bad_input():
    rec, truth = loop_mission(duration=2.0, seed=0)
    with pytest.raises(ValueError, match="x0_lo"):
        dig_slam(rec, GRID, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="x0_lo"):
        dig_slam(rec, GRID, [1.0, 0.0], [0.0, 0.0])
    with pytest.raises(ValueError, match="record"):
        dig_slam(rec[0], GRID, [0.0, 0.0], [0.0, 0.0])
    with pytest.raises(ValueError, match="max_iter"):
        DigSlamConfig(max_iter=0)
    with pytest.raises(ValueError, match="unknown"):
        DigSlamConfig.from_dict({"max_iters": 3})
    d = rec.as_dict()
    d["range"] = d["range"][:, :, ::-1].copy()
    with pytest.raises(ValueError, match="range"):
        MissionRecord(**d)


def test_lateral_slip_stays_in_the_tube():
    """``x' = R(psi) v`` with ``v_2 != 0`` (Eq. 3.59, 6.12, B.20): a robot sliding sideways at 0.3 m/s while
    it turns stays in the tube at every gate and inside every slice (exact truth, :mod:`slip_mission`); the
    unicycle model (``lateral`` forced to ``[0, 0]``) loses it, so the lateral term matters."""
    from slip_mission import DT, N, inside, mission

    grid = Grid((-8.0, -8.0), (8.0, 8.0), (64, 64))
    res = dig_slam(mission(), grid, [0.0, 0.0], [0.0, 0.0])
    assert res.consistent
    tube = res.tube
    assert all(inside(tube.gate_lo[k], tube.gate_hi[k], float(tube.t[k])) for k in range(N))
    for k in range(N - 1):  # times strictly inside slice k
        for f in (0.25, 0.5, 0.75):
            assert inside(tube.slice_lo[k], tube.slice_hi[k], float(tube.t[k]) + f * DT), (k, f)
    assert float(np.max(tube.widths())) < 0.5  # the guarantee is not vacuous
    uni = dig_slam(mission(lateral=False), grid, [0.0, 0.0], [0.0, 0.0])
    out = [k for k in range(N) if not inside(uni.tube.gate_lo[k], uni.tube.gate_hi[k], float(uni.tube.t[k]))]
    assert uni.consistent and out and out[-1] == N - 1


def test_unicycle_record_gives_the_unicycle_velocity_bit_for_bit():
    """A record with ``lateral = [0, 0]`` gives the velocity boxes of ``v (cos psi, sin psi)`` (Eq. 6.23) to
    the bit, signs of zero included, so the tube of a unicycle record is the one before ``lateral`` existed."""
    from digslam.observer.slam.digslam import odometry_velocity
    from digslam.observer.tube.tube import heading_from_compass, unicycle_velocity

    rec, _ = loop_mission(duration=20.0, seed=5)
    assert not rec.lateral.any()
    h = heading_from_compass(rec.t, rec.heading[:, 0], rec.heading[:, 1], rec.yaw_rate[1:, 0],
                             rec.yaw_rate[1:, 1])  # fmt: skip
    new = odometry_velocity(rec, h)
    old = unicycle_velocity(rec.speed[1:, 0], rec.speed[1:, 1], h.slice_lo[:, 0], h.slice_hi[:, 0])
    assert all(a.tobytes() == b.tobytes() for a, b in zip(new, old, strict=True))


def test_the_odometry_increment_keeps_the_offline_tube_narrow_under_pymunk() -> None:
    """A pymunk episode (inertia: wide speed hulls): the offline tube with the record's odometry increment
    holds the true pose and is far narrower than with the hulls alone; a contradicting increment is
    reported as an inconsistency."""
    from digslam.envs import ExploreEnv
    from digslam.envs.explore.episode import record_episode
    from digslam.observer.record.grid import Grid
    from digslam.observer.record.mission import MissionRecord
    from digslam.observer.slam.digslam import DigSlamConfig, odometry_increment

    rng = np.random.default_rng(3)
    env = ExploreEnv(world="rocks")
    ep = record_episode(env, 5, np.column_stack([rng.uniform(0.2, 1.0, 80), rng.uniform(-1, 1, 80)]))
    rec, truth = ep.records, ep.truth
    grid = Grid(env.world.frame[:2], env.world.frame[2:], (80, 80))
    p0 = truth.pose[0, :2]
    cfg = DigSlamConfig(explored=False)
    res = dig_slam(rec, grid, p0, p0, cfg)
    hulls = dig_slam(MissionRecord(**{**rec.as_dict(), "mean_velocity": None}), grid, p0, p0, cfg)
    assert res.consistent and hulls.consistent
    for tube in (res.tube, hulls.tube):
        assert np.all((tube.gate_lo <= truth.pose[:, :2]) & (truth.pose[:, :2] <= tube.gate_hi))
    assert res.tube.widths().max() < 0.05 < 0.5 < hulls.tube.widths().max()
    assert odometry_increment(MissionRecord(**{**rec.as_dict(), "mean_velocity": None}), res.heading) is None
    bad = rec.as_dict()
    bad["mean_velocity"] = bad["mean_velocity"].copy()
    bad["mean_velocity"][40] += 5.0  # 5 m/s off: outside the speed hull's reach
    off = dig_slam(MissionRecord(**bad), grid, p0, p0, cfg)
    assert not off.consistent and off.first_empty is not None and off.first_empty <= 41
