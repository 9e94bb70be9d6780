"""The guaranteed observer wrapper and ``digslam/DigCoverage-v0``: API, determinism, guarantees, bad input."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import digslam.envs
from digslam.envs import (
    DigCoverageEnv,
    ExploreEnv,
    GuaranteedObserver,
    GuaranteeMonitor,
    GuaranteeViolation,
    ObserverConfig,
)
from digslam.envs.dig_coverage.maps_jit import three_state
from digslam.observer.online.observer import OnlineConfig
from digslam.observer.record.mission import MissionRecord
from digslam.observer.thick.cells import DARK

COVERAGE_IDS = list(digslam.envs.COVERAGE_IDS)


def _actions(n: int, seed: int = 0) -> np.ndarray:
    a = np.random.default_rng(seed).uniform(-1, 1, (n, 2)).astype(np.float32)
    a[:, 0] = np.abs(a[:, 0])  # mostly forward: the robot explores
    return a


def _layer(env: gym.Env) -> DigCoverageEnv:
    while not isinstance(env, DigCoverageEnv):
        env = env.env
    return env


@pytest.mark.parametrize("env_id", COVERAGE_IDS)
def test_check_env_passes(env_id: str) -> None:
    env = gym.make(env_id, render_mode="rgb_array", map_size=36)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*different from the unwrapped.*")
        check_env(_layer(env), skip_render_check=False)
    obs, _ = env.reset(seed=0)
    assert (
        obs["map"].dtype == np.uint8 and obs["map"].shape[0] == 4 and set(np.unique(obs["map"])) <= {0, 255}
    )
    env.close()


def test_same_seed_gives_identical_rollouts_and_reward_is_certified_gain() -> None:
    runs = []
    for _ in range(2):
        env = gym.make("digslam/DigCoverage-v0", map_size=36)
        obs, info = env.reset(seed=7)
        out = [(obs, 0.0, info["certified_coverage"])]
        for a in _actions(25, 1):
            obs, r, _, _, info = env.step(a)
            out.append((obs, r, info["certified_coverage"]))
        runs.append(out)
    for (o1, r1, c1), (o2, r2, c2) in zip(*runs, strict=True):
        assert all(np.array_equal(o1[k], o2[k]) for k in o1) and r1 == r2 and c1 == c2
    u = _layer(env)
    rewards = sum(r for _, r, _ in runs[1][1:])
    gained = (runs[1][-1][2] - runs[1][0][2]) * u.n_reachable * u.cell_area
    assert rewards == pytest.approx(gained - u.config.collision_penalty * int(info["bumps"]))
    assert 0 < info["certified_coverage"] < 1 and 0 < info["true_coverage"] <= 1


@pytest.mark.parametrize(
    ("world", "model", "sensors"),
    [
        ("room", "uniform", {}),
        ("rocks", "adversarial", {}),
        ("caves", "uniform", {"n_sonars": 0}),
        ("rooms", "adversarial", {"omni": False}),
        ("rocks", "biased", {"n_sonars": 3, "omni": False, "sonar_gamma": 0.6}),
        ("room", "adversarial", {"n_sonars": 0, "omni_range": 2.0}),
    ],
)
def test_monitor_finds_no_violation(world: str, model: str, sensors: dict) -> None:
    env = DigCoverageEnv(
        world=world, noise={"model": model}, monitor=True, map_size=36, fixed_world=False, **sensors
    )
    for ep in range(2):
        env.reset(seed=10 + ep)
        for a in _actions(60, ep):
            _, _, term, trunc, info = env.step(a)
            assert info["consistent"] and not (term or trunc)
    assert env.monitor is not None and env.monitor.violations == 0
    assert env.monitor.checked.any()  # clear cells were claimed and checked exactly


def test_monitor_catches_a_false_claim() -> None:
    env = DigCoverageEnv(monitor=True, map_size=36)
    _, info = env.reset(seed=0)
    env.filter.pose_lo, env.filter.pose_hi = env.filter.pose_lo + 1.0, env.filter.pose_hi + 1.0  # a lie
    assert env.monitor is not None
    with pytest.raises(GuaranteeViolation, match="pose box") as exc:
        env.monitor.check(env.filter, info["truth"], info["record"], 0)
    assert isinstance(exc.value, RuntimeError) and isinstance(exc.value.record, MissionRecord)
    mon = GuaranteeMonitor(env.unwrapped.world, env.grid)
    wall = np.zeros(env.grid.shape, bool)
    wall[0, :] = True  # the top row holds the room's outer wall
    assert len(mon.obstacle_cells(wall)) > 0


class _Outlier(gym.Wrapper):
    """Replaces the record of step ``at`` by short echoes on every sensor: an injected outlier."""

    def __init__(self, env: gym.Env, at: int) -> None:
        super().__init__(env)
        self.at, self.k = at, 0

    def step(self, action):  # type: ignore[no-untyped-def]
        obs, r, term, trunc, info = self.env.step(action)
        self.k += 1
        if self.k == self.at:
            d = info["record"].as_dict()
            d["range"] = np.tile([0.01, 0.02], (len(d["alpha"]), 1))
            d["no_echo"], d["outlier"] = np.zeros_like(d["no_echo"]), np.ones_like(d["outlier"])
            info = {**info, "record": MissionRecord(**d)}
        return obs, r, term, trunc, info


def test_outlier_gives_a_reported_inconsistency_never_a_false_claim() -> None:
    env = GuaranteedObserver(_Outlier(ExploreEnv(), at=6), map_size=36, monitor=True)
    env.reset(seed=0)
    flags = []
    for a in _actions(8):
        obs, _, _, trunc, info = env.step(a)  # the monitor raises on any false claim
        flags.append((info["consistent"], trunc))
    assert flags[:5] == [(True, False)] * 5 and flags[5] == (False, True)
    assert info["inconsistent_step"] is not None and info["certified_coverage"] == 0.0
    assert np.all(obs["map"][1] == 255) and not obs["map"][[0, 2, 3]].any()  # every claim withdrawn


def test_observation_state_sets_and_crop() -> None:
    env = GuaranteedObserver(ExploreEnv(world="rocks"), map_size=40, crop=4.0)
    obs, info = env.reset(seed=3)
    for a in _actions(20, 2):
        obs, _, _, _, info = env.step(a)
    assert obs["map"].shape == (7, 40, 40) and env.observation_space.contains(obs)
    m = obs["map"] > 0
    assert np.all(m[0].astype(int) + m[1] + m[2] == 1) and np.all(m[4].astype(int) + m[5] + m[6] == 1)
    assert m[3].any() and m[0].any() and m[2].any()
    x, y, th = info["truth"].pose
    box = info["pose_box"]
    assert box[0, 0] <= x <= box[1, 0] and box[0, 1] <= y <= box[1, 1]
    assert info["heading_box"][0] <= th <= info["heading_box"][1]
    sets = env.sets()
    assert np.all(sets["clear"] <= sets["dig"]) and np.all((sets["explored"] == DARK) <= ~sets["clear"])
    assert info["clear_area"] == pytest.approx(info["certified_coverage"] * env.n_reachable * env.cell_area)
    assert np.count_nonzero(sets["clear"] & env.reachable) * env.cell_area == pytest.approx(
        info["clear_area"]
    )


def test_info_carries_the_sets_only_when_asked() -> None:
    """``info_sets=False`` (the default): no set in ``info``, ``sets()`` gives them on demand;
    ``info_sets=True``: ``info`` carries copies equal to ``sets()``, each the caller's own."""
    plain = gym.make("digslam/DigCoverage-v0", world="rocks")
    full = gym.make("digslam/DigCoverage-v0", world="rocks", info_sets=True)
    _, a = plain.reset(seed=5)
    _, b = full.reset(seed=5)
    for act in _actions(15, 1):
        _, _, _, _, a = plain.step(act)
        _, _, _, _, b = full.step(act)
    assert not {"explored", "clear", "dig"} & set(a)
    mine, theirs = plain.get_wrapper_attr("sets")(), full.get_wrapper_attr("sets")()
    for key in ("explored", "clear", "dig"):
        assert np.array_equal(mine[key], theirs[key]) and np.array_equal(b[key], theirs[key])
        assert mine[key].shape == plain.get_wrapper_attr("grid").shape
    assert mine["clear"].any() and (mine["explored"] == DARK).any()
    assert mine["explored"].dtype == np.int8 and mine["dig"].dtype == bool and mine["clear"].dtype == bool
    b["clear"][:] = True  # the copies are the caller's own: the observer's sets are unchanged
    mine["dig"][:] = True
    assert (
        not full.get_wrapper_attr("sets")()["clear"].all()
        and not plain.get_wrapper_attr("sets")()["dig"].all()
    )
    assert (
        a["certified_coverage"] == b["certified_coverage"]
        and a["pose_box"].tolist() == b["pose_box"].tolist()
    )


