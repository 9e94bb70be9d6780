"""Every ``digslam`` subcommand on the inputs a user gets wrong: one line on stderr saying what was wrong
and what to do, exit status 2, no traceback, nothing written half-way."""

from __future__ import annotations

import importlib.util
import os
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

from digslam.agents.cli import main as cli

HAS_RAY = importlib.util.find_spec("ray") is not None


def run(capsys, *argv: str) -> str:  # type: ignore[no-untyped-def]
    """``main(argv)``: assert status 2, one stderr line, no traceback; return that line."""
    rc = cli.main(list(argv))
    out, err = capsys.readouterr()
    lines = [s for s in err.splitlines() if s.strip()]
    assert rc == 2, (rc, out, err)
    assert "Traceback" not in err + out
    assert len(lines) == 1, err
    assert lines[0].startswith(f"digslam {argv[0]}: ")
    return lines[0]


@pytest.fixture(scope="module")
def episode(tmp_path_factory) -> Path:  # type: ignore[no-untyped-def]
    path = tmp_path_factory.mktemp("ep") / "ep.npz"
    assert cli.main(["record", "--agent", "random", "--steps", "3", "--out", str(path), "--no-progress"]) == 0
    return path


# --- replay: every way an episode file can be wrong ----------------------------------------------------
def test_replay_missing_file(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    line = run(capsys, "replay", str(tmp_path / "nope.npz"))
    assert "no such file" in line and "digslam record" in line


def test_replay_directory(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    assert "is a folder" in run(capsys, "replay", str(tmp_path))


def test_replay_text_file(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = tmp_path / "notes.npz"
    p.write_text("hello")
    line = run(capsys, "replay", str(p))
    assert "not an .npz archive" in line and "pickle" not in line


def test_replay_truncated_file(capsys, episode, tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = tmp_path / "cut.npz"
    p.write_bytes(episode.read_bytes()[: episode.stat().st_size // 2])
    assert "give an episode .npz" in run(capsys, "replay", str(p))


def test_replay_bad_crc(capsys, episode, tmp_path) -> None:  # type: ignore[no-untyped-def]
    data = bytearray(episode.read_bytes())
    with zipfile.ZipFile(episode) as z:
        info = z.getinfo("config.npy")
    start = info.header_offset + 30 + len(info.filename) + len(info.extra) + 100
    data[start] ^= 0xFF
    p = tmp_path / "crc.npz"
    p.write_bytes(bytes(data))
    line = run(capsys, "replay", str(p))
    assert "not an episode" in line and ("damaged" in line or "CRC" in line)


def test_replay_foreign_npz(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = tmp_path / "foreign.npz"
    np.savez(p, x=np.arange(3))
    assert "no 'config' array" in run(capsys, "replay", str(p))


def test_replay_missing_key(capsys, episode, tmp_path) -> None:  # type: ignore[no-untyped-def]
    with np.load(episode) as z:
        data = {k: z[k] for k in z.files if k != "actions"}
    p = tmp_path / "partial.npz"
    np.savez(p, **data)
    assert "no 'actions' array" in run(capsys, "replay", str(p))


def test_replay_pickled_objects(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = tmp_path / "obj.npz"
    np.savez(p, config=np.array([{"a": 1}], dtype=object))
    assert "pickled objects" in run(capsys, "replay", str(p))


# --- environment ids and keys --------------------------------------------------------------------------
def test_unknown_env_id_lists_the_ids(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    line = run(capsys, "demo", "--env", "digslam/Nope-v0", "--out", str(tmp_path / "o"))
    assert "no such environment" in line and "digslam/DigCoverage-v0" in line and "Explore-v0" in line
    assert not (tmp_path / "o").exists()


def test_raw_env_id_says_which_envs_demo_takes(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    line = run(capsys, "demo", "--env", "digslam/Explore-v0", "--out", str(tmp_path))
    assert "takes the certified-coverage environments" in line and "crop" not in line


def test_record_wrong_env(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    run(capsys, "record", "--env", "CartPole-v1", "--out", str(tmp_path / "e.npz"))
    assert not (tmp_path / "e.npz").exists()


def test_train_unknown_env_kwarg_is_caught_before_workers(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    line = run(capsys, "train", "env_kwargs.map_sise=40", "n_envs=2", f"out_dir={tmp_path / 'run'}")
    assert "map_sise" in line and "map_size" in line and "ConnectionResetError" not in line
    assert not (tmp_path / "run").exists()


def test_train_unknown_key(capsys) -> None:  # type: ignore[no-untyped-def]
    assert "n_envz" in run(capsys, "train", "n_envz=2")


def test_train_bad_number(capsys) -> None:  # type: ignore[no-untyped-def]
    assert "total_timesteps: must be >= 1" in run(capsys, "train", "total_timesteps=0")


def test_train_missing_config(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    assert "no configuration file" in run(capsys, "train", str(tmp_path / "none.toml"))


def test_train_wrong_config_type(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = tmp_path / "c.yaml"
    p.write_text("n_envs: 2")
    assert ".toml or .json" in run(capsys, "train", str(p))


def test_train_unparsable_config(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = tmp_path / "c.toml"
    p.write_text("n_envs = = 2")
    assert "cannot read" in run(capsys, "train", str(p))


def test_train_raw_env(capsys) -> None:  # type: ignore[no-untyped-def]
    assert "env_id digslam/Explore-v0" in run(capsys, "train", 'env_id="digslam/Explore-v0"')


def test_train_unwritable_out_dir(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    f = tmp_path / "file"
    f.write_text("x")
    assert "out_dir" in run(capsys, "train", f"out_dir={f / 'run'}")


def test_dig_coverage_unknown_key_lists_what_can_be_passed() -> None:
    import gymnasium as gym

    import digslam.envs  # noqa: F401

    with pytest.raises(ValueError) as exc:
        gym.make("digslam/DigCoverage-v0", map_sise=36)
    msg = str(exc.value)
    assert all(k in msg for k in ("map_size", "crop", "target", "grid_cell", "monitor", "did you mean"))


# --- models and agents ---------------------------------------------------------------------------------
def test_demo_missing_model_is_an_error(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    line = run(capsys, "demo", "--model", "/nonexistent.zip", "--out", str(tmp_path / "o"))
    assert "/nonexistent.zip: does not exist" in line
    assert not (tmp_path / "o").exists()


def test_demo_model_not_a_zip(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = tmp_path / "m.zip"
    p.write_text("not a model")
    assert "not a PPO model" in run(capsys, "demo", "--model", str(p), "--out", str(tmp_path / "o"))


def test_unknown_agent(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    line = run(capsys, "evaluate", "--agents", "frontier", "nobody", "--out", str(tmp_path))
    assert "nobody" in line and "lawnmower" in line


def test_bad_numbers(capsys) -> None:  # type: ignore[no-untyped-def]
    assert "--maps must be >= 1" in run(capsys, "evaluate", "--maps", "0")
    assert "--seed must be >= 0" in run(capsys, "demo", "--seed", "-1")


# --- extras and outputs --------------------------------------------------------------------------------
@pytest.mark.skipif(HAS_RAY, reason="ray is installed")
def test_ray_missing_names_the_extra(capsys) -> None:  # type: ignore[no-untyped-def]
    assert 'pip install "digslam[ray]"' in run(capsys, "evaluate", "--ray")


@pytest.mark.skipif(HAS_RAY, reason="ray is installed")
def test_sweep_without_ray_names_the_extra(capsys) -> None:  # type: ignore[no-untyped-def]
    assert 'pip install "digslam[ray]"' in run(capsys, "sweep", "agents/configs/sweep_example.toml")


def test_unwritable_out(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    f = tmp_path / "file"
    f.write_text("x")
    assert "is a file, not a folder" in run(capsys, "demo", "--out", str(f / "sub"))
    assert "exists and is not a folder" in run(capsys, "evaluate", "--out", str(f))
    assert "is a folder" in run(capsys, "record", "--out", str(tmp_path))


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes anywhere")
def test_read_only_out(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    ro = tmp_path / "ro"
    ro.mkdir(mode=0o500)
    assert "permission denied" in run(capsys, "demo", "--out", str(ro / "o"))


def test_record_adds_the_suffix_it_writes(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    assert cli.main(["record", "--agent", "random", "--steps", "2", "--out", str(tmp_path / "ep"),
                     "--no-progress"]) == 0  # fmt: skip
    assert f"wrote {tmp_path / 'ep.npz'}" in capsys.readouterr().out
    assert [p.name for p in tmp_path.iterdir()] == ["ep.npz"]  # no scratch file left


# --- Ctrl-C during training --------------------------------------------------------------------------
def test_ctrl_c_during_train_keeps_a_checkpoint(tmp_path) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("stable_baselines3")
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "digslam.agents.cli.main", "train", "n_envs=1", "total_timesteps=1000000",
           "n_steps=64", "batch_size=32", "eval_freq=0", "checkpoint_freq=0", "progress_bar=false",
           'env_kwargs={map_size = 36, fixed_world = true}', f"out_dir={out}"]  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    # the TensorBoard folder appears when learn() starts (after the env is built and its kernels compiled,
    # which takes minutes on a fresh machine): interrupt only then
    deadline = time.monotonic() + 600
    while not (out / "tb").exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.5)
    time.sleep(5)  # into learn()
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=300)
    lines = [s for s in stderr.splitlines() if s.strip()]
    assert proc.returncode == 2, stderr
    assert "Traceback" not in stderr and len(lines) == 1, stderr
    assert "interrupted after" in lines[0] and "interrupted_model.zip" in lines[0]
    assert (out / "interrupted_model.zip").is_file()


# --- a source folder named digslam shadowing the installed package -------------------------------------
def test_shadowing_source_folder_is_reported_in_one_line(tmp_path) -> None:  # type: ignore[no-untyped-def]
    import shutil

    from digslam.observer.cache import origin

    if origin.installed_root() is None:
        pytest.skip("digslam is not installed")
    shutil.copytree(Path(cli.__file__).parents[1], tmp_path / "digslam" / "agents",
                    ignore=shutil.ignore_patterns("__pycache__", "data"))  # fmt: skip
    res = subprocess.run([sys.executable, "-c", "import digslam.agents"], cwd=tmp_path, capture_output=True,
                         text=True, timeout=60)  # fmt: skip
    lines = [s for s in res.stderr.splitlines() if s.strip()]
    assert res.returncode == 0 and len(lines) == 1, res.stderr
    assert "folder named digslam" in lines[0] and "not from the installed package" in lines[0]
    quiet = subprocess.run([sys.executable, "-c", "import digslam.agents"], cwd=Path(cli.__file__).parents[2],
                           capture_output=True, text=True, timeout=60)  # fmt: skip
    assert quiet.stderr.strip() == ""
