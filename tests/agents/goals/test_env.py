"""``GoalSelectionEnv``: the Gymnasium contract, determinism, masks, no ground truth in observations, the
reward and the episode's end.

``digslam.agents.goals`` is imported inside the tests, not at collection: importing it registers the
``digslam/DigCoverageGoals*`` ids, and other test modules list the registered ``digslam/`` ids when they are
collected (``tests/envs/test_check_env.py``, the guarantee audit).
"""

from __future__ import annotations

import copy
import importlib
import subprocess
import sys
import warnings
from types import ModuleType
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces
from gymnasium.utils.env_checker import check_env

from digslam.agents.baselines.policy import parse
from digslam.envs.stack import find_wrapper

SIZES = ("span", "max_speed", "max_yaw_rate", "dt", "sensor_range")


@pytest.fixture(scope="module")
def G() -> ModuleType:
    return importlib.import_module("digslam.agents.goals")


def _make(G: ModuleType, env_id: str = "digslam/DigCoverageGoals-v0", **kw: Any) -> Any:
    env = gym.make(env_id, **{"map_size": 36, "max_steps": 300, **kw})
    assert isinstance(find_wrapper(env, G.GoalSelectionEnv), G.GoalSelectionEnv)
    return env


class _FirstSample(spaces.Discrete):
    """``check_env`` samples actions without the mask: candidate 0 is valid at every decision."""

    def sample(self, mask: Any = None, probability: Any = None) -> np.int64:
        return np.int64(0)


class _Record(gym.Wrapper):
    """Keeps every base observation (with the end flags) and every low-level action."""

    def reset(self, **kw: Any) -> Any:
        obs, info = self.env.reset(**kw)
        self.frames, self.actions = [(copy.deepcopy(obs), False, False)], []
        return obs, info

    def step(self, action: Any) -> Any:
        obs, r, te, tr, info = self.env.step(action)
        self.frames.append((copy.deepcopy(obs), te, tr))
        self.actions.append(np.array(action))
        return obs, r, te, tr, info


class _Replay(gym.Env):
    """Plays recorded base observations back, whatever the actions, with empty infos and no reward: no
    ground truth, no certified coverage, no world."""

    def __init__(self, observation_space: spaces.Space, action_space: spaces.Space, frames: list) -> None:
        self.observation_space, self.action_space, self.frames = observation_space, action_space, frames

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> Any:
        super().reset(seed=seed)
        self.k, self.actions = 0, []
        return copy.deepcopy(self.frames[0][0]), {}

    def step(self, action: Any) -> Any:
        self.k += 1
        self.actions.append(np.array(action))
        obs, te, tr = self.frames[self.k]
        return copy.deepcopy(obs), 0.0, te, tr, {}


