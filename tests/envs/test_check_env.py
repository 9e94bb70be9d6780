"""Every registered environment keeps the Gymnasium contract, wrapped (``gym.make``) and unwrapped.

The certified-coverage environments wrap the raw exploration env; its own ``step`` must return a real
observation (the observer skips it through the raw env's public ``step_record``). As for any env an entry
point builds, ``gym.make`` writes the id's spec onto ``env.unwrapped``, and ``check_env(env.unwrapped)``
passes too, render checks included (each render mode of the raw env made from that spec).
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


def _make(env_id: str, **kw: object) -> gym.Env:
    return gym.make(env_id, **({"map_size": 36} if env_id in digslam.envs.COVERAGE_IDS else {}), **kw)


@pytest.mark.parametrize("env_id", IDS)
def test_check_env_wrapped_and_unwrapped(env_id: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The whole checker, render modes included (each mode of ``metadata`` made from the env's spec and
    rendered; ``human`` headless)."""
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    env = _make(env_id)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # check_env notes that gym.make's env is wrapped
            check_env(env)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # the raw env: no note at all (it has a spec of its own)
            check_env(env.unwrapped)
    finally:
        env.close()


@pytest.mark.parametrize("env_id", IDS)
def test_spec_and_metadata_say_what_each_layer_is(env_id: str) -> None:
    """``env.spec`` is the id's; a DigCoverage env's ``env.unwrapped`` is the raw exploration env, with the
    id's spec (written there by ``gym.make``, as Gymnasium does for any entry point: ``spec.make()`` builds
    an equal env) and the render modes of the raw env; the DigCoverage env itself renders ``rgb_array``
    and ``human``."""
    env = _make(env_id)
    raw = env.unwrapped
    try:
        assert env.spec is not None and env.spec.id == env_id and env.spec.max_episode_steps == 1000
        assert isinstance(raw, digslam.envs.ExploreEnv) and raw.spec is not None
        assert raw.metadata["render_modes"] == ["rgb_array", "human"]
        if env_id in digslam.envs.ENV_IDS:
            assert raw.spec.id == env_id
            return
        assert raw.spec.id == env_id and env.spec.additional_wrappers == ()
        assert env.metadata["render_modes"] == ["rgb_array", "human"]
        again = raw.spec.make()
        try:
            assert type(again.unwrapped) is digslam.envs.ExploreEnv and again.unwrapped.config == raw.config
            assert again.spec is not None and again.spec.id == env_id
        finally:
            again.close()
    finally:
        env.close()


@pytest.mark.parametrize("env_id", IDS)
def test_seeded_rollouts_repeat(env_id: str) -> None:
    """Two envs of one id, reset with one seed and given the same actions, return the same observations,
    rewards and ends."""
    actions = np.random.default_rng(7).uniform([0.2, -1.0], [1.0, 1.0], (25, 2)).astype(np.float32)
    runs = []
    for _ in range(2):
        env = _make(env_id)
        try:
            obs, _ = env.reset(seed=11)
            steps = [(obs, 0.0, False, False)]
            for a in actions:
                obs, reward, terminated, truncated, _ = env.step(a)
                steps.append((obs, reward, terminated, truncated))
        finally:
            env.close()
        runs.append(steps)
    for (oa, ra, ta, ua), (ob, rb, tb, ub) in zip(*runs, strict=True):
        assert oa.keys() == ob.keys() and (ra, ta, ua) == (rb, tb, ub)
        for k in oa:
            np.testing.assert_array_equal(oa[k], ob[k], err_msg=k)


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
