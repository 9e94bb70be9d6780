"""The coverage benchmark suite: every generator, the test levels, an uncapped metric and a leaderboard.

:func:`run_suite` runs every agent on ``n_maps`` levels of each generator of :data:`GENERATORS` (the
benchmark's generators of the world registry, :data:`digslam.envs.sim.generators.BENCHMARK`; the first
``n_maps`` seeds of a split of :mod:`digslam.envs.splits`, the test split by default; the same levels for
every agent), each episode with ``target=1.0`` (no early end: the curve is not capped) and a step budget of
``steps`` (3000). :class:`SuiteResult` turns the curves into the metrics of :mod:`.metrics` per generator
and writes the leaderboard. Its headline is ``T_level``, the steps to each generator's target level
(:data:`.levels.TARGET_LEVELS`, fixed on the validation split): two Markdown tables (per agent: ``T_level``
per generator with its success rate; and over all maps ``T_level``, T90, AUC and the final pose box, the
geometric mean over the maps of ``T_level(best baseline) / T_level(agent)`` with its paired bootstrap 95 %
interval) and a figure (``T_level`` per generator, and the mean certified coverage curves with their
spread).

>>> curves = {"a": np.array([[0.0, 0.95, 0.95]]), "b": np.array([[0.0, 0.5, 0.91]])}
>>> zero = {"a": np.zeros(1), "b": np.zeros(1)}
>>> r = SuiteResult({"room": EvalResult(curves, {}, zero, zero)}, steps=2)
>>> r.times("T90")["a"].tolist(), r.times("T90")["b"].tolist(), r.best(["a", "b"])
([1.0], [2.0], 'a')
>>> r.times()["b"].tolist(), r.level_name("room")  # the room's target level, 0.95
([2.0], 'T95')
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from digslam.agents.common.policy import PolicyFactory, PolicyPredictor, reset_policy
from digslam.agents.evaluation.evaluate import EvalResult, evaluate
from digslam.agents.evaluation.levels import TARGET_LEVELS, level_metric
from digslam.agents.evaluation.metrics import paired_bootstrap_geomean
from digslam.envs import FLOORPLAN_WORLD_SIZE
from digslam.envs.config import ExploreConfig
from digslam.envs.sim.generators import BENCHMARK

#: The environment id every suite episode runs on (the world is a keyword).
SUITE_ENV = "digslam/DigCoverage-v0"
#: Generator -> the keywords of its levels beside ``world``: the floorplan levels are windows of
#: ``2 * FLOORPLAN_WORLD_SIZE`` metres (:data:`digslam.envs.FLOORPLAN_WORLD_SIZE`, as
#: ``digslam/DigCoverageFloorplan-v0``), the procedural ones the default frame.
WORLD_KWARGS: dict[str, dict[str, Any]] = {"floorplan": {"world_size": FLOORPLAN_WORLD_SIZE}}
#: Generator name -> (environment id, keywords): the suite's worlds, those of
#: :data:`~digslam.envs.sim.generators.BENCHMARK` in its order (the default world needs no keyword), each
#: with its :data:`WORLD_KWARGS`.
GENERATORS: dict[str, tuple[str, dict[str, Any]]] = {
    name: (SUITE_ENV, ({} if name == ExploreConfig.world else {"world": name}) | WORLD_KWARGS.get(name, {}))
    for name in BENCHMARK
}
#: What every suite episode runs with: no early end, so the metric is not capped at 0.8.
SUITE_KWARGS: dict[str, Any] = {"target": 1.0}


@dataclass
class SuiteResult:
    """Per generator, the :class:`~.evaluate.EvalResult` of every agent on the same levels.

    Attributes:
        results: generator -> its evaluation (curves of ``steps + 1`` points per episode).
        steps: the step budget (an unreached level counts as ``steps``).
        split, seeds: the levels run (``seeds[i]`` is map ``i`` of every generator).
    """

    results: dict[str, EvalResult]
    steps: int
    split: str = "test"
    seeds: list[int] = field(default_factory=list)

    @property
    def agents(self) -> list[str]:
        """The agents, in the order they ran."""
        return list(next(iter(self.results.values())).curves) if self.results else []

    def metrics(self) -> dict[str, dict[str, dict[str, np.ndarray]]]:
        """generator -> agent -> metric -> ``(n_maps,)`` (:meth:`.evaluate.EvalResult.metrics`)."""
        return {g: r.metrics() for g, r in self.results.items()}

    def level_name(self, generator: str) -> str:
        """The metric of ``generator``'s target level (``"T95"`` for 0.95; :data:`.levels.TARGET_LEVELS`,
        ``"T90"`` for a generator without one)."""
        return level_metric(TARGET_LEVELS[generator]) if generator in TARGET_LEVELS else "T90"

    def times(self, level: str | None = None) -> dict[str, np.ndarray]:
        """agent -> the ``level`` metric (``"T90"``, ``"S90"``, ...) over every map of every generator,
        generators in order (paired across agents); None: each generator's target level, ``T_level``."""
        m = self.metrics()
        return {a: np.concatenate([m[g][a][level or self.level_name(g)] for g in self.results])
                for a in self.agents}  # fmt: skip

    def t90(self, level: str = "T90") -> dict[str, np.ndarray]:
        """:meth:`times` at a fixed level (``"T90"`` by default) on every generator."""
        return self.times(level)

    def _rank(self, agent: str, level: str | None = None) -> tuple[float, float]:
        """Sort key: the mean ``level`` (None: ``T_level``) over all maps, then the larger mean AUC."""
        m = self.metrics()
        auc = np.concatenate([m[g][agent]["AUC"] for g in self.results])
        return float(np.mean(self.times(level)[agent])), -float(np.mean(auc))

    def best(self, candidates: Iterable[str], level: str | None = None, generator: str | None = None) -> str:
        """The candidate with the smallest mean ``level`` (None: ``T_level``) over all maps, or over the maps
        of one ``generator`` (ties: the larger mean AUC, then the first)."""
        names = [a for a in candidates if a in self.agents]
        if not names:
            raise ValueError("candidates: none of them ran")
        if generator is not None:
            part = SuiteResult({generator: self.results[generator]}, self.steps, self.split, self.seeds)
            return part.best(names, level)
        return min(names, key=lambda a: (*self._rank(a, level), names.index(a)))

    def success(self, agent: str, level: str | None = None) -> float:
        """Share of all maps on which ``agent`` reached the level (``"S90"``: 0.9 certified coverage; None:
        each generator's target level)."""
        if level is not None:
            return float(np.mean(self.times(level)[agent]))
        m = self.metrics()
        flags = [m[g][agent]["S" + self.level_name(g)[1:]] for g in self.results]
        return float(np.mean(np.concatenate(flags)))

    def table(self, baselines: Sequence[str]) -> str:
        """The leaderboard (Markdown): the two tables of :meth:`tables`, a blank line between them."""
        return "\n\n".join(self.tables(baselines))

    def tables(self, baselines: Sequence[str]) -> tuple[str, str]:
        """The leaderboard as two Markdown tables, agents sorted by mean ``T_level`` over all maps (then AUC)
        in both: per generator, ``T_level`` with its success rate; over all maps, ``T_level`` (success),
        T90, AUC, the final pose box and the ratio column, the geometric mean over the maps of
        ``T_level(best baseline) / T_level(agent)`` (> 1: faster than the best baseline) with its paired
        bootstrap 95 % interval. (Two tables, so that each fits a page's width.)"""
        m, t, t90 = self.metrics(), self.times(), self.times("T90")
        best = self.best(baselines) if any(b in t for b in baselines) else None
        gens = list(self.results)
        head = ["agent"] + [f"{self.level_name(g)} {g} (success)" for g in gens]
        head2 = ["agent", "T_level all (success)", "T90 all", "AUC", "final pose box (m)",
                 "speedup vs best baseline [95 % CI]"]  # fmt: skip
        lines = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
        lines2 = ["| " + " | ".join(head2) + " |", "|---" * len(head2) + "|"]
        for a in sorted(self.agents, key=self._rank):
            cells = [a]
            for g in gens:
                lv = self.level_name(g)
                cells.append(f"{np.mean(m[g][a][lv]):.0f} ({np.mean(m[g][a]['S' + lv[1:]]):.0%})")
            lines.append("| " + " | ".join(cells) + " |")
            auc = np.concatenate([m[g][a]["AUC"] for g in gens])
            box = np.concatenate([m[g][a]["final_tube"] for g in gens])
            cells = [a, f"{np.mean(t[a]):.0f} ({self.success(a):.0%})", f"{np.mean(t90[a]):.0f}"]
            cells += [f"{np.mean(auc):.3f}", f"{np.nanmean(box):.3f}" if np.isfinite(box).any() else "n/a"]
            if best is None:
                cells.append("n/a")
            else:
                r, lo, hi = paired_bootstrap_geomean(t[best], t[a])
                cells.append(f"{r:.3f} [{lo:.3f}, {hi:.3f}]" + (" (best baseline)" if a == best else ""))
            lines2.append("| " + " | ".join(cells) + " |")
        return "\n".join(lines), "\n".join(lines2)

    def figure(self, path: str | Path) -> Path:
        """``T_level`` per generator (bars, mean over the maps, with the spread as error bars) beside the mean
        certified coverage against steps (all maps of all generators, ± one standard deviation); returns the
        path written (matplotlib, Agg)."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        m, gens, agents = self.metrics(), list(self.results), self.agents
        fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11.0, 4.0), dpi=110)
        width = 0.8 / max(len(agents), 1)
        for k, a in enumerate(agents):
            mean = [float(np.mean(m[g][a][self.level_name(g)])) for g in gens]
            sd = [float(np.std(m[g][a][self.level_name(g)])) for g in gens]
            ax0.bar(np.arange(len(gens)) + (k - (len(agents) - 1) / 2) * width, mean, width, yerr=sd,
                    label=a, color=f"C{k}", capsize=2)  # fmt: skip
            curves = np.concatenate([self.results[g].curves[a] for g in gens])
            mu, s = curves.mean(axis=0), curves.std(axis=0)
            x = np.arange(mu.size)
            ax1.plot(x, mu, color=f"C{k}", label=a)
            ax1.fill_between(x, np.clip(mu - s, 0, 1), np.clip(mu + s, 0, 1), color=f"C{k}", alpha=0.15)
        ax0.set_xticks(np.arange(len(gens)), [f"{g} ({self.level_name(g)})" for g in gens])
        ax0.set_ylabel(f"T_level (steps; {self.steps} = not reached)")
        ax0.set_title("steps to each generator's target level")
        for g in gens:
            ax1.axhline(TARGET_LEVELS.get(g, 0.9), color="grey", lw=0.8, ls=":")
        ax1.set_xlabel("step")
        ax1.set_ylabel("certified coverage")
        ax1.set_ylim(0, 1)
        ax1.set_title(f"mean over {len(gens)} generators x {len(self.seeds)} {self.split} maps")
        ax1.legend(loc="lower right", fontsize=8)
        fig.tight_layout()
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(out)
        plt.close(fig)
        return out

    def to_json(self, path: str | Path) -> Path:
        """Write every generator's curves and metrics as JSON; returns the path."""
        data = {
            "steps": self.steps, "split": self.split, "seeds": self.seeds,
            "generators": {g: {"curves": {a: c.tolist() for a, c in r.curves.items()},
                               "true_curves": {a: c.tolist() for a, c in r.true_curves.items()},
                               "metrics": {a: {k: v.tolist() for k, v in mm.items()}
                                           for a, mm in r.metrics().items()}}
                           for g, r in self.results.items()},
        }  # fmt: skip
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(data).replace("NaN", "null"))
        return out

    @classmethod
    def from_json(cls, path: str | Path) -> SuiteResult:
        """Read a suite written by :meth:`to_json` (curves, and the collisions, final pose box and path
        length of its metrics); several runs of other agents on the same levels merge with :func:`merge`.

        Raises:
            ValueError: the file is not a suite's JSON.
        """
        try:
            data = json.loads(Path(path).read_text())
            results = {}
            for g, d in data["generators"].items():
                met = {a: {k: np.array([np.nan if x is None else x for x in v], dtype=np.float64)
                           for k, v in mm.items()} for a, mm in d["metrics"].items()}  # fmt: skip
                results[g] = EvalResult(
                    curves={a: np.array(c, dtype=np.float64) for a, c in d["curves"].items()},
                    true_curves={
                        a: np.array(c, dtype=np.float64) for a, c in d.get("true_curves", {}).items()
                    },
                    collisions={a: met[a]["collisions"] for a in met},
                    final_tube_width={a: met[a]["final_tube"] for a in met},
                    path_lengths={a: met[a]["path_length"] for a in met},
                )
            return cls(
                results, int(data["steps"]), str(data.get("split", "test")), list(data.get("seeds", []))
            )
        except (KeyError, TypeError, json.JSONDecodeError) as exc:
            raise ValueError(f"path: {path} is not a suite JSON ({exc!r})") from None


