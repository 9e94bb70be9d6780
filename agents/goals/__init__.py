"""Goal selection: certified coverage as a choice among candidate goals, driven by the frontier agent's loop.

Importing this package registers ``digslam/DigCoverageGoals-v0`` (room) and ``DigCoverageGoalsRocks-v0``,
``DigCoverageGoalsCaves-v0``, ``DigCoverageGoalsRooms-v0``, ``DigCoverageGoalsFloorplan-v0``
(:data:`GOAL_IDS`, one per generator of the benchmark); in worker processes use
``"digslam.agents.goals:digslam/DigCoverageGoals-v0"``.

Lives here: :mod:`.driver` (``GoalDriver``: the frontier agent's loop towards a fixed goal, and the events
that end a macro step), :mod:`.candidates` (the candidate goals and their features, from the observation
only), :mod:`.extra` (more candidate features named by an entry point, such as the map predictor's
gains), :mod:`.env` (``GoalSelectionEnv``, the semi-MDP wrapper), :mod:`.agent` (``GoalAgent``: a goal-level
chooser, e.g. a trained ``MaskablePPO``, as a policy of the low-level env, step by step), :mod:`.policy`
(``FirstCandidatePolicy``, ``RandomCandidatePolicy``) and :mod:`.registry` (the ids).

May import: :mod:`digslam.envs`, :mod:`digslam.agents.common` (the policy contract),
:mod:`digslam.agents.baselines`; numpy, scipy, gymnasium.
"""

from .agent import (
    GOAL_KWARGS,
    REWARD_KWARGS,
    GoalAgent,
    MacroState,
    base_env_kwargs,
    split_goal_kwargs,
)
from .candidates import (
    FEATURES,
    N_FEATURES,
    Candidates,
    candidates,
    clusters,
    tiers,
)
from .driver import (
    CLOSURE,
    FRONTIER,
    KEEP_FACTOR,
    KEEP_SLACK,
    KINDS,
    TURN,
    GoalDriver,
    Plan,
    driver_for,
    regret,
)
from .env import (
    GLOBALS,
    MAX_EMPTY,
    GoalSelectionEnv,
)
from .extra import (
    CandidateFeatures,
)
from .policy import (
    FirstCandidatePolicy,
    RandomCandidatePolicy,
)
from .registry import (
    ENTRY_POINT,
    GOAL_IDS,
    register_goal_envs,
)

register_goal_envs()

__all__ = [
    "CLOSURE",
    "CandidateFeatures",
    "Candidates",
    "ENTRY_POINT",
    "FEATURES",
    "FRONTIER",
    "FirstCandidatePolicy",
    "GLOBALS",
    "GOAL_IDS",
    "GOAL_KWARGS",
    "GoalAgent",
    "GoalDriver",
    "GoalSelectionEnv",
    "KEEP_FACTOR",
    "KEEP_SLACK",
    "KINDS",
    "MAX_EMPTY",
    "MacroState",
    "N_FEATURES",
    "Plan",
    "REWARD_KWARGS",
    "RandomCandidatePolicy",
    "TURN",
    "base_env_kwargs",
    "candidates",
    "clusters",
    "driver_for",
    "register_goal_envs",
    "regret",
    "split_goal_kwargs",
    "tiers",
]
