"""Frontier exploration that plans a tour: the goal starts the shortest open tour over the frontier clusters.

The greedy frontier agent (:class:`~.frontier.FrontierAgent`) takes the cheapest frontier pixel and may
leave a small frontier near the robot for a larger one farther on; the small one then costs a long trip back
at the end (on the ``rooms`` generator, a corridor stub next to the start room, skipped for the corridor on
the other side). Tour-based exploration planners (FUEL, Zhou et al. 2021, and before it the TSP ordering of
frontier viewpoints) order the frontiers by a shortest tour instead.

:class:`TourFrontierAgent` keeps every cost of the frontier agent and adds a regret term: the frontier pixels
next to dark ground are grouped into clusters (8-connected), the ``max_clusters`` cheapest clusters become
the stops of a tour, the path lengths between them come from one Dijkstra per stop over the planner's own
graph, each stopped once every stop is settled (:func:`.planning.pair_lengths`), and
:func:`.tour_jit.open_tours` gives for every stop ``i`` the length ``R_i`` of the shortest open path from
``i`` through all the others. A pixel of cluster ``i`` costs
``tour_weight * (R_i - min R)`` more: the cluster that starts the best tour costs what it did, one that would
leave a detour behind costs that detour. Clusters outside the tour, the other tiers and the hysteresis are
those of the frontier agent. Everything comes from the observation, as for every baseline.

The tour pays where frontiers are few and far apart (corridors between rooms) and costs where they are many
and small (the gaps between rocks: ordering a dozen small clusters delays the last few per cent); it is a
comparison row of the leaderboard (``docs/benchmark.md``), not the frontier agent's replacement.

>>> from gymnasium import spaces
>>> from digslam.envs.observation import N_STATE, Channel, State
>>> agent = TourFrontierAgent(spaces.Box(-1, 1, (2,)))
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
from digslam.agents.baselines.frontier import FrontierAgent
from digslam.agents.baselines.policy import Memory, View
from digslam.agents.baselines.tour_jit import MAX_STOPS, open_tours

__all__ = ["TourFrontierAgent", "tour_regret"]


def tour_regret(lengths: np.ndarray) -> np.ndarray:
    """``(K,)`` regret of starting the tour at each stop of the ``(K, K)`` path-length matrix: the shortest
    open tour from that stop through all the others, less the shortest over all starts (0 for the best
    start; every entry 0 when no tour is finite).

    >>> d = np.array([[0.0, 1.0, 5.0], [1.0, 0.0, 1.0], [5.0, 1.0, 0.0]])
    >>> tour_regret(d).tolist()
    [0.0, 4.0, 0.0]
    """
    r = open_tours(np.ascontiguousarray(lengths, dtype=np.float64))
    best = float(r.min()) if r.size else math.inf
    if not math.isfinite(best):
        return np.zeros_like(r)
    return np.where(np.isfinite(r), r - best, np.inf)


class TourFrontierAgent(FrontierAgent):
    """The frontier agent with a tour-regret term over its frontier clusters (see the module docstring).

    Args:
        tour_weight: Weight of the regret (path lengths, pixels); 0 gives the frontier agent exactly.
        max_clusters: Stops of the tour: the cheapest frontier clusters, at most :data:`.tour_jit.MAX_STOPS`.
        min_cluster: Pixels a cluster needs to be a stop (a lone pixel next to dark ground is often a hole in
            the penumbra, not a way on).
        **kw: :class:`~.frontier.FrontierAgent` arguments.
    """

    def __init__(
        self,
        action_space: spaces.Space,
        observation_space: spaces.Space | None = None,
        seed: int | None = None,
        tour_weight: float = 2.0,
        max_clusters: int = 8,
        min_cluster: int = 2,
        **kw: Any,
    ) -> None:
        if not (math.isfinite(tour_weight) and tour_weight >= 0):
            raise ValueError(f"tour_weight: must be finite and >= 0, got {tour_weight!r}")
        if not (isinstance(max_clusters, int) and 2 <= max_clusters <= MAX_STOPS):
            raise ValueError(f"max_clusters: must be an integer in [2, {MAX_STOPS}], got {max_clusters!r}")
        if not (isinstance(min_cluster, int) and min_cluster >= 1):
            raise ValueError(f"min_cluster: must be an integer >= 1, got {min_cluster!r}")
        self.tour_weight, self.max_clusters, self.min_cluster = float(tour_weight), max_clusters, min_cluster
        super().__init__(action_space, observation_space, seed, **kw)

    def _costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        cost = self.frontier_costs(view, mem, reach, dist)
        if self.tour_weight > 0:
            self.add_regret(view, mem, reach, cost)
        return cost

    def stops(self, view: View, mem: Memory, reach: np.ndarray, cost: np.ndarray) -> tuple[np.ndarray, list]:
        """The tour's stops: ``(S, 2)`` pixels (each cluster's cheapest) and each cluster's pixel mask, the
        ``max_clusters`` cheapest clusters of at least ``min_cluster`` frontier pixels next to dark ground."""
        dark = self.frontier_tiers(view, mem, reach)[0] & np.isfinite(cost)
        labels, n = ndimage.label(dark, structure=pl.SQUARE)
        idx = np.flatnonzero(labels)
        lab, val = labels.ravel()[idx], cost.ravel()[idx]
        order = np.lexsort((idx, val, lab))  # by cluster, then cost, then flat index (argmin's first)
        head = order[np.flatnonzero(np.diff(lab[order], prepend=0))]  # each cluster's cheapest pixel
        big = head[np.bincount(lab, minlength=n + 1)[lab[head]] >= self.min_cluster]
        chosen = big[np.argsort(val[big], kind="stable")][: self.max_clusters]  # cheapest first
        w = cost.shape[1]
        pix = np.stack([idx[chosen] // w, idx[chosen] % w], axis=1).astype(np.int64).reshape(-1, 2)
        return pix, [labels == lab[i] for i in chosen]

    def add_regret(self, view: View, mem: Memory, reach: np.ndarray, cost: np.ndarray) -> None:
        """Add ``tour_weight`` times the tour regret to the pixels of every stop's cluster, in place."""
        pix, masks = self.stops(view, mem, reach, cost)
        if len(masks) < 2:
            return
        free, weight = self.planner_graph(view, mem, reach)
        d = pl.pair_lengths(free, pix, weight)
        regret = tour_regret(d)
        for mask, r in zip(masks, regret, strict=True):
            cost[mask] += self.tour_weight * r