def merge(parts: Sequence[SuiteResult]) -> SuiteResult:
    """One suite of every part's agents: the parts ran the same levels (split, seeds and steps), each its
    own agents (or the same generators for several agents).

    Raises:
        ValueError: the parts ran different levels or step budgets.
    """
    first = parts[0]
    for p in parts[1:]:
        if (p.steps, p.split, list(p.seeds)) != (first.steps, first.split, list(first.seeds)):
            raise ValueError(
                "parts: ran different levels or step budgets; merge only runs of the same levels"
            )
    results: dict[str, EvalResult] = {}
    for p in parts:
        for g, r in p.results.items():
            results[g] = merge_agents([results[g], r]) if g in results else r
    return SuiteResult(results, first.steps, first.split, list(first.seeds))


def run_suite(
    policies: Mapping[str, PolicyPredictor | PolicyFactory],
    n_maps: int = 30,
    steps: int = 3000,
    split: str = "test",
    generators: Sequence[str] | None = None,
    agent_env_kwargs: Mapping[str, Mapping[str, Any]] | None = None,
    progress: bool = False,
) -> SuiteResult:
    """Every policy on the first ``n_maps`` levels of ``split`` of each generator (:data:`GENERATORS`, all
    by default), ``target=1.0`` and ``steps`` steps each; ``agent_env_kwargs[name]`` adds environment keywords
    for one agent (a learned policy's observation settings: they change what it sees, not the levels).

    The same suite on Ray workers (policies given as specs) is
    :func:`digslam.agents.evaluation.ray_eval.run_suite_ray`, with an identical result."""
    from digslam.envs.splits import seeds as split_seeds

    gens = check_generators(generators)
    levels = split_seeds(split, n_maps)
    results: dict[str, EvalResult] = {}
    for g, env_id, env_kwargs, group in suite_plan(list(policies), gens, agent_env_kwargs):
        part = evaluate({a: policies[a] for a in group}, env_id, n_maps=n_maps, seed=levels[0], steps=steps,
                        env_kwargs=env_kwargs, progress=progress)  # fmt: skip
        results[g] = merge_agents([results[g], part]) if g in results else part
    return SuiteResult(results, steps, split, levels)


