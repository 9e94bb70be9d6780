"""The map predictor end to end: ``digslam train`` on a tiny configuration, then ``demo`` and ``evaluate``
with the predictive agent; the shipped predictor's smoke check of learning."""

from __future__ import annotations

import json
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("torch")

from digslam.agents.prediction.fit import PredictorConfig, is_predictor_config  # noqa: E402
from digslam.agents.prediction.model import SHIPPED, load  # noqa: E402

CONFIG = Path(__file__).resolve().parents[3] / "agents" / "configs" / "map_predictor.toml"
BUILDINGS = CONFIG.with_name("map_predictor_buildings.toml")


def _digslam(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "digslam.agents.cli.main", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=600)  # fmt: skip


def test_the_shipped_config_is_a_predictor_config():
    assert is_predictor_config(CONFIG)
    cfg = PredictorConfig.from_file(CONFIG, ["epochs=3"])
    assert cfg.epochs == 3 and cfg.kind == "map_predictor"
    with pytest.raises(ValueError, match="unknown"):
        PredictorConfig.from_file(CONFIG, ["epoch=3"])


def test_the_shipped_weights_come_from_the_buildings_stage():
    """Stage 2 (``map_predictor_buildings.toml``) fine-tunes stage 1 (``map_predictor.toml``) with the
    floorplan training windows; the shipped sidecar holds the same settings."""
    stage2 = PredictorConfig.from_file(BUILDINGS)
    assert stage2.init == PredictorConfig.from_file(CONFIG).out_dir + "/map_predictor.pt"
    assert "floorplan" in stage2.generators
    assert "floorplan" not in PredictorConfig.from_file(CONFIG).generators
    meta = json.loads(SHIPPED.with_suffix(".json").read_text())
    same = ("generators", "train_levels", "val_levels", "episode_steps", "snapshot_every", "width", "epochs",
            "batch_size", "lr", "clear_weight", "seed")  # fmt: skip
    assert {k: meta["config"][k] for k in same} == {k: getattr(stage2, k) for k in same}
    assert meta["epochs_done"] == stage2.epochs and meta["config"]["init"]


def test_tiny_training_then_demo_and_evaluate(tmp_path):
    tiny = ["generators=['room']", "train_levels=1", "val_levels=1", "episode_steps=60", "snapshot_every=30",
            "epochs=1", "batch_size=2", "progress=false", f"out_dir='{tmp_path / 'run'}'",
            f"data_dir='{tmp_path / 'data'}'"]  # fmt: skip
    res = _digslam("train", str(CONFIG), *tiny, cwd=tmp_path)
    assert res.returncode == 0, res.stderr[-2000:]
    weights = tmp_path / "run" / "map_predictor.pt"
    meta = json.loads(weights.with_suffix(".json").read_text())
    assert meta["train_levels"] == 1 and meta["epochs_done"] == 1 and meta["seed"] == 0
    assert {"predictor", "base_rate", "dilate"} <= set(meta["validation"]["all"])
    assert "digslam train" in meta["command"] and meta["wall_s"] > 0
    assert (tmp_path / "run" / "checkpoint.pt").is_file() and any((tmp_path / "run" / "tb").iterdir())
    again = _digslam("train", str(CONFIG), *tiny, cwd=tmp_path)  # resumes: the one epoch is done already
    assert again.returncode == 0 and "resuming after epoch 1" in again.stdout
    ckpt = tmp_path / "run" / "checkpoint.pt"
    good = ckpt.read_bytes()
    import torch

    torch.save({"net": Fraction(1, 3)}, ckpt)  # a pickled object: loaded with weights_only=True, refused
    bad = _digslam("train", str(CONFIG), *tiny, cwd=tmp_path)
    assert bad.returncode != 0 and "not a checkpoint of this trainer" in bad.stderr
    assert "Traceback" not in bad.stderr
    ckpt.write_bytes(good)
    demo = _digslam("demo", "--agent", "predictive_frontier", "--model", str(weights), "--steps", "40",
                    "--out", str(tmp_path / "demo"), cwd=tmp_path)  # fmt: skip
    assert demo.returncode == 0, demo.stderr[-2000:]
    assert (tmp_path / "demo" / "episode.gif").is_file()
    if SHIPPED.is_file():
        ev = _digslam("evaluate", "--agents", "predictive_frontier", "frontier", "--maps", "1", "--steps", "40",
                      "--out", str(tmp_path / "eval"), cwd=tmp_path)  # fmt: skip
        assert ev.returncode == 0, ev.stderr[-2000:]
        assert (
            "predictive_frontier" in json.loads((tmp_path / "eval" / "evaluation.json").read_text())["curves"]
        )


