"""Distributed evaluation on Ray: one task per (agent, map), merged into the single-machine result.

:func:`evaluate_ray` runs :func:`~digslam.agents.evaluation.evaluate.evaluate` in Ray workers, one task per
pair
``(agent, map i)`` with ``n_maps=1`` and ``seed=seed + i`` (map ``i`` of the single-machine evaluation is
``reset(seed=seed + i)``), and stacks the episodes back in map order, so the
:class:`~digslam.agents.evaluation.evaluate.EvalResult` is the one :func:`evaluate` gives on the same seeds
(same
table, same figures). Policies travel as picklable *specs*, built inside the worker by :func:`build_policy`:
a baseline name (:data:`~digslam.agents.baselines.registry.BASELINES`) or the path of an SB3 ``.zip``.

Without ``address`` a local Ray instance is started (``ray.init(num_cpus=...)``) and shut down at the end;
with one (``"auto"``, ``"ray://host:10001"``, ``"host:6379"``) the evaluation attaches to that cluster,
which must have ``digslam`` installed on every node (see ``docs/ray.md``).

The specs are checked before any Ray start:

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

import dataclasses
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from digslam.agents.learning import models

#: Baseline names accepted as specs (mirrors ``digslam.agents.baselines.registry.BASELINES``; checked in the
#: worker).
BASELINE_NAMES = ("random", "lawnmower", "frontier", "uncertainty_frontier")

PolicySpec = str


def _baseline_names() -> tuple[str, ...]:
    try:
        from digslam.agents.baselines.registry import BASELINES
    except ImportError:  # pragma: no cover - baselines.py not there yet
        return BASELINE_NAMES
    return tuple(BASELINES)


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
    names = _baseline_names()
    out: dict[str, str] = {}
    for name, spec in items.items():
        spec = str(spec)
        if spec not in names and not spec.endswith(".zip"):
            raise ValueError(
                f"policies_spec: {name!r} -> {spec!r} is neither a baseline {names} nor an SB3 .zip path"
            )
        out[str(name)] = spec
    return out


def build_policy(spec: PolicySpec, env_id: str, env_kwargs: Mapping[str, Any] | None = None) -> Any:
    """The policy of ``spec``: ``make_baseline(spec, env)`` for a baseline name, else ``PPO.load(spec)``.

    The environment (made only for its spaces) is closed before returning.
    """
    import gymnasium as gym

    import digslam.envs  # noqa: F401  (registers the ids)
    from digslam.agents.baselines.registry import BASELINES, make_baseline

    if spec in BASELINES:
        env = gym.make(env_id, **dict(env_kwargs or {}))
        try:
            return make_baseline(spec, env)
        finally:
            env.close()
    if not Path(spec).is_file():
        raise ValueError(f"spec: no baseline named {spec!r} and no model file at that path")
    from stable_baselines3 import PPO

    return PPO.load(spec, device="cpu")


def evaluate_one(
    name: str, spec: PolicySpec, env_id: str, seed: int, steps: int, env_kwargs: Mapping[str, Any] | None
) -> Any:
    """One episode (the map ``reset(seed=seed)``) of agent ``name``: ``evaluate`` with ``n_maps=1``."""
    from digslam.agents.evaluation.evaluate import evaluate

    if spec.endswith(".zip"):  # torch only for SB3 models (a baseline's worker need not import it)
        from digslam.agents.learning.train import pin_threads

        pin_threads(1)
    policy = build_policy(spec, env_id, env_kwargs)
    return evaluate({name: policy}, env_id=env_id, n_maps=1, seed=seed, steps=steps,
                    env_kwargs=dict(env_kwargs) if env_kwargs else None)  # fmt: skip


def merge_results(parts: Mapping[str, list[Any]], seed: int, n_maps: int) -> Any:
    """Stack per-map results ``{agent: [EvalResult of map 0, map 1, ...]}`` into one ``EvalResult``.

    Fields that map agents to per-episode arrays are concatenated along the episode axis, in map order;
    ``seed``/``n_maps`` fields take the whole evaluation's values; any other field comes from the first part.
    """
    first = next(iter(parts.values()))[0]
    values: dict[str, Any] = {}
    for f in dataclasses.fields(first):
        v = getattr(first, f.name)
        if isinstance(v, Mapping) and all(isinstance(x, np.ndarray) for x in v.values()):
            values[f.name] = {
                agent: np.concatenate([np.asarray(getattr(p, f.name)[agent]) for p in ps], axis=0)
                for agent, ps in parts.items()
            }
        elif f.name == "seed":
            values[f.name] = seed
        elif f.name == "n_maps":
            values[f.name] = n_maps
        elif isinstance(v, Mapping):  # per-agent metadata
            values[f.name] = {k: x for ps in parts.values() for k, x in getattr(ps[0], f.name).items()}
        else:
            values[f.name] = v
    return type(first)(**values)


def start_ray(address: str | None, num_cpus: int | None) -> bool:
    """Attach to ``address`` or start a local instance; returns whether this call started Ray."""
    import ray

    if ray.is_initialized():
        return False
    kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False, "configure_logging": False}
    if address is None:
        ray.init(num_cpus=num_cpus, **kwargs)
    else:
        if num_cpus is not None:
            raise ValueError("num_cpus: only for a local instance; a cluster has its own resources")
        ray.init(address=address, **kwargs)
    return True


def evaluate_ray(
    policies_spec: Mapping[str, Any] | Iterable[str],
    env_id: str = "digslam/DigCoverage-v0",
    n_maps: int = 20,
    seed: int = 1000,
    steps: int = 3000,
    env_kwargs: Mapping[str, Any] | None = None,
    address: str | None = None,
    num_cpus: int | None = None,
) -> Any:
    """``evaluate`` distributed over Ray, one task per (agent, map); see the module docstring.

    Args:
        policies_spec: ``{agent name: spec}`` (baseline name or SB3 ``.zip`` path) or a list of specs.
        env_id, n_maps, seed, steps, env_kwargs: as in :func:`~digslam.agents.evaluation.evaluate.evaluate`.
        address: Ray cluster to attach to; None starts a local instance (shut down at the end).
        num_cpus: CPUs of the local instance (None: all); not allowed with ``address``.

    Returns:
        The :class:`~digslam.agents.evaluation.evaluate.EvalResult` of ``evaluate`` on the same seeds.
    """
    specs = normalize_specs(policies_spec)
    if n_maps < 1:
        raise ValueError(f"n_maps: must be >= 1, got {n_maps}")
    if steps < 1:
        raise ValueError(f"steps: must be >= 1, got {steps}")
    import ray

    started = start_ray(address, num_cpus)
    try:
        task = ray.remote(num_cpus=1)(evaluate_one)
        kw = dict(env_kwargs) if env_kwargs else None
        refs = {name: [task.remote(name, spec, env_id, seed + i, steps, kw) for i in range(n_maps)]
                for name, spec in specs.items()}  # fmt: skip
        parts = {name: ray.get(rs) for name, rs in refs.items()}
    finally:
        if started:
            ray.shutdown()
    return merge_results(parts, seed, n_maps)


def agent_specs(
    agents: Sequence[str], model: str | Path | None = None
) -> tuple[dict[str, str], dict[str, Any]]:
    """``(specs, env_kwargs)`` for :func:`evaluate_ray` from agent names (what ``digslam evaluate --ray``
    takes): ``"ppo"`` is the saved model ``model`` (None: the shipped policy), whose sidecar gives the
    environment keywords; any other agent is a baseline name.

    Raises:
        FileNotFoundError: ``"ppo"`` is among the agents and there is no model file.
    """
    path = Path(model) if model else models.PRETRAINED
    if "ppo" in agents and not path.is_file():
        raise FileNotFoundError(f"model: no saved policy at {str(path)!r}")
    specs = {a: (str(path) if a == "ppo" else a) for a in agents}
    return specs, (models.model_env_kwargs(path) if "ppo" in specs else {})


__all__ = [
    "agent_specs",
    "build_policy",
    "evaluate_one",
    "evaluate_ray",
    "merge_results",
    "normalize_specs",
    "start_ray",
]
