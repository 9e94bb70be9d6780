"""The contract of a policy: what evaluation, pictures, benchmarks and the command line call an agent.

A policy is any object with stable-baselines3's ``predict`` (:class:`PolicyPredictor`): the heuristic
baselines (:class:`~digslam.agents.baselines.policy.BaselinePolicy`), the goal-level agent
(:class:`~digslam.agents.goals.agent.GoalAgent`) and SB3's own models (``PPO``, ``MaskablePPO``). It takes
one observation ``{"map", "state"}`` of a certified-coverage env (or a VecEnv batch of them) and returns the
action and a recurrent state (None for every policy here). :func:`reset_policy` starts a new episode for
any of them. Where a policy must read the env it plays (the true-map diagnosis), a :data:`PolicyFactory`
builds it on that env.

>>> import numpy as np
>>> class Still:
...     def predict(self, observation, state=None, episode_start=None, deterministic=False):
...         return np.zeros(2, np.float32), None
>>> isinstance(Still(), PolicyPredictor)
True
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np

if TYPE_CHECKING:  # gymnasium for the types only
    import gymnasium as gym

#: An observation of a certified-coverage env: ``{"map": uint8 (C, m, m), "state": float32 (N_STATE,)}``, or
#: a VecEnv batch of them (a leading axis).
Observation = dict[str, np.ndarray]


@runtime_checkable
class PolicyPredictor(Protocol):
    """A policy that predicts (stable-baselines3's ``predict``): the action for ``observation`` and the
    recurrent state (None for a policy without one)."""

    def predict(
        self,
        observation: Observation,
        state: tuple[np.ndarray, ...] | None = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = False,
    ) -> tuple[np.ndarray, tuple[np.ndarray, ...] | None]: ...


#: A policy built on the env it plays (``evaluate`` calls it once with that env).
PolicyFactory = Callable[["gym.Env"], PolicyPredictor]


def reset_policy(policy: object) -> None:
    """Start a new episode: ``policy.reset()`` for a policy with per-episode state (a baseline, the goal
    agent, a goal chooser); nothing for a stable-baselines3 model (it has ``.policy`` and keeps no state
    between calls)."""
    reset = getattr(policy, "reset", None)
    if callable(reset) and not hasattr(policy, "policy"):
        reset()


__all__ = ["Observation", "PolicyFactory", "PolicyPredictor", "reset_policy"]
