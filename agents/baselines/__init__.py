"""Heuristic coverage agents: the baselines every learned policy is compared to.

Lives here: :mod:`.registry` (``BASELINES``, ``make_baseline``), :mod:`.policy` (the policy interface,
``RandomAgent``), :mod:`.planning` (grid path planning) and :mod:`.frontier` (frontier, uncertainty-aware
frontier and lawnmower agents).

May import: :mod:`digslam.envs` (observations and spaces); numpy, scipy.
"""

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
    path_to,
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

__all__ = [
    "KEEP_FACTOR",
    "KEEP_SLACK",
    "keep_bound",
    "BASELINES",
    "BaselinePolicy",
    "FrontierAgent",
    "LawnmowerAgent",
    "Memory",
    "NavigatingAgent",
    "RandomAgent",
    "SQUARE",
    "UncertaintyAwareFrontier",
    "View",
    "dilate",
    "erode",
    "line_of_sight",
    "make_baseline",
    "parse",
    "path_to",
    "shortest_paths",
    "turn_then_go",
    "wrap",
]
