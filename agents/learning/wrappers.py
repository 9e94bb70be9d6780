"""Training wrappers of the low-level PPO: discrete turn-or-go actions and a penalty on tube growth.

A continuous Gaussian policy whose mean leaves the action box acts, deterministically, unlike the clipped
samples it was trained on, and turning while driving widens the pose box until nothing more can be
certified. These wrappers make the deterministic policy the trained one and the tube's cost visible:

* :class:`TurnGoActions`: ``Discrete(len(TURN_GO))`` actions, each a fixed ``(v, ω)`` of the continuous
  space: drive straight (full or slow) or turn in place (either way, full or slow), the motion primitives
  of the frontier agent (:func:`digslam.agents.baselines.planning.turn_then_go`: an arc grows the pose box
  about 17 times faster than a straight line). A categorical policy's deterministic action, its mode, is
  one of the actions it was trained on.
* :class:`TubePenalty`: the reward less ``weight`` times the growth of the pose box's widest side over the
  step (m; ``info["pose_box"]``, the observer's claim, not ground truth).

:class:`TurnGoPolicy` lets a model trained on :class:`TurnGoActions` act in the continuous environment
(``demo``, ``evaluate``, ``record``, ``benchmark``): it maps the model's action indices through
:data:`TURN_GO`. :func:`~digslam.agents.learning.models.load_ppo` wraps a model whose action space is
discrete in it.

>>> import gymnasium as gym
>>> import digslam.envs
>>> env = TubePenalty(TurnGoActions(gym.make("digslam/DigCoverage-v0", map_size=36)), weight=10.0)
>>> env.action_space, TURN_GO[2].tolist()
(Discrete(6), [0.0, 1.0])
>>> obs, info = env.reset(seed=1)
>>> obs, reward, *_ = env.step(0)
>>> bool(np.isfinite(reward))
True
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np

if TYPE_CHECKING:  # stable-baselines3 is imported on use only
    from stable_baselines3.common.base_class import BaseAlgorithm

#: The discrete actions as normalised ``(v, ω)``: drive full, drive slow, turn left, turn right, turn left
#: slow, turn right slow.
TURN_GO = np.array(
    [[1.0, 0.0], [0.3, 0.0], [0.0, 1.0], [0.0, -1.0], [0.0, 0.3], [0.0, -0.3]],
    dtype=np.float32,
)

#: The action modes of :class:`~digslam.agents.learning.train_config.TrainConfig` (``actions``).
ACTION_MODES = ("continuous", "turn_go")


class TurnGoActions(gym.ActionWrapper):
    """``Discrete(6)`` actions mapped to the continuous ``(v, ω)`` of :data:`TURN_GO`."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self.action_space = gym.spaces.Discrete(len(TURN_GO))

    def action(self, action: Any) -> np.ndarray:
        a = int(np.asarray(action).reshape(()))
        if not 0 <= a < len(TURN_GO):
            raise ValueError(f"action: must be an integer in [0, {len(TURN_GO)}), got {action!r}")
        return TURN_GO[a].copy()


def tube_width(info: dict[str, Any]) -> float:
    """Widest side (m) of ``info["pose_box"]``; nan when there is none or it is not finite."""
    box = np.asarray(info.get("pose_box", np.full((2, 2), np.nan)), dtype=np.float64)
    return float(np.max(box[1] - box[0])) if np.all(np.isfinite(box)) else math.nan


class TubePenalty(gym.Wrapper):
    """Reward less ``weight`` times the growth (m) of the pose box's widest side over the step.

    Args:
        env: A certified-coverage environment (its ``info`` holds ``"pose_box"``).
        weight: Reward units per metre of growth (>= 0).
    """

    def __init__(self, env: gym.Env, weight: float) -> None:
        if not (math.isfinite(weight) and weight >= 0):
            raise ValueError(f"weight: must be finite and >= 0, got {weight!r}")
        super().__init__(env)
        self.weight = float(weight)
        self._tube = math.nan

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(**kwargs)
        self._tube = tube_width(info)
        return obs, info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        tube = tube_width(info)
        growth = tube - self._tube
        r = float(reward)
        if math.isfinite(growth) and growth > 0:
            r -= self.weight * growth
        self._tube = tube
        return obs, r, terminated, truncated, info


def wrap_training_env(env: gym.Env, actions: str = "continuous", tube_penalty: float = 0.0) -> gym.Env:
    """``env`` with the training wrappers a :class:`~.train_config.TrainConfig` asks for."""
    if actions not in ACTION_MODES:
        raise ValueError(f"actions: must be one of {ACTION_MODES}, got {actions!r}")
    if tube_penalty:
        env = TubePenalty(env, tube_penalty)
    return TurnGoActions(env) if actions == "turn_go" else env


class TurnGoPolicy:
    """A model trained on :class:`TurnGoActions`, acting in the continuous environment (SB3's ``predict``).

    Args:
        model: The SB3 model (its action space is ``Discrete(len(TURN_GO))``).
    """

    def __init__(self, model: BaseAlgorithm) -> None:
        n = getattr(model.action_space, "n", None)
        if n != len(TURN_GO):
            raise ValueError(
                f"model: expected a Discrete({len(TURN_GO)}) action space, got {model.action_space}"
            )
        self.model = model
        self.policy = model.policy  # marks an SB3 model for the evaluation loop (no per-episode state)
        self.observation_space = model.observation_space

    def predict(self, observation: dict[str, np.ndarray], state: tuple[np.ndarray, ...] | None = None,
                episode_start: np.ndarray | None = None,
                deterministic: bool = True) -> tuple[np.ndarray, tuple[np.ndarray, ...] | None]:  # fmt: skip
        a, state = self.model.predict(observation, state=state, episode_start=episode_start,
                                      deterministic=deterministic)  # fmt: skip
        return TURN_GO[np.asarray(a, dtype=np.int64)], state


__all__ = ["ACTION_MODES", "TURN_GO", "TubePenalty", "TurnGoActions", "TurnGoPolicy", "tube_width",
           "wrap_training_env"]  # fmt: skip
