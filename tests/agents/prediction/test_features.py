"""The map predictor's gains as candidate features (``candidate_features``, the learned chooser's inputs).

* the goal env with the entry point appends two features to the 15 of every candidate, zero on padding, the
  first 15 unchanged, and passes gymnasium's checker;
* the features are the ``predictive_frontier`` gain at each goal pixel, and its uncertainty discount;
* a ``GoalAgent`` with the same entry point makes the goal env's observations (what a trained chooser was
  fitted on), step for step;
* bad entry points get one line;
* ``agents/configs/goals_predictive.toml`` trains at tiny size, loads as a ``GoalAgent`` and runs in the suite
  and in ``digslam demo --agent predictive_chooser``.
"""

from __future__ import annotations

import copy
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("torch")

import digslam.agents.goals as G  # noqa: E402
from digslam.agents.baselines.policy import parse  # noqa: E402
from digslam.agents.goals.extra import resolve, with_extra  # noqa: E402
from digslam.agents.prediction.agent import visible_shares  # noqa: E402
from digslam.agents.prediction.features import ENTRY_POINT, SCALE, PredictedGain  # noqa: E402

KW = {"base_id": "digslam/DigCoverage-v0", "map_size": 40, "max_steps": 300, "step_cap": 20,
      "fixed_world": False, "world": "caves"}  # fmt: skip


def _pair():
    plain = G.GoalSelectionEnv(**KW)
    more = G.GoalSelectionEnv(candidate_features=ENTRY_POINT, **KW)
    return plain, more


def test_two_more_features_the_rest_unchanged():
    plain, more = _pair()
    a, _ = plain.reset(seed=1_000_002)
    b, _ = more.reset(seed=1_000_002)
    assert more.observation_space["candidates"].shape == (16, G.N_FEATURES + 2)
    for _ in range(6):
        np.testing.assert_array_equal(a["candidates"], b["candidates"][:, : G.N_FEATURES])
        np.testing.assert_array_equal(a["mask"], b["mask"])
        extra = b["candidates"][:, G.N_FEATURES :]
        assert np.all(extra[b["mask"] == 0] == 0) and np.all((extra >= 0) & (extra <= 1))
        assert np.any(extra[b["mask"] > 0, 0] > 0)  # a frontier opens onto predicted free ground
        assert more.observation_space.contains(b)
        a, *_ = plain.step(0)
        b, *_ = more.step(0)


def test_the_features_are_the_predictive_agents_gain():
    _, env = _pair()
    obs, _ = env.reset(seed=1_000_003)
    c = env.candidates
    view = parse(env.base_observation["map"], env.base_observation["state"])
    p, var = resolve(ENTRY_POINT).predictor.free(view.image)
    slots = np.flatnonzero(c.mask)
    radius = env.driver.sensor_range / env.driver.px(view.clear.shape[0])
    g0 = visible_shares(view, p, var, c.goal[slots, 0], c.goal[slots, 1], radius, 0.0)
    g1 = visible_shares(view, p, var, c.goal[slots, 0], c.goal[slots, 1], radius, 1.0)
    got = obs["candidates"][slots, G.N_FEATURES :]
    np.testing.assert_allclose(got[:, 0], np.tanh(SCALE * g0), atol=1e-6)
    np.testing.assert_allclose(got[:, 1], np.tanh(SCALE * (g0 - g1)), atol=1e-6)
    assert np.all(g1 <= g0 + 1e-12)


def test_goal_agent_makes_the_goal_envs_observations():
    _, env = _pair()
    seen_env, seen_agent = [], []

    class Record:
        def __init__(self, seen):
            self.seen = seen

        def predict(self, obs, action_masks=None):
            self.seen.append(obs["candidates"].copy())
            return 0

    obs, _ = env.reset(seed=1_000_004)
    chooser = Record(seen_env)
    for _ in range(5):
        obs, *_ = env.step(chooser.predict(obs))
    low = env.env
    agent = G.GoalAgent.from_env(low, Record(seen_agent), n_candidates=16, step_cap=20, max_steps=300,
                                 candidate_features=ENTRY_POINT)  # fmt: skip
    assert agent.goal_observation_space["candidates"].shape == (16, G.N_FEATURES + 2)
    o, _ = low.reset(seed=1_000_004)
    while len(seen_agent) < 5:
        o, *_ = low.step(agent.predict(o)[0])
    for a, b in zip(seen_env, seen_agent[:5], strict=True):
        np.testing.assert_array_equal(a, b)


def test_deepcopy_shares_the_predictor():
    g = PredictedGain()
    assert copy.deepcopy(g) is g


@pytest.mark.parametrize(
    ("name", "says"),
    [("no_colon", "expected 'package.module:name'"), ("digslam.nowhere:X", "cannot load"),
     ("digslam.agents.prediction.features:ENTRY_POINT", "not callable"),
     ("digslam.agents.prediction.model:Predictor", "could not be built with no arguments"),
     ("digslam.agents.prediction.model:load_shipped", "builds no features")],
)  # fmt: skip
def test_bad_entry_points_say_so(name, says):
    with pytest.raises(ValueError, match=says):
        resolve(name)


def test_padding_stays_zero_whatever_the_object_gives():
    env = G.GoalSelectionEnv(**KW)
    env.reset(seed=1_000_002)
    c = env.candidates
    view = parse(env.base_observation["map"], env.base_observation["state"])
    out = with_extra(ENTRY_POINT, env.driver, view, c)
    assert out.shape == (16, G.N_FEATURES + 2) and np.all(out[~c.mask] == 0)


def test_the_chooser_config_trains_loads_and_evaluates_at_tiny_size(tmp_path):
    """``agents/configs/goals_predictive.toml`` end to end at tiny size: warm start (the frontier teacher
    here, for speed), PPO, the sidecar naming the entry point, and the model acting in the low-level env as
    a ``GoalAgent`` with the same features."""
    pytest.importorskip("sb3_contrib")
    from pathlib import Path

    from digslam.agents.evaluation.suite import run_suite
    from digslam.agents.learning import models
    from digslam.agents.learning.train import train
    from digslam.agents.learning.train_config import TrainConfig

    cfg = TrainConfig.from_file(
        Path(__file__).parents[3] / "agents" / "configs" / "goals_predictive.toml",
        ["warm_start=frontier", "warm_start_levels=1", "bc_epochs=1", "n_envs=1", "total_timesteps=32",
         "n_steps=16", "batch_size=16", "n_epochs=1", "eval_freq=0", "checkpoint_freq=32",
         "env_kwargs.max_steps=120", "env_kwargs.step_cap=20", "env_kwargs.map_size=36",
         f'out_dir="{tmp_path.as_posix()}"'],
    )  # fmt: skip
    path = train(cfg)
    assert models.model_meta(path)["env_kwargs"]["candidate_features"] == ENTRY_POINT
    policy = {"chooser": lambda env: models.load_ppo(path, env)}
    res = run_suite(policy, n_maps=1, steps=60, split="validation", generators=["caves"])
    assert res.times("T80")["chooser"].shape == (1,)
    demo = subprocess.run([sys.executable, "-m", "digslam.agents.cli.main", "demo", "--agent",
                           "predictive_chooser", "--model", str(path), "--steps", "30", "--out",
                           str(tmp_path / "demo")], capture_output=True, text=True, timeout=600)  # fmt: skip
    assert demo.returncode == 0, demo.stderr[-2000:]
    assert (tmp_path / "demo" / "episode.gif").is_file()
