"""digslam.agents: coverage-planning baselines, training, evaluation and the command line.

Names are imported on first use, so ``import digslam.agents`` needs neither torch nor stable-baselines3
(those are imported inside the functions that train or load a learned policy).

Folders: :mod:`~digslam.agents.common` (what several parts share: the policy contract
``PolicyPredictor``), :mod:`~digslam.agents.baselines` (heuristic agents), :mod:`~digslam.agents.goals`
(the goal-selection env ``digslam/DigCoverageGoals-v0``: candidate goals driven by the frontier agent's
loop, registered when that folder is imported), :mod:`~digslam.agents.learning` (training, sweeps, the
shipped models), :mod:`~digslam.agents.prediction` (the map predictor and the agent that plans on it),
:mod:`~digslam.agents.evaluation` (evaluation, the benchmark suite, pictures) and
:mod:`~digslam.agents.cli` (the command line, the only place that wires argparse). The evaluation function
is exported as :func:`evaluate_agents` (``digslam.agents.evaluation.evaluate`` is its module).
"""

from __future__ import annotations

import importlib
from typing import Any

from digslam.observer.cache import origin as _origin

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
    "PolicyPredictor": "common",
    "FirstCandidatePolicy": "goals",
    "GoalAgent": "goals",
    "GoalSelectionEnv": "goals",
    "TrainConfig": "learning.train_config",
    "train": "learning.train",
    "EvalResult": "evaluation.evaluate",
    "coverage_figure": "evaluation.evaluate",
    "evaluate_agents": "evaluation.evaluate",
    "SuiteResult": "evaluation.suite",
    "run_suite": "evaluation.suite",
    "record_episode_gif": "evaluation.pictures",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        mod = importlib.import_module(f".{_LAZY[name]}", __name__)
        return getattr(mod, "evaluate" if name == "evaluate_agents" else name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = sorted(_LAZY)
