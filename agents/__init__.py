"""digslam.agents: coverage-planning baselines, training, evaluation and the command line.

Names are imported on first use, so ``import digslam.agents`` needs neither torch nor stable-baselines3
(those are imported inside the functions that train or load a learned policy).

``digslam.agents.evaluate`` is the evaluation module (a submodule always shadows a package attribute of
the same name once imported); its function is exported as :func:`evaluate_agents` too.
"""

from __future__ import annotations

import importlib
from typing import Any

from . import origin as _origin

_origin.warn_if_shadowed(__name__)

#: Public names and the submodule that defines each.
_LAZY = {
    "BASELINES": "baselines",
    "BaselinePolicy": "baselines",
    "FrontierAgent": "baselines",
    "LawnmowerAgent": "baselines",
    "RandomAgent": "baselines",
    "UncertaintyAwareFrontier": "baselines",
    "make_baseline": "baselines",
    "EvalResult": "evaluate",
    "coverage_figure": "evaluate",
    "evaluate_agents": "evaluate",
    "record_episode_gif": "evaluate",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        mod = importlib.import_module(f".{_LAZY[name]}", __name__)
        return getattr(mod, "evaluate" if name == "evaluate_agents" else name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = sorted(_LAZY)
