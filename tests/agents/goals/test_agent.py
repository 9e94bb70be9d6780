"""``GoalAgent``: a goal-level chooser as a policy of the low-level env.

* fidelity: with ``FirstCandidatePolicy`` it takes the frontier agent's actions, step for step, and the
  goal env's (the same certified-coverage curve over 1000 steps of the room, levels 1 000 000-1 000 001);
* a VecEnv batch is handled per index; a bad chooser or env says so;
* a goal-level ``MaskablePPO`` saved with its sidecar loads through ``load_ppo`` as a ``GoalAgent`` of the
  low-level env, whose keywords ``model_env_kwargs`` gives, and runs in ``digslam evaluate``.

``digslam.agents.goals`` is imported inside the tests, not at collection (see ``test_env.py``).
"""

from __future__ import annotations

import importlib
import json
from pathlib import Path
from types import ModuleType

import gymnasium as gym
import numpy as np
import pytest
from goal_curves import Curve as _Curve

import digslam.envs  # noqa: F401  (registers the base ids)
from digslam.agents.baselines.registry import make_baseline
from digslam.agents.evaluation.evaluate import run_episode
from digslam.agents.evaluation.suite import GENERATORS

SEEDS = (1_000_000, 1_000_001)
GOAL_KW = {"map_size": 36, "max_steps": 200, "step_cap": 10, "fixed_world": False}


@pytest.fixture(scope="module")
def G() -> ModuleType:
    return importlib.import_module("digslam.agents.goals")


def _room(steps: int) -> _Curve:
    kw = {"target": 1.0, "horizon": steps, **GENERATORS["room"][1]}
    return _Curve(gym.make("digslam/DigCoverage-v0", max_episode_steps=steps, **kw))


@pytest.mark.parametrize("seed", SEEDS)
def test_first_candidate_goal_agent_is_the_frontier_agent(G: ModuleType, seed: int) -> None:
    steps = 1000
    env = _room(steps)
    frontier = run_episode(make_baseline("frontier", env), env, seed, steps)[0]
    f_actions = np.array(env.actions)
    agent = G.GoalAgent.from_env(env, G.FirstCandidatePolicy())
    assert agent.max_steps == steps  # the env's horizon, as the goal env gives its base env
    goal = run_episode(agent, env, seed, steps)[0]
    np.testing.assert_array_equal(np.array(env.actions), f_actions)
    np.testing.assert_array_equal(goal, frontier)
    assert 0 < agent.state().decisions < steps / 5  # macro steps, not single steps
    st = agent.choice_stats()  # always candidate 0: never differs from the frontier agent, always a frontier
    assert st["decisions"] == agent.state().decisions and st["not_first"] == 0.0 and st["frontier"] == 1.0
    run_episode(agent, env, seed + 1, 50)  # a second episode adds to the counts (reset keeps them)
    assert agent.choice_stats()["decisions"] > st["decisions"]
    # and the goal env driven by the same chooser
    base = _room(steps)
    genv = G.GoalSelectionEnv(base, max_steps=steps)
    obs, _ = genv.reset(seed=seed)
    done = False
    while not done:
        obs, _, te, tr, _ = genv.step(G.FirstCandidatePolicy().predict(obs)[0])
        done = te or tr
    cov = np.array(base.cov)
    np.testing.assert_array_equal(np.concatenate([cov, np.full(steps + 1 - cov.size, cov[-1])]), goal)
    np.testing.assert_array_equal(np.array(base.actions), f_actions[: len(base.actions)])


def test_a_batch_is_driven_per_index(G: ModuleType) -> None:
    from stable_baselines3.common.vec_env import DummyVecEnv

    make = [lambda: gym.make("digslam/DigCoverage-v0", map_size=36, max_episode_steps=40)] * 2
    vec = DummyVecEnv(make)
    vec.seed(3)
    single = [gym.make("digslam/DigCoverage-v0", map_size=36, max_episode_steps=40) for _ in range(2)]
    batch_agent = G.GoalAgent.from_env(single[0], G.FirstCandidatePolicy(), step_cap=7)
    agents = [G.GoalAgent.from_env(e, G.FirstCandidatePolicy(), step_cap=7) for e in single]
    obs = vec.reset()
    one = [e.reset(seed=3 + i)[0] for i, e in enumerate(single)]
    start = np.ones(2, bool)
    for _ in range(25):
        act, _ = batch_agent.predict(obs, episode_start=start)
        assert act.shape == (2, 2)
        for i in range(2):
            a, _ = agents[i].predict(one[i])
            np.testing.assert_array_equal(act[i], a)
            one[i] = single[i].step(a)[0]
        obs, _, _, _ = vec.step(act)
        start = np.zeros(2, bool)
    assert batch_agent.state(1).decisions == agents[1].state().decisions > 0


