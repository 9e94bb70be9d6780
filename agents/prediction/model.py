"""The map predictor: a small U-Net from the observer's map to the free probability of every pixel.

**Input** (:func:`inputs`): the observation's first four map channels (clear, penumbra, dark, pose-box
footprint, as 0/1) and two coordinate channels (row and column in ``[-1, 1]``: the world frame's border is
always a wall, and a fully convolutional net cannot see where it is without them). Nothing else: the
observation is all a run-time predictor reads.

**Output**: one logit per pixel; ``sigmoid`` of it is the probability that the pixel is certifiable
reachable free space (the training label, :mod:`.dataset`). The uncertainty is the **predicted variance of
that Bernoulli free indicator**, ``p (1 - p)``: with a calibrated ``p`` (measured by ECE in :mod:`.quality`)
it is the variance of what the sensors will find, which is what a gain estimate must discount. An ensemble
or MC dropout would add the model's own (epistemic) spread at several times the cost per prediction and per
training run on a 2-core CPU; the quality benchmark reports calibration so that the choice can be checked.

:class:`MapUNet` has four down- and up-sampling stages (``width`` to ``8 width`` channels) around an
``8 width`` bottleneck at 1/16 of the map side (its receptive field spans most of the map, which the
layout behind a frontier needs); narrow at full resolution, where most of a U-Net's time goes.
:class:`Predictor` wraps a trained net for the agents (``free(image) -> (p, var)``, numpy in and out, one
torch thread, no gradients); :func:`save` writes the weights with a JSON sidecar and :func:`load` reads them
back.

>>> import torch
>>> net = MapUNet()
>>> net(torch.zeros(2, N_INPUTS, 64, 64)).shape, sum(p.numel() for p in net.parameters()) < 2_000_000
(torch.Size([2, 64, 64]), True)
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from digslam.envs.observation import BASE_CHANNELS

#: Input channels of the net: the observation's clear, penumbra, dark and pose-box channels
#: (:data:`~digslam.envs.observation.BASE_CHANNELS` of :class:`~digslam.envs.observation.Channel`), then the
#: pixel's row and column coordinates in ``[-1, 1]``.
N_INPUTS = BASE_CHANNELS + 2
#: The net's coordinate input channels.
ROW, COL = BASE_CHANNELS, BASE_CHANNELS + 1
#: The shipped weights (their sidecar is the same name with ``.json``).
SHIPPED = Path(__file__).parents[1] / "data" / "map_predictor.pt"


def inputs(images: np.ndarray) -> np.ndarray:
    """``(N, 6, m, m)`` float32 net inputs of ``(N, C, m, m)`` uint8 maps (module docstring)."""
    img = np.asarray(images)
    if img.ndim == 3:
        img = img[None]
    n, _, m, _ = img.shape
    out = np.empty((n, N_INPUTS, m, m), dtype=np.float32)
    out[:, :BASE_CHANNELS] = img[:, :BASE_CHANNELS] > 127
    axis = (np.arange(m, dtype=np.float32) + 0.5) / m * 2.0 - 1.0
    out[:, ROW] = axis[None, :, None]
    out[:, COL] = axis[None, None, :]
    return out


def _torch() -> Any:
    try:
        import torch
    except ImportError:
        raise ImportError('the map predictor needs torch; pip install "digslam[train]"') from None
    return torch


def _module_base() -> Any:
    return _torch().nn.Module


class MapUNet(_module_base()):  # type: ignore[misc]  # torch's nn.Module, a base imported on use
    """U-Net of the map predictor (module docstring). ``width``: channels of the first stage."""

    def __init__(self, width: int = 8) -> None:
        torch = _torch()
        nn = torch.nn
        super().__init__()
        if not (isinstance(width, int) and width >= 1):
            raise ValueError(f"width: must be an integer >= 1, got {width!r}")
        self.width = width
        w = (width, 2 * width, 4 * width, 8 * width, 8 * width)

        def block(a: int, b: int) -> Any:
            layers = []
            for c in (a, b):
                layers += [nn.Conv2d(c, b, 3, padding=1), nn.BatchNorm2d(b), nn.ReLU(inplace=True)]
            return nn.Sequential(*layers)

        self.down = nn.ModuleList([block(N_INPUTS, w[0]), *(block(w[i], w[i + 1]) for i in range(3))])
        self.mid = block(w[3], w[4])
        self.up = nn.ModuleList([block(w[i + 1] + w[i], w[i]) for i in (3, 2, 1, 0)])
        self.head = nn.Conv2d(w[0], 1, 1)
        self.pool = nn.MaxPool2d(2, ceil_mode=True)

    def forward(self, x: Any) -> Any:
        torch = _torch()
        skips = []
        for d in self.down:
            x = d(x)
            skips.append(x)
            x = self.pool(x)
        x = self.mid(x)
        for u, s in zip(self.up, reversed(skips), strict=True):
            x = torch.nn.functional.interpolate(x, size=s.shape[-2:], mode="nearest")
            x = u(torch.cat([x, s], dim=1))
        return self.head(x)[:, 0]


class Predictor:
    """A trained :class:`MapUNet` as a map source (``free(image) -> (p, var)``), on the CPU.

    Args:
        net: The trained net (put in eval mode here).
        meta: Its sidecar (what :func:`save` wrote), kept as :attr:`meta`.
    """

    def __init__(self, net: Any, meta: dict[str, Any] | None = None) -> None:
        self.net, self.meta = net.eval(), dict(meta or {})

    def logits(self, images: np.ndarray) -> np.ndarray:
        """``(N, m, m)`` float32 logits of ``(N, C, m, m)`` (or one ``(C, m, m)``) uint8 maps, on one torch
        thread (the caller's thread count is restored after): a 64 x 64 map takes about 10 ms so, and
        torch's own pool of threads would spin against the other processes of a parallel evaluation."""
        torch = _torch()
        threads = torch.get_num_threads()
        torch.set_num_threads(1)
        try:
            with torch.inference_mode():
                return self.net(torch.from_numpy(inputs(images))).numpy()
        finally:
            torch.set_num_threads(threads)

    def free(self, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(p, p (1 - p))`` of one ``(C, m, m)`` uint8 map (float64 ``(m, m)`` each)."""
        p = 1.0 / (1.0 + np.exp(-self.logits(image)[0].astype(np.float64)))
        return p, p * (1.0 - p)


def save(net: Any, path: str | Path, meta: dict[str, Any]) -> Path:
    """Write ``net``'s weights to ``path`` and ``meta`` (plus ``width``) to its ``.json`` sidecar."""
    torch = _torch()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    torch.save(net.state_dict(), path)
    path.with_suffix(".json").write_text(json.dumps({**meta, "width": net.width}, indent=2) + "\n")
    return path


def load(path: str | Path) -> Predictor:
    """The :class:`Predictor` saved at ``path`` by :func:`save`.

    Raises:
        ValueError: a missing or unreadable file, saying which.
    """
    torch = _torch()
    path = Path(path)
    side = path.with_suffix(".json")
    if not path.is_file() or not side.is_file():
        raise ValueError(f"{path}: no map predictor there (weights and .json sidecar); train one with "
                         "`digslam train agents/configs/map_predictor.toml`")  # fmt: skip
    try:
        meta = json.loads(side.read_text())
        net = MapUNet(int(meta.get("width", 8)))
        net.load_state_dict(torch.load(path, map_location="cpu", weights_only=True))
    except Exception as exc:  # torch raises unpickling, runtime and key errors of its own for a bad file
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ValueError(f"{path}: not a map predictor saved by digslam ({first})") from None
    return Predictor(net, meta)


def load_shipped() -> Predictor:
    """The shipped map predictor (:data:`SHIPPED`)."""
    return load(SHIPPED)


__all__ = ["N_INPUTS", "SHIPPED", "MapUNet", "Predictor", "inputs", "load", "load_shipped", "save"]
