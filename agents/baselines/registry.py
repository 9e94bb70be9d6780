"""Heuristic coverage baselines for ``digslam/DigCoverage-v0`` with SB3's ``predict`` interface.

* :class:`RandomAgent`: uniform actions;
* :class:`LawnmowerAgent`: boustrophedon lanes over the world frame, reached through the grid planner
  (:mod:`.lawnmower`);
* :class:`FrontierAgent`: nearest frontier between clear and dark (then penumbra) ground, Dijkstra over
  the clear pixels (:mod:`.frontier`, on the loop of :mod:`.navigating` and the planner of :mod:`.planning`);
  it turns in place and drives straight, since the guaranteed observer's box grows about 17 times faster
  along arcs than along straight lines;
* :class:`TourFrontierAgent`: the frontier agent whose goal starts the shortest open tour over the frontier
  clusters (a regret term on the clusters that would leave a detour behind, :mod:`.tour`);
* :class:`DistanceAdvantageAgent`: the frontier agent whose goal is the frontier cluster close to the robot
  and far from the other clusters (distance advantage, Ericson et al. 2025, :mod:`.distance_advantage`);
* :class:`UncertaintyAwareFrontier`: when the tube is wider than a threshold, goes back into clear ground
  near sensed obstacles, visited while the tube was narrow, and turns there until the tube shrinks (active
  loop closure, :mod:`.uncertainty`).

All read only the observation (:mod:`digslam.agents.baselines.policy`). :func:`make_baseline` sizes one
from an env (:func:`sizing`: its observer layer, :func:`digslam.envs.stack.observer_of`).

>>> import gymnasium as gym, digslam.envs
>>> env = gym.make("digslam/DigCoverage-v0", map_size=36)
>>> agent = make_baseline("frontier", env)
>>> obs, _ = env.reset(seed=0)
>>> action, _ = agent.predict(obs)
>>> action.shape, bool(env.action_space.contains(action))
((2,), True)
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from digslam.agents.baselines.distance_advantage import DistanceAdvantageAgent
from digslam.agents.baselines.frontier import FrontierAgent
from digslam.agents.baselines.lawnmower import LawnmowerAgent
from digslam.agents.baselines.policy import BaselinePolicy, RandomAgent
from digslam.agents.baselines.tour import TourFrontierAgent
from digslam.agents.baselines.uncertainty import UncertaintyAwareFrontier
from digslam.envs.stack import observer_of

#: Baseline names and classes.
BASELINES: dict[str, type[BaselinePolicy]] = {
    "random": RandomAgent,
    "lawnmower": LawnmowerAgent,
    "frontier": FrontierAgent,
    "uncertainty_frontier": UncertaintyAwareFrontier,
    "tour_frontier": TourFrontierAgent,
    "distance_advantage": DistanceAdvantageAgent,
}


def make_baseline(name: str, env: gym.Env, seed: int | None = None) -> BaselinePolicy:
    """The baseline ``name`` (a key of :data:`BASELINES`) sized from ``env`` (grid span, speeds, ranges).

    Raises:
        ValueError: ``name`` is not a known baseline.
    """
    if name not in BASELINES:
        raise ValueError(f"name: unknown baseline {name!r}; known: {sorted(BASELINES)}")
    return BASELINES[name](env.action_space, env.observation_space, seed=seed, **sizing(env))


def sizing(env: gym.Env) -> dict[str, Any]:
    """The :class:`BaselinePolicy` keywords that size an agent for ``env``: grid span, speeds, step and
    sensor range (none for an env without a ``GuaranteedObserver`` layer)."""
    try:
        layer = observer_of(env)
    except ValueError:  # not a certified-coverage env: the agents' defaults
        return {}
    g = layer.grid
    raw: Any = layer.unwrapped  # the raw ExploreEnv (its robot and sensors), which this folder may not import
    return {"span": float(g.hi[0] - g.lo[0]), "max_speed": raw.config.max_speed,
            "max_yaw_rate": raw.config.max_yaw_rate, "dt": raw.config.dt,
            "sensor_range": float(raw.suite.r_max.max())}  # fmt: skip


__all__ = [
    "BASELINES",
    "sizing",
    "BaselinePolicy",
    "DistanceAdvantageAgent",
    "FrontierAgent",
    "LawnmowerAgent",
    "RandomAgent",
    "TourFrontierAgent",
    "UncertaintyAwareFrontier",
    "make_baseline",
]
