"""Test helper: a wrapper that records the certified coverage after every low-level step, and the actions
(the goal-selection tests compare the frontier agent with its goal-level reproductions step by step)."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np


class Curve(gym.Wrapper):
    """Certified coverage after every low-level step (``cov``, the reset's first), and the actions."""

    def reset(self, **kw: Any) -> Any:
        obs, info = self.env.reset(**kw)
        self.cov, self.actions = [info["certified_coverage"]], []
        return obs, info

    def step(self, action: Any) -> Any:
        obs, r, te, tr, info = self.env.step(action)
        self.cov.append(info["certified_coverage"])
        self.actions.append(np.array(action, np.float32))
        return obs, r, te, tr, info
