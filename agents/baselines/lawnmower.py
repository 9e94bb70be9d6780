"""The lawnmower: boustrophedon lanes over the world frame, each lane end reached through the planner.

>>> from gymnasium import spaces
>>> LawnmowerAgent(spaces.Box(-1, 1, (2,)), lane_spacing=5.0).lanes(20)[:3].tolist()
[[1.0, 1.0], [1.0, 19.0], [6.0, 19.0]]
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces

from digslam.agents.baselines import planning as pl
from digslam.agents.baselines.navigating import NavigatingAgent
from digslam.agents.baselines.policy import Memory, View


class LawnmowerAgent(NavigatingAgent):
    """Boustrophedon over the world frame: lanes ``lane_spacing`` m apart, top to bottom, alternating
    direction; each lane end is reached through the planner (the reachable pixel nearest to it).

    Args:
        lane_spacing: Distance between lanes (m).
        edge: Distance of the first and last lanes and lane ends from the frame's border (m).
        **kw: :class:`NavigatingAgent` arguments.
    """

    def __init__(
        self,
        action_space: spaces.Space,
        observation_space: spaces.Space | None = None,
        seed: int | None = None,
        lane_spacing: float = 3.0,
        edge: float = 1.0,
        **kw: Any,
    ) -> None:
        for name, v in (("lane_spacing", lane_spacing), ("edge", edge)):
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name}: must be finite and > 0, got {v!r}")
        self.lane_spacing, self.edge = lane_spacing, edge
        super().__init__(action_space, observation_space, seed, **kw)

    def lanes(self, m: int) -> np.ndarray:
        """``(K, 2)`` lane-end pixels ``(row, col)`` of the boustrophedon, in visiting order."""
        px = self.px(m)
        ys = np.arange(self.edge, self.span - self.edge + 1e-9, self.lane_spacing) / px
        a, b = self.edge / px, (self.span - self.edge) / px
        ends = [((a, b) if i % 2 == 0 else (b, a)) for i in range(len(ys))]
        return np.array([(y, c) for y, e in zip(ys, ends, strict=True) for c in e])

    def _costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        m = view.clear.shape[0]
        lanes = mem.extra.setdefault("lanes", self.lanes(m))
        i = mem.extra.setdefault("lane", 0) % len(lanes)
        rr, cc = pl.pixel_centres(m)
        d = np.hypot(rr - lanes[i, 0], cc - lanes[i, 1])
        return np.where(reach, 1e3 * d + dist, np.inf)  # nearest to the lane end, then shortest

    def _act(self, view: View, mem: Memory) -> np.ndarray:
        if mem.goal is not None and mem.goal_steps > mem.goal_budget:
            mem.extra["lane"] = mem.extra.get("lane", 0) + 1  # unreachable lane end: skip it
            mem.goal = mem.waypoint = None
        return super()._act(view, mem)

    def _goal_reached(self, view: View, mem: Memory) -> None:
        m = view.clear.shape[0]
        lanes = mem.extra.setdefault("lanes", self.lanes(m))
        i = mem.extra.get("lane", 0) % len(lanes)
        near = np.hypot(*(lanes[i] - view.pos)) * self.px(m) < 2.0
        if near or mem.extra.get("last") == mem.goal:  # at the lane end, or no nearer to it: next lane
            mem.extra["lane"] = i + 1
        mem.extra["last"] = mem.goal


__all__ = ["LawnmowerAgent"]
