"""The ``digslam`` command: help of every subcommand, demo at reduced length, record/replay round trip."""

from __future__ import annotations

import ast
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from digslam.agents.cli import commands
from digslam.agents.cli import main as cli
from digslam.agents.learning import models
from digslam.envs.explore.episode import Episode

SUBCOMMANDS = ["demo", "train", "evaluate", "record", "replay", "benchmark"]


def test_help_lists_every_subcommand(capsys) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(SystemExit) as exc:
        cli.main(["--help"])
    out = capsys.readouterr().out
    assert exc.value.code == 0 and all(c in out for c in SUBCOMMANDS)


@pytest.mark.parametrize("command", SUBCOMMANDS)
def test_each_subcommand_has_help(command: str, capsys) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(SystemExit) as exc:
        cli.main([command, "--help"])
    out = capsys.readouterr().out
    assert exc.value.code == 0 and f"digslam {command}" in out


def test_console_script_and_module_entry_points() -> None:
    exe = shutil.which("digslam")
    cmd = [exe, "--help"] if exe else [sys.executable, "-m", "digslam.agents.cli.main", "--help"]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
    assert res.returncode == 0 and "demo" in res.stdout and "usage: digslam" in res.stdout
    cmd = [sys.executable, "-W", "error::RuntimeWarning", "-m", "digslam.agents.cli.main", "--help"]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=60)  # no "found in sys.modules" warning
    assert res.returncode == 0 and "usage: digslam" in res.stdout and not res.stderr


def test_the_console_script_target_is_main(capsys) -> None:  # type: ignore[no-untyped-def]
    """The console script ``digslam`` is ``digslam.agents.cli.main:main``."""
    from importlib import metadata

    eps = [e for e in metadata.entry_points(group="console_scripts") if e.name == "digslam"]
    assert eps and eps[0].value == "digslam.agents.cli.main:main"
    with pytest.raises(SystemExit) as exc:
        eps[0].load()(["--help"])
    assert exc.value.code == 0 and "usage: digslam" in capsys.readouterr().out


def test_argparse_and_the_cli_only_inside_the_cli_folder() -> None:
    """No module of ``agents/`` outside ``agents/cli/`` imports argparse or ``digslam.agents.cli``, at module
    level or inside a function."""
    root = Path(cli.__file__).resolve().parents[1]
    bad = []
    for path in sorted(root.rglob("*.py")):
        if "cli" in path.relative_to(root).parts[:1]:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
            if isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            if any(n == "argparse" or n.startswith("digslam.agents.cli") for n in names):
                bad.append(f"{path.relative_to(root)}:{node.lineno}")
    assert not bad, bad


def test_demo_at_reduced_length(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("matplotlib")
    pytest.importorskip("digslam.agents.evaluation.evaluate")
    rc = cli.main(["demo", "--steps", "20", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert rc == 0 and (tmp_path / "episode.gif").stat().st_size > 0 and (tmp_path / "coverage.png").is_file()
    line = next(s for s in out.splitlines() if s.startswith("certified coverage"))
    assert 0.0 < float(line.split(":")[1].split()[0]) <= 1.0


def test_the_demo_runs_the_best_agent_of_the_shipped_leaderboard_and_says_which(
    tmp_path, capsys, monkeypatch
) -> None:  # type: ignore[no-untyped-def]
    """``--agent best`` (the demo's default) reads ``agents/data/leaderboard.json``; with a leaderboard that
    names another agent it runs that one, and with none (or a damaged one) the frontier agent."""
    best, why = models.best_agent()
    assert best in cli.agent_names() and best != "best" and "leaderboard" in why
    board = tmp_path / "board.json"
    board.write_text(json.dumps(models.leaderboard_record("lawnmower", 812.0, 30, 3000, ["room", "rocks"])))
    monkeypatch.setattr(models, "LEADERBOARD", board)
    name, policy, kwargs = cli.resolve_agent("best", cli.DEFAULT_ENV, None)
    assert name == "lawnmower" and kwargs == {} and type(policy).__name__ == "LawnmowerAgent"
    assert (
        "--agent best: lawnmower, best on the leaderboard (board.json: mean T_level 812 steps"
        in capsys.readouterr().out
    )
    board.write_text("{not json")
    assert models.best_agent()[0] == "frontier"
    assert cli.resolve_agent("best", cli.DEFAULT_ENV, None)[0] == "frontier"


def test_demo_falls_back_to_frontier_without_the_shipped_model(tmp_path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setattr(models, "PRETRAINED", tmp_path / "missing.zip")
    with pytest.warns(UserWarning, match="frontier"):
        name, policy, _ = cli.resolve_agent("ppo", cli.DEFAULT_ENV, None)
    assert name == "frontier" and hasattr(policy, "predict")


def test_a_named_model_that_cannot_load_is_an_error(tmp_path) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(cli.UserError, match="missing.zip: does not exist"):
        cli.resolve_agent("ppo", cli.DEFAULT_ENV, tmp_path / "missing.zip")


def test_record_replay_round_trip(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    path = tmp_path / "ep.npz"
    assert cli.main(["record", "--agent", "frontier", "--steps", "12", "--seed", "3", "--out", str(path),
                     "--no-progress"]) == 0  # fmt: skip
    ep = Episode.load(path)
    assert len(ep.actions) == 12 and ep.seed == 3 and ep.truth.pose.shape == (13, 3)
    assert cli.main(["replay", str(path), "--digslam", "--grid", "32", "--max-iter", "1"]) == 0
    out = capsys.readouterr().out
    assert "replay identical: True" in out and "truth inside the tube: True" in out
    ep.actions = -ep.actions  # a tampered episode no longer replays identically
    bad = tmp_path / "bad.npz"
    ep.save(bad)
    assert cli.main(["replay", str(bad)]) == 1 and "replay identical: False" in capsys.readouterr().out


def test_bad_arguments_are_reported(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    assert cli.main(["demo", "--steps", "0"]) == 2 and "--steps" in capsys.readouterr().err
    assert cli.main(["train", "n_envz=2"]) == 2 and "n_envz" in capsys.readouterr().err
    assert cli.main(["train", "n_envs=x"]) == 2 and "n_envs: must be int" in capsys.readouterr().err
    assert cli.main(["record", "--agent", "nobody", "--out", str(tmp_path / "x.npz")]) == 2
    assert "nobody" in capsys.readouterr().err


def test_benchmark_runs_scripts_or_explains(monkeypatch, capsys) -> None:  # type: ignore[no-untyped-def]
    assert cli.main(["benchmark", "no_such_bench"]) == 2
    assert "known:" in capsys.readouterr().err
    monkeypatch.setattr(commands, "benchmarks_dir", lambda: None)
    assert cli.main(["benchmark", "agents"]) == 2
    assert "source checkout" in capsys.readouterr().err


def test_the_leaderboards_predictive_agent_falls_back_to_frontier_without_torch(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """``--agent best`` naming ``predictive_frontier`` on an install without torch: one warning and the
    frontier agent, not a failure; named on its own it is an error of one line."""
    monkeypatch.setattr(models, "best_agent", lambda path=None: ("predictive_frontier", "best on the board"))
    monkeypatch.setitem(sys.modules, "torch", None)  # import torch raises ImportError
    with pytest.warns(UserWarning, match="needs torch"):
        name, policy, _ = cli.resolve_agent("best", cli.DEFAULT_ENV, None)
    assert name == "frontier" and type(policy).__name__ == "FrontierAgent"
    with pytest.raises(cli.UserError, match="predictive_frontier: the map predictor needs torch"):
        cli.resolve_agent("predictive_frontier", cli.DEFAULT_ENV, None)
