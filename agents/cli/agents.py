"""The agents a command runs: ``--agent``/``--agents`` names, the saved PPO models, the frontier fallback.

The model registry (the shipped policy, its environment keywords, loading a ``.zip``) is
:mod:`digslam.agents.learning.models`; here its :class:`~digslam.agents.learning.models.ModelError` becomes a
:class:`~digslam.agents.cli.common.UserError` worded with the command's options.

``--agent ppo --model M`` also takes a goal-level model (a ``MaskablePPO`` trained on
``digslam/DigCoverageGoals*``, as its sidecar says): it acts in the ``--env`` low-level env as a
:class:`~digslam.agents.goals.GoalAgent`, built with the low-level keywords :func:`model_env_kwargs` reads
from that sidecar.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

from digslam.agents.cli.common import UserError, make_env
from digslam.agents.learning import models

if TYPE_CHECKING:  # the types; gymnasium is imported with the environments
    import gymnasium as gym

    from digslam.agents.common.policy import PolicyPredictor


def agent_names() -> list[str]:
    """Names ``--agent`` takes: ``best`` (the leaderboard's best, :func:`~.models.best_agent`), ``ppo`` and
    the baselines."""
    from digslam.agents.baselines.registry import BASELINES

    return ["best", "ppo", *BASELINES, "predictive_frontier", "predictive_chooser"]


def model_env_kwargs(model: Path | None = None) -> dict[str, Any]:
    """:func:`~digslam.agents.learning.models.model_env_kwargs` (None: the shipped policy); a damaged
    sidecar raises :class:`UserError`."""
    try:
        return models.model_env_kwargs(model)
    except models.ModelError as exc:
        raise UserError(str(exc)) from None


def load_ppo(path: Path, env: gym.Env) -> PolicyPredictor:
    """The saved PPO model at ``path``, checked against ``env``'s spaces (:class:`UserError` otherwise)."""
    try:
        return models.load_ppo(path, env, opt="--model")
    except models.ModelError as exc:
        raise UserError(str(exc)) from None


def load_agent(name: str, env: gym.Env, model: Path | None = None) -> PolicyPredictor:
    """A policy with SB3's ``predict``: ``"ppo"`` (a saved PPO model, default the shipped one; a goal-level
    model comes as a :class:`~digslam.agents.goals.GoalAgent`), ``"predictive_frontier"`` (on the map
    predictor ``model``, default the shipped one), ``"predictive_chooser"`` (the goal-level ``model`` that
    reads the predicted gains, default :data:`~digslam.agents.learning.models.CHOOSER`) or a baseline name of
    :data:`digslam.agents.baselines.registry.BASELINES`.

    Raises:
        UserError: unknown ``name``, or a model that cannot be loaded for ``env``.
    """
    if name == "ppo":
        return load_ppo(Path(model) if model is not None else models.PRETRAINED, env)
    if name == "predictive_chooser":
        return load_ppo(Path(model) if model is not None else models.CHOOSER, env)
    if name == "best":
        name = models.best_agent()[0]
    if name == "predictive_frontier":
        from digslam.agents.prediction import make_predictive

        try:
            if model is None:
                return make_predictive(env)
            from digslam.agents.prediction.model import load

            return make_predictive(env, predictor=load(model))  # a map predictor of `digslam train`
        except (ImportError, ValueError) as exc:
            raise UserError(f"--agent predictive_frontier: {exc}") from None
    if name not in agent_names() or name == "best":
        raise UserError(f"--agent {name!r}: unknown agent; known: {', '.join(agent_names())}")
    from digslam.agents.baselines.registry import make_baseline

    return make_baseline(name, env)


def resolve_agent(name: str, env_id: str, model: Path | None) -> tuple[str, Any, dict[str, Any]]:
    """``(name, policy, env_kwargs)``. ``"best"`` is the leaderboard's best agent
    (:func:`~.models.best_agent`; printed with the reason), or ``"ppo"`` when a ``model`` is given. A
    ``--model`` the user names must load (:class:`UserError` otherwise); without one, ``"ppo"`` falls back to
    ``"frontier"`` (with a warning) when the shipped policy, torch or stable-baselines3 is unavailable, and so
    does a leaderboard's ``"predictive_frontier"`` without torch."""
    if name not in agent_names():
        raise UserError(f"--agent {name!r}: unknown agent; known: {', '.join(agent_names())}")
    if name == "best" and model is not None:  # a model named on its own is the agent to run
        name = "ppo"
    from_board = name == "best"
    if name == "best":  # the leaderboard's best agent, and the line that says so
        best, why = models.best_agent()
        print(f"--agent best: {best}, {why}")
        name = best if best in agent_names() and best != "best" else "frontier"
    if model is not None and name not in ("ppo", "predictive_frontier", "predictive_chooser"):
        raise UserError("--model: only with --agent ppo, predictive_frontier or predictive_chooser "
                        f"(got --agent {name})")  # fmt: skip
    pretrained = models.PRETRAINED  # read at call time (tests point it elsewhere)
    if name == "predictive_chooser" and model is None:
        model = models.CHOOSER
    path = Path(model) if model is not None else pretrained
    kwargs = model_env_kwargs(path) if name in ("ppo", "predictive_chooser") else {}
    env = make_env(env_id, kwargs, f"{path.with_suffix('.json')}" if kwargs else "--env")
    try:
        if from_board and name == "predictive_frontier":
            try:
                import torch  # noqa: F401
            except ImportError:
                warnings.warn('the leaderboard\'s best agent needs torch (pip install "digslam[train]"); '
                              "using frontier", stacklevel=2)  # fmt: skip
                return "frontier", load_agent("frontier", env), kwargs
        if name == "ppo" and model is None:
            try:
                import sb3_contrib  # noqa: F401
                import stable_baselines3  # noqa: F401
            except ImportError:
                need = 'stable-baselines3, sb3-contrib and torch (pip install "digslam[train]")'
                warnings.warn(f"the shipped learned agent needs {need}; using frontier", stacklevel=2)
                return "frontier", load_agent("frontier", env), kwargs
            if not pretrained.is_file():
                warnings.warn(
                    f"no shipped learned agent at {pretrained}; using the frontier agent", stacklevel=2
                )
                return "frontier", load_agent("frontier", env), kwargs
        return name, load_agent(name, env, model), kwargs
    finally:
        env.close()


__all__ = ["agent_names", "load_agent", "load_ppo", "model_env_kwargs", "resolve_agent"]
