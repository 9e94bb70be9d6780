"""``digslam record --format mcap|sqlite3|bag``: the episode as a ROS bag plus ``bounds.toml``; read back, each
reading's interval holds the env's own interval (so the truth) and exceeds it by the float32 rounding and
the bounds file's pad only; so does the pymunk odometry increment (``mean_velocity``), carried by the pose."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from digslam.agents.cli import main as cli
from digslam.envs.explore.episode import Episode

pytest.importorskip("rosbags")
bag = pytest.importorskip("digslam.observer.record.bag")
ARGS = ["record", "--agent", "frontier", "--steps", "8", "--seed", "3", "--no-progress"]


@pytest.fixture(scope="module")
def episode(tmp_path_factory: pytest.TempPathFactory) -> Episode:
    path = tmp_path_factory.mktemp("npz") / "ep.npz"
    assert cli.main([*ARGS, "--out", str(path)]) == 0
    return Episode.load(path)


@pytest.mark.parametrize("fmt,name", [("mcap", "ep"), ("bag", "ep.bag")])
def test_bag_holds_the_env_intervals(tmp_path: Path, fmt: str, name: str, episode: Episode, capsys) -> None:  # type: ignore[no-untyped-def]
    assert cli.main([*ARGS, "--format", fmt, "--out", str(tmp_path / "ep.npz")]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([name, "bounds.toml"])
    assert "bounds.toml" in capsys.readouterr().out
    log = bag.read_log(tmp_path / name, tmp_path / "bounds.toml")
    env, got = episode.records, log.records
    assert len(got) == len(env) and got.n_sensors == env.n_sensors
    assert np.allclose(got.t, env.t, rtol=0, atol=1e-9)
    assert np.array_equal(got.no_echo, env.no_echo)
    echo = ~env.no_echo
    lo, hi = env.range[..., 0][echo], env.range[..., 1][echo]
    g_lo, g_hi = got.range[..., 0][echo], got.range[..., 1][echo]
    assert np.all(g_lo <= lo) and np.all(hi <= g_hi)
    slack = 2 * np.spacing(np.float32(hi)).astype(np.float64) + 1e-8  # float32 neighbours plus the pad
    assert np.all(lo - g_lo <= slack) and np.all(g_hi - hi <= slack)
    assert np.allclose(got.alpha[0], env.alpha[0], rtol=0, atol=1e-15) and np.array_equal(
        got.gamma, env.gamma
    )
    for f in ("speed", "yaw_rate", "heading"):
        a, b = getattr(env, f)[1:], getattr(got, f)[1:]
        assert np.all(b[:, 0] <= a[:, 0]) and np.all(a[:, 1] <= b[:, 1]), f
    # pymunk (the default): the increment, on the pose (source = "pose"), as tight as the env's but the pad
    assert episode.config.dynamics == "pymunk" and np.isfinite(env.mean_velocity).all()
    a, b = env.mean_velocity[1:], got.mean_velocity[1:]
    assert np.all(b[..., 0] <= a[..., 0]) and np.all(a[..., 1] <= b[..., 1])
    assert np.max((b[..., 1] - b[..., 0]) - (a[..., 1] - a[..., 0])) <= 1e-8  # 2 x the 1e-9 pad, and err
    assert np.array_equal(log.x0_lo, episode.truth.pose[0]) and np.array_equal(
        log.x0_hi, episode.truth.pose[0]
    )


def test_refuses_to_overwrite(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    (tmp_path / "bounds.toml").write_text("")
    assert cli.main([*ARGS, "--format", "sqlite3", "--out", str(tmp_path / "ep")]) == 2
    err = capsys.readouterr().err
    assert "bounds.toml: exists already" in err and len(err.strip().splitlines()) == 1
