"""The benchmark suite: the same test levels for every agent, uncapped curves, the leaderboard."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import digslam.envs  # noqa: F401
from digslam.agents.baselines.registry import make_baseline
from digslam.agents.evaluation.suite import GENERATORS, run_suite, steps_per_second
from digslam.envs.splits import TEST


def test_suite_runs_every_agent_on_the_same_test_levels_and_writes_the_leaderboard(tmp_path: Path) -> None:
    env = gym.make("digslam/DigCoverage-v0")
    agents = {n: make_baseline(n, env, seed=0) for n in ("random", "frontier")}
    res = run_suite(agents, n_maps=2, steps=40, generators=["room", "rocks"])
    assert res.seeds == [TEST.start, TEST.start + 1] and list(res.results) == ["room", "rocks"]
    for r in res.results.values():
        for c in r.curves.values():
            assert c.shape == (2, 41) and np.all(np.diff(c, axis=1) >= -1e-12)  # certified never shrinks
    m = res.metrics()
    assert set(m["room"]["frontier"]) >= {"T80", "T90", "T95", "S90", "AUC", "path_length", "final_tube"}
    assert np.all(res.t90()["random"] == 40)  # 0.9 is out of reach in 40 steps: the budget
    table = res.table(["random", "frontier"])
    assert table.count("\n") == 3 and "T90 rooms" not in table and "(best baseline)" in table
    assert res.best(["random", "frontier"]) == "frontier"  # the same T90: the larger AUC wins
    assert res.figure(tmp_path / "lb.png").stat().st_size > 10_000
    data = json.loads(res.to_json(tmp_path / "suite.json").read_text())
    assert data["seeds"] == res.seeds and set(data["generators"]) == {"room", "rocks"}
    # the same levels for every agent: the first map's start pose is the same world and start
    starts = []
    for _ in range(2):
        e = gym.make("digslam/DigCoverage-v0", world="rocks", target=1.0)
        starts.append(e.reset(seed=TEST.start)[1]["truth"].pose)
    assert np.array_equal(starts[0], starts[1])
    assert steps_per_second(agents["frontier"], steps=30) > 0
    with pytest.raises(ValueError, match="generators"):
        run_suite(agents, n_maps=1, steps=5, generators=["moon"])
    assert set(GENERATORS) == {"room", "rocks", "caves", "rooms"}
