"""The q-relaxed online observer (thesis §2.6.2 on Algorithm 6.3): no false claim from up to q bad readings.

* ``q = 0`` is the former filter, bit for bit (digests of synthetic episodes computed with the code before
  the q-relaxed mode existed);
* with ``q = 1`` and one corrupted reading per step (a false short echo, a false long echo, a reading
  shifted by +0.3 m) no dug or clear cell meets an obstacle and the true pose stays in the box, on the
  rocks world of ``ExploreOutliers-v0`` (seeds 950001...) and in the synthetic square room;
* ``DigCoverageOutliers-v0`` runs clean under the guarantee monitor;
* more than ``q`` bad readings per step are tolerated without false claims or reported inconsistent.
"""

from __future__ import annotations

import dataclasses
import math

import gymnasium as gym
import numpy as np
import pytest
from ground_truth import assert_free
from qrelaxed_data import GRID, HALF, digest, run, square_room_records

import digslam.envs  # noqa: F401  (registers the environments)
from digslam.envs.config import NoiseConfig
from digslam.envs.dig_coverage.config import ObserverConfig
from digslam.envs.dig_coverage.monitor import GuaranteeViolation
from digslam.envs.dig_coverage.wrapper import GuaranteedObserver
from digslam.envs.explore.env import ExploreEnv
from digslam.envs.sim.noise import outliers
from digslam.observer.online.observer import OnlineConfig
from digslam.observer.online.pose_jit import impact_bound, impact_bound_q
from digslam.observer.record.mission import MissionRecord

#: Digests of ``run(square_room_records(seed, 300))`` computed with the filter before the q-relaxed mode.
OLD_DIGESTS = {
    0: "6a493d9b0771f10912b0ecc21c99c633cb693dc8e1dd0295eca28dfda1c1e107",
    1: "0285afa5a8648c575744eddf5fcc61572725b78757416ef0b9b36604891446c7",
    2: "f1472ed6da440657eafa35e3e33048ebe841b2f81e48704c686ca344f590eea0",
}


def _room_cells_ok(free: np.ndarray) -> bool:
    """Every cell of ``free`` lies in the open square room (the walls and beyond are obstacles)."""
    rows, cols = np.nonzero(free)
    lo, hi = GRID.cell_boxes(rows, cols)
    return bool(np.all(lo > -HALF) and np.all(hi < HALF))


def _corrupt(rec: MissionRecord, k: int, mode: str, shift: float = 0.3) -> MissionRecord:
    """``rec`` with reading ``k`` replaced by a bad one (its interval misses the truth); flag untouched."""
    d = rec.as_dict()
    rg, no_echo = np.array(d["range"], dtype=np.float64), np.array(d["no_echo"])
    r_max = float(d["r_max"][k])
    if mode == "short":  # a false short echo
        rg[k], no_echo[k] = (0.01, 0.02), False
    elif mode == "long":  # a false long echo (digs through whatever is in the cone)
        rg[k], no_echo[k] = (0.97 * r_max, 0.98 * r_max), False
    elif mode == "shift":  # a reading shifted up
        if no_echo[k]:
            return rec
        rg[k] = rg[k] + shift
    else:
        raise AssertionError(mode)
    d["range"], d["no_echo"] = rg, no_echo
    return MissionRecord(**d)


# --------------------------------------------------------------------------- q = 0 is the former filter
@pytest.mark.parametrize("seed", sorted(OLD_DIGESTS))
def test_q0_reproduces_the_former_filter_bit_for_bit(seed: int) -> None:
    """Without the cone contractor (``cones=False``, which came later), q = 0 is the former filter."""
    recs, poses = square_room_records(seed, 300)
    f = run(recs, OnlineConfig(cones=False))
    assert digest(f) == OLD_DIGESTS[seed]
    assert digest(run(recs, OnlineConfig(q=0, cones=False))) == OLD_DIGESTS[seed]
    assert digest(run(recs, OnlineConfig(smoothing_window=5, cones=False))) == OLD_DIGESTS[seed]
    assert f.consistent and f.pose_lo[0] <= poses[-1, 0] <= f.pose_hi[0] and _room_cells_ok(f.dig.free)
    g = run(recs)  # with the cones: still consistent and sound
    assert g.consistent and np.all(g.pose_lo <= poses[-1, :2]) and np.all(poses[-1, :2] <= g.pose_hi)
    assert _room_cells_ok(g.dig.free)


def test_impact_bound_q_is_the_q_plus_first_smallest_echo() -> None:
    rng = np.random.default_rng(3)
    for _ in range(200):
        n = int(rng.integers(1, 10))
        rg = np.sort(rng.uniform(0, 5, (n, 2)), axis=1)
        no_echo = rng.uniform(size=n) < 0.3
        rg[no_echo, 1] = np.inf
        ups = np.sort(rg[~no_echo, 1])
        assert impact_bound_q(no_echo, rg, 0) == impact_bound(no_echo, rg)
        for q in range(4):
            assert impact_bound_q(no_echo, rg, q) == (ups[q] if q < ups.size else math.inf)


