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
    levels, overall = res.tables(["random", "frontier"])
    assert table == levels + "\n\n" + overall  # two tables: per generator, and over all maps
    assert levels.count("\n") == overall.count("\n") == 3 and "T90 rooms" not in table
    assert "T95 room (success)" in levels and "speedup" not in levels and "(best baseline)" in overall
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
    assert list(GENERATORS) == ["room", "rocks", "caves", "rooms", "floorplan"]


def test_the_floorplan_levels_are_windows_of_the_registered_ids_size() -> None:
    """The suite's floorplan levels are those of ``digslam/DigCoverageFloorplan-v0`` (the same window size,
    :data:`digslam.envs.FLOORPLAN_WORLD_SIZE`); the procedural ones keep the default frame."""
    from digslam.envs import COVERAGE_IDS, ENV_IDS, FLOORPLAN_WORLD_SIZE

    env_id, kw = GENERATORS["floorplan"]
    assert kw == {"world": "floorplan", "world_size": FLOORPLAN_WORLD_SIZE}
    assert COVERAGE_IDS["digslam/DigCoverageFloorplan-v0"] == {
        "world": "floorplan",
        "world_size": kw["world_size"],
    }
    assert ENV_IDS["digslam/ExploreFloorplan-v0"] == {"world": "floorplan", "world_size": kw["world_size"]}
    assert all("world_size" not in GENERATORS[g][1] for g in ("room", "rocks", "caves", "rooms"))
    env = gym.make("digslam/DigCoverageFloorplan-v0")
    assert env.unwrapped.config.world_size == FLOORPLAN_WORLD_SIZE
    env.close()


def test_benchmark_agents_refuses_a_bad_setting_or_generator_in_one_line() -> None:
    """``--set KEY=VALUE`` (an environment keyword for every agent), ``--generators``, ``--agents``,
    ``--predictive`` and ``--predictor`` are checked before any episode: an unknown keyword, an item without
    ``=``, an unknown generator or agent, a missing settings or predictor file is one line, exit 2."""
    import subprocess
    import sys

    from digslam.agents.cli.commands import benchmarks_dir

    script = str(benchmarks_dir() / "bench_agents.py")
    for argv, msg in ((["--set", "bogus=1"], "unknown keyword"), (["--set", "grid_cell"], "expected KEY=VALUE"),
                      (["--generators", "nope"], "unknown ['nope']"),
                      (["--agents", "frontier", "nope"], "--agents: unknown ['nope']"),
                      (["--predictive", "nope.toml"], "--predictive: path: no configuration file"),
                      (["--predictor", "nope.pt"], "--predictor: no such file nope.pt")):  # fmt: skip
        out = subprocess.run([sys.executable, script, "--quick", *argv], capture_output=True, text=True)
        assert out.returncode == 2 and msg in out.stderr.splitlines()[-1], out.stderr[-400:]


def test_benchmark_agents_runs_the_agents_it_is_given() -> None:
    """``--agents`` picks the baselines it names, in the registry's order, the frontier agent always among
    them (``eval_steps_per_s`` measures it); ``ppo`` alone leaves the frontier agent; a bad name raises."""
    import importlib.util

    from digslam.agents.cli.commands import benchmarks_dir

    spec = importlib.util.spec_from_file_location("bench_agents", benchmarks_dir() / "bench_agents.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    from digslam.agents.baselines.registry import BASELINES

    assert mod.chosen_baselines(None) == list(BASELINES)
    assert mod.chosen_baselines(["lawnmower"]) == [a for a in BASELINES if a in ("frontier", "lawnmower")]
    assert mod.chosen_baselines(["ppo"]) == ["frontier"]
    assert mod.chosen_baselines(["ppo_lowlevel", "ppo"]) == ["frontier"]  # the learned rows are no baselines
    with pytest.raises(ValueError, match="unknown"):
        mod.chosen_baselines(["frontier", "bogus"])
