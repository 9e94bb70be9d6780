"""Policies as picklable *specs*: what travels to a Ray worker, which builds the policy there.

A spec is a baseline name (:data:`~digslam.agents.baselines.registry.BASELINES`) or the path of a model
``.zip`` saved by ``digslam train``. :func:`normalize_specs` checks them before any worker starts,
:func:`build_policy` builds one on an env id, :func:`agent_specs` turns the agent names of
``digslam evaluate --ray`` into specs.

>>> normalize_specs({"frontier": "frontier", "ppo": "runs/x/final_model.zip"})
{'frontier': 'frontier', 'ppo': 'runs/x/final_model.zip'}
>>> normalize_specs(["random", "lawnmower"])
{'random': 'random', 'lawnmower': 'lawnmower'}
>>> normalize_specs({"x": "no_such_agent"})  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: policies_spec: 'x' -> 'no_such_agent' is neither a baseline (...) nor an SB3 .zip path
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from digslam.agents.learning import models

if TYPE_CHECKING:  # the policy types; the baselines and gymnasium are imported on use
    from digslam.agents.common.policy import PolicyPredictor

#: A policy as a picklable spec: a baseline name or the path of a saved model (``.zip``).
PolicySpec = str


def normalize_specs(policies_spec: Mapping[str, Any] | Iterable[str]) -> dict[str, str]:
    """``{agent name: spec}`` from a mapping or a list of specs (a list names each agent by its spec).

    Raises:
        ValueError: a spec is neither a baseline name nor a path ending in ``.zip``, or nothing was given.
    """
    items = (
        dict(policies_spec) if isinstance(policies_spec, Mapping) else {str(s): str(s) for s in policies_spec}
    )
    if not items:
        raise ValueError("policies_spec: no agent given")
    from digslam.agents.baselines.registry import BASELINES

    names = tuple(BASELINES)
    out: dict[str, str] = {}
    for name, spec in items.items():
        spec = str(spec)
        if spec not in names and not spec.endswith(".zip"):
            raise ValueError(
                f"policies_spec: {name!r} -> {spec!r} is neither a baseline {names} nor an SB3 .zip path"
            )
        out[str(name)] = spec
    return out


def build_policy(
    spec: PolicySpec, env_id: str, env_kwargs: Mapping[str, Any] | None = None, seed: int | None = None
) -> PolicyPredictor:
    """The policy of ``spec``: ``make_baseline(spec, env, seed=seed)`` for a baseline name, else
    the saved model at ``spec`` as a policy of the low-level environment (:func:`.models.load_ppo`: a
    turn-or-go model mapped to ``(v, ω)``, a goal-selection model as a ``GoalAgent``; ``seed`` unused).

    The environment (made only for its spaces) is closed before returning.
    """
    import gymnasium as gym

    import digslam.envs  # noqa: F401  (registers the ids)
    from digslam.agents.baselines.registry import BASELINES, make_baseline

    if spec in BASELINES:
        env = gym.make(env_id, **dict(env_kwargs or {}))
        try:
            return make_baseline(spec, env, seed=seed)
        finally:
            env.close()
    if not Path(spec).is_file():
        raise ValueError(f"spec: no baseline named {spec!r} and no model file at that path")
    env = gym.make(env_id, **dict(env_kwargs or {}))
    try:
        return models.load_ppo(spec, env)
    finally:
        env.close()


def agent_specs(
    agents: Sequence[str], model: str | Path | None = None
) -> tuple[dict[str, str], dict[str, Any]]:
    """``(specs, env_kwargs)`` for :func:`~.ray_eval.evaluate_ray` from agent names (what ``digslam evaluate
    --ray`` takes): ``"ppo"`` is the saved model ``model`` (None: the shipped policy), whose sidecar gives the
    environment keywords; any other agent is a baseline name.

    Raises:
        FileNotFoundError: ``"ppo"`` is among the agents and there is no model file.
    """
    path = Path(model) if model else models.PRETRAINED
    if "ppo" in agents and not path.is_file():
        raise FileNotFoundError(f"model: no saved policy at {str(path)!r}")
    specs = {a: (str(path) if a == "ppo" else a) for a in agents}
    return specs, (models.model_env_kwargs(path) if "ppo" in specs else {})


__all__ = ["PolicySpec", "agent_specs", "build_policy", "normalize_specs"]