# --------------------------------------------------------------------------- synthetic room, exact check
@pytest.mark.parametrize("mode", ["short", "long", "shift"])
def test_q1_one_bad_reading_per_step_makes_no_false_claim_in_the_square_room(mode: str) -> None:
    recs, poses = square_room_records(7, 250)
    rng = np.random.default_rng(1)
    bad = [recs[0]] + [_corrupt(r, int(rng.integers(9)), mode) for r in recs[1:]]
    f0 = run(bad)  # q = 0 swallows the bad readings: false space dug (or a reported inconsistency)
    if mode == "long":
        assert not f0.consistent or not _room_cells_ok(f0.dig.free)
    f = run(bad, OnlineConfig(q=1))
    assert f.consistent and _room_cells_ok(f.dig.free) and f.dig.free.sum() > 500
    assert f.pose_lo[0] <= poses[-1, 0] <= f.pose_hi[0] and f.pose_lo[1] <= poses[-1, 1] <= f.pose_hi[1]
    assert np.all(f.sensed_sure == f.dig.free)
    # step by step: the true pose stays in the box
    g = run(bad[:1], OnlineConfig(q=1))
    for r, p in zip(bad[1:], poses[1:], strict=True):
        g.update(r)
        assert g.pose_lo[0] <= p[0] <= g.pose_hi[0] and g.pose_lo[1] <= p[1] <= g.pose_hi[1]
        assert g.heading_lo <= p[2] <= g.heading_hi


def test_q_at_least_the_number_of_readings_digs_nothing() -> None:
    recs, _ = square_room_records(3, 60)
    for q in (9, 12):
        f = run(recs, OnlineConfig(q=q))
        assert f.consistent and not f.dig.free.any() and not f.sensed_sure.any() and f.sensed_maybe.any()
    f1, f2 = run(recs, OnlineConfig(q=1)), run(recs, OnlineConfig(q=2))
    assert np.all(f2.dig.free <= f1.dig.free) and np.all(f1.dig.free <= run(recs).dig.free)


# --------------------------------------------------------------------------- the rocks world, env seeds
class _Corrupting(gym.Wrapper):
    """Corrupts ``n_bad`` readings of every step's record (drawn among the sensors), leaving the flag alone."""

    def __init__(
        self, env: gym.Env, mode: str, n_bad: int = 1, seed: int = 0, among: int | None = None
    ) -> None:
        super().__init__(env)
        self.mode, self.n_bad, self.rng, self.among = mode, n_bad, np.random.default_rng(seed), among

    def step(self, action):  # type: ignore[no-untyped-def]
        obs, r, term, trunc, info = self.env.step(action)
        rec = info["record"]
        for k in self.rng.choice(self.among or rec.n_sensors, self.n_bad, replace=False):
            rec = _corrupt(rec, int(k), self.mode)
        return obs, r, term, trunc, {**info, "record": rec}


def _episode(env: GuaranteedObserver, seed: int, steps: int) -> dict:
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    info: dict = {}
    for _ in range(steps):
        a = np.array([rng.uniform(0.2, 1.0), rng.uniform(-1.0, 1.0)], np.float32)
        _, _, term, trunc, info = env.step(a)  # the monitor raises on any false claim
        if term or trunc:
            break
    return info


@pytest.mark.parametrize("mode", ["short", "long", "shift"])
@pytest.mark.parametrize("seed", [950001, 950002, 950007])
def test_q1_one_bad_reading_per_step_on_the_outlier_world(mode: str, seed: int) -> None:
    env = GuaranteedObserver(_Corrupting(ExploreEnv(world="rocks"), mode, 1, seed), map_size=36, monitor=True,
                             q=1)  # fmt: skip
    info = _episode(env, seed, 150)
    assert info["consistent"] and info["certified_coverage"] > 0.0
    assert_free(env.filter.dig.free, env.env.unwrapped.world, env.grid, np.random.default_rng(seed))


def test_q0_is_fooled_by_one_long_echo_on_the_outlier_world() -> None:
    """The claim before detection: with ``q = 0`` one false long echo per step is a false claim (the monitor
    raises) or, at best, a reported inconsistency."""
    env = GuaranteedObserver(_Corrupting(ExploreEnv(world="rocks"), "long", 1, 1), map_size=36, monitor=True)
    try:
        info = _episode(env, 950001, 150)
    except GuaranteeViolation:
        return
    assert not info["consistent"]


