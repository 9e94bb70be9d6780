"""The environments of a training run: spawn-safe factories, vectorized envs, torch thread pinning.

:class:`EnvFactory` is a picklable module-level object, so ``SubprocVecEnv`` workers started with ``spawn``
can build their env: it makes the id in the ``"<module>:<id>"`` form (:func:`env_module`: a fresh worker
imports the package that registers it), adds the training wrappers (:func:`~.wrappers.wrap_training_env`)
and SB3's ``Monitor``, and pins torch to ``torch_threads`` threads (:func:`pin_threads`: one thread is
several times faster on small machines). :func:`make_vec_env` builds ``n`` copies; :class:`SeedCycle` walks
the held-out maps of the evaluation callback.

>>> env_module("digslam/DigCoverageGoals-v0"), env_module("digslam/DigCoverage-v0")
('digslam.agents.goals', 'digslam.envs')
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import gymnasium as gym

from digslam.agents.learning.wrappers import wrap_training_env

if TYPE_CHECKING:  # stable-baselines3 is imported on use only
    from stable_baselines3.common.vec_env import VecEnv


def pin_threads(n: int) -> None:
    """Pin torch (and the BLAS/OpenMP pools of child processes) to ``n`` threads."""
    for var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
        os.environ[var] = str(n)
    import torch

    torch.set_num_threads(n)


def env_module(env_id: str) -> str:
    """The module that registers ``env_id`` (``gym.make("<module>:<id>")`` imports it first in a fresh
    worker): :mod:`digslam.agents.goals` for the goal-selection ids, else :mod:`digslam.envs`."""
    return "digslam.agents.goals" if env_id.split("/")[-1].startswith("DigCoverageGoals") else "digslam.envs"


class SeedCycle(gym.Wrapper):
    """Unseeded resets walk through ``seeds`` in turn (the held-out maps of the evaluation callback)."""

    def __init__(self, env: gym.Env, seeds: tuple[int, ...]) -> None:
        super().__init__(env)
        self.seeds, self.k = tuple(seeds), 0

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> Any:
        if seed is None:
            seed, self.k = self.seeds[self.k % len(self.seeds)], self.k + 1
        return self.env.reset(seed=seed, options=options)


@dataclass(frozen=True)
class EnvFactory:
    """Picklable environment factory for vectorized envs (``spawn``-safe).

    Args:
        env_id: Registered id; made as ``"<module>:<id>"`` (:func:`env_module`) so a fresh worker imports
            the package that registers it.
        env_kwargs: ``gym.make`` keyword arguments.
        torch_threads: Torch threads in the worker.
        seeds: If given, unseeded resets cycle through these seeds (held-out evaluation maps).
        actions, tube_penalty: The training wrappers (:func:`~.wrappers.wrap_training_env`).
    """

    env_id: str
    env_kwargs: Mapping[str, Any] = field(default_factory=dict)
    torch_threads: int = 1
    seeds: tuple[int, ...] | None = None
    actions: str = "continuous"
    tube_penalty: float = 0.0

    def __call__(self) -> gym.Env:
        from stable_baselines3.common.monitor import Monitor

        pin_threads(self.torch_threads)
        env_id = self.env_id if ":" in self.env_id else f"{env_module(self.env_id)}:{self.env_id}"
        env = gym.make(env_id, **dict(self.env_kwargs))
        env = wrap_training_env(env, self.actions, self.tube_penalty)
        if self.seeds:
            env = SeedCycle(env, self.seeds)
        return Monitor(env)


def make_vec_env(factory: EnvFactory, n: int, seed: int) -> VecEnv:
    """``n`` copies of ``factory``: a ``DummyVecEnv`` if ``n == 1``, else a spawn ``SubprocVecEnv``;
    env ``i`` is seeded ``seed + i``."""
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    fns: list[Callable[[], gym.Env]] = [factory] * n
    vec: VecEnv = DummyVecEnv(fns) if n == 1 else SubprocVecEnv(fns, start_method="spawn")
    vec.seed(seed)
    return vec


__all__ = ["EnvFactory", "SeedCycle", "env_module", "make_vec_env", "pin_threads"]
