"""``digslam/Explore-v0`` and its variants: API conformance, determinism, vector envs, replay, bad input."""

from __future__ import annotations

import math
import os
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import digslam.envs
from digslam.envs import Episode, ExploreConfig, ExploreEnv, record_episode, replay
from digslam.observer.record.mission import MissionRecord

IDS = list(digslam.envs.ENV_IDS)


@pytest.fixture(autouse=True)
def _headless(monkeypatch: pytest.MonkeyPatch) -> None:
    """check_env also renders in "human" mode: keep pygame headless."""
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")


def _actions(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(-1, 1, (n, 2)).astype(np.float32)


@pytest.mark.parametrize("env_id", IDS)
def test_check_env_passes(env_id: str) -> None:
    env = gym.make(env_id, render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)
    env.close()


@pytest.mark.parametrize("env_id", ["digslam/Explore-v0", "digslam/ExploreOutliers-v0"])
def test_same_seed_and_actions_give_identical_results(env_id: str) -> None:
    runs = []
    for _ in range(2):
        env = gym.make(env_id)
        obs, info = env.reset(seed=42)
        out = [(obs, 0.0, info)]
        for a in _actions(60):
            obs, r, _, _, info = env.step(a)
            out.append((obs, r, info))
        runs.append(out)
    for (o1, r1, i1), (o2, r2, i2) in zip(*runs, strict=True):
        assert all(np.array_equal(o1[k], o2[k]) for k in o1)
        assert r1 == r2 and i1["record"] == i2["record"] and i1["truth"] == i2["truth"]
        assert i1["coverage"] == i2["coverage"]
    env = gym.make(env_id)
    env.reset(seed=43)
    other = [env.step(a)[2] for a in _actions(60)]
    assert other != [r for _, r, _ in runs[0][1:]]


@pytest.mark.parametrize("model", ["uniform", "adversarial", "biased"])
def test_observation_matches_record_and_truth_is_inside(model: str) -> None:
    env = gym.make("digslam/ExploreRocks-v0", noise={"model": model, "range": 0.05})
    obs, info = env.reset(seed=3)
    for a in _actions(100, 1):
        obs, reward, term, trunc, info = env.step(a)
        rec, truth = info["record"], info["truth"]
        assert isinstance(rec, MissionRecord) and env.observation_space.contains(obs)
        assert reward >= 0.0
        assert rec.speed[0] <= truth.speed <= rec.speed[1]
        assert rec.yaw_rate[0] <= truth.yaw_rate <= rec.yaw_rate[1]
        assert rec.heading[0] <= truth.pose[2] <= rec.heading[1]
        assert np.all(rec.range[:, 0] <= truth.ranges) and np.all(truth.ranges <= rec.range[:, 1])
        assert np.array_equal(obs["no_echo"].astype(bool), rec.no_echo)
        assert np.allclose(obs["ranges"][~rec.no_echo], rec.range[~rec.no_echo])
        assert "pose" not in rec.as_dict()  # ground truth kept apart from the measurements


def test_reward_is_the_newly_covered_free_area() -> None:
    env = gym.make("digslam/Explore-v0")
    env.reset(seed=0)
    cov = env.unwrapped.coverage
    before = np.count_nonzero(cov.seen)
    total = 0.0
    for a in _actions(50, 2):
        total += env.step(a)[1]
    assert total == pytest.approx((np.count_nonzero(cov.seen) - before) * cov.cell_area)
    assert not np.any(cov.seen & ~cov.free)


def test_time_limit_truncates() -> None:
    env = gym.make("digslam/Explore-v0", max_episode_steps=5)
    env.reset(seed=0)
    flags = [env.step(np.zeros(2, dtype=np.float32))[3] for _ in range(5)]
    assert flags == [False] * 4 + [True]


@pytest.mark.parametrize("mode", ["sync", "async"])
def test_gymnasium_vector_env(mode: str) -> None:
    envs = gym.make_vec("digslam/ExploreRocks-v0", num_envs=2, vectorization_mode=mode)
    obs, info = envs.reset(seed=[1, 2])
    assert obs["ranges"].shape == (2, 9, 2)
    for _ in range(5):
        obs, rew, term, trunc, info = envs.step(envs.action_space.sample())
    assert rew.shape == (2,) and "record" in info
    envs.close()


def test_sb3_subproc_vec_env() -> None:
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import SubprocVecEnv

    # "module:id" makes each worker process import digslam.envs (registering the ids) before gym.make.
    venv = make_vec_env("digslam.envs:digslam/Explore-v0", n_envs=2, seed=0, vec_env_cls=SubprocVecEnv)
    obs = venv.reset()
    assert obs["ranges"].shape == (2, 9, 2)
    for _ in range(5):
        obs, rew, done, infos = venv.step(np.stack([venv.action_space.sample() for _ in range(2)]))
    assert rew.shape == (2,) and isinstance(infos[0]["record"], MissionRecord)
    venv.close()


def test_sb3_env_checker() -> None:
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    sb3_check_env(gym.make("digslam/ExploreRocks-v0"), warn=False)


def test_recorded_episode_replays_to_identical_records(tmp_path: Path) -> None:
    env = gym.make("digslam/ExploreCaves-v0", noise={"outlier_prob": 0.1})
    ep = record_episode(env, 9, _actions(80, 3))
    assert len(ep.records) == 81 and ep.records.range.shape == (81, 9, 2)
    ep.save(tmp_path / "ep.npz")
    loaded = Episode.load(tmp_path / "ep.npz")
    assert loaded.records == ep.records and loaded.truth == ep.truth and loaded.config == ep.config
    again = replay(loaded)
    assert again.records == ep.records and again.truth == ep.truth
    ep.records.save_npz(tmp_path / "rec.npz")
    assert MissionRecord.load_npz(tmp_path / "rec.npz") == ep.records


def test_an_episode_saved_before_pymunk_dynamics_loads_as_a_unicycle(tmp_path: Path) -> None:
    """An episode file without the config's ``dynamics``, the truth's ``lateral``, ``states`` and ``taus`` and
    the record's ``lateral`` (saved before they existed, by the unicycle) loads with their old meaning and
    replays to the same records."""
    import json

    ep = record_episode(ExploreEnv(world="rocks", dynamics="unicycle"), 4, _actions(30, 1))
    ep.save(tmp_path / "new.npz")
    with np.load(tmp_path / "new.npz") as z:
        data = dict(z)
    cfg = json.loads(str(data["config"]))
    del cfg["dynamics"]
    data["config"] = np.array(json.dumps(cfg))
    for key in ("truth_lateral", "truth_states", "truth_taus", "record_lateral", "record_mean_velocity"):
        del data[key]
    np.savez(tmp_path / "old.npz", **data)
    old = Episode.load(tmp_path / "old.npz")
    assert old.config.dynamics == "unicycle" and old.records == ep.records and old.truth == ep.truth
    assert old.truth.states.shape == (31, 0, 3) and old.truth.taus.shape == (31, 0)
    again = replay(old)
    assert again.records == ep.records and again.truth == ep.truth


def test_pymunk_episode_keeps_its_path_and_lateral_velocity() -> None:
    env = ExploreEnv(world="rooms")
    assert env.config.dynamics == "pymunk" and env.observation_space["odometry"].shape == (3, 2)
    ep = record_episode(env, 2, _actions(40, 2))
    truth, rec = ep.truth, ep.records
    assert truth.states.shape == (41, 5, 3) and truth.taus.shape == (41, 4)
    assert np.array_equal(truth.states[1:, 0], truth.states[:-1, -1])  # each step starts where the last ended
    assert np.array_equal(truth.states[:, -1], truth.pose) and np.all(truth.pose_error == 0)
    assert np.all(np.isnan(truth.pieces))
    assert np.all(rec.lateral[:, 0] <= truth.lateral) and np.all(truth.lateral <= rec.lateral[:, 1])
    assert np.any(rec.lateral[1:, 1] - rec.lateral[1:, 0] > 0.0)
    # the odometry increment: R(-psi_{k-1}) (x_k - x_{k-1}) / dt, inside the record, and narrow where the
    # speed hull is wide (the robot speeds up from rest within the first step)
    d = np.diff(truth.pose[:, :2], axis=0) / np.diff(truth.t)[:, None]
    c, s = np.cos(truth.pose[:-1, 2]), np.sin(truth.pose[:-1, 2])
    inc = np.column_stack([c * d[:, 0] + s * d[:, 1], c * d[:, 1] - s * d[:, 0]])
    mean = rec.mean_velocity[1:]
    assert np.all(mean[..., 0] <= inc + 1e-12) and np.all(inc - 1e-12 <= mean[..., 1])  # floats: see premise
    assert np.all(mean[..., 1] - mean[..., 0] <= 2 * env.config.noise.speed + 1e-9)
    assert np.max(rec.speed[1:, 1] - rec.speed[1:, 0]) > 0.5


def test_a_unicycle_record_does_not_measure_the_increment() -> None:
    ep = record_episode(ExploreEnv(world="rocks", dynamics="unicycle"), 4, _actions(5, 1))
    assert ep.records.mean_velocity.shape == (6, 2, 2)
    assert np.all(ep.records.mean_velocity == [[-np.inf, np.inf], [-np.inf, np.inf]])


def test_render_modes(tmp_path: Path) -> None:
    env = gym.make("digslam/ExploreRooms-v0", render_mode="rgb_array")
    env.reset(seed=0)
    env.step(np.array([1.0, 0.3], dtype=np.float32))
    img = env.render()
    assert (
        img.shape == (512, 512, 3)
        and img.dtype == np.uint8
        and len(np.unique(img.reshape(-1, 3), axis=0)) > 4
    )
    env.close()
    env = gym.make("digslam/Explore-v0", render_mode="human")
    env.reset(seed=0)
    env.step(np.array([1.0, 0.0], dtype=np.float32))
    assert env.render() is None
    env.close()


def test_fixed_world_and_new_worlds() -> None:
    env = ExploreEnv(world="rocks", fixed_world=True)
    env.reset(seed=1)
    w = env.world
    env.reset()
    assert env.world is w
    env = ExploreEnv(world="rocks")  # the default: every episode a new level
    env.reset(seed=1)
    w = env.world
    env.reset()
    assert not np.array_equal(env.world.edges, w.edges)


@pytest.mark.parametrize("world", ["room", "rocks", "caves", "rooms"])
def test_every_seed_is_a_new_level_with_a_free_reachable_start(world: str) -> None:
    """Different seeds give different worlds and starts, the same seed the same episode; every start is
    free with the start clearance and lies in the reachable region (the largest one, not a pocket)."""
    env = gym.make(f"digslam/Explore{'' if world == 'room' else world.capitalize()}-v0")
    u = env.unwrapped
    cfg = u.config
    clearance = 1.5 * cfg.robot_radius + 1.5 * cfg.max_speed * cfg.dt / cfg.substeps
    edges, starts = [], []
    for seed in (0, 1, 2, 1_000_000, 2_000_000):
        _, info = env.reset(seed=seed)
        pose = info["truth"].pose
        edges.append(u.world.edges.copy())
        starts.append(pose.copy())
        assert u.world.clearance(pose[None, :2])[0] >= clearance
        cells = u.world.reachable_cells(clearance)
        xs, ys = (u.world.frame[0], u.world.frame[1])
        i, j = int((pose[1] - ys) / 0.1), int((pose[0] - xs) / 0.1)
        assert cells[max(i - 1, 0) : i + 2, max(j - 1, 0) : j + 2].any()  # in (or next to) the region
    for a in range(len(edges)):
        for b in range(a):
            assert edges[a].shape != edges[b].shape or not np.array_equal(edges[a], edges[b])
            assert not np.array_equal(starts[a], starts[b])
    acts = _actions(20, 3)
    runs = []
    for _ in range(2):
        _, info = env.reset(seed=7)
        recs = [info["record"]]
        for a in acts:
            recs.append(env.step(a)[4]["record"])
        runs.append(MissionRecord.stack(recs))
    assert runs[0] == runs[1]


def test_map_seed_pins_the_world_and_the_splits_are_disjoint() -> None:
    from digslam.envs import splits

    env = ExploreEnv(world="rocks", map_seed=12)
    env.reset(seed=0)
    w = env.world
    _, info = env.reset(seed=1)
    assert env.world is w and not np.array_equal(info["truth"].pose, env.reset(seed=0)[1]["truth"].pose)
    assert np.array_equal(ExploreEnv(world="rocks", map_seed=12).generator.generate(12).edges, w.edges)
    names = [splits.split_of(s) for s in (0, 999_999, 1_000_000, 1_000_999, 2_000_000, 2_000_999)]
    assert names == ["train", "train", "validation", "validation", "test", "test"]
    assert not set(splits.TRAIN) & set(splits.VALIDATION) and not set(splits.VALIDATION) & set(splits.TEST)
    with pytest.raises(ValueError, match="test split"):
        splits.check_not_test("seed", [3, 2_000_004])
    with pytest.raises(ValueError, match="map_seed"):
        ExploreEnv(map_seed=-1)
    with pytest.raises(ValueError, match="room_jitter"):
        ExploreEnv(room_jitter=5.0)


def test_bad_input_errors_name_the_field() -> None:
    with pytest.raises(ValueError, match="sonar_rnage"):
        gym.make("digslam/Explore-v0", sonar_rnage=3.0)
    with pytest.raises(ValueError, match="sonar_gamma"):
        ExploreEnv(sonar_gamma=0.0)
    with pytest.raises(ValueError, match="sonar_gamma"):
        ExploreEnv(sonar_gamma=math.pi + 0.01)
    with pytest.raises(ValueError, match="noise.range"):
        gym.make("digslam/Explore-v0", noise={"range": -0.01})
    with pytest.raises(ValueError, match="world"):
        ExploreConfig(world="moon")
    with pytest.raises(ValueError, match="dynamics"):
        ExploreConfig(dynamics="tank")
    with pytest.raises(ValueError, match="map_path"):
        ExploreConfig(world="file")
    env = gym.make("digslam/Explore-v0")
    env.reset(seed=0)
    for bad in ([1.5, 0.0], [np.nan, 0.0], [0.0, -np.inf], [0.1, 0.2, 0.3]):
        with pytest.raises(ValueError, match="action"):
            env.step(np.array(bad, dtype=np.float32))
    with pytest.raises(ValueError, match="start"):
        ExploreEnv(world="room", start=(9.5, 9.5, 0.0)).reset(seed=0)  # outside the room's polygon
    env = ExploreEnv(world="rocks")
    env.reset(seed=0)
    rock = env.world.rings[1].mean(axis=0)
    with pytest.raises(ValueError, match="start"):
        ExploreEnv(world="rocks", start=(float(rock[0]), float(rock[1]), 0.0)).reset(seed=0)


def test_user_map_file(tmp_path: Path) -> None:
    free = np.ones((60, 60), dtype=bool)
    free[10:20, 25:35] = False  # a block north of the centre (row 0 is the top)
    np.save(tmp_path / "map.npy", free)
    env = gym.make("digslam/Explore-v0", world="file", map_path=str(tmp_path / "map.npy"), world_size=6.0)
    obs, info = env.reset(seed=0)
    assert env.unwrapped.world.name == "map" and env.observation_space.contains(obs)
    for a in _actions(20):
        env.step(a)
    with pytest.raises(ValueError, match="map_path"):
        gym.make("digslam/Explore-v0", world="file", map_path=str(tmp_path / "nope.npy"))


def test_config_is_frozen_and_replace_checks_keys() -> None:
    cfg = ExploreConfig()
    with pytest.raises(AttributeError):
        cfg.dt = 0.2  # type: ignore[misc]
    assert cfg.replace(dt=0.2).dt == 0.2
    with pytest.raises(ValueError, match="dtt"):
        cfg.replace(dtt=0.2)
    with pytest.raises(ValueError, match="sonar_rnage"):
        ExploreConfig(sonar_rnage=3.0)  # the constructor too, not only from_dict
    assert ExploreConfig.from_dict({"noise": {"model": "biased"}}).noise.model == "biased"


def test_example_script_writes_a_png(tmp_path: Path) -> None:
    import subprocess
    import sys

    script = Path(__file__).resolve().parents[3] / "examples" / "explore_env.py"
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy"}
    subprocess.run(
        [sys.executable, str(script), str(tmp_path), "--steps", "20"],
        check=True,
        env=env,
        capture_output=True,
    )
    assert (tmp_path / "Explore-v0.png").stat().st_size > 1000


def test_step_record_is_the_step_without_its_observation() -> None:
    """The wrappers' fast path: the same reward, ends, record and truth as ``step``, the env moved alike."""
    a, b = ExploreEnv(), ExploreEnv()
    a.reset(seed=2)
    b.reset(seed=2)
    for act in _actions(12, 1):
        _, reward, terminated, truncated, info = a.step(act)
        *ends, fast = b.step_record(act)
        assert tuple(ends) == (reward, terminated, truncated) and fast.keys() == info.keys()
        assert info["record"].same_as(fast["record"]) and info["truth"] == fast["truth"]


def test_without_coverage_the_raw_env_measures_no_ground_truth() -> None:
    env = ExploreEnv(measure_coverage=False)
    obs, info = env.reset(seed=1)
    assert env.coverage is None and "coverage" not in info and env.observation_space.contains(obs)
    obs, reward, terminated, _, info = env.step(np.array([1.0, 0.3], np.float32))
    assert (reward, terminated) == (0.0, False) and "coverage" not in info and "record" in info
    assert env.observation_space.contains(obs)
