"""Attention over the candidate goals: the goal-selection policy of ``algo = "maskable_ppo"``.

The goal-selection observation (:mod:`digslam.agents.goals`) is a *set* of candidates, each a row of
features, plus the decision's globals and a mask. An MLP on the flattened rows ties each weight to a slot;
here every candidate is scored by the same network, so a candidate means the same in any slot:

* :class:`CandidateAttentionExtractor`: each candidate's features through a shared MLP into a
  ``d``-vector, the globals through another, added to every candidate; then one transformer block
  (multi-head self-attention restricted to the valid candidates, then a feed-forward layer, both residual
  with layer norm), so that a candidate's score can depend on the others (ARiADNE's attention over
  neighbouring nodes). Its output is every candidate's vector, flattened, followed by the mean over the valid
  ones: ``features_dim = (n + 1) * d``.
* :class:`CandidateScorer`: the action logits, ``logit_k = w . h_k + b + prior_k``: one linear score per
  candidate vector ``h_k`` plus a per-slot bias that starts at the heuristic's ranking
  (``prior_k = heuristic_prior * (1 - k / n)``; the candidates come sorted by the frontier agent's cost, so
  with ``w`` started at 0.01 of its orthogonal init the untrained policy picks the frontier agent's goal).
  Masked slots are SB3-contrib's to remove.
* :class:`CandidateAttentionPolicy`: sb3-contrib's ``MaskableMultiInputActorCriticPolicy`` with the two
  above; the value head is an MLP on the whole feature vector.

>>> import numpy as np, torch
>>> from gymnasium import spaces
>>> space = spaces.Dict({"candidates": spaces.Box(-1, 1, (4, 3), np.float32), "mask": spaces.MultiBinary(4),
...                      "global": spaces.Box(-1, 1, (2,), np.float32)})
>>> ext = CandidateAttentionExtractor(space, d=8)
>>> obs = {"candidates": torch.zeros(2, 4, 3), "mask": torch.tensor([[1., 1, 0, 0]] * 2),
...        "global": torch.zeros(2, 2)}
>>> ext(obs).shape, ext.features_dim
(torch.Size([2, 40]), 40)
>>> CandidateScorer(4, 8, prior=2.0)(ext(obs)).shape
torch.Size([2, 4])
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np
import torch
from sb3_contrib.common.maskable.policies import MaskableMultiInputActorCriticPolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn


def _check_space(space: gym.spaces.Space) -> tuple[int, int, int]:
    """``(n, F, G)`` of a goal-selection observation space, or ValueError in one line."""
    keys = {"candidates", "mask", "global"}
    if not isinstance(space, gym.spaces.Dict) or not keys <= set(space.spaces):
        raise ValueError(f"observation_space: need a Dict with {sorted(keys)} (the goal-selection env's), "
                         f"got {space!r}")  # fmt: skip
    shape, mask, glob = (space[k].shape or () for k in ("candidates", "mask", "global"))
    if len(shape) != 2 or mask != (shape[0],) or len(glob) != 1:
        raise ValueError(f"observation_space: 'candidates' must be (n, F), 'mask' (n,) and 'global' (G,), "
                         f"got {shape}, {mask}, {glob}")  # fmt: skip
    return int(shape[0]), int(shape[1]), int(glob[0])


def rank_prior(n: int, strength: float) -> torch.Tensor:
    """``(n,)``: the heuristic's ranking as logits, ``strength * (1 - k / n)`` for slot ``k``."""
    return torch.tensor([strength * (1.0 - k / n) for k in range(n)], dtype=torch.float32)


class CandidateAttentionExtractor(BaseFeaturesExtractor):
    """Per-candidate vectors after one masked self-attention block, and their valid mean (module docstring).

    Args:
        observation_space: The goal-selection env's ``Dict`` (``"candidates"`` ``(n, F)``, ``"mask"``
            ``(n,)``, ``"global"`` ``(G,)``; other keys, e.g. ``"map"``, are not read).
        d: Width of a candidate's vector.
        heads: Attention heads (must divide ``d``).
    """

    def __init__(self, observation_space: gym.spaces.Dict, d: int = 64, heads: int = 4) -> None:
        n, f, g = _check_space(observation_space)
        if not (isinstance(d, int) and isinstance(heads, int) and d >= 1 and heads >= 1 and d % heads == 0):
            raise ValueError(f"d, heads: need positive integers with heads dividing d, got {d!r}, {heads!r}")
        super().__init__(observation_space, (n + 1) * d)
        self.n, self.d = n, d
        self.cand = nn.Sequential(nn.Linear(f, d), nn.ReLU(), nn.Linear(d, d))
        self.glob = nn.Sequential(nn.Linear(g, d), nn.ReLU(), nn.Linear(d, d))
        self.attn = nn.MultiheadAttention(d, heads, batch_first=True)
        self.norm1, self.norm2 = nn.LayerNorm(d), nn.LayerNorm(d)
        self.ff = nn.Sequential(nn.Linear(d, 2 * d), nn.ReLU(), nn.Linear(2 * d, d))

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        x = observations["candidates"].float()
        valid = observations["mask"].float() > 0.5
        valid = valid | ~valid.any(dim=1, keepdim=True)  # a row with no valid slot attends to all (no NaN)
        h = torch.relu(self.cand(x) + self.glob(observations["global"].float()).unsqueeze(1))
        a, _ = self.attn(h, h, h, key_padding_mask=~valid, need_weights=False)
        h = self.norm1(h + a)
        h = self.norm2(h + self.ff(h))
        w = valid.unsqueeze(-1).float()
        pooled = (h * w).sum(dim=1) / w.sum(dim=1)
        return torch.cat([h.flatten(1), pooled], dim=1)