def test_bad_choosers_and_envs_are_refused(G: ModuleType) -> None:
    env = gym.make("digslam/DigCoverage-v0", map_size=36)
    obs, _ = env.reset(seed=0)

    class Masked:
        def predict(self, goal_obs: dict) -> tuple[int, None]:
            return int(np.flatnonzero(goal_obs["mask"] == 0)[0]), None

    with pytest.raises(ValueError, match="masked out"):
        G.GoalAgent.from_env(env, Masked()).predict(obs)
    with pytest.raises(ValueError, match="chooser"):
        G.GoalAgent.from_env(env, object())
    with pytest.raises(ValueError, match="unknown keyword"):
        G.GoalAgent.from_env(env, G.FirstCandidatePolicy(), n_candidate=8)
    genv = gym.make("digslam/DigCoverageGoals-v0", map_size=36)
    with pytest.raises(ValueError, match="low-level"):
        G.GoalAgent.from_env(genv, G.FirstCandidatePolicy())


@pytest.fixture(scope="module")
def goal_model(G: ModuleType, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A tiny MaskablePPO on the goal env, saved with its sidecar."""
    from sb3_contrib import MaskablePPO
    from stable_baselines3.common.vec_env import DummyVecEnv

    from digslam.agents.learning.checkpoints import write_sidecar
    from digslam.agents.learning.train_config import TrainConfig

    vec = DummyVecEnv([lambda: gym.make("digslam/DigCoverageGoals-v0", **GOAL_KW)])
    model = MaskablePPO("MultiInputPolicy", vec, n_steps=16, batch_size=16, n_epochs=1, seed=0, device="cpu")
    model.learn(16)
    path = tmp_path_factory.mktemp("goal_model") / "goals_model.zip"
    model.save(path)
    vec.close()
    cfg = TrainConfig(algo="maskable_ppo", env_id="digslam/DigCoverageGoals-v0", env_kwargs=dict(GOAL_KW))
    write_sidecar(path, cfg)
    return path


def test_a_goal_model_loads_as_a_goal_agent_of_the_low_level_env(G: ModuleType, goal_model: Path) -> None:
    from digslam.agents.learning import models

    assert models.model_meta(goal_model)["env_id"] == "digslam/DigCoverageGoals-v0"
    kw = models.model_env_kwargs(goal_model)  # the low-level env's: no goal keyword, the goal env's horizon
    assert kw == {"map_size": 36, "horizon": 200}
    env = gym.make("digslam/DigCoverage-v0", max_episode_steps=50, **kw)
    agent = models.load_ppo(goal_model, env)
    assert isinstance(agent, G.GoalAgent) and not hasattr(agent, "policy")  # reset per episode
    assert (agent.step_cap, agent.n, agent.max_steps) == (10, 16, 200)
    cert, _, _, _, n, _ = run_episode(agent, env, 5, 50)
    assert n == 50 and cert[-1] > cert[0] and agent.state().decisions >= 5
    # a model of other goal observations is refused in one line
    side = goal_model.with_suffix(".json")
    meta = json.loads(side.read_text())
    try:
        side.write_text(json.dumps({**meta, "env_kwargs": {**meta["env_kwargs"], "n_candidates": 8}}))
        with pytest.raises(models.ModelError, match="trained on goal observations"):
            models.load_ppo(goal_model, env)
    finally:
        side.write_text(json.dumps(meta))


def test_digslam_evaluate_runs_a_goal_model(goal_model: Path, tmp_path: Path) -> None:
    from digslam.agents.cli.main import main

    out = tmp_path / "eval"
    args = ["evaluate", "--agents", "ppo", "--model", str(goal_model), "--maps", "1", "--steps", "30"]
    assert main([*args, "--out", str(out)]) == 0
    assert (out / "evaluation.json").is_file()