@pytest.mark.parametrize("mode", ["short", "long", "shift"])
def test_more_than_q_bad_readings_are_tolerated_or_reported(mode: str) -> None:
    """Two bad sonars per step with ``q = 1`` (two cones that never overlap): no false claim while the filter
    stays consistent, or the inconsistency is reported (then every claim is withdrawn)."""
    env = GuaranteedObserver(_Corrupting(ExploreEnv(world="rocks"), mode, 2, 5, among=8), map_size=36,
                             monitor=True, q=1)  # fmt: skip
    info = _episode(env, 950003, 120)
    if info["consistent"]:
        assert_free(env.filter.dig.free, env.env.unwrapped.world, env.grid, np.random.default_rng(0))
    else:
        assert info["certified_coverage"] == 0.0 and not env.sets()["clear"].any()


def test_more_than_q_false_short_echoes_are_reported() -> None:
    """Every reading a false short echo: the q-relaxed impact contraction empties the box."""
    recs, _ = square_room_records(2, 40)
    bad = recs[:20] + [_corrupt(_corrupt(r, 0, "short"), 1, "short") for r in recs[20:]]
    for k in range(2, 9):
        bad[20:] = [_corrupt(r, k, "short") for r in bad[20:]]
    f = run(bad, OnlineConfig(q=1))
    assert not f.consistent and 20 <= f.inconsistent_step <= 22


def test_q_plus_one_coordinated_bad_readings_can_make_a_false_claim() -> None:
    """The limit of the premise: two false long echoes in the same direction (a sonar and the omni) with
    ``q = 1`` prove the same cells free; false space is dug before any inconsistency shows."""
    recs, _ = square_room_records(4, 200)
    bad = [recs[0]] + [_corrupt(_corrupt(r, 0, "long"), 8, "long") for r in recs[1:]]
    f = run(bad, OnlineConfig(q=1))
    assert not f.consistent or not _room_cells_ok(f.dig.free)
    assert _room_cells_ok(run(bad, OnlineConfig(q=2)).dig.free)  # q = 2 covers them


# --------------------------------------------------------------------------- the registered env
@pytest.mark.parametrize("dynamics", ["unicycle", "pymunk"])
def test_digcoverage_outliers_runs_clean_under_the_monitor(dynamics: str) -> None:
    env = gym.make("digslam/DigCoverageOutliers-v0", map_size=36, monitor=True, dynamics=dynamics)
    layer = env
    while not isinstance(layer, GuaranteedObserver):
        layer = layer.env
    assert layer.filter.config.q == 1 and layer.obs_config.q == 1
    assert layer.env.unwrapped.config.noise.max_outliers == 1
    env.reset(seed=950001)
    rng = np.random.default_rng(0)
    n_out = []
    for _ in range(200):
        a = np.array([rng.uniform(0.2, 1.0), rng.uniform(-1.0, 1.0)], np.float32)
        _, _, term, trunc, info = env.step(a)
        n_out.append(int(info["record"].outlier.sum()))
        assert info["consistent"]
        if term or trunc:
            break
    assert max(n_out) == 1 and sum(n_out) > 10 and info["certified_coverage"] > 0.02
    assert_free(layer.filter.dig.free, layer.env.unwrapped.world, layer.grid, rng)


# --------------------------------------------------------------------------- configuration
def test_outliers_are_capped_with_the_same_draws() -> None:
    r_max = np.full(9, 5.0)
    for seed in range(20):
        a, b = np.random.default_rng(seed), np.random.default_rng(seed)
        f0, lo0, hi0 = outliers(9, 0.4, r_max, 0.01, a)
        f1, lo1, hi1 = outliers(9, 0.4, r_max, 0.01, b, max_count=1)
        assert a.uniform() == b.uniform()  # the same number of draws
        assert f1.sum() == min(f0.sum(), 1) and np.all(f1 <= f0)
        assert np.array_equal(lo0, lo1) and np.array_equal(hi0, hi1)
    f, _, _ = outliers(9, 1.0, r_max, 0.01, np.random.default_rng(0), max_count=0)
    assert not f.any()
    with pytest.raises(ValueError, match="max_count"):
        outliers(9, 1.0, r_max, 0.01, np.random.default_rng(0), max_count=-1)


def test_bad_q_and_max_outliers_are_rejected() -> None:
    for bad in (-1, 1.5, True, "1"):
        with pytest.raises(ValueError, match="q"):
            OnlineConfig(q=bad)  # type: ignore[arg-type]
        with pytest.raises(ValueError, match="q"):
            ObserverConfig(q=bad)  # type: ignore[arg-type]
    for bad in (-1, 0.5, True):
        with pytest.raises(ValueError, match="noise.max_outliers"):
            NoiseConfig(max_outliers=bad)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="disagrees"):
        ObserverConfig(q=2, online={"q": 1})
    c = ObserverConfig(q=2)
    assert c.online.q == 2 and ObserverConfig(online={"q": 3}).q == 3 and ObserverConfig().online.q == 0
    assert dataclasses.replace(c.online, q=0).q == 0
    env = GuaranteedObserver(ExploreEnv(), map_size=36, q=2)
    assert env.filter.config.q == 2 and env.obs_config.q == 2