class CandidateScorer(nn.Module):
    """Logits ``w . h_k + b + prior_k`` from :class:`CandidateAttentionExtractor`'s features (module
    docstring); ``prior`` is the heuristic's strength (0: no prior)."""

    def __init__(self, n: int, d: int, prior: float = 0.0) -> None:
        super().__init__()
        self.n, self.d = n, d
        self.score = nn.Linear(d, 1)
        self.slot_bias = nn.Parameter(rank_prior(n, prior))

    def forward(self, features: torch.Tensor) -> torch.Tensor:
        h = features[:, : self.n * self.d].reshape(-1, self.n, self.d)
        return self.score(h).squeeze(-1) + self.slot_bias


class CandidateAttentionPolicy(MaskableMultiInputActorCriticPolicy):
    """sb3-contrib's masked actor-critic with :class:`CandidateAttentionExtractor` and
    :class:`CandidateScorer` (module docstring). ``heuristic_prior`` is the scorer's starting slot bias;
    ``d`` and ``heads`` go to the extractor. ``MaskablePPO.load`` rebuilds it from the saved keywords."""

    def __init__(self, observation_space: gym.spaces.Dict, action_space: gym.spaces.Space,
                 lr_schedule: Callable[[float], float], *, d: int = 64, heads: int = 4,
                 heuristic_prior: float = 0.0, **kwargs: Any) -> None:  # fmt: skip
        if not np.isfinite(heuristic_prior) or heuristic_prior < 0:
            raise ValueError(f"heuristic_prior: must be finite and >= 0, got {heuristic_prior!r}")
        self.heuristic_prior = float(heuristic_prior)
        kwargs.setdefault("net_arch", {"pi": [], "vf": [64]})
        kwargs["features_extractor_class"] = CandidateAttentionExtractor
        kwargs["features_extractor_kwargs"] = {"d": d, "heads": heads}
        super().__init__(observation_space, action_space, lr_schedule, **kwargs)

    @property
    def attention(self) -> CandidateAttentionExtractor:
        """The features extractor (always a :class:`CandidateAttentionExtractor`)."""
        ext = self.features_extractor
        if not isinstance(ext, CandidateAttentionExtractor):
            raise TypeError(f"features_extractor: expected a CandidateAttentionExtractor, got {type(ext)}")
        return ext

    def _build(self, lr_schedule: Callable[[float], float]) -> None:
        super()._build(lr_schedule)
        ext = self.attention
        if self.mlp_extractor.latent_dim_pi != ext.features_dim:
            raise ValueError("net_arch: the actor must read the extractor's features as they are (pi=[])")
        scorer = CandidateScorer(ext.n, ext.d, self.heuristic_prior)
        nn.init.orthogonal_(scorer.score.weight, gain=0.01)
        nn.init.zeros_(scorer.score.bias)
        self.action_net = scorer
        # SB3 types optimizer_class as type[Optimizer], whose base takes no lr; its own _build passes lr too
        self.optimizer = self.optimizer_class(  # type: ignore[call-arg]
            self.parameters(), lr=lr_schedule(1), **self.optimizer_kwargs
        )

    def _get_constructor_parameters(self) -> dict[str, Any]:
        data = super()._get_constructor_parameters()
        ext = self.attention
        data.update(d=ext.d, heads=ext.attn.num_heads, heuristic_prior=self.heuristic_prior)
        data.pop("features_extractor_class", None)
        data.pop("features_extractor_kwargs", None)
        return data


__all__ = [
    "CandidateAttentionExtractor",
    "CandidateAttentionPolicy",
    "CandidateScorer",
    "rank_prior",
]
