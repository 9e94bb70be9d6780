"""The saved models of a training run: atomic saves, their sidecars, the latest checkpoint to resume from.

Every model that :func:`~digslam.agents.learning.train.train` writes is saved by :func:`save_model` (to a
scratch file, then renamed: an interrupted save leaves no half-written model) with its sidecar
``<model>.json`` (:func:`write_sidecar`: the environment id and keywords it was trained with, which
:func:`~digslam.agents.learning.models.model_env_kwargs` reads back). :func:`latest_checkpoint` finds the
model of a run with the most timesteps (``resume = true``).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import TYPE_CHECKING

from digslam.agents.learning.train_config import TrainConfig

if TYPE_CHECKING:  # stable-baselines3 is imported on use only
    from stable_baselines3.common.base_class import BaseAlgorithm


def write_sidecar(path: Path, cfg: TrainConfig) -> Path:
    """Write ``<model>.json`` beside the model ``path``: the environment id and keywords it was trained
    with, which ``demo``, ``evaluate``, ``record`` and ``benchmark`` read
    (:func:`~digslam.agents.learning.models.model_env_kwargs`)."""
    side = path.with_suffix(".json")
    meta = {"env_id": cfg.env_id, "env_kwargs": dict(cfg.env_kwargs), "actions": cfg.actions}
    side.write_text(json.dumps(meta, indent=2))
    return side


def save_model(model: BaseAlgorithm, path: Path, cfg: TrainConfig) -> None:
    """``model.save`` to a scratch file, then renamed (an interrupted save leaves no half-written model),
    and its sidecar (:func:`write_sidecar`)."""
    tmp = path.with_name(f".{path.stem}.part{os.getpid()}.zip")
    try:
        model.save(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    write_sidecar(path, cfg)


def latest_checkpoint(out: str | Path) -> tuple[Path, int] | None:
    """The saved model of the run in ``out`` with the most timesteps, and that count: the checkpoints
    (``checkpoints/*.zip``) and ``interrupted_model.zip``; None when there is none."""
    from stable_baselines3.common.save_util import load_from_zip_file

    out = Path(out)
    best: tuple[Path, int] | None = None
    for path in [*sorted((out / "checkpoints").glob("*.zip")), out / "interrupted_model.zip"]:
        if not path.is_file():
            continue
        try:
            data, _, _ = load_from_zip_file(path, load_data=True, device="cpu")
            steps = int((data or {}).get("num_timesteps", -1))
        except Exception:  # noqa: BLE001 - a damaged file is not a checkpoint to resume from
            continue
        if steps >= 0 and (best is None or steps > best[1]):
            best = (path, steps)
    return best


__all__ = ["latest_checkpoint", "save_model", "write_sidecar"]
