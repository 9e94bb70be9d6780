"""Policies over the goal-selection env's observation, with SB3's ``predict`` signature.

* :class:`FirstCandidatePolicy`: always candidate 0, the frontier agent's own pick (the fidelity baseline:
  through :class:`~.env.GoalSelectionEnv` it drives as :class:`~digslam.agents.baselines.FrontierAgent`);
* :class:`RandomCandidatePolicy`: a uniform valid candidate (seeded), for tests and as a floor.

>>> obs = {"mask": np.array([1, 1, 0, 0], np.int8)}
>>> int(FirstCandidatePolicy().predict(obs)[0]), RandomCandidatePolicy(seed=0).predict(obs)[0] in (0, 1)
(0, True)
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces


class FirstCandidatePolicy:
    """Candidate 0 at every decision (valid at every decision: a frontier cluster or the turn)."""

    def __init__(
        self,
        action_space: spaces.Space | None = None,
        observation_space: spaces.Space | None = None,
        seed: int | None = None,
    ) -> None:
        self.action_space, self.observation_space, self.seed = action_space, observation_space, seed

    def reset(self) -> None:
        """Nothing to forget (stateless)."""

    def predict(
        self,
        observation: dict[str, np.ndarray],
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, None]:
        """Action 0 for one observation (a 0-d array) or a batch (one per row of ``"mask"``)."""
        mask = _mask(observation)
        return np.zeros(() if mask.ndim == 1 else mask.shape[0], np.int64), None


class RandomCandidatePolicy(FirstCandidatePolicy):
    """A uniform random valid candidate (the ``"mask"``), from a generator seeded by ``seed``."""

    def __init__(
        self,
        action_space: spaces.Space | None = None,
        observation_space: spaces.Space | None = None,
        seed: int | None = None,
    ) -> None:
        super().__init__(action_space, observation_space, seed)
        self.reset()

    def reset(self) -> None:
        """Reseed."""
        self.rng = np.random.default_rng(self.seed)

    def predict(
        self,
        observation: dict[str, np.ndarray],
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, None]:
        """A valid action per observation."""
        mask = _mask(observation)
        rows = mask.reshape(-1, mask.shape[-1]) > 0
        out = np.array([self.rng.choice(np.flatnonzero(r)) for r in rows], np.int64)
        return (out[0] if mask.ndim == 1 else out), None


def _mask(observation: dict[str, np.ndarray]) -> np.ndarray:
    if not isinstance(observation, dict) or "mask" not in observation:
        raise ValueError("observation: expected a dict with 'mask' (the goal-selection env's observation)")
    mask = np.asarray(observation["mask"])
    if mask.ndim not in (1, 2) or mask.shape[-1] < 1:
        raise ValueError(f"observation: bad 'mask' shape {mask.shape}")
    return mask


__all__ = [
    "FirstCandidatePolicy",
    "RandomCandidatePolicy",
]
