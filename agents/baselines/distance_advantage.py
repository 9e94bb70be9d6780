"""Frontier exploration by distance advantage: finish the isolated frontiers before passing them by.

Reaching a coverage level is *quality-constrained* exploration: the area to sense is fixed, so what an
explorer can save is path, not information. Ericson, Pedro and Jensfelt (2025, "Information Gain Is Not All
You Need") therefore drop information gain as the objective and pick, among the candidate frontiers ``S``,
the one with the largest *distance advantage*

    ``A(s) = min_{s' in S, s' != s} d(s', s) - d(x, s)``,

where ``d`` is the path length and ``x`` the robot: ``A(s) > 0`` when the robot is closer to ``s`` now than
any other candidate is, so ``s`` is best taken now, before the robot moves on and ``s`` becomes a detour.
A frontier close to the robot and far from the others comes first; two frontiers side by side cancel out
and the nearer one wins.

:class:`DistanceAdvantageAgent` puts that score on the frontier agent's machinery
(:class:`~.frontier.FrontierAgent`), reading only the observation like every baseline:

* the candidates are the frontier clusters of :class:`~.tour.TourFrontierAgent`: 8-connected frontier
  pixels next to dark ground, at least ``min_cluster`` of them, the ``max_clusters`` cheapest; each is
  represented by its cheapest pixel;
* ``min_{s'} d(s', s)`` is the path length from that pixel to the nearest pixel of another cluster
  (:func:`isolation`), from one multi-source Dijkstra over the planner's own graph (soft costs: penumbra and
  the unnavigable edge of the clear zone cost more); ``d(x, s)`` is the frontier agent's path length;
* a pixel of cluster ``s`` costs ``frontier cost - advantage_weight * min_{s'} d(s', s)``, so with weight 1
  the cheapest cluster is the one of largest ``A(s)`` up to the frontier agent's own terms; the default,
  0.4, weighs the isolation less than the paper.

Where it differs from the paper: the frontier agent's turn and expected-gain terms stay in the cost (the
paper's candidates are filtered by gain, ours are weighted by it), the candidates are clusters of pixels
rather than viewpoints, a candidate with no other one in reach has no advantage term (``A`` is undefined
for a lone frontier), the other tiers of the frontier agent (penumbra, unvisited ground) come after the
clusters as before, and the goal keeps the frontier agent's hysteresis (:func:`~.navigating.keep_bound`).

>>> from gymnasium import spaces
>>> from digslam.envs.observation import N_STATE, Channel, State
>>> agent = DistanceAdvantageAgent(spaces.Box(-1, 1, (2,)))
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

from digslam.agents.baselines import planning as pl
from digslam.agents.baselines.policy import Memory, View
from digslam.agents.baselines.tour import TourFrontierAgent

__all__ = ["DistanceAdvantageAgent", "isolation"]


def isolation(lengths: np.ndarray, masks: list[np.ndarray]) -> np.ndarray:
    """``(K,)`` path length from each candidate's pixel to the nearest pixel of any other candidate,
    ``min_{j != i} min lengths[i][masks[j]]``, from the ``(K, m, m)`` path lengths out of each candidate's
    pixel and the ``K`` candidates' ``(m, m)`` pixel masks; 0 where no other candidate is in reach (or
    ``K < 2``), so that such a candidate gets no advantage term.

    >>> cols = np.arange(4)[None, :].repeat(4, 0)  # three candidates: the columns 0, 1 and 3 of a 4 x 4 map
    >>> m = [cols == c for c in (0, 1, 3)]
    >>> d = np.array([np.abs(cols - c) for c in (0, 1, 3)], dtype=float)  # lengths out of each candidate
    >>> isolation(d, m).tolist()
    [1.0, 1.0, 2.0]
    """
    d = np.asarray(lengths, dtype=np.float64)
    k = len(masks)
    if d.ndim != 3 or d.shape[0] != k:
        raise ValueError(f"lengths, masks: expected ({k}, m, m) lengths for {k} masks, got {d.shape}")
    near = np.full(k, np.inf)
    for i in range(k):
        for j in range(k):
            if i != j and masks[j].any():
                near[i] = min(near[i], float(d[i][masks[j]].min()))
    return np.where(np.isfinite(near), near, 0.0)


class DistanceAdvantageAgent(TourFrontierAgent):
    """The frontier agent with the distance-advantage term over its frontier clusters (see the module).

    Args:
        advantage_weight: Weight of ``min_{s'} d(s', s)`` (path lengths, pixels); 1 is the paper's score,
            0 gives the frontier agent exactly.
        max_clusters, min_cluster: The candidates (:class:`~.tour.TourFrontierAgent`).
        **kw: :class:`~.frontier.FrontierAgent` arguments.
    """

    def __init__(
        self,
        action_space: spaces.Space,
        observation_space: spaces.Space | None = None,
        seed: int | None = None,
        advantage_weight: float = 0.4,
        max_clusters: int = 8,
        min_cluster: int = 2,
        **kw: Any,
    ) -> None:
        if not (math.isfinite(advantage_weight) and advantage_weight >= 0):
            raise ValueError(f"advantage_weight: must be finite and >= 0, got {advantage_weight!r}")
        self.advantage_weight = float(advantage_weight)
        kw.pop("tour_weight", None)
        super().__init__(action_space, observation_space, seed, tour_weight=0.0, max_clusters=max_clusters,
                         min_cluster=min_cluster, **kw)  # fmt: skip

    def _costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        cost = self.frontier_costs(view, mem, reach, dist)
        if self.advantage_weight > 0:
            self.add_advantage(view, mem, reach, cost)
        return cost

    def add_advantage(self, view: View, mem: Memory, reach: np.ndarray, cost: np.ndarray) -> np.ndarray:
        """Lower the pixels of every candidate cluster by ``advantage_weight`` times its distance to the
        nearest other candidate, in place; returns those distances (pixels, candidates by cost)."""
        pix, masks = self.stops(view, mem, reach, cost)
        if len(masks) < 2:
            return np.zeros(len(masks))
        near = isolation(self.stop_lengths(view, mem, reach, pix), masks)
        for mask, n in zip(masks, near, strict=True):
            cost[mask] -= self.advantage_weight * n
        return near

    def stop_lengths(self, view: View, mem: Memory, reach: np.ndarray, pix: np.ndarray) -> np.ndarray:
        """``(K, m, m)`` path lengths from each stop pixel of ``pix (K, 2)`` over the planner's graph."""
        free, weight = self.planner_graph(view, mem, reach)
        return pl.path_lengths(free, pix, weight)
