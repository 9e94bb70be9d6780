"""A pool of long-lived Ray actors that keep warm environments and run batches of episodes.

:class:`EpisodeRunner` is the body of an actor: created once, it imports digslam, builds each environment
it is asked for once (cached by id, step budget and keywords, warmed by one ``reset`` and one ``step`` so
that the compiled kernels are loaded) and each policy once (cached by spec, :func:`~.specs.build_policy`),
then runs *batches*: a contiguous block of map seeds for one agent on one environment, returning the rows
of :func:`~.evaluate.run_episode`. :func:`run_jobs` hands the blocks of :func:`~.batches.plan_batches` to
whichever actor is free and returns every job's rows in map order. :func:`start_ray` attaches to a cluster
or starts a local instance.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from digslam.agents.evaluation.batches import plan_batches
from digslam.agents.evaluation.specs import PolicySpec, build_policy

if TYPE_CHECKING:  # gymnasium and the policy types for the annotations only
    import gymnasium as gym

    from digslam.agents.common.policy import PolicyPredictor


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

        self.envs: dict[tuple[Any, ...], gym.Env] = {}
        self.policies: dict[tuple[Any, ...], PolicyPredictor] = {}

    def env(self, env_id: str, steps: int, env_kwargs: Mapping[str, Any] | None) -> gym.Env:
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
    ) -> PolicyPredictor:
        """The cached policy of ``spec`` (:func:`build_policy`; torch on one thread for an SB3 model)."""
        key = (spec, env_id, _key(env_kwargs), seed)
        if key not in self.policies:
            if spec.endswith(".zip"):
                from digslam.agents.learning.vec_env import pin_threads

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


__all__ = ["EpisodeRunner", "pool_size", "run_jobs", "start_ray"]
