"""Ray scale-out (issues 11, 18): the actor-pool evaluation and suite equal the sequential ones, bit for bit;
batches are balanced and in map order; sweeps run end to end.

Skipped when ray (the ``ray`` extra) is not installed. Two tests start a local Ray instance with 2 CPUs
(``evaluate_ray`` and ``run_suite_ray``, each starting and shutting down its own); the batching tests need
no Ray; the sweep test (2 trials of 256 timesteps, ``ray[tune]``) is marked expensive.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
from pathlib import Path

import numpy as np
import pytest

ray = pytest.importorskip("ray")


def _has_tune() -> bool:
    try:
        import ray.tune  # noqa: F401
    except ImportError:  # ray without the tune extra: only the sweep test needs it
        return False
    return True


needs_tune = pytest.mark.skipif(not _has_tune(), reason="ray[tune] is not installed")

from digslam.agents.cli.distributed import add_ray_options as add_eval_cli  # noqa: E402
from digslam.agents.cli.distributed import add_sweep_parser as add_sweep_cli  # noqa: E402
from digslam.agents.evaluation.batches import merge_results, plan_batches, split_batches  # noqa: E402
from digslam.agents.evaluation.evaluate import evaluate  # noqa: E402
from digslam.agents.evaluation.ray_eval import evaluate_ray, run_suite_ray  # noqa: E402
from digslam.agents.evaluation.specs import build_policy, normalize_specs  # noqa: E402
from digslam.agents.evaluation.suite import run_suite  # noqa: E402
from digslam.agents.learning.sweep import SweepConfig, run_sweep  # noqa: E402

ENV = "digslam/DigCoverage-v0"
SMALL = {"map_size": 36}


def assert_same_result(a: object, b: object) -> None:
    for f in dataclasses.fields(a):
        va, vb = getattr(a, f.name), getattr(b, f.name)
        if isinstance(va, dict):
            assert list(va) == list(vb), f.name
            for k in va:
                np.testing.assert_array_equal(va[k], vb[k], err_msg=f"{f.name}[{k}]")
        else:
            assert va == vb, f.name


def test_distributed_evaluation_matches_single_machine() -> None:
    """3 maps x 2 agents, 30 steps on a pool of 2 actors (blocks of one and two maps): the very same arrays
    as the sequential evaluation."""
    specs = {"frontier": "frontier", "lawnmower": "lawnmower"}
    dist = evaluate_ray(specs, env_id=ENV, n_maps=3, seed=1000, steps=30, env_kwargs=SMALL, num_cpus=2)
    assert not ray.is_initialized()  # the local instance it started is shut down
    local = evaluate({n: build_policy(s, ENV, SMALL) for n, s in specs.items()}, env_id=ENV, n_maps=3,
                     seed=1000, steps=30, env_kwargs=SMALL)  # fmt: skip
    assert_same_result(dist, local)
    assert dist.curves["frontier"].shape == (3, 31)
    assert dist.seed == 1000 and dist.n_maps == 3
    assert dist.table(at=(30,)) == local.table(at=(30,))
    assert not np.array_equal(dist.curves["frontier"][0], dist.curves["frontier"][1])  # two different maps


def test_suite_on_ray_gives_the_sequential_tables() -> None:
    """The suite (random with seed 0, frontier; 2 generators x 2 test maps x 25 steps) on 2 actors: the
    same SuiteResult, table and metrics as ``run_suite`` in this process."""
    import gymnasium as gym

    from digslam.agents.baselines.registry import make_baseline

    env = gym.make(ENV)
    local_policies = {n: make_baseline(n, env, seed=0) for n in ("random", "frontier")}
    env.close()
    gens = ["room", "rocks"]
    seq = run_suite(local_policies, n_maps=2, steps=25, generators=gens)
    dist = run_suite_ray(["random", "frontier"], n_maps=2, steps=25, generators=gens, workers=2)
    assert not ray.is_initialized()
    assert (dist.steps, dist.split, dist.seeds) == (seq.steps, seq.split, seq.seeds)
    assert list(dist.results) == gens
    for g in gens:
        assert_same_result(dist.results[g], seq.results[g])
    assert dist.table(["random", "frontier"]) == seq.table(["random", "frontier"])
    with pytest.raises(ValueError, match="generators"):
        run_suite_ray(["frontier"], n_maps=1, steps=5, generators=["moon"])


def test_batches_are_balanced_contiguous_and_in_order() -> None:
    for n in range(1, 40):
        for k in range(1, 12):
            blocks = split_batches(n, k)
            assert len(blocks) == min(n, k)
            assert blocks[0][0] == 0 and blocks[-1][1] == n
            assert all(b[1] == c[0] for b, c in zip(blocks, blocks[1:], strict=False))  # contiguous, in order
            sizes = [b - a for a, b in blocks]
            assert min(sizes) >= 1 and max(sizes) - min(sizes) <= 1 and sizes == sorted(sizes, reverse=True)
    assert split_batches(10, 4) == [(0, 3), (3, 6), (6, 8), (8, 10)]
    with pytest.raises(ValueError, match="n_maps"):
        split_batches(0, 2)
    # the suite of bench_sweep: 2 jobs of 20 maps on 2 actors -> 8 blocks of 5, 4 per job, jobs in order
    plan = plan_batches([20, 20], n_actors=2)
    assert plan == [(j, a, a + 5) for j in (0, 1) for a in range(0, 20, 5)]
    # many small jobs: at least one block each, about 4 per actor in all, every map exactly once
    plan = plan_batches([3, 1, 2, 5, 4], n_actors=2)
    assert plan[:3] == [(0, 0, 2), (0, 2, 3), (1, 0, 1)]  # ceil(8 / 5) = 2 blocks per job
    for j, n in enumerate([3, 1, 2, 5, 4]):
        maps = [i for jj, a, b in plan if jj == j for i in range(a, b)]
        assert maps == list(range(n))
    assert plan_batches([], 2) == []


def test_merge_results_stacks_maps_in_order() -> None:
    """Per-map results are stacked along the episode axis in map order; seed and n_maps are the whole's."""
    from digslam.agents.evaluation.evaluate import EvalResult

    def part(v: float) -> EvalResult:
        one = {"a": np.full((1, 3), v)}
        return EvalResult(one, one, {"a": np.array([v])}, {"a": np.array([v])}, {"a": np.array([2.0])},
                          ENV, 7 + int(v), 1)  # fmt: skip

    res = merge_results({"a": [part(0.0), part(1.0), part(2.0)]}, seed=7, n_maps=3)
    np.testing.assert_array_equal(res.curves["a"][:, 0], [0.0, 1.0, 2.0])
    np.testing.assert_array_equal(res.collisions["a"], [0.0, 1.0, 2.0])
    assert (res.seed, res.n_maps, res.env_id) == (7, 3, ENV)


