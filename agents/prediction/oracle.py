"""The diagnosis: the predictive planner given the true map behind the frontiers (an upper bound).

:func:`oracle_suite` runs :class:`~.agent.PredictiveFrontierAgent` with :class:`~.agent.TrueMap` as its map
source, the true certifiable reachable free share of every pixel of the level being played, on the
suite's levels (:func:`digslam.agents.evaluation.suite.run_suite`), as the agent named ``"oracle"``. It
reads ground truth and is **not an agent**: it says how fast this planner would be with a perfect
predictor, so that a learned agent's shortfall can be put on the predictor (far from the oracle) or on the
planner (the oracle itself no faster than the heuristics).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the types; the suite and the agent are imported on use
    import gymnasium as gym

    from digslam.agents.common.policy import PolicyFactory, PolicyPredictor
    from digslam.agents.evaluation.suite import SuiteResult

#: The oracle's row name in a suite.
ORACLE = "oracle"


def oracle_factory(**agent_kw: Any) -> PolicyFactory:
    """A factory ``env -> agent``: the predictive planner reading ``env``'s true map."""
    from digslam.agents.prediction import make_predictive
    from digslam.agents.prediction.agent import TrueMap

    def build(env: gym.Env) -> PolicyPredictor:
        return make_predictive(env, predictor=TrueMap(env), **agent_kw)

    return build


def oracle_suite(
    n_maps: int = 30,
    steps: int = 3000,
    split: str = "test",
    generators: Sequence[str] | None = None,
    progress: bool = False,
    **agent_kw: Any,
) -> SuiteResult:
    """The :class:`~digslam.agents.evaluation.suite.SuiteResult` of the oracle alone (module docstring)."""
    from digslam.agents.evaluation.suite import run_suite

    return run_suite({ORACLE: oracle_factory(**agent_kw)}, n_maps=n_maps, steps=steps, split=split,
                     generators=generators, progress=progress)  # fmt: skip


__all__ = ["ORACLE", "oracle_factory", "oracle_suite"]
