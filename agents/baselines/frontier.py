"""Frontier exploration: the nearest frontier between clear and dark ground, weighed by what it may open.

:class:`FrontierAgent` plans as every :class:`~.navigating.NavigatingAgent` does; its goals are, by tier:

* traversable pixels next to dark ground (within the penumbra band that the tube width adds), then next to
  penumbra, then any pixel not yet visited, each tier with a path-length penalty, less a bonus for the dark
  ground around the pixel (the expected gain, ``gain_weight``) and plus the time to turn towards it
  (``turn_weight``); a pixel within ``visit_radius`` m of the robot's past positions is no longer a
  candidate (if it is still next to dark ground once the robot was there, it borders an obstacle, not the
  unexplored);
* the unexplored may lie beyond a corridor seen only in penumbra, so the penumbra pixels next to dark ground
  and deep in the penumbra are goals too, at ``penumbra_penalty``, beside the clear tiers
  (``penumbra_frontier``).

>>> from gymnasium import spaces
>>> from digslam.envs.observation import N_STATE, Channel, State
>>> agent = FrontierAgent(spaces.Box(-1, 1, (2,)))
>>> state = np.zeros(N_STATE, np.float32); state[[State.COS, State.CONSISTENT]] = 1.0   # centre, heading +x
>>> state[State.ELAPSED] = 0.1
>>> img = np.zeros((4, 36, 36), np.uint8); img[Channel.CLEAR, 8:28, 8:28] = 255
>>> img[Channel.DARK] = 255 - img[Channel.CLEAR]
>>> a, _ = agent.predict({"map": img, "state": state})
>>> agent.memory(0).goal is not None, a.shape
(True, (2,))
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces
from scipy import ndimage

from digslam.agents.baselines import planning as pl
from digslam.agents.baselines.navigating import NavigatingAgent
from digslam.agents.baselines.policy import Memory, View


class FrontierAgent(NavigatingAgent):
    """Nearest frontier between clear and dark ground (then penumbra, then unvisited clear ground).

    Args:
        penumbra_penalty: Extra path length (m) of a goal next to penumbra only.
        unvisited_penalty: Extra path length (m) of a goal that is merely not yet visited.
        turn_weight: Weight of the time to turn in place towards a goal, counted as the distance that
            could be driven meanwhile (a half turn takes as long as 3 m of driving at full scale).
        gain_weight: Weight (m) of the expected gain: a candidate's cost is lowered by ``gain_weight`` times
            the dark share of the square of side twice the sensor range around it (the unexplored it may
            open up), so that of two frontiers about as far the one facing more dark ground wins.
        penumbra_frontier: Also take as goals the reachable penumbra pixels next to dark ground not yet
            visited that lie farther from clear ground than the tube's band along walls (a corridor that the
            cones saw only in penumbra, otherwise entered only once every clear pixel was visited), at the
            ``penumbra_penalty``; when no pixel is a candidate at all, any such penumbra pixel next to dark
            ground (at the ``unvisited_penalty``).
        **kw: :class:`NavigatingAgent` arguments.
    """

    def __init__(
        self,
        action_space: spaces.Space,
        observation_space: spaces.Space | None = None,
        seed: int | None = None,
        penumbra_penalty: float = 6.0,
        unvisited_penalty: float = 12.0,
        turn_weight: float = 4.0,
        penumbra_frontier: bool = True,
        gain_weight: float = 40.0,
        **kw: Any,
    ) -> None:
        self.penumbra_frontier = bool(penumbra_frontier)
        if not (math.isfinite(gain_weight) and gain_weight >= 0):
            raise ValueError(f"gain_weight: must be finite and >= 0, got {gain_weight!r}")
        self.gain_weight = float(gain_weight)
        named = (("penumbra_penalty", penumbra_penalty), ("unvisited_penalty", unvisited_penalty),
                 ("turn_weight", turn_weight))  # fmt: skip
        for name, v in named:
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"{name}: must be finite and >= 0, got {v!r}")
        self.penumbra_penalty, self.unvisited_penalty = penumbra_penalty, unvisited_penalty
        self.turn_weight = turn_weight
        super().__init__(action_space, observation_space, seed, **kw)

    def frontier_tiers(self, view: View, mem: Memory, reach: np.ndarray) -> tuple[np.ndarray, ...]:
        """The candidate pixels by tier: ``(dark, pen, free)``, reachable unvisited pixels next to dark ground
        (within the band the tube adds), those next to penumbra only, and all reachable unvisited ones."""
        px = self.px(view.clear.shape[0])
        band = self.erosion(view) + 1 + int(math.ceil(view.tube / px))
        free = reach & ~mem.visited
        dark = free & pl.dilate(view.dark, band + 1)
        pen = free & ~dark & pl.dilate(view.penumbra, self.erosion(view) + 1)
        return dark, pen, free

    def frontier_costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """Path length plus the tier penalty of every frontier pixel (``inf`` elsewhere)."""
        px = self.px(view.clear.shape[0])
        dark, pen, free = self.frontier_tiers(view, mem, reach)
        cost = np.full(dist.shape, np.inf)
        cost[free] = dist[free] + self.unvisited_penalty / px
        cost[pen] = dist[pen] + self.penumbra_penalty / px
        cost[dark] = dist[dark]
        if self.penumbra_frontier:
            # the unexplored may lie beyond a passage seen only in penumbra (a corridor that the sonar cones,
            # cut short by its walls, never cleared): its edge with dark ground, deeper in the penumbra than
            # the band that the tube puts along every wall, is a goal beside the clear tiers; with no goal at
            # all, any edge of the penumbra with dark ground
            edge = np.isfinite(dist) & view.penumbra & pl.dilate(view.dark, 1) & ~mem.visited
            deep = edge & ~pl.dilate(view.clear, int(math.ceil(view.tube / px)) + 2)
            if deep.any():
                cost[deep] = np.minimum(cost[deep], dist[deep] + self.penumbra_penalty / px)
            elif not np.isfinite(cost).any():
                cost[edge] = dist[edge] + self.unvisited_penalty / px
        if self.turn_weight > 0:
            rr, cc = pl.pixel_centres(view.clear.shape[0])
            err = np.abs(
                np.angle(np.exp(1j * (np.arctan2(view.pos[0] - rr, cc - view.pos[1]) - view.heading)))
            )
            cost += self.turn_weight * err / self._turn * (self.max_speed * self.dt) / px
        if self.gain_weight > 0:
            cost -= self.gain_weight * self.expected_gain(view, mem, np.isfinite(cost)) / px
        return cost

    def expected_gain(self, view: View, mem: Memory, candidates: np.ndarray) -> np.ndarray:
        """``(m, m)`` expected gain of each candidate pixel, in ``[0, 1]`` (weighted by ``gain_weight``):
        here the dark share of the square of side twice the sensor range around the pixel."""
        k = 2 * int(round(self.sensor_range / self.px(view.clear.shape[0]))) + 1
        return ndimage.uniform_filter(view.dark.astype(np.float64), size=k, mode="constant")

    def _costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        return self.frontier_costs(view, mem, reach, dist)


__all__ = ["FrontierAgent"]
