"""Distributed evaluation on Ray: long-lived actors that keep warm environments and take batches of episodes.

:func:`evaluate_ray` (``digslam evaluate --ray``) and :func:`run_suite_ray` (``digslam benchmark agents
--ray``) start a pool of :class:`EpisodeRunner` actors, one per worker CPU. Each actor is created once; it
imports digslam, builds each environment it is asked for once (cached by id, step budget and keywords,
warmed by one ``reset`` and one ``step`` so that the compiled kernels are loaded) and each policy once
(cached by spec), and then runs *batches*: a contiguous block of map seeds for one agent on one
environment, returning the rows of :func:`~digslam.agents.evaluation.evaluate.run_episode`. The driver
splits every (agent, environment) job into balanced contiguous blocks (:func:`split_batches`, about
:data:`BATCHES_PER_ACTOR` blocks per actor over all jobs, :func:`plan_batches`), hands the next block to
whichever actor is free, and puts the episodes back in map order, so the
:class:`~digslam.agents.evaluation.evaluate.EvalResult` is bit for bit the one of the sequential
:func:`~digslam.agents.evaluation.evaluate.evaluate` on the same seeds (and :func:`run_suite_ray`'s
:class:`~digslam.agents.evaluation.suite.SuiteResult` that of
:func:`~digslam.agents.evaluation.suite.run_suite`). The per-episode overhead of the old one-task-per-episode
scheme (worker imports, cold kernel caches, environment construction) is paid once per actor.

Policies travel as picklable *specs*, built inside the actor by :func:`build_policy`: a baseline name
(:data:`~digslam.agents.baselines.registry.BASELINES`) or the path of an SB3 ``.zip``.

Without ``address`` a local Ray instance is started (``ray.init(num_cpus=...)``) and shut down at the end
(a Ray already initialized in this process is used as it is); with one (``"auto"``,
``"ray://host:10001"``, ``"host:6379"``) the evaluation attaches to that cluster, which must have
``digslam`` installed on every node (see ``docs/ray.md``); the actors are killed at the end either way.

The specs are checked before any Ray start:

>>> normalize_specs({"frontier": "frontier", "ppo": "runs/x/final_model.zip"})
{'frontier': 'frontier', 'ppo': 'runs/x/final_model.zip'}
>>> normalize_specs(["random", "lawnmower"])
{'random': 'random', 'lawnmower': 'lawnmower'}
>>> normalize_specs({"x": "no_such_agent"})  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: policies_spec: 'x' -> 'no_such_agent' is neither a baseline (...) nor an SB3 .zip path

Blocks are contiguous, in map order, and balanced:

>>> split_batches(10, 4)
[(0, 3), (3, 6), (6, 8), (8, 10)]
>>> plan_batches([10, 4], n_actors=2, per_actor=2)
[(0, 0, 5), (0, 5, 10), (1, 0, 2), (1, 2, 4)]
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from digslam.agents.evaluation.evaluate import EvalResult
from digslam.agents.evaluation.suite import SuiteResult, check_generators, merge_agents, suite_plan
from digslam.agents.learning import models

#: Blocks of episodes per actor the driver aims at over the whole evaluation (balance against overhead).
BATCHES_PER_ACTOR = 4

#: Baseline names accepted as specs (mirrors ``digslam.agents.baselines.registry.BASELINES``; checked in the
#: worker).
BASELINE_NAMES = ("random", "lawnmower", "frontier", "uncertainty_frontier", "tour_frontier")

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


def build_policy(
    spec: PolicySpec, env_id: str, env_kwargs: Mapping[str, Any] | None = None, seed: int | None = None
) -> Any:
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
    """Stack per-map results ``{agent: [EvalResult of map 0, map 1, ...]}`` into one ``EvalResult`` (the
    merge of the former one-task-per-episode scheme, kept for callers).

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
                if agent in getattr(ps[0], f.name)  # an unmeasured field (e.g. path lengths) stays empty
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
    """Attach to ``address`` or start a local instance; returns whether this call started Ray.

    A local instance runs its workers at the driver's priority (``worker_niceness`` 0; Ray's default of 15
    lets any other process on the machine starve them, which a sequential run in the driver does not
    suffer); a cluster keeps its own settings."""
    import ray

    if ray.is_initialized():
        return False
    kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False, "configure_logging": False}
    if address is None:  # workers at the driver's priority (Ray's default nices them by 15)
        ray.init(num_cpus=num_cpus, _system_config={"worker_niceness": 0}, **kwargs)
    else:
        if num_cpus is not None:
            raise ValueError("num_cpus: only for a local instance; a cluster has its own resources")
        ray.init(address=address, **kwargs)
    return True


