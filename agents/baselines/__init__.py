"""Heuristic coverage agents: the baselines every learned policy is compared to.

Lives here: :mod:`.registry` (``BASELINES``, ``make_baseline``), :mod:`.policy` (the base of the agents:
observation parsing, per-environment memory, SB3's ``predict``; ``RandomAgent``), :mod:`.planning` (grid
path planning; its kernels in :mod:`.planning_jit` and :mod:`.policy_jit`), :mod:`.navigating` (the
planning agents' loop and goal hysteresis), one module per agent: :mod:`.frontier`, :mod:`.lawnmower`,
:mod:`.uncertainty` (the uncertainty-aware frontier: active loop closure), :mod:`.tour` (the tour frontier
agent; its Held-Karp kernel in :mod:`.tour_jit`) and :mod:`.distance_advantage`.

May import: :mod:`digslam.envs` (observations and spaces), :mod:`digslam.observer.core.scalar_jit` (the
project's ``njit``); numpy, scipy, numba.
"""

from .distance_advantage import DistanceAdvantageAgent, isolation
from .frontier import FrontierAgent
from .lawnmower import LawnmowerAgent
from .navigating import (
    KEEP_FACTOR,
    KEEP_SLACK,
    NavigatingAgent,
    keep_bound,
)
from .planning import (
    SQUARE,
    dilate,
    erode,
    line_of_sight,
    path_lengths,
    path_to,
    pixel_graph,
    shortest_paths,
    turn_then_go,
    wrap,
)
from .policy import (
    BaselinePolicy,
    Memory,
    RandomAgent,
    View,
    parse,
)
from .registry import (
    BASELINES,
    make_baseline,
)
from .tour import TourFrontierAgent, tour_regret
from .uncertainty import UncertaintyAwareFrontier

__all__ = [
    "KEEP_FACTOR",
    "KEEP_SLACK",
    "keep_bound",
    "BASELINES",
    "BaselinePolicy",
    "DistanceAdvantageAgent",
    "FrontierAgent",
    "LawnmowerAgent",
    "Memory",
    "NavigatingAgent",
    "RandomAgent",
    "SQUARE",
    "TourFrontierAgent",
    "UncertaintyAwareFrontier",
    "View",
    "dilate",
    "erode",
    "isolation",
    "line_of_sight",
    "make_baseline",
    "parse",
    "path_lengths",
    "path_to",
    "pixel_graph",
    "shortest_paths",
    "tour_regret",
    "turn_then_go",
    "wrap",
]
