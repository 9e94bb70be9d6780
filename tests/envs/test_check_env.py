"""Every registered environment keeps the Gymnasium contract, wrapped (``gym.make``) and unwrapped.

The certified-coverage environments wrap the raw exploration env; its own ``step`` must return a real
observation (the observer's skipping of it is an internal fast path), so ``check_env(env.unwrapped)``
passes too.
"""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import digslam.envs  # noqa: F401

#: The ids registered by ``digslam.envs`` (the goal-selection ids of ``digslam.agents.goals``, registered
#: when that package is imported, are checked in ``tests/agents/goals``).
IDS = sorted(i for i in gym.registry if i in set(digslam.envs.ENV_IDS) | set(digslam.envs.COVERAGE_IDS))


def test_every_id_is_checked() -> None:
    ours = {i for i in gym.registry if i.startswith("digslam/") and "Goals" not in i}
    assert set(IDS) == ours == set(digslam.envs.ENV_IDS) | set(digslam.envs.COVERAGE_IDS)


@pytest.mark.parametrize("env_id", IDS)
def test_check_env_wrapped_and_unwrapped(env_id: str) -> None:
    kw = {"map_size": 36} if env_id in digslam.envs.COVERAGE_IDS else {}
    env = gym.make(env_id, **kw)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # check_env notes that gym.make's env is wrapped
            check_env(env, skip_render_check=True)
        check_env(env.unwrapped, skip_render_check=True)
    finally:
        env.close()


@pytest.mark.parametrize("env_id", sorted(digslam.envs.COVERAGE_IDS))
def test_inner_env_step_returns_its_observation(env_id: str) -> None:
    env = gym.make(env_id, map_size=36)
    try:
        env.reset(seed=0)
        raw = env.unwrapped
        obs = raw.step(np.zeros(2, np.float32))[0]
        assert obs is not None and raw.observation_space.contains(obs)
        assert set(env.step(np.zeros(2, np.float32))[0]) == {"map", "state"}
    finally:
        env.close()
