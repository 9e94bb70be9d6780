"""Teachers of the warm start: the rollout teacher looks ahead on copies and leaves the env as it was; its
picks are valid candidates; the frontier teacher is candidate 0; demonstrations come as arrays."""

from __future__ import annotations

import gymnasium as gym
import pytest

import digslam.agents.goals  # noqa: F401
from digslam.agents.goals.teacher import RolloutTeacher, demonstrations, teacher

KW = {"max_steps": 150, "step_cap": 20}


def _env() -> gym.Env:
    return gym.make("digslam/DigCoverageGoals-v0", **KW)


def test_rollout_teacher_picks_valid_candidates_and_leaves_the_env_untouched() -> None:
    a, b = _env(), _env()
    obs_a, _ = a.reset(seed=1_000_001)
    b.reset(seed=1_000_001)
    t = RolloutTeacher(k=3, horizon=40)
    picks = []
    for _ in range(4):
        pick = t.choose(a, obs_a)  # looks ahead on copies of a
        assert obs_a["mask"][pick] == 1
        picks.append(pick)
        obs_a, ra, da, ca, ia = a.step(pick)
        _, rb, db, cb, ib = b.step(pick)  # b never looked ahead
        assert (ra, da, ca, ia["elapsed"], ia["certified_coverage"]) == (rb, db, cb, ib["elapsed"],
                                                                         ib["certified_coverage"])  # fmt: skip
        if da or ca:
            break
    # a huge margin leaves candidate 0 every time
    assert RolloutTeacher(k=3, horizon=40, margin=10.0).choose(a, obs_a) == 0


def test_demonstrations_arrays_and_the_frontier_teacher() -> None:
    env = _env()
    data = demonstrations(env, teacher("frontier"), [1_000_000], log=(lines := []).append)
    n = len(data["action"])
    assert n > 0 and set(data) == {"obs_candidates", "obs_mask", "obs_global", "mask", "action"}
    assert data["obs_candidates"].shape[0] == n and data["mask"].dtype == bool
    assert not data["action"].any() and data["mask"][:, 0].all()
    assert len(lines) == 1 and "1000000" in lines[0]


def test_bad_teacher_arguments() -> None:
    with pytest.raises(ValueError, match="teacher"):
        teacher("oracle")
    with pytest.raises(ValueError, match="k, horizon"):
        RolloutTeacher(k=0)
    with pytest.raises(ValueError, match="margin"):
        RolloutTeacher(margin=float("nan"))
    with pytest.raises(ValueError, match="no level"):
        demonstrations(_env(), teacher("frontier"), [])