def split_batches(n_maps: int, n_batches: int) -> list[tuple[int, int]]:
    """``[start, stop)`` blocks covering ``range(n_maps)`` in order, at most ``n_batches`` of them (at least
    one, none empty), sizes differing by at most one (the larger first).

    Raises:
        ValueError: ``n_maps < 1``.
    """
    if n_maps < 1:
        raise ValueError(f"n_maps: must be >= 1, got {n_maps}")
    k = max(1, min(int(n_batches), n_maps))
    q, r = divmod(n_maps, k)
    out, start = [], 0
    for i in range(k):
        stop = start + q + (i < r)
        out.append((start, stop))
        start = stop
    return out


def plan_batches(
    job_sizes: Sequence[int], n_actors: int, per_actor: int = BATCHES_PER_ACTOR
) -> list[tuple[int, int, int]]:
    """``(job, start, stop)`` blocks of every job (``job_sizes[j]`` maps), jobs in order, each split by
    :func:`split_batches` into ``ceil(per_actor * n_actors / n_jobs)`` blocks (fewer for a job with fewer
    maps): about ``per_actor`` blocks per actor over all jobs."""
    if not job_sizes:
        return []
    per_job = math.ceil(max(1, per_actor) * max(1, n_actors) / len(job_sizes))
    return [(j, a, b) for j, n in enumerate(job_sizes) for a, b in split_batches(n, per_job)]


def _key(kwargs: Mapping[str, Any] | None) -> tuple[tuple[str, str], ...]:
    """A hashable, order-free key for keyword arguments."""
    return tuple(sorted((str(k), repr(v)) for k, v in (kwargs or {}).items()))


class EpisodeRunner:
    """The body of a long-lived Ray actor: warm environments and policies, batches of episodes.

    Environments are cached by ``(env_id, steps, env_kwargs)`` and warmed on creation (one ``reset`` and one
    ``step``: compiled kernels load once per actor); policies are cached by ``(spec, policy env, seed)``.
    Every episode starts with ``reset(seed=...)`` and the policy's own ``reset``, so a cached environment or
    policy gives the episode a fresh one would (as :func:`~.evaluate.evaluate` reuses one of each over its
    maps).
    """

    def __init__(self) -> None:
        import digslam.envs  # noqa: F401  (registers the environments)

        self.envs: dict[Any, Any] = {}
        self.policies: dict[Any, Any] = {}

    def env(self, env_id: str, steps: int, env_kwargs: Mapping[str, Any] | None) -> Any:
        """The cached, warmed environment of ``evaluate`` for these settings."""
        from digslam.agents.evaluation.evaluate import make_env

        key = (env_id, int(steps), _key(env_kwargs))
        if key not in self.envs:
            env = make_env(env_id, steps, dict(env_kwargs) if env_kwargs else None)
            env.reset(seed=0)
            env.step(np.zeros(env.action_space.shape, dtype=env.action_space.dtype))
            self.envs[key] = env
        return self.envs[key]

    def policy(
        self, spec: PolicySpec, env_id: str, env_kwargs: Mapping[str, Any] | None, seed: int | None
    ) -> Any:
        """The cached policy of ``spec`` (:func:`build_policy`; torch on one thread for an SB3 model)."""
        key = (spec, env_id, _key(env_kwargs), seed)
        if key not in self.policies:
            if spec.endswith(".zip"):
                from digslam.agents.learning.train import pin_threads

                pin_threads(1)
            self.policies[key] = build_policy(spec, env_id, env_kwargs, seed)
        return self.policies[key]

    def run(self, job: Mapping[str, Any], start: int, stop: int) -> list[tuple[Any, ...]]:
        """Episodes ``start .. stop - 1`` of ``job`` (keys ``spec``, ``policy_env``, ``policy_kwargs``,
        ``policy_seed``, ``env_id``, ``steps``, ``env_kwargs``, ``seed``): map ``i`` is
        ``reset(seed=job["seed"] + i)``; the rows of :func:`~.evaluate.run_episode`, in map order."""
        from digslam.agents.evaluation.evaluate import run_episode

        policy = self.policy(job["spec"], job["policy_env"], job["policy_kwargs"], job["policy_seed"])
        env = self.env(job["env_id"], job["steps"], job["env_kwargs"])
        return [run_episode(policy, env, job["seed"] + i, job["steps"]) for i in range(start, stop)]

    def close(self) -> None:
        """Close every cached environment."""
        for env in self.envs.values():
            env.close()
        self.envs.clear()


