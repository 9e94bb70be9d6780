"""Map prediction: a learned guess of the unseen layout, and the agent that plans on it.

The layout of every training level is free ground truth, so the net learns the world rather than a
teacher's choices. Lives here: :mod:`.dataset` takes snapshots of the observer's map along episodes of the
training levels with the true free share of every pixel as label; :mod:`.model` is the predictor (a small
U-Net, the observation's map in, a free probability per pixel out); :mod:`.fit` trains it end to end
(``digslam train agents/configs/map_predictor.toml``); :mod:`.quality` scores it against two baselines on
the pixels the input leaves open; :mod:`.agent` holds ``predictive_frontier`` (the frontier agent with the
gain read on the predicted map) and the true-map diagnosis :class:`~.agent.TrueMap`, which
:mod:`.oracle` runs; :mod:`.gate` is its do-no-harm gate and :mod:`.settings` reads its settings
(``agents/configs/predictive_frontier.toml``); :mod:`.features` gives the goal env's candidates the
predicted gain and its spread as features (``candidate_features``), the inputs of the learned chooser
``predictive_chooser`` (``digslam train agents/configs/goals_predictive.toml``).

The prediction only ranks goals: every claim still comes from the observer, so a wrong prediction costs
time, never soundness. Ground truth enters the training labels only, and the oracle diagnosis, which is
not an agent.

May import: numpy, scipy, numba, torch (inside the functions that need it), :mod:`digslam.observer.core`,
:mod:`digslam.envs` and the baselines, evaluation, goals and learning folders of :mod:`digslam.agents`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the types; the agent (and torch) are imported on use
    from pathlib import Path

    import gymnasium as gym

    from digslam.agents.prediction.agent import MapSource, PredictiveFrontierAgent
    from digslam.agents.prediction.settings import PredictiveSettings


def make_predictive(
    env: gym.Env, predictor: MapSource | None = None, seed: int | None = None,
    settings: PredictiveSettings | str | Path | None = None, **kw: Any,
) -> PredictiveFrontierAgent:  # fmt: skip
    """A :class:`~.agent.PredictiveFrontierAgent` sized from ``env`` (as the baselines are,
    :func:`digslam.agents.baselines.registry.sizing`), reading ``predictor`` (None: the shipped one), with
    ``settings`` (:class:`~.settings.PredictiveSettings` or its file; None: the shipped
    ``agents/configs/predictive_frontier.toml``) and keyword overrides ``kw``."""
    from digslam.agents.baselines.registry import sizing
    from digslam.agents.prediction.agent import PredictiveFrontierAgent
    from digslam.agents.prediction.settings import PredictiveSettings, load_settings

    if not isinstance(settings, PredictiveSettings):
        settings = load_settings(settings)
    return PredictiveFrontierAgent(env.action_space, env.observation_space, seed=seed, predictor=predictor,
                                   **sizing(env), **{**settings.agent_kwargs(), **kw})  # fmt: skip


__all__ = ["make_predictive"]
