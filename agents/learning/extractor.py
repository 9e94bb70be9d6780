"""``MapStateExtractor``: an SB3 features extractor sized from the ``DigCoverage`` observation space.

The observation of :class:`~digslam.envs.dig_coverage.wrapper.GuaranteedObserver` is a ``Dict`` with a
``"map"`` image ``(C, m, m)`` (4 channels, or 7 with an egocentric crop) and a ``"state"`` vector, laid out
by :mod:`digslam.envs.observation` (:func:`~digslam.envs.observation.observation_space`).
The image goes through stride-2 convolutions (as many as it takes to bring the side down to at most 8
pixels, so any side from 36 upwards works), the state through a small MLP, and both are fused into
``features_dim`` features. SB3 has already scaled the ``uint8`` image to ``[0, 1]``.

>>> import torch
>>> from digslam.envs.observation import N_STATE, observation_space
>>> ext = MapStateExtractor(observation_space(36, crop=True), features_dim=64)
>>> ext({"map": torch.zeros(2, 7, 36, 36), "state": torch.zeros(2, N_STATE)}).shape
torch.Size([2, 64])
"""

from __future__ import annotations

import gymnasium as gym
import torch
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn


def conv_plan(side: int, target: int = 8) -> list[tuple[int, int]]:
    """``(kernel, stride)`` of the convolutions for an image of side ``side``: 3x3 stride 2 until the side
    is at most ``target`` (a 5x5 first layer when the side is large), then one 3x3 stride 1."""
    if side < 3:
        raise ValueError(f"side: the map must be at least 3 pixels wide, got {side}")
    plan: list[tuple[int, int]] = []
    s = side
    while s > target:
        k = 5 if not plan and s >= 48 else 3
        plan.append((k, 2))
        s = (s - k) // 2 + 1
    plan.append((3, 1) if s >= 3 else (1, 1))
    return plan


class MapStateExtractor(BaseFeaturesExtractor):
    """CNN on ``"map"`` plus MLP on ``"state"``, fused into ``features_dim`` features.

    Args:
        observation_space: ``Dict`` with ``"map"`` (``Box`` of shape ``(C, m, m)``) and ``"state"``.
        features_dim: Size of the output features.
        channels: Filters of the first convolution (doubled once after it, capped at ``4 * channels``).
        state_dim: Width of the state MLP.
    """

    def __init__(
        self,
        observation_space: gym.spaces.Dict,
        features_dim: int = 128,
        channels: int = 16,
        state_dim: int = 64,
    ) -> None:
        if not isinstance(observation_space, gym.spaces.Dict) or not {"map", "state"} <= set(
            observation_space.spaces
        ):
            raise ValueError(
                f"observation_space: need a Dict with 'map' and 'state', got {observation_space!r}"
            )
        shape = observation_space["map"].shape or ()
        if len(shape) != 3 or shape[1] != shape[2]:
            raise ValueError(f"observation_space: 'map' must have shape (C, m, m), got {shape}")
        if not isinstance(features_dim, int) or features_dim < 1:
            raise ValueError(f"features_dim: must be a positive integer, got {features_dim!r}")
        super().__init__(observation_space, features_dim)
        c_in, side = int(shape[0]), int(shape[1])
        layers: list[nn.Module] = []
        c = c_in
        for i, (k, s) in enumerate(conv_plan(side)):
            c_out = min(channels * (2 if i else 1), 4 * channels)
            layers += [nn.Conv2d(c, c_out, k, stride=s), nn.ReLU()]
            c = c_out
        layers.append(nn.Flatten())
        self.cnn = nn.Sequential(*layers)
        with torch.no_grad():
            n_flat = int(self.cnn(torch.zeros(1, c_in, side, side)).shape[1])
        n_state = int((observation_space["state"].shape or (0,))[0])
        self.state_mlp = nn.Sequential(nn.Linear(n_state, state_dim), nn.ReLU())
        self.head = nn.Sequential(nn.Linear(n_flat + state_dim, features_dim), nn.ReLU())

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        m = self.cnn(observations["map"].float())
        s = self.state_mlp(observations["state"].float())
        return self.head(torch.cat([m, s], dim=1))


__all__ = [
    "MapStateExtractor",
    "conv_plan",
]