def test_downsampling_is_conservative() -> None:
    rng = np.random.default_rng(0)
    for n, m in ((128, 36), (64, 64), (128, 64), (128, 32), (20, 48), (100, 37)):
        clear = rng.uniform(size=(n, n)) < 0.9
        dark = ~clear & (rng.uniform(size=(n, n)) < 0.5)
        c, p, d = three_state(clear, dark, m)
        s = (np.arange(m) * n) // m
        e = np.maximum(np.append(s[1:], n), s + 1)
        for i, j in zip(*np.nonzero(c), strict=True):
            assert clear[s[i] : e[i], s[j] : e[j]].all()
        for i, j in zip(*np.nonzero(d), strict=True):
            assert dark[s[i] : e[i], s[j] : e[j]].all()
        assert np.all(c.astype(int) + p + d == 1)


def test_record_odometry_bounds_the_whole_step() -> None:
    env = ExploreEnv(world="rocks", noise={"model": "adversarial"})
    env.reset(seed=1)
    recs = [env._last]
    for a in _actions(80, 4):
        _, _, _, _, info = env.step(a)
        lo, hi = env.sim.speed_hull
        rec = info["record"]
        assert rec.speed[0] <= lo <= hi <= rec.speed[1] and rec.yaw_rate[0] <= env.sim.yaw_hull[0]
        assert env.sim.yaw_hull[1] <= rec.yaw_rate[1]
        recs.append(rec)
    stacked = MissionRecord.stack(recs)
    assert stacked.speed[0, 0] <= 0.0 <= stacked.speed[0, 1] <= 0.01  # at rest at reset


