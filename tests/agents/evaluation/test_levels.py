"""The per-generator target levels: the choice rule, the shipped table, and (expensive) a fresh choice."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import digslam.envs  # noqa: F401  (registers the ids)
from digslam.agents.baselines import make_baseline
from digslam.agents.evaluation.levels import (
    CANDIDATE_LEVELS,
    LEVEL_EVIDENCE,
    LEVEL_MAPS,
    LEVEL_SHARE,
    LEVEL_STEPS,
    TARGET_LEVELS,
    choose_level,
    choose_levels,
    format_levels,
    level_metric,
)
from digslam.agents.evaluation.suite import GENERATORS, SuiteResult, run_suite


def _curves(finals: list[float], steps: int = 10) -> np.ndarray:
    """Curves that rise linearly to each final coverage at the last step."""
    return np.array([np.linspace(0.0, f, steps + 1) for f in finals])


def test_the_level_is_the_highest_reached_on_ninety_percent_of_the_levels() -> None:
    ten = [0.96] * 9 + [0.86]  # 0.95 on 90 %, 0.85 on all
    assert choose_level({"a": _curves(ten)}, steps=10)[:2] == (0.95, "a")
    eight = [0.96] * 8 + [0.86] * 2  # 0.95 on 80 % only: the next level down
    assert choose_level({"a": _curves(eight)}, steps=10)[:2] == (0.85, "a")
    # the best baseline for a level is the one that reaches it most often
    level, agent, share = choose_level({"a": _curves(eight), "b": _curves(ten)}, steps=10)
    assert (level, agent, share) == (0.95, "b", pytest.approx(0.9))
    # a level reached after the step budget does not count
    assert choose_level({"a": _curves(ten, steps=20)}, steps=10)[0] == 0.8
    # none qualifies: the lowest level, with its best baseline
    assert choose_level({"a": _curves([0.5] * 10)}, steps=10)[:2] == (0.8, "a")


def test_ties_go_to_the_faster_baseline() -> None:
    slow = np.array([[0.0, 0.0, 0.0, 0.96]] * 10)
    fast = np.array([[0.0, 0.96, 0.96, 0.96]] * 10)
    assert choose_level({"slow": slow, "fast": fast}, steps=3)[1] == "fast"


def test_the_shipped_table_covers_every_generator_with_a_candidate_level() -> None:
    assert set(TARGET_LEVELS) == set(GENERATORS)
    assert all(v in CANDIDATE_LEVELS and v >= 0.8 for v in TARGET_LEVELS.values())
    assert set(LEVEL_EVIDENCE) == set(GENERATORS)
    assert all(share >= LEVEL_SHARE for _, share in LEVEL_EVIDENCE.values())
    assert level_metric("rooms") == level_metric(TARGET_LEVELS["rooms"])
    assert format_levels({"room": 0.95, "rooms": 0.8}) == "room:0.95,rooms:0.8"
    with pytest.raises(ValueError, match="unknown generator"):
        level_metric("moon")


def test_a_suite_reads_back_and_gives_the_same_levels(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from digslam.agents.evaluation.evaluate import EvalResult

    c = {"a": _curves([0.96] * 10), "b": _curves([0.9] * 10)}
    z = {k: np.zeros(10) for k in c}
    res = SuiteResult({"room": EvalResult(c, c, z, z), "rooms": EvalResult(c, c, z, z)}, steps=10)
    back = SuiteResult.from_json(res.to_json(tmp_path / "s.json"))
    assert choose_levels(back) == choose_levels(res)
    assert np.array_equal(back.times()["a"], res.times()["a"])
    assert back.success("a") == res.success("a") == 1.0


@pytest.mark.expensive
def test_each_shipped_level_is_reached_by_its_baseline_on_ninety_percent_of_the_validation_levels() -> None:
    """Recompute the choice on the validation split (about 10 minutes a baseline on one core)."""
    env = gym.make("digslam/DigCoverage-v0")
    names = sorted({agent for agent, _ in LEVEL_EVIDENCE.values()})
    policies = {n: make_baseline(n, env, seed=0) for n in names}
    env.close()
    res = run_suite(policies, n_maps=LEVEL_MAPS, steps=LEVEL_STEPS, split="validation")
    chosen = choose_levels(res, names)
    for g, (level, _, share) in chosen.items():
        assert level == TARGET_LEVELS[g], (g, level, share)
        assert share >= LEVEL_SHARE
