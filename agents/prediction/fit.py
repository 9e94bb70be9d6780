"""Training the map predictor end to end: snapshots, fit, validation, weights with their sidecar.

:class:`PredictorConfig` is read from TOML or JSON (``kind = "map_predictor"``, the key by which
``digslam train`` tells it from a PPO configuration) with ``key=value`` overrides
(:meth:`~digslam.observer.core.config.Config.from_file`). :func:`fit`:

1. writes the snapshots of ``train_levels`` training-split and ``val_levels`` validation-split levels of
   every generator under ``data_dir`` (:func:`.dataset.generate`: one file per level, resumable, in
   ``workers`` processes);
2. fits :class:`~.model.MapUNet` (a fresh one, or the weights of ``init``: fine-tuning) by weighted
   binary cross-entropy against the free share of each pixel (open pixels weigh 1, clear ones
   ``clear_weight``: they are known free), with random flips and quarter turns, AdamW and a cosine
   learning rate, ``epochs`` passes or ``max_minutes`` of wall time, whichever comes first; a checkpoint
   after every epoch (``out_dir/checkpoint.pt``; a rerun resumes from it, ``init`` or not), TensorBoard
   scalars under ``out_dir/tb`` and a progress bar;
3. scores the net on the validation snapshots (:mod:`.quality`) and writes ``out_dir/map_predictor.pt``
   with its sidecar: the command, the seed, the wall time, the data sizes and the validation figures.

``device = "auto"`` takes a GPU when torch sees one; nothing needs one.

>>> PredictorConfig.from_dict({"kind": "map_predictor", "epochs": 2}).epochs
2
"""

from __future__ import annotations

import math
import pickle
import sys
import time
from dataclasses import field
from pathlib import Path
from typing import Any

import numpy as np

from digslam.envs.observation import Channel
from digslam.observer.core.config import (
    Config,
    check,
    check_finite_pos,
    check_int,
    config_dataclass,
    read_config_file,
)

#: The value of ``kind`` that marks a map-predictor configuration.
KIND = "map_predictor"


def _generators() -> list[str]:
    """The procedural generators (:data:`digslam.envs.PROCEDURAL`): the data the shipped predictor was fitted
    on; floorplan windows join only when a config names them."""
    from digslam.envs import PROCEDURAL

    return list(PROCEDURAL)


@config_dataclass
class PredictorConfig(Config):
    """A map-predictor training run (module docstring).

    Attributes:
        kind: Always ``"map_predictor"``.
        out_dir: Where the weights, checkpoint and TensorBoard logs go.
        data_dir: Where the snapshots go (``train/`` and ``validation/``).
        generators: World generators of the levels.
        train_levels, val_levels: Levels per generator (the first of each split).
        episode_steps, snapshot_every: Low-level steps per episode and between snapshots.
        workers: Processes that write the snapshots (one level each at a time).
        width: Channels of the net's first stage.
        init: Weights to start from (a map predictor saved by :func:`.model.save` of the same ``width``, the
            shipped one for example): the fit then fine-tunes them on this run's snapshots; empty for a
            fresh net.
        epochs, batch_size, lr, weight_decay, clear_weight: The fit.
        max_minutes: Wall-time limit of the fit (the run stops after the epoch that passes it).
        seed: Seed of the net and of the batches.
        device: ``"auto"``, ``"cpu"`` or a torch device.
        torch_threads: Torch threads on the CPU.
        progress: Progress bars.
    """

    kind: str = KIND
    out_dir: str = "runs/map_predictor"
    data_dir: str = "runs/map_predictor/data"
    generators: list[str] = field(default_factory=_generators)
    train_levels: int = 200
    val_levels: int = 24
    episode_steps: int = 2000
    snapshot_every: int = 60
    workers: int = 1
    width: int = 8
    init: str = ""
    epochs: int = 8
    batch_size: int = 64
    lr: float = 2e-3
    weight_decay: float = 1e-4
    clear_weight: float = 0.1
    max_minutes: float = 100.0
    seed: int = 0
    device: str = "auto"
    torch_threads: int = 2
    progress: bool = True

    def __post_init__(self) -> None:
        from digslam.agents.evaluation.suite import check_generators

        check(self.kind == KIND, "kind", f'must be "{KIND}", got {self.kind!r}')
        check_generators(self.generators)
        for name in ("train_levels", "val_levels", "episode_steps", "snapshot_every", "workers", "width",
                     "epochs", "batch_size", "torch_threads"):  # fmt: skip
            check_int(name, getattr(self, name), 1)
        check(isinstance(self.init, str), "init", f"must be a path (a string), got {self.init!r}")
        check_int("seed", self.seed, 0)
        for name in ("lr", "max_minutes"):
            check_finite_pos(name, getattr(self, name))
        for name in ("weight_decay", "clear_weight"):
            v = getattr(self, name)
            check(
                isinstance(v, (int, float)) and math.isfinite(v) and v >= 0, name, f"must be >= 0, got {v!r}"
            )


