"""Fidelity: ``FirstCandidatePolicy`` through the goal env drives as the frontier agent on the base env.

Candidate 0 is the frontier agent's own pick and the driver is its loop, so the two runs take the same
low-level actions and reach the same certified coverage at every step (measured on the validation levels
1 000 000 and 1 000 001: identical over 3000 steps on all four generators). The fast test checks 1000 steps
of the room; the expensive one every generator over the suite's 3000.

``digslam.agents.goals`` is imported inside the tests, not at collection (see ``test_env.py``).
"""

from __future__ import annotations

import importlib
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from goal_curves import Curve as _Curve

import digslam.envs  # noqa: F401  (registers the base ids)
from digslam.agents.baselines.registry import make_baseline
from digslam.agents.evaluation.evaluate import run_episode
from digslam.agents.evaluation.metrics import episodes_metrics
from digslam.agents.evaluation.suite import GENERATORS

SEEDS = (1_000_000, 1_000_001)


def _runs(world: str, seed: int, steps: int, step_cap: int = 100) -> dict[str, Any]:
    goals = importlib.import_module("digslam.agents.goals")
    kw = {"target": 1.0, "horizon": steps, **GENERATORS[world][1]}
    env = _Curve(gym.make("digslam/DigCoverage-v0", max_episode_steps=steps, **kw))
    frontier = run_episode(make_baseline("frontier", env), env, seed, steps)[0]
    f_actions = np.array(env.actions)
    base = _Curve(gym.make("digslam/DigCoverage-v0", max_episode_steps=steps, **kw))
    genv = goals.GoalSelectionEnv(base, max_steps=steps, step_cap=step_cap)
    policy = goals.FirstCandidatePolicy()
    obs, _ = genv.reset(seed=seed)
    decisions, done = 0, False
    while not done:
        obs, _, te, tr, _ = genv.step(policy.predict(obs)[0])
        decisions, done = decisions + 1, te or tr
    cov = np.array(base.cov)
    first = np.concatenate([cov, np.full(steps + 1 - cov.size, cov[-1])])
    return {"frontier": frontier, "first": first, "f_actions": f_actions, "g_actions": np.array(base.actions),
            "decisions": decisions}  # fmt: skip


def _check(r: dict[str, Any], steps: int) -> None:
    f, g = r["frontier"], r["first"]
    for t in (steps // 4, steps // 2, steps):
        assert abs(f[t] - g[t]) <= 0.03, (t, f[t], g[t])  # within a few percent at the same step
    mf, mg = episodes_metrics(f[None], steps), episodes_metrics(g[None], steps)
    assert abs(mf["T80"][0] - mg["T80"][0]) <= 0.05 * steps
    assert r["decisions"] < steps / 5  # macro steps, not single steps (the default cap: 100)
    n = min(len(r["f_actions"]), len(r["g_actions"]))
    np.testing.assert_array_equal(r["f_actions"][:n], r["g_actions"][:n])  # and in fact the same actions


@pytest.mark.parametrize("seed", SEEDS)
def test_first_candidate_reproduces_the_frontier_agent_on_the_room(seed: int) -> None:
    _check(_runs("room", seed, 1000), 1000)


def test_a_short_step_cap_changes_no_action() -> None:
    """Macro steps cut every 7 steps: the goal being driven to comes back as candidate 0 (``continuing``)
    with its waypoint and budget, as the frontier agent keeps it."""
    r = _runs("rocks", SEEDS[0], 400, step_cap=7)
    assert r["decisions"] >= 400 / 7
    np.testing.assert_array_equal(r["f_actions"], r["g_actions"])
    np.testing.assert_array_equal(r["frontier"], r["first"])


@pytest.mark.expensive
@pytest.mark.parametrize("world", sorted(GENERATORS))
@pytest.mark.parametrize("seed", SEEDS)
def test_first_candidate_reproduces_the_frontier_agent_on_every_generator(world: str, seed: int) -> None:
    r = _runs(world, seed, 3000)
    _check(r, 3000)
    assert np.array_equal(r["frontier"], r["first"])