def _assert_same(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> None:
    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


# --- registration and the Gymnasium contract ------------------------------------------------------------------
def test_one_id_per_suite_generator_registered_on_import_only(G: ModuleType) -> None:
    from digslam.agents.evaluation.suite import GENERATORS

    assert set(G.GOAL_IDS) <= set(gym.registry)
    worlds = {kw.get("world", "room") for kw in G.GOAL_IDS.values()}
    assert worlds == set(GENERATORS) and {GENERATORS[w][0] for w in worlds} == {"digslam/DigCoverage-v0"}
    env = gym.make("digslam.agents.goals:digslam/DigCoverageGoalsRocks-v0", map_size=36)
    assert env.unwrapped.config.world == "rocks"
    assert env.unwrapped.spec.id == "digslam/DigCoverageGoalsRocks-v0"
    code = "import gymnasium as gym, digslam.envs; print(any('Goals' in i for i in gym.registry))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"  # the envs never import the agents


def test_check_env_on_the_registered_env(G: ModuleType) -> None:
    env = find_wrapper(_make(G), G.GoalSelectionEnv)  # gym.make's checker wrappers off: the goal env itself
    env.action_space = _FirstSample(env.n)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", message=".*different from the unwrapped version")  # a wrapper
        check_env(env)  # renders too: the spec rebuilds the env with render_mode="rgb_array"
    assert env.observation_space["candidates"].shape == (16, G.N_FEATURES)
    assert env.observation_space["global"].shape == (len(G.GLOBALS),)


def test_same_seed_and_actions_give_identical_observations_and_rewards(G: ModuleType) -> None:
    runs = []
    for seed in (7, 7, 8):
        env, pol = _make(G), G.RandomCandidatePolicy(seed=0)
        obs, _ = env.reset(seed=seed)
        run = [(obs, 0.0, 0)]
        for _ in range(10):
            obs, r, te, tr, info = env.step(pol.predict(obs)[0])
            run.append((obs, r, info["steps"]))
            if te or tr:
                break
        runs.append(run)
    assert len(runs[0]) == len(runs[1])
    for (o1, r1, n1), (o2, r2, n2) in zip(runs[0], runs[1], strict=True):
        _assert_same(o1, o2)
        assert r1 == r2 and n1 == n2
    assert not np.array_equal(runs[0][0][0]["global"], runs[2][0][0]["global"])  # another level


# --- masks ---------------------------------------------------------------------------------------------------
def test_a_random_masked_policy_keeps_to_valid_reachable_goals(G: ModuleType) -> None:
    kinds = set()
    for seed in (11, 12, 13):
        env = _make(G, "digslam/DigCoverageGoalsRocks-v0" if seed == 12 else "digslam/DigCoverageGoals-v0",
                    max_steps=400)  # fmt: skip
        raw, pol = find_wrapper(env, G.GoalSelectionEnv), G.RandomCandidatePolicy(seed=seed)
        obs, _ = env.reset(seed=seed)
        done, elapsed = False, 0
        while not done:
            mask = raw.action_masks()
            assert mask.dtype == bool and mask[0] and np.array_equal(obs["mask"], mask.astype(np.int8))
            assert mask.tolist() == sorted(mask.tolist(), reverse=True) and not obs["candidates"][~mask].any()
            assert env.observation_space.contains(obs)
            c = raw.candidates
            view = parse(raw.base_observation["map"], raw.base_observation["state"])
            plan = raw.driver.probe(view, copy.deepcopy(raw.mem))
            for kind, goal in zip(c.kind[mask], c.goal[mask], strict=True):
                kinds.add(int(kind))
                if kind == G.TURN:
                    assert tuple(goal) == view.cell
                else:
                    # a reachable clear pixel, or (the frontier agent's corridor goals) a reachable
                    # penumbra pixel next to dark ground
                    g = tuple(goal)
                    assert np.isfinite(plan.dist[g]) and (
                        plan.reach[g] or (view.penumbra[g] and kind == G.FRONTIER)
                    )
            a = pol.predict(obs)[0]
            assert mask[a]
            obs, r, te, tr, info = env.step(a)
            elapsed += info["steps"]
            assert info["elapsed"] == elapsed and 0 <= info["steps"] <= raw.step_cap and np.isfinite(r)
            done = te or tr
        assert elapsed == 400 or te
    assert kinds == {G.FRONTIER, G.CLOSURE, G.TURN}


def test_a_masked_or_malformed_action_raises_value_error(G: ModuleType) -> None:
    env = find_wrapper(_make(G), G.GoalSelectionEnv)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(0)
    env.reset(seed=3)
    bad = int(np.flatnonzero(~env.action_masks())[0])
    with pytest.raises(ValueError, match=f"candidate {bad} is masked out"):
        env.step(bad)
    for action in (env.n, -1):
        with pytest.raises(ValueError, match="out of range"):
            env.step(action)
    for action in (0.5, [0, 1], "a", True):
        with pytest.raises(ValueError, match="expected one integer candidate index"):
            env.step(action)
    env.step(np.array([0]))  # a one-element array (a VecEnv's action) is fine
    with pytest.raises(ValueError, match="env=None"):
        G.GoalSelectionEnv(gym.make("digslam/DigCoverage-v0", map_size=36), map_size=48)


# --- no ground truth -----------------------------------------------------------------------------------------
def test_the_observation_is_a_function_of_the_base_observations_only(G: ModuleType) -> None:
    """The same base observations played back with empty infos (no truth, no certified coverage, no world
    behind them) give the same goal observations and the same low-level actions."""
    base = _Record(gym.make("digslam/DigCoverage-v0", map_size=36, max_episode_steps=300, horizon=300))
    env = G.GoalSelectionEnv(base, max_steps=300)
    pol = G.RandomCandidatePolicy(seed=5)
    obs, info = env.reset(seed=21)
    assert "true_coverage" in info  # the base info passes through: it is there, only not observed
    seen, actions = [obs], []
    for _ in range(8):
        actions.append(pol.predict(obs)[0])
        obs, _, te, tr, _ = env.step(actions[-1])
        seen.append(obs)
        if te or tr:
            break
    sizes = {k: getattr(env.driver, k) for k in SIZES}
    replay = _Replay(base.observation_space, base.action_space, base.frames)
    again = G.GoalSelectionEnv(replay, max_steps=300, driver_kwargs=sizes)
    _assert_same(again.reset(seed=0)[0], seen[0])
    for a, expected in zip(actions, seen[1:], strict=True):
        _assert_same(again.step(a)[0], expected)
    np.testing.assert_array_equal(np.array(replay.actions), np.array(base.actions))


# --- reward and episode ---------------------------------------------------------------------------------------
def test_reward_is_the_base_reward_minus_the_step_cost_plus_the_target_bonus(G: ModuleType) -> None:
    env = _make(G, step_cost=0.1, target_bonus=2.0, reward_scale=0.5)
    obs, _ = env.reset(seed=4)
    events = set()
    for _ in range(12):
        obs, r, te, tr, info = env.step(0)
        reached = info["event"] == "reached" and info["kind"] in ("frontier", "closure")
        events.add(info["event"])
        assert r == pytest.approx(0.5 * info["base_reward"] - 0.1 * info["steps"] + 2.0 * reached)
        assert {"certified_coverage", "pose_box", "steps", "elapsed", "event", "kind", "goal"} <= set(info)
    assert "reached" in events


def test_episodes_end_at_max_steps_low_level_steps_and_macro_steps_at_the_cap(G: ModuleType) -> None:
    env = _make(G, max_steps=120, step_cap=7, target=1.0)
    env.reset(seed=2)
    steps, te, tr = [], False, False
    while not (te or tr):
        _, _, te, tr, info = env.step(0)
        steps.append(info["steps"])
    assert tr and not te and sum(steps) == 120 == info["elapsed"] and max(steps) <= 7
    assert info["event"] == "done"


def test_maskable_ppo_learns_on_it(G: ModuleType) -> None:
    sb3c = pytest.importorskip("sb3_contrib")
    env = _make(G, max_steps=200)
    model = sb3c.MaskablePPO("MultiInputPolicy", env, n_steps=16, batch_size=8, n_epochs=1, seed=0)
    model.learn(16)
    obs, _ = env.reset(seed=1)
    goal = find_wrapper(env, G.GoalSelectionEnv)
    action, _ = model.predict(obs, action_masks=goal.action_masks(), deterministic=True)
    assert goal.action_masks()[int(action)]


def test_module_doctests(G: ModuleType) -> None:
    import doctest

    res = doctest.testmod(G.policy, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert res.attempted > 0 and res.failed == 0
