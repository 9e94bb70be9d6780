"""The goal-selection env ids: one per world generator of the coverage suite, registered on import of
:mod:`digslam.agents.goals` (the envs never import the agents).

``gym.make("digslam/DigCoverageGoals-v0")`` after ``import digslam.agents.goals``, or
``gym.make("digslam.agents.goals:digslam/DigCoverageGoals-v0")``, which imports it first (worker
processes). No ``TimeLimit`` is added: an episode's length is counted in low-level steps by the env itself
(``max_steps``, 3000 by default, the suite's budget).
"""

from __future__ import annotations

import gymnasium as gym

import digslam.envs  # noqa: F401  (registers the base ids the goal ids wrap)
from digslam.envs import FLOORPLAN_WORLD_SIZE

#: Entry point of every id.
ENTRY_POINT = "digslam.agents.goals.env:GoalSelectionEnv"
#: Goal-selection ids and their keywords: the worlds of ``digslam.agents.evaluation.suite.GENERATORS``.
GOAL_IDS: dict[str, dict[str, object]] = {
    "digslam/DigCoverageGoals-v0": {"base_id": "digslam/DigCoverage-v0"},
    "digslam/DigCoverageGoalsRocks-v0": {"base_id": "digslam/DigCoverage-v0", "world": "rocks"},
    "digslam/DigCoverageGoalsCaves-v0": {"base_id": "digslam/DigCoverage-v0", "world": "caves"},
    "digslam/DigCoverageGoalsRooms-v0": {"base_id": "digslam/DigCoverage-v0", "world": "rooms"},
    "digslam/DigCoverageGoalsFloorplan-v0": {
        "base_id": "digslam/DigCoverage-v0",
        "world": "floorplan",
        "world_size": FLOORPLAN_WORLD_SIZE,
    },
}


def register_goal_envs() -> list[str]:
    """Register the ids of :data:`GOAL_IDS` not registered yet; returns the ids registered now."""
    new = [i for i in GOAL_IDS if i not in gym.registry]
    for env_id in new:
        gym.register(id=env_id, entry_point=ENTRY_POINT, kwargs=dict(GOAL_IDS[env_id]))
    return new


__all__ = [
    "ENTRY_POINT",
    "GOAL_IDS",
    "register_goal_envs",
]