def result_from_rows(
    rows: Mapping[str, Sequence[tuple[Any, ...]]], env_id: str, seed: int, n_maps: int
) -> EvalResult:
    """The :class:`~.evaluate.EvalResult` of per-agent episode rows (in map order), built as
    :func:`~.evaluate.evaluate` builds it."""
    out: dict[str, dict[str, np.ndarray]] = {k: {} for k in "ctbwnp"}
    for name, rs in rows.items():
        for key, j in zip("ctbwnp", range(6), strict=True):
            out[key][name] = np.array([r[j] for r in rs], dtype=np.float64)
    return EvalResult(out["c"], out["t"], out["b"], out["w"], out["n"], env_id, seed, n_maps, out["p"])


def pool_size(workers: int | None, n_episodes: int) -> int:
    """Actors to start: ``workers`` (None: one per CPU of the Ray instance), at most the instance's CPUs (an
    actor holds one; more would wait forever) and one per episode."""
    import ray

    cpus = max(1, int(ray.cluster_resources().get("CPU", 1)))
    if workers is None:
        workers = cpus
    if workers < 1:
        raise ValueError(f"workers: must be >= 1, got {workers}")
    return max(1, min(int(workers), cpus, n_episodes))


def run_jobs(
    jobs: Sequence[Mapping[str, Any]], workers: int | None = None, progress: bool = False
) -> list[list[tuple[Any, ...]]]:
    """Every job's episode rows (maps ``0 .. job["n_maps"] - 1``, in order) from a pool of
    :class:`EpisodeRunner` actors on the Ray instance this process is attached to.

    The blocks of :func:`plan_batches` go to whichever actor is free (one block in flight per actor); the
    actors are killed at the end.
    """
    import ray

    sizes = [int(j["n_maps"]) for j in jobs]
    n_actors = pool_size(workers, sum(sizes))
    blocks = plan_batches(sizes, n_actors)
    runner = ray.remote(num_cpus=1)(EpisodeRunner)
    actors = [runner.remote() for _ in range(n_actors)]
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=sum(sizes), desc=f"evaluate (ray, {n_actors} actors)", unit="episode")
    parts: dict[int, list[tuple[Any, ...]]] = {}
    try:
        queue, pending = deque(range(len(blocks))), {}
        for actor in actors:
            if queue:
                k = queue.popleft()
                j, a, b = blocks[k]
                pending[actor.run.remote(jobs[j], a, b)] = (k, actor)
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1, timeout=1.0)  # a timeout lets Ctrl-C through
            if not done:
                continue
            k, actor = pending.pop(done[0])
            parts[k] = ray.get(done[0])
            if bar is not None:
                bar.update(len(parts[k]))
            if queue:
                k = queue.popleft()
                j, a, b = blocks[k]
                pending[actor.run.remote(jobs[j], a, b)] = (k, actor)
    finally:
        if bar is not None:
            bar.close()
        for actor in actors:
            ray.kill(actor)
    rows: list[list[tuple[Any, ...]]] = [[] for _ in jobs]
    for k, (j, _, _) in enumerate(blocks):  # blocks are in map order within each job
        rows[j].extend(parts[k])
    return rows


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
    "BATCHES_PER_ACTOR",
    "EpisodeRunner",
    "agent_specs",
    "build_policy",
    "evaluate_one",
    "evaluate_ray",
    "merge_results",
    "normalize_specs",
    "plan_batches",
    "pool_size",
    "result_from_rows",
    "run_jobs",
    "run_suite_ray",
    "split_batches",
    "start_ray",
]
