"""The baselines' decisions are pinned: fixed levels, fixed seeds, the actions of the first 300 steps as the
agents took them before their planning moved to compiled kernels (``data/baseline_actions.npz``, recorded
with the numpy / ``scipy.sparse`` planner). Every step of those runs matches bit for bit, so the leaderboard
does not move with the speed-ups."""

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import digslam.envs  # noqa: F401
from digslam.agents.baselines.registry import make_baseline

FIXTURE = np.load(Path(__file__).with_name("data") / "baseline_actions.npz")


@pytest.mark.parametrize("key", sorted(FIXTURE.files))
def test_the_actions_of_a_fixed_run_are_those_recorded(key: str) -> None:
    world, name, seed = key.split("__")
    expected = FIXTURE[key]
    kw = {"target": 1.0, "fixed_world": False, "max_episode_steps": 1501}
    env = gym.make("digslam/DigCoverage-v0", **kw, **({} if world == "room" else {"world": world}))
    try:
        agent = make_baseline(name, env, seed=0)
        obs, _ = env.reset(seed=int(seed))
        for t, want in enumerate(expected):
            action = np.asarray(agent.predict(obs)[0], np.float32)
            assert np.array_equal(action, want), f"{key}: step {t}: {action} != {want}"
            obs, _, terminated, truncated, _ = env.step(action)
            assert not (terminated or truncated)
    finally:
        env.close()
