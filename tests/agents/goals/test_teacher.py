"""Teachers of the warm start: the rollout teacher looks ahead on copies and leaves the env as it was; its
picks are valid candidates; the frontier teacher is candidate 0; demonstrations come as arrays."""

from __future__ import annotations

import copy

import gymnasium as gym
import numpy as np
import pytest

import digslam.agents.goals  # noqa: F401
from digslam.agents.goals.teacher import RolloutTeacher, demonstrations, teacher

KW = {"max_steps": 150, "step_cap": 20}


def _env() -> gym.Env:
    return gym.make("digslam/DigCoverageGoals-v0", **KW)


@pytest.mark.parametrize("fresh_noise", [False, True])
def test_rollout_teacher_picks_valid_candidates_and_leaves_the_env_untouched(fresh_noise: bool) -> None:
    a, b = _env(), _env()
    obs_a, _ = a.reset(seed=1_000_001)
    b.reset(seed=1_000_001)
    t = RolloutTeacher(k=3, horizon=40, fresh_noise=fresh_noise)
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


def test_a_fresh_stream_changes_what_a_copy_measures() -> None:
    """The mechanism of ``fresh_noise``: a copy given its own generator draws other noise than the episode
    (the pose box differs after the same decisions), while a plain copy draws the same."""
    env = _env()
    obs, _ = env.reset(seed=1_000_002)
    plain, fresh = copy.deepcopy(env), copy.deepcopy(env)
    fresh.unwrapped.np_random = np.random.default_rng((0, 1))
    for _ in range(3):
        o, *_ = env.step(0)
        p, *_ = plain.step(0)
        f, *_ = fresh.step(0)
    assert np.array_equal(o["global"], p["global"])
    assert not np.array_equal(o["global"], f["global"])


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
    with pytest.raises(ValueError, match="seed"):
        RolloutTeacher(seed=-1)
    with pytest.raises(ValueError, match="no level"):
        demonstrations(_env(), teacher("frontier"), [])


def test_bench_teacher_plays_a_level_and_rejects_bad_arguments() -> None:
    """``benchmarks/bench_teacher.py``: its worker plays one level to the step budget (T90 is the budget when
    0.9 is out of reach); bad arguments give one line and exit 2."""
    import importlib.util
    import subprocess
    import sys

    from digslam.agents.cli.commands import benchmarks_dir

    script = benchmarks_dir() / "bench_teacher.py"
    spec = importlib.util.spec_from_file_location("bench_teacher", script)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    row = mod.play(("room", 1_000_000, "rollout_fresh_noise", 60))
    assert row["t90"] == 60 and row["certified"] < 0.9 and row["mode"] == "rollout_fresh_noise"
    for argv, msg in ((["--levels", "0"], "must be >= 1"), (["--generators", "nope"], "unknown ['nope']")):
        out = subprocess.run([sys.executable, str(script), *argv], capture_output=True, text=True)
        assert out.returncode == 2 and msg in out.stderr.splitlines()[-1], out.stderr[-400:]