def check_generators(generators: Sequence[str] | None) -> list[str]:
    """The generators to run (all of :data:`GENERATORS` for None), checked.

    Raises:
        ValueError: an unknown generator name.
    """
    gens = list(generators) if generators is not None else list(GENERATORS)
    unknown = [g for g in gens if g not in GENERATORS]
    if unknown:
        raise ValueError(f"generators: unknown {unknown}; known: {list(GENERATORS)}")
    return gens


def suite_plan(
    agents: Sequence[str], generators: Sequence[str], agent_env_kwargs: Mapping[str, Mapping[str, Any]] | None
) -> list[tuple[str, str, dict[str, Any], list[str]]]:
    """The suite's evaluations, in order: ``(generator, env_id, env_kwargs, agents)``; per generator, the
    agents without extra keywords together, then each agent of ``agent_env_kwargs`` on its own keywords.

    >>> [(g, kw, a) for g, _, kw, a in suite_plan(["f", "ppo"], ["room"], {"ppo": {"crop": 4.0}})]
    [('room', {'target': 1.0}, ['f']), ('room', {'target': 1.0, 'crop': 4.0}, ['ppo'])]
    """
    extra = {k: dict(v) for k, v in (agent_env_kwargs or {}).items()}
    plan = []
    for g in generators:
        env_id, kw = GENERATORS[g]
        plain = [a for a in agents if a not in extra]
        groups: list[tuple[list[str], dict[str, Any]]] = [(plain, {})] if plain else []
        groups += [([a], extra[a]) for a in extra if a in agents]
        plan += [(g, env_id, {**kw, **SUITE_KWARGS, **more}, group) for group, more in groups]
    return plan


