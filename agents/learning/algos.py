"""The learning algorithm of a :class:`~.train_config.TrainConfig`: a new stable-baselines3 model, or a
saved one to continue.

:func:`build_model` gives SB3's ``PPO("MultiInputPolicy")`` with the map-state extractor
(:class:`~.extractor.MapStateExtractor`), or with ``algo = "maskable_ppo"`` sb3-contrib's ``MaskablePPO`` on
the goal-selection envs (:func:`build_maskable`: the attention policy or an MLP, its logits started from the
frontier heuristic's ranking). :func:`load_model` reads a saved model of the same algorithm. Torch,
stable-baselines3 and sb3-contrib are imported inside these functions.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from gymnasium import spaces

from digslam.agents.learning.train_config import TrainConfig

if TYPE_CHECKING:  # stable-baselines3 is imported on use only
    from stable_baselines3.common.base_class import BaseAlgorithm
    from stable_baselines3.common.vec_env import VecEnv


def ppo_kwargs(cfg: TrainConfig, tensorboard_log: str | None) -> dict[str, Any]:
    """The PPO hyperparameters of ``cfg`` that PPO and MaskablePPO share."""
    return {"learning_rate": cfg.learning_rate, "n_steps": cfg.n_steps, "batch_size": cfg.batch_size,
            "n_epochs": cfg.n_epochs, "gamma": cfg.gamma, "ent_coef": cfg.ent_coef,
            "tensorboard_log": tensorboard_log, "seed": cfg.seed, "device": cfg.device,
            "verbose": cfg.verbose}  # fmt: skip


def build_maskable(cfg: TrainConfig, env: VecEnv, tensorboard_log: str | None = None) -> BaseAlgorithm:
    """sb3-contrib's ``MaskablePPO`` of ``cfg`` on the vectorized goal-selection ``env``, its logits started
    from the heuristic's ranking (``cfg.heuristic_prior``): with ``policy = "attention"``
    :class:`~.attention.CandidateAttentionPolicy` (``d = features_dim``), else an MLP on the flattened
    candidate features and globals (``MultiInputPolicy``) whose output bias carries the prior."""
    import torch
    from sb3_contrib import MaskablePPO

    if cfg.policy == "attention":
        from digslam.agents.learning.attention import CandidateAttentionPolicy

        heads = 4 if cfg.features_dim % 4 == 0 else 1
        kw = {"d": cfg.features_dim, "heads": heads, "heuristic_prior": cfg.heuristic_prior}
        ppo = ppo_kwargs(cfg, tensorboard_log)
        return MaskablePPO(CandidateAttentionPolicy, env, policy_kwargs=kw, **ppo)
    arch = {"pi": [cfg.features_dim, 64], "vf": [cfg.features_dim, 64]}
    model = MaskablePPO(
        "MultiInputPolicy", env, policy_kwargs={"net_arch": arch}, **ppo_kwargs(cfg, tensorboard_log)
    )
    if cfg.heuristic_prior:
        space = env.action_space
        if not isinstance(space, spaces.Discrete):
            raise ValueError(f"heuristic_prior: needs the goal envs' Discrete actions, got {space}")
        n = int(space.n)
        head: Any = model.policy.action_net
        with torch.no_grad():
            head.weight.mul_(0.01)  # start from the prior, not from the random projection
            head.bias.copy_(torch.tensor([cfg.heuristic_prior * (1.0 - k / n) for k in range(n)]))
    return model


def load_model(
    cfg: TrainConfig, path: Path, env: VecEnv, tensorboard_log: str | None = None
) -> BaseAlgorithm:
    """The model saved at ``path`` (``cfg.algo``'s class) on ``env``, to continue training."""
    algo: type[BaseAlgorithm]
    if cfg.algo == "maskable_ppo":
        from sb3_contrib import MaskablePPO

        algo = MaskablePPO
    else:
        from stable_baselines3 import PPO

        algo = PPO
    return algo.load(path, env=env, device=cfg.device, tensorboard_log=tensorboard_log)


def build_model(cfg: TrainConfig, env: VecEnv, tensorboard_log: str | None = None) -> BaseAlgorithm:
    """The model of ``cfg`` on the vectorized ``env``: PPO with the map-state extractor, or
    :func:`build_maskable` with ``algo = "maskable_ppo"``."""
    if cfg.algo == "maskable_ppo":
        return build_maskable(cfg, env, tensorboard_log)
    from stable_baselines3 import PPO

    from digslam.agents.learning.extractor import MapStateExtractor

    policy_kwargs = {
        "features_extractor_class": MapStateExtractor,
        "features_extractor_kwargs": {"features_dim": cfg.features_dim},
        "net_arch": {"pi": [64], "vf": [64]},
    }
    return PPO("MultiInputPolicy", env, policy_kwargs=policy_kwargs, **ppo_kwargs(cfg, tensorboard_log))


__all__ = ["build_maskable", "build_model", "load_model", "ppo_kwargs"]