def test_vector_env() -> None:
    envs = gym.make_vec("digslam/DigCoverage-v0", num_envs=2, vectorization_mode="sync", map_size=36)
    obs, _ = envs.reset(seed=[1, 2])
    assert obs["map"].shape == (2, 4, 36, 36) and obs["state"].shape == (2, 11)
    for _ in range(3):
        obs, rew, *_ = envs.step(envs.action_space.sample())
    assert rew.shape == (2,)
    envs.close()


def test_render_uses_the_colour_blind_safe_palette() -> None:
    env = gym.make("digslam/DigCoverage-v0", render_mode="rgb_array", map_size=36)
    env.reset(seed=0)
    for a in _actions(5):
        env.step(a)
    img = env.render()
    colours = {tuple(c) for c in img.reshape(-1, 3)}
    assert img.shape == (512, 512, 3) and {(86, 180, 233), (230, 159, 0), (38, 38, 56)} <= colours
    assert (0xE4, 0x1A, 0x1C) not in colours  # proved free is never red
    assert (20, 160, 60) in colours and (0, 0, 0) in colours  # the true robot and the pose box


@pytest.mark.parametrize(
    "module",
    [
        "dig_coverage.maps_jit",
        "dig_coverage.monitor",
        "dig_coverage.config",
        "dig_coverage.wrapper",
        "dig_coverage.env",
    ],
)
def test_module_doctests(module: str) -> None:
    import doctest
    import importlib

    mod = importlib.import_module(f"digslam.envs.{module}")
    res = doctest.testmod(mod, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert res.attempted > 0 and res.failed == 0


def test_bad_input_errors() -> None:
    with pytest.raises(ValueError, match="grid_frame.*does not cover"):
        GuaranteedObserver(ExploreEnv(), config={"grid_frame": (-5.0, -5.0, 5.0, 5.0)})
    for bad in (0.0, -0.1, float("nan")):
        with pytest.raises(ValueError, match="grid_cell"):
            GuaranteedObserver(ExploreEnv(), grid_cell=bad)
    with pytest.raises(ValueError, match="map_size.*NatureCNN"):
        gym.make("digslam/DigCoverage-v0", map_size=20)
    assert ObserverConfig(map_size=20, custom_extractor=True).map_size == 20
    with pytest.raises(ValueError, match="map_sise"):
        gym.make("digslam/DigCoverage-v0", map_sise=40)  # unknown keys are rejected (raw env's message)
    with pytest.raises(ValueError, match="smoothing"):
        ObserverConfig(online={"smoothing": 2})
    with pytest.raises(ValueError, match="target"):
        DigCoverageEnv(target=1.5)
    with pytest.raises(AttributeError):
        ObserverConfig().map_size = 40  # type: ignore[misc]
    env = GuaranteedObserver(ExploreEnv(), config=OnlineConfig(smoothing_window=2))
    assert env.obs_config.online.smoothing_window == 2


def test_smoothing_window_keeps_the_guarantee() -> None:
    env = DigCoverageEnv(monitor=True, map_size=36, online={"smoothing_window": 3}, world="rocks")
    env.reset(seed=2)
    for a in _actions(40, 5):
        _, _, _, _, info = env.step(a)
    assert info["consistent"] and env.monitor is not None and env.monitor.violations == 0


@pytest.mark.expensive
def test_sb3_ppo_learns_a_few_hundred_steps() -> None:
    pytest.importorskip("stable_baselines3")
    from stable_baselines3 import PPO

    env = gym.make("digslam/DigCoverage-v0", map_size=36, max_episode_steps=100)
    model = PPO("MultiInputPolicy", env, n_steps=128, batch_size=64, n_epochs=2, seed=0, verbose=0)
    model.learn(total_timesteps=256)
    obs, _ = env.reset(seed=0)
    action, _ = model.predict(obs, deterministic=True)
    assert env.action_space.contains(action)


def test_offline_observer_on_a_re_indexed_env_mission_contains_the_truth() -> None:
    from digslam.envs import record_episode
    from digslam.observer.online.smoother import dig_slam
    from digslam.observer.record.grid import Grid
    from digslam.observer.slam.digslam import DigSlamConfig

    env = ExploreEnv(world="rocks", noise={"model": "adversarial"})
    ep = record_episode(env, 4, _actions(40, 6))
    start = ep.truth.pose[0, :2]
    grid = Grid((-10.0, -10.0), (10.0, 10.0), (64, 64))
    res = dig_slam(ep.records, grid, start, start, DigSlamConfig(max_iter=2))
    assert res.consistent
    assert np.all(res.tube.contains(ep.records.t, ep.truth.pose[:, :2]))


def test_wrapper_skips_only_the_raw_observation_it_replaces() -> None:
    from digslam.envs.dig_coverage.wrapper import GuaranteedObserver
    from digslam.envs.explore.env import ExploreEnv

    raw, ref = ExploreEnv(), ExploreEnv()
    env = GuaranteedObserver(raw, map_size=36)
    calls = []
    fast = raw.step_record
    raw.step_record = lambda a: calls.append(False) or fast(a)  # type: ignore[method-assign]  # a spy
    env.reset(seed=3)
    ref.reset(seed=3)
    a = np.array([0.7, 0.2], np.float32)
    obs, reward, _, _, info = env.step(a)
    ref_obs, ref_reward, _, _, ref_info = ref.step(a)
    assert set(obs) == {"map", "state"} and ref.observation_space.contains(ref_obs)
    assert info["record"].same_as(ref_info["record"]) and info["truth"] == ref_info["truth"]
    # the wrapper measures the ground-truth coverage on its reachable cells: one truth for both keys
    assert info["coverage"] == info["true_coverage"] and reward >= 0.0
    assert calls == [False]  # the wrapper asked for the fast path
    assert raw.observation_space.contains(raw.step(a)[0]) and ref.step(a)[0] is not None