def merge_agents(parts: Sequence[EvalResult]) -> EvalResult:
    """One :class:`~.evaluate.EvalResult` holding every part's agents (the same maps), in order."""
    first = parts[0]
    out = EvalResult({}, {}, {}, {}, {}, first.env_id, first.seed, first.n_maps, {})
    for p in parts:
        for mine, theirs in ((out.curves, p.curves), (out.true_curves, p.true_curves),
                             (out.collisions, p.collisions), (out.final_tube_width, p.final_tube_width),
                             (out.lengths, p.lengths), (out.path_lengths, p.path_lengths)):  # fmt: skip
            mine.update(theirs)
    return out


def steps_per_second(policy: PolicyPredictor, env_id: str = SUITE_ENV, steps: int = 2000, seed: int = 0,
                     env_kwargs: Mapping[str, Any] | None = None) -> float:  # fmt: skip
    """Observed environment steps per second of ``policy`` driving one environment in this process (the
    policy's own time included), resetting to the next level whenever an episode ends; timed after one
    untimed step (compiled kernels loaded). :func:`eval_rates` also gives the env's own share."""
    return eval_rates(policy, env_id, steps, seed, env_kwargs)[0]


def eval_rates(policy: PolicyPredictor, env_id: str = SUITE_ENV, steps: int = 2000, seed: int = 0,
               env_kwargs: Mapping[str, Any] | None = None) -> tuple[float, float]:  # fmt: skip
    """``(eval steps/s, observed env steps/s)`` of one run of ``policy`` (see :func:`steps_per_second`): the
    first counts the agent's ``predict`` and the env's ``step`` (resets included), the second the env's
    alone, on the same path, timed call by call in the same loop. Their ratio is ``eval_over_observed``: the
    share of the observed env's speed an evaluation keeps (1 for an agent that costs nothing)."""
    import time

    from digslam.agents.evaluation.evaluate import make_env

    env = make_env(env_id, steps + 1, {**SUITE_KWARGS, **dict(env_kwargs or {})})
    clock = time.perf_counter
    try:
        reset_policy(policy)
        obs, _ = env.reset(seed=seed)
        obs = env.step(np.asarray(policy.predict(obs)[0], np.float32))[0]
        t_agent = t_env = 0.0
        for _ in range(steps):
            t0 = clock()
            action = np.asarray(policy.predict(obs)[0], np.float32)
            t1 = clock()
            obs, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                seed += 1
                obs, _ = env.reset(seed=seed)
            t_env += clock() - t1
            t_agent += t1 - t0
        return steps / (t_agent + t_env), steps / t_env
    finally:
        env.close()


__all__ = [
    "GENERATORS",
    "SUITE_ENV",
    "SUITE_KWARGS",
    "SuiteResult",
    "WORLD_KWARGS",
    "check_generators",
    "eval_rates",
    "merge",
    "merge_agents",
    "run_suite",
    "steps_per_second",
    "suite_plan",
]