@pytest.mark.skipif(not SHIPPED.is_file(), reason="no shipped map predictor")
def test_the_shipped_predictor_continues_a_corridor():
    """A straight corridor seen up to a point (clear floor, penumbra walls): its unseen continuation is
    predicted free, more than the dark ground beside the corridor's walls."""
    img = np.zeros((4, 64, 64), np.uint8)
    img[2] = 255  # all dark
    for ch, rows in ((1, slice(27, 37)), (0, slice(29, 35))):
        img[:, rows, 4:30] = 0
        img[ch, rows, 4:30] = 255
    img[3, 31:33, 26:28] = 255  # the pose box near the seen end
    p, _ = load(SHIPPED).free(img)
    ahead = p[30:34, 32:40].mean()
    beside = np.concatenate([p[12:20, 32:40].ravel(), p[44:52, 32:40].ravel()]).mean()
    assert ahead > 0.5 and ahead > beside


def _tiny_config(tmp_path: Path, **kw: object) -> PredictorConfig:
    base = {"kind": "map_predictor", "generators": ["room"], "train_levels": 1, "val_levels": 1,
            "episode_steps": 60, "snapshot_every": 30, "epochs": 1, "batch_size": 2, "progress": False,
            "out_dir": str(tmp_path / "run"), "data_dir": str(tmp_path / "data"), "torch_threads": 1}  # fmt: skip
    return PredictorConfig.from_dict({**base, **kw})


def test_init_fine_tunes_the_given_weights(tmp_path):
    """``init`` starts the fit from saved weights: at a vanishing learning rate the result is those weights,
    not the fresh net the seed would draw."""
    import torch

    from digslam.agents.prediction.fit import fit
    from digslam.agents.prediction.model import MapUNet, save

    torch.manual_seed(123)
    start = save(MapUNet(2), tmp_path / "start" / "p.pt", {"note": "start"})
    fine = load(fit(_tiny_config(tmp_path, width=2, init=str(start), lr=1e-12))).net.state_dict()
    first = load(start).net.state_dict()
    fresh = load(fit(_tiny_config(tmp_path / "fresh", width=2, lr=1e-12))).net.state_dict()
    key = next(k for k in first if k.endswith("weight"))
    assert torch.allclose(fine[key], first[key], atol=1e-6)
    assert not torch.allclose(fresh[key], first[key], atol=1e-3)
    assert json.loads((tmp_path / "run" / "map_predictor.json").read_text())["config"]["init"] == str(start)


def test_init_of_another_width_or_no_file_fails_in_one_line(tmp_path):
    from digslam.agents.prediction.fit import fit
    from digslam.agents.prediction.model import MapUNet, save

    start = save(MapUNet(2), tmp_path / "start" / "p.pt", {})
    with pytest.raises(ValueError, match=r"init: .* has width 2, the config says width 3"):
        fit(_tiny_config(tmp_path, width=3, init=str(start)))
    with pytest.raises(ValueError, match="no map predictor there"):
        fit(_tiny_config(tmp_path, init=str(tmp_path / "none.pt")))
    assert not (tmp_path / "data").exists()  # refused before any snapshot was taken
    with pytest.raises(ValueError, match="init"):
        _tiny_config(tmp_path, init=3)