def is_predictor_config(path: str | Path | None) -> bool:
    """Whether the configuration file at ``path`` says ``kind = "map_predictor"``."""
    if path is None or not Path(path).is_file():
        return False
    try:
        return read_config_file(path).get("kind") == KIND
    except ValueError:
        return False


def _device(name: str) -> Any:
    import torch

    if name == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(name)


def augment(maps: np.ndarray, labels: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """The same random quarter turn and flip of a batch of maps ``(B, C, m, m)`` and labels ``(B, m, m)``."""
    k = int(rng.integers(4))
    maps, labels = np.rot90(maps, k, axes=(2, 3)), np.rot90(labels, k, axes=(1, 2))
    if rng.random() < 0.5:
        maps, labels = maps[..., ::-1], labels[..., ::-1]
    return np.ascontiguousarray(maps), np.ascontiguousarray(labels)


def predict_all(net: Any, maps: np.ndarray, device: Any, batch: int = 256) -> np.ndarray:
    """``(N, m, m)`` free probabilities of ``(N, C, m, m)`` uint8 maps."""
    import torch

    from digslam.agents.prediction.model import inputs

    net.eval()
    out = []
    with torch.inference_mode():
        for i in range(0, len(maps), batch):
            x = torch.from_numpy(inputs(maps[i : i + batch])).to(device)
            out.append(torch.sigmoid(net(x)).cpu().numpy())
    return np.concatenate(out) if out else np.zeros((0, *maps.shape[2:]), np.float32)


def _data(cfg: PredictorConfig) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    from digslam.agents.prediction import dataset
    from digslam.envs.splits import seeds

    kw: dict[str, Any] = {
        "steps": cfg.episode_steps,
        "every": cfg.snapshot_every,
        "progress": cfg.progress,
        "workers": cfg.workers,
    }
    root = Path(cfg.data_dir)
    train = dataset.generate(root / "train", cfg.generators, seeds("train", cfg.train_levels), **kw)
    val = dataset.generate(root / "validation", cfg.generators, seeds("validation", cfg.val_levels), **kw)
    return dataset.load(train), dataset.load(val)


def fit(cfg: PredictorConfig, command: str | None = None) -> Path:
    """Run the whole training (module docstring); the path of the saved weights."""
    import torch

    from digslam.agents.prediction import model, quality

    t0 = time.time()
    torch.set_num_threads(cfg.torch_threads)
    device = _device(cfg.device)
    out = Path(cfg.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(cfg.seed)
    net = model.MapUNet(cfg.width)
    if cfg.init:  # read before the snapshots, so that a bad path fails at once
        start_from = model.load(cfg.init).net
        if start_from.width != cfg.width:
            raise ValueError(
                f"init: {cfg.init} has width {start_from.width}, the config says width "
                f"{cfg.width}; set width={start_from.width} or start from a fresh net (init='')"
            )
        net.load_state_dict(start_from.state_dict())
    net = net.to(device)
    train, val = _data(cfg)
    opt = torch.optim.AdamW(net.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    n = len(train["map"])
    per_epoch = max(n // cfg.batch_size, 1)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=cfg.lr, total_steps=cfg.epochs * per_epoch)
    ckpt, epoch, spent = out / "checkpoint.pt", 0, 0.0
    if ckpt.is_file():
        try:  # tensors and plain values only: a checkpoint from elsewhere cannot run code here
            state = torch.load(ckpt, map_location=device, weights_only=True)
        except pickle.UnpicklingError as exc:
            why = str(exc).splitlines()[0]
            raise ValueError(
                f"{ckpt}: not a checkpoint of this trainer (it holds more than tensors and "
                f"plain values: {why}); move it away to start afresh"
            ) from None
        net.load_state_dict(state["net"])
        opt.load_state_dict(state["opt"])
        sched.load_state_dict(state["sched"])
        epoch, spent = int(state["epoch"]), float(state["spent"])
        print(f"resuming after epoch {epoch} ({spent / 60:.1f} min spent)")
    from torch.utils.tensorboard import SummaryWriter

    writer = SummaryWriter(str(out / "tb"))
    start = time.time() - spent
    while epoch < cfg.epochs and (time.time() - start) < 60.0 * cfg.max_minutes:
        rng = np.random.default_rng((cfg.seed, epoch))
        order = rng.permutation(n)
        net.train()
        bar: Any = None  # a tqdm bar over the epoch's batches
        if cfg.progress:
            from tqdm.auto import tqdm

            bar = tqdm(range(per_epoch), desc=f"epoch {epoch + 1}/{cfg.epochs}", unit="batch")
        total = 0.0
        for b in bar if bar is not None else range(per_epoch):
            idx = np.sort(order[b * cfg.batch_size : (b + 1) * cfg.batch_size])
            maps, labels = augment(train["map"][idx], train["free"][idx], rng)
            x = torch.from_numpy(model.inputs(maps)).to(device)
            y = torch.from_numpy(labels).to(device)
            w = torch.where(x[:, int(Channel.CLEAR)] > 0.5, cfg.clear_weight, 1.0)
            loss = torch.nn.functional.binary_cross_entropy_with_logits(net(x), y, weight=w)
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            total += float(loss.detach())
            if bar is not None:
                bar.set_postfix(loss=f"{total / (b + 1):.4f}")
        epoch += 1
        writer.add_scalar("train/loss", total / per_epoch, epoch)
        p = predict_all(net, val["map"], device)
        s = quality.scores(p, val["free"], quality.open_pixels(val["map"]))
        for k in ("accuracy", "iou", "ece"):
            writer.add_scalar(f"validation/{k}", s[k], epoch)
        print(f"epoch {epoch}: loss {total / per_epoch:.4f}, validation iou {s['iou']:.4f} accuracy "
              f"{s['accuracy']:.4f} ece {s['ece']:.4f}", flush=True)  # fmt: skip
        torch.save({"net": net.state_dict(), "opt": opt.state_dict(), "sched": sched.state_dict(),
                    "epoch": epoch, "spent": time.time() - start}, ckpt)  # fmt: skip
    writer.close()
    p = predict_all(net, val["map"], device)
    rate = quality.base_rate(train["map"], train["free"])
    rep = quality.report(p, val["map"], val["free"], val["generator"], rate)
    meta = {"command": command or " ".join(sys.argv), "config": cfg.to_dict(), "seed": cfg.seed,
            "epochs_done": epoch, "wall_s": round(time.time() - t0, 1),
            "fit_s": round(time.time() - start, 1), "train_snapshots": int(n),
            "train_levels": int(train["level"].max() + 1), "val_snapshots": int(len(val["map"])),
            "base_rate": rate, "validation": rep,
            "parameters": int(sum(q.numel() for q in net.parameters()))}  # fmt: skip
    return model.save(net.cpu(), out / "map_predictor.pt", meta)


__all__ = ["KIND", "PredictorConfig", "augment", "fit", "is_predictor_config", "predict_all"]
