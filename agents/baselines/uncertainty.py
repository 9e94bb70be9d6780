"""Active loop closure: the frontier agent that returns to obstacles it sensed with a narrow tube.

The observer contracts the pose box with the nearest echo, ``dist(x, comp M⁻) <= y⁺`` (Eq. 6.22): the side
of the box away from the nearest obstacle is cut down to about the obstacle's setback in the dig zone, which
is small where the obstacle was dug while the tube was narrow. :class:`UncertaintyAwareFrontier` turns that
into goals: pixels next to sensed obstacles (penumbra) that the robot passed while its tube was at most half
as wide as now.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces

from digslam.agents.baselines import planning as pl
from digslam.agents.baselines.frontier import FrontierAgent
from digslam.agents.baselines.policy import Memory, View


class UncertaintyAwareFrontier(FrontierAgent):
    """:class:`FrontierAgent` with active loop closure.

    The observer contracts the pose box with the nearest echo, ``dist(x, comp M⁻) <= y⁺`` (Eq. 6.22): the
    side of the box away from the nearest obstacle is cut down to about the obstacle's setback in the dig
    zone, which is small where the obstacle was dug while the tube was narrow. So when the tube width
    exceeds ``tube_high`` m, the agent visits, one after the other, up to ``visits`` clear pixels next to
    sensed obstacles (penumbra) that it passed with a tube at most half as wide as now, each at least
    ``spread`` m from the previous ones (obstacles on other sides cut other sides of the box), until the
    tube is below ``shrink`` times its width at the switch or ``closure_steps`` steps have passed. A
    closure that did not shrink the tube raises the threshold by ``backoff`` (no endless returns).

    Args:
        tube_high: Tube width (m) that triggers a loop closure.
        shrink: Target tube width, as a share of the width at the switch.
        closure_steps: Longest closure (steps).
        visits: Most obstacle visits per closure.
        spread: Least distance (m) between the visits of one closure.
        backoff: Factor on ``tube_high`` after a closure that failed.
        **kw: :class:`FrontierAgent` arguments.
    """

    def __init__(
        self,
        action_space: spaces.Space,
        observation_space: spaces.Space | None = None,
        seed: int | None = None,
        tube_high: float = 0.5,
        shrink: float = 0.75,
        closure_steps: int = 300,
        visits: int = 4,
        spread: float = 3.0,
        backoff: float = 1.3,
        **kw: Any,
    ) -> None:
        checks = (("tube_high", tube_high, 0.0), ("shrink", shrink, 0.0), ("backoff", backoff, 1.0),
                  ("spread", spread, 0.0))  # fmt: skip
        for name, v, low in checks:
            if not (math.isfinite(v) and v > low):
                raise ValueError(f"{name}: must be finite and > {low}, got {v!r}")
        for name, n in (("closure_steps", closure_steps), ("visits", visits)):
            if not (isinstance(n, int) and n >= 1):
                raise ValueError(f"{name}: must be an integer >= 1, got {n!r}")
        self.tube_high, self.shrink, self.closure_steps = tube_high, shrink, closure_steps
        self.visits, self.spread, self.backoff = visits, spread, backoff
        super().__init__(action_space, observation_space, seed, **kw)

    def _act(self, view: View, mem: Memory) -> np.ndarray:
        x = mem.extra
        high = x.setdefault("high", self.tube_high)
        if x.get("closing") is None and view.tube > high:
            x.update(closing=view.tube, t0=mem.t, done_at=[])
            x["closures"] = x.get("closures", 0) + 1
            mem.goal = mem.waypoint = None
        if x.get("closing") is not None:
            over = mem.t - x["t0"] > self.closure_steps or len(x["done_at"]) >= self.visits
            if view.tube <= self.shrink * x["closing"] or over:
                self._end_closure(view, mem)
                mem.goal = mem.waypoint = None  # the goal was a loop-closure target
        return super()._act(view, mem)

    def _end_closure(self, view: View, mem: Memory) -> None:
        """Leave the loop-closure mode; a closure that did not shrink the tube raises the threshold."""
        x = mem.extra
        if view.tube > self.shrink * x["closing"]:
            x["high"] = max(x["high"], view.tube) * self.backoff
        x["closing"] = None

    def _plan(self, view: View, mem: Memory) -> None:
        """Plan as :class:`NavigatingAgent`; a closure with no target left in the last planning pass (no
        remembered narrow-tube obstacle pixel reachable, even across penumbra) ends at once, as a failed
        one unless the tube already shrank, and the goal just chosen (a frontier goal) is kept."""
        x = mem.extra
        x["targets"] = False
        super()._plan(view, mem)
        if x.get("closing") is not None and not x["targets"]:
            self._end_closure(view, mem)
            x["exhausted"] = x.get("exhausted", 0) + 1  # closures that ran out of targets (diagnostics)

    def _goal_reached(self, view: View, mem: Memory) -> None:
        if mem.extra.get("closing") is not None:
            mem.extra["done_at"].append(view.pos.copy())

    def closure_targets(self, view: View, mem: Memory, reach: np.ndarray) -> np.ndarray:
        """``(m, m)`` bool: the reachable pixels next to sensed obstacles passed with a tube at most half as
        wide as at the switch, at least ``spread`` m from the visits done in this closure."""
        m = view.clear.shape[0]
        near = (
            reach
            & pl.dilate(view.penumbra, self.erosion(view) + 1)
            & (mem.best_tube <= 0.5 * mem.extra["closing"])
        )
        for p in mem.extra["done_at"]:
            near &= ~self._disk(m, p, self.spread / self.px(m))
        return near

    def _costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """Path lengths to the closure targets while closing a loop; frontier costs otherwise, and when no
        target is reachable in this pass (``_plan`` then ends the closure, unless the cautious pass over
        penumbra reaches one)."""
        x = mem.extra
        if x.get("closing") is None:
            return self.frontier_costs(view, mem, reach, dist)
        near = self.closure_targets(view, mem, reach)
        x["targets"] = bool(near.any())
        if not x["targets"]:
            return self.frontier_costs(view, mem, reach, dist)
        return np.where(near, dist, np.inf)


__all__ = ["UncertaintyAwareFrontier"]
