"""An evaluation in blocks of episodes, and its results put back together in map order.

:func:`split_batches` cuts one job (an agent on an environment, ``n_maps`` maps) into balanced contiguous
blocks; :func:`plan_batches` does so for every job of an evaluation, about :data:`BATCHES_PER_ACTOR` blocks
per worker over all jobs (balance against per-block overhead). :func:`result_from_rows` builds the
:class:`~.evaluate.EvalResult` of the episode rows of :func:`~.evaluate.run_episode` in map order, as
:func:`~.evaluate.evaluate` does; :func:`merge_results` stacks per-map results.

>>> split_batches(10, 4)
[(0, 3), (3, 6), (6, 8), (8, 10)]
>>> plan_batches([10, 4], n_actors=2, per_actor=2)
[(0, 0, 5), (0, 5, 10), (1, 0, 2), (1, 2, 4)]
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from digslam.agents.evaluation.evaluate import EvalResult

#: Blocks of episodes per actor the driver aims at over the whole evaluation (balance against overhead).
BATCHES_PER_ACTOR = 4


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


def merge_results(parts: Mapping[str, list[EvalResult]], seed: int, n_maps: int) -> EvalResult:
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


__all__ = ["BATCHES_PER_ACTOR", "merge_results", "plan_batches", "result_from_rows", "split_batches"]