def test_specs_are_checked_before_starting_ray() -> None:
    assert normalize_specs(["frontier"]) == {"frontier": "frontier"}
    with pytest.raises(ValueError, match="policies_spec"):
        normalize_specs({"x": "nope"})
    with pytest.raises(ValueError, match="policies_spec"):
        evaluate_ray({}, n_maps=1)
    with pytest.raises(ValueError, match="n_maps"):
        evaluate_ray(["frontier"], n_maps=0)
    with pytest.raises(ValueError, match="spec"):
        build_policy("missing_model.zip", ENV, SMALL)


def test_sweep_config_rejects_unknown_and_bad_keys(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['trials'\]"):
        SweepConfig.from_dict({"trials": 2})
    with pytest.raises(ValueError, match="TrainConfig: unknown key"):
        SweepConfig.from_dict({"base": {"n_env": 2}})
    with pytest.raises(ValueError, match="space: unknown or fixed TrainConfig key 'lr'"):
        SweepConfig.from_dict({"space": {"lr": {"grid": [1e-3]}}})
    with pytest.raises(ValueError, match="space: unknown or fixed TrainConfig key 'seed'"):
        SweepConfig.from_dict({"space": {"seed": {"grid": [1, 2]}}})
    with pytest.raises(ValueError, match="space.gamma"):
        SweepConfig.from_dict({"space": {"gamma": {"normal": [0.9, 0.99]}}})
    with pytest.raises(ValueError, match="loguniform needs low > 0"):
        SweepConfig.from_dict({"space": {"learning_rate": {"loguniform": [0.0, 1e-3]}}})
    with pytest.raises(ValueError, match="metric"):
        SweepConfig.from_dict({"metric": "reward"})
    with pytest.raises(ValueError, match="cpus_per_trial"):
        SweepConfig.from_dict({"cpus_per_trial": 0})
    cfg = SweepConfig.from_dict({"space": {"env_kwargs": {"map_size": {"choice": [36, 40]}}}, "seeds": [3]})
    assert cfg.space_keys() == ["env_kwargs.map_size", "seed"]
    assert dataclasses.is_dataclass(cfg) and cfg.__dataclass_params__.frozen


@needs_tune
def test_example_sweep_file_and_cli(tmp_path: Path) -> None:
    example = Path(__file__).resolve().parents[3] / "agents" / "configs" / "sweep_example.toml"
    cfg = SweepConfig.from_file(example)
    assert Path(cfg.base).is_absolute() and cfg.base_config().progress_bar is False
    assert set(cfg.param_space()) == {"learning_rate", "ent_coef", "seed"}
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers(dest="command")
    add_sweep_cli(sub)
    ev = sub.add_parser("evaluate")
    ev.add_argument("--agents", nargs="+", default=["frontier"])
    handler = add_eval_cli(ev)
    args = parser.parse_args(["sweep", str(example), "--address", "auto", "--resume"])
    assert (args.config, args.address, args.resume, callable(args.func)) == (str(example), "auto", True, True)
    args = parser.parse_args(["evaluate", "--ray", "--address", "auto"])
    assert args.ray and args.address == "auto" and args.ray_evaluate is handler


def test_evaluate_ray_handler_on_the_cli_parser(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """``add_ray_options`` on the real ``digslam evaluate`` parser: ``--ray`` turns the parsed agents into specs
    (``ppo`` -> the ``--model`` path with its sidecar's env keywords) for ``evaluate_ray``."""
    import json

    import digslam.agents.evaluation.ray_eval as ray_eval
    from digslam.agents.cli.main import build_parser

    parser = build_parser()  # ``digslam evaluate`` carries the ``--ray`` options of ``add_ray_options``
    model = tmp_path / "m.zip"
    model.write_bytes(b"")
    model.with_suffix(".json").write_text(json.dumps({"env_kwargs": {"map_size": 40, "fixed_world": True}}))
    calls: list[tuple[dict, dict]] = []
    monkeypatch.setattr(ray_eval, "evaluate_ray", lambda specs, **kw: calls.append((specs, kw)) or "result")
    args = parser.parse_args(["evaluate", "--ray", "--address", "auto", "--agents", "ppo", "frontier",
                              "--model", str(model), "--maps", "3", "--steps", "50", "--seed", "7"])  # fmt: skip
    handler = args.ray_evaluate
    assert handler(args) == "result"
    specs, kw = calls[0]
    assert specs == {"ppo": str(model), "frontier": "frontier"}
    assert kw == {"env_id": ENV, "n_maps": 3, "seed": 7, "steps": 50, "env_kwargs": {"map_size": 40},
                  "address": "auto", "num_cpus": None}  # fmt: skip
    with pytest.raises(ValueError, match="only with --ray"):
        handler(parser.parse_args(["evaluate", "--address", "auto"]))


@pytest.mark.expensive
@needs_tune
def test_tiny_sweep_end_to_end(tmp_path: Path) -> None:
    """2 trials (two learning rates) of 256 timesteps on a local Ray instance with 2 CPUs: the table,
    the CSV, the trials' models; resuming the finished sweep gives the same table."""
    base = {"n_envs": 1, "total_timesteps": 256, "n_steps": 128, "batch_size": 64, "n_epochs": 1,
            "features_dim": 32, "eval_freq": 128, "eval_maps": 1, "checkpoint_freq": 0,
            "env_kwargs": {"map_size": 36, "crop": 4.0, "max_episode_steps": 30}}  # fmt: skip
    cfg = SweepConfig.from_dict({"name": "tiny", "base": base, "storage_path": str(tmp_path), "seeds": [0],
                                 "space": {"learning_rate": {"grid": [1e-4, 3e-4]}}, "eval_steps": 30})  # fmt: skip
    table, csv_path = run_sweep(cfg, num_cpus=2)
    lines = table.splitlines()
    assert lines[0].startswith("| trial | learning_rate | seed | best_certified")
    assert len(lines) == 4  # header, rule, 2 trials
    rows = list(csv.DictReader(csv_path.open()))
    assert csv_path == tmp_path / "tiny" / "results.csv" and len(rows) == 2
    assert sorted(float(r["learning_rate"]) for r in rows) == [1e-4, 3e-4]
    for r in rows:
        assert r["status"] == "done" and int(r["timesteps"]) == 256 and int(r["evals"]) == 2
        assert 0.0 < float(r["best_certified"]) <= 1.0
        assert (tmp_path / "tiny" / "models" / r["trial"] / "final_model.zip").is_file()
    with pytest.raises(ValueError, match="already exists"):
        run_sweep(cfg, num_cpus=2)
    again, _ = run_sweep(cfg, resume=True, num_cpus=2)
    assert again == table


def test_benchmark_agents_ray_flags_reach_the_script(monkeypatch: pytest.MonkeyPatch) -> None:
    """``digslam benchmark agents --ray --address A --workers N`` runs bench_agents.py with those arguments,
    which its parser accepts (``--address``/``--workers`` only with ``--ray``)."""
    import subprocess
    import sys

    from digslam.agents.cli import commands
    from digslam.agents.cli.main import build_parser

    args = build_parser().parse_args(["benchmark", "agents", "--quick", "--ray", "--address", "auto",
                                      "--workers", "2"])  # fmt: skip
    calls: list[list[str]] = []
    monkeypatch.setattr(commands.subprocess, "call", lambda cmd: calls.append(cmd) or 0)
    assert commands.cmd_benchmark(args) == 0
    assert calls[0][0] == sys.executable and calls[0][1].endswith("bench_agents.py")
    assert calls[0][2:] == ["--quick", "--ray", "--address", "auto", "--workers", "2"]
    out = subprocess.run([sys.executable, calls[0][1], "--workers", "2"], capture_output=True, text=True)
    assert out.returncode == 2 and "only with --ray" in out.stderr
