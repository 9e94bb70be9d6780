"""Distributed evaluation on Ray: long-lived actors that keep warm environments and take batches of episodes.

:func:`evaluate_ray` (``digslam evaluate --ray``) and :func:`run_suite_ray` (``digslam benchmark agents
--ray``) start a pool of :class:`~.ray_pool.EpisodeRunner` actors, one per worker CPU. Each actor is
created once; it imports digslam, builds each environment it is asked for once (cached by id, step budget
and keywords, warmed by one ``reset`` and one ``step`` so that the compiled kernels are loaded) and each
policy once (cached by spec), and then runs *batches*: a contiguous block of map seeds for one agent on one
environment, returning the rows of :func:`~digslam.agents.evaluation.evaluate.run_episode`. The driver
splits every (agent, environment) job into balanced contiguous blocks (:mod:`.batches`), hands the next
block to whichever actor is free (:mod:`.ray_pool`), and puts the episodes back in map order, so the
:class:`~digslam.agents.evaluation.evaluate.EvalResult` is bit for bit the one of the sequential
:func:`~digslam.agents.evaluation.evaluate.evaluate` on the same seeds (and :func:`run_suite_ray`'s
:class:`~digslam.agents.evaluation.suite.SuiteResult` that of
:func:`~digslam.agents.evaluation.suite.run_suite`). Worker imports, warm kernel caches and environment
construction are paid once per actor, not once per episode.

Policies travel as picklable *specs* (:mod:`.specs`), built inside the actor: a baseline name
(:data:`~digslam.agents.baselines.registry.BASELINES`) or the path of an SB3 ``.zip``; they are checked
before any Ray start.

Without ``address`` a local Ray instance is started (``ray.init(num_cpus=...)``) and shut down at the end
(a Ray already initialized in this process is used as it is); with one (``"auto"``,
``"ray://host:10001"``, ``"host:6379"``) the evaluation attaches to that cluster, which must have
``digslam`` installed on every node (see ``docs/ray.md``); the actors are killed at the end either way.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from digslam.agents.evaluation.batches import result_from_rows
from digslam.agents.evaluation.evaluate import EvalResult, evaluate
from digslam.agents.evaluation.ray_pool import run_jobs, start_ray
from digslam.agents.evaluation.specs import PolicySpec, build_policy, normalize_specs
from digslam.agents.evaluation.suite import SuiteResult, check_generators, merge_agents, suite_plan


def evaluate_one(
    name: str, spec: PolicySpec, env_id: str, seed: int, steps: int, env_kwargs: Mapping[str, Any] | None
) -> EvalResult:
    """One episode (the map ``reset(seed=seed)``) of agent ``name``: ``evaluate`` with ``n_maps=1``."""
    if spec.endswith(".zip"):  # torch only for SB3 models (a baseline's worker need not import it)
        from digslam.agents.learning.vec_env import pin_threads

        pin_threads(1)
    policy = build_policy(spec, env_id, env_kwargs)
    return evaluate({name: policy}, env_id=env_id, n_maps=1, seed=seed, steps=steps,
                    env_kwargs=dict(env_kwargs) if env_kwargs else None)  # fmt: skip


def evaluate_ray(
    policies_spec: Mapping[str, Any] | Iterable[str],
    env_id: str = "digslam/DigCoverage-v0",
    n_maps: int = 20,
    seed: int = 1000,
    steps: int = 3000,
    env_kwargs: Mapping[str, Any] | None = None,
    address: str | None = None,
    num_cpus: int | None = None,
    workers: int | None = None,
    policy_seed: int | None = None,
    progress: bool = False,
) -> EvalResult:
    """``evaluate`` on a pool of long-lived Ray actors taking batches of episodes; see the module docstring.

    Args:
        policies_spec: ``{agent name: spec}`` (baseline name or SB3 ``.zip`` path) or a list of specs.
        env_id, n_maps, seed, steps, env_kwargs: as in :func:`~digslam.agents.evaluation.evaluate.evaluate`.
        address: Ray cluster to attach to; None starts a local instance (shut down at the end).
        num_cpus: CPUs of the local instance (None: all); not allowed with ``address``.
        workers: actors (None: one per CPU of the instance).
        policy_seed: the baselines' seed (``make_baseline(..., seed=)``; only the random agent uses it).
        progress: a progress bar over the episodes.

    Returns:
        The :class:`~digslam.agents.evaluation.evaluate.EvalResult` of ``evaluate`` on the same seeds, with
        the policies ``build_policy(spec, env_id, env_kwargs, policy_seed)``.
    """
    specs = normalize_specs(policies_spec)
    if n_maps < 1:
        raise ValueError(f"n_maps: must be >= 1, got {n_maps}")
    if steps < 1:
        raise ValueError(f"steps: must be >= 1, got {steps}")
    import ray

    kw = dict(env_kwargs) if env_kwargs else None
    jobs = [{"spec": spec, "policy_env": env_id, "policy_kwargs": kw, "policy_seed": policy_seed,
             "env_id": env_id, "steps": steps, "env_kwargs": kw, "seed": seed, "n_maps": n_maps}
            for spec in specs.values()]  # fmt: skip
    started = start_ray(address, num_cpus)
    try:
        rows = run_jobs(jobs, workers if workers is not None else num_cpus, progress)
    finally:
        if started:
            ray.shutdown()
    return result_from_rows(dict(zip(specs, rows, strict=True)), env_id, seed, n_maps)


def run_suite_ray(
    policies_spec: Mapping[str, Any] | Iterable[str],
    n_maps: int = 30,
    steps: int = 3000,
    split: str = "test",
    generators: Sequence[str] | None = None,
    agent_env_kwargs: Mapping[str, Mapping[str, Any]] | None = None,
    address: str | None = None,
    workers: int | None = None,
    policy_env: str = "digslam/DigCoverage-v0",
    policy_seed: int | None = 0,
    progress: bool = False,
) -> SuiteResult:
    """:func:`~digslam.agents.evaluation.suite.run_suite` on a pool of Ray actors: the same levels, episodes
    and :class:`~digslam.agents.evaluation.suite.SuiteResult` as ``run_suite`` with the policies
    ``build_policy(spec, policy_env, None, policy_seed)`` (what ``benchmarks/bench_agents.py`` builds:
    baselines sized from the default environment, seed 0). Every (generator, agent) pair is one job; the
    blocks of all jobs share one pool, so generators run side by side.

    Args:
        policies_spec: ``{agent name: spec}`` or a list of specs (see :func:`normalize_specs`).
        n_maps, steps, split, generators, agent_env_kwargs: as in ``run_suite``.
        address: Ray cluster to attach to; None starts a local instance with ``workers`` CPUs (None: all)
            and shuts it down at the end (a Ray already initialized here is used as it is).
        workers: actors (None: one per CPU of the instance).
        policy_env, policy_seed: the environment id the baselines are sized from, and their seed.
        progress: a progress bar over the episodes.
    """
    from digslam.envs.splits import seeds as split_seeds

    specs = normalize_specs(policies_spec)
    gens = check_generators(generators)
    if steps < 1:
        raise ValueError(f"steps: must be >= 1, got {steps}")
    if workers is not None and workers < 1:
        raise ValueError(f"workers: must be >= 1, got {workers}")
    levels = split_seeds(split, n_maps)
    plan = suite_plan(list(specs), gens, agent_env_kwargs)
    jobs = [{"spec": specs[a], "policy_env": policy_env, "policy_kwargs": None, "policy_seed": policy_seed,
             "env_id": env_id, "steps": steps, "env_kwargs": kw, "seed": levels[0], "n_maps": n_maps}
            for _, env_id, kw, group in plan for a in group]  # fmt: skip
    import ray

    started = start_ray(address, workers if address is None else None)
    try:
        rows = run_jobs(jobs, workers, progress)
    finally:
        if started:
            ray.shutdown()
    results: dict[str, EvalResult] = {}
    it = iter(rows)
    for g, env_id, _, group in plan:
        part = result_from_rows({a: next(it) for a in group}, env_id, levels[0], n_maps)
        results[g] = merge_agents([results[g], part]) if g in results else part
    return SuiteResult(results, steps, split, levels)


__all__ = ["evaluate_one", "evaluate_ray", "run_suite_ray"]
