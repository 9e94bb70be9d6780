"""Heuristic coverage agents: the baselines every learned policy is compared to.

Lives here: :mod:`.registry` (``BASELINES``, ``make_baseline``), :mod:`.policy` (the policy interface,
``RandomAgent``), :mod:`.planning` (grid path planning), :mod:`.frontier` (frontier, uncertainty-aware
frontier and lawnmower agents) and :mod:`.tour` (the tour frontier agent; its Held-Karp kernel beside it in
:mod:`.tour_jit`) and :mod:`.distance_advantage` (the distance-advantage frontier agent).

May import: :mod:`digslam.envs` (observations and spaces), :mod:`digslam.observer.core.scalar_jit` (the
project's ``njit``); numpy, scipy, numba.
"""

from .distance_advantage import DistanceAdvantageAgent, isolation
from .frontier import (
    KEEP_FACTOR,
    KEEP_SLACK,
    FrontierAgent,
    LawnmowerAgent,
    NavigatingAgent,
    UncertaintyAwareFrontier,
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
