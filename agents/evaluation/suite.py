"""The coverage benchmark suite: every generator, the test levels, an uncapped metric and a leaderboard.

:func:`run_suite` runs every agent on ``n_maps`` levels of each generator of :data:`GENERATORS` (the first
``n_maps`` seeds of a split of :mod:`digslam.envs.splits`, the test split by default; the same levels for
every agent), each episode with ``target=1.0`` (no early end at 0.8: the curve is not capped) and a step
budget of ``steps`` (3000). :class:`SuiteResult` turns the curves into the metrics of :mod:`.metrics` per
generator and writes the leaderboard: a Markdown table (per agent: T90 per generator with its success
rate, and over all maps T90, AUC and the final tube width, the ratio of the best baseline's mean T90 to the
agent's with its paired bootstrap 95 % interval) and a figure (T90 per generator, and the mean certified
coverage curves with their spread).

>>> curves = {"a": np.array([[0.0, 0.95, 0.95]]), "b": np.array([[0.0, 0.5, 0.91]])}
>>> zero = {"a": np.zeros(1), "b": np.zeros(1)}
>>> r = SuiteResult({"room": EvalResult(curves, {}, zero, zero)}, steps=2)
>>> r.t90()["a"].tolist(), r.t90()["b"].tolist(), r.best(["a", "b"])
([1.0], [2.0], 'a')
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from digslam.agents.evaluation.evaluate import EvalResult, evaluate
from digslam.agents.evaluation.metrics import paired_bootstrap_ratio

#: Generator name -> (environment id, keywords): the suite's worlds.
GENERATORS: dict[str, tuple[str, dict[str, Any]]] = {
    "room": ("digslam/DigCoverage-v0", {}),
    "rocks": ("digslam/DigCoverage-v0", {"world": "rocks"}),
    "caves": ("digslam/DigCoverage-v0", {"world": "caves"}),
    "rooms": ("digslam/DigCoverage-v0", {"world": "rooms"}),
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

    def t90(self, level: str = "T90") -> dict[str, np.ndarray]:
        """agent -> the ``level`` metric over every map of every generator, generators in order (paired
        across agents)."""
        m = self.metrics()
        return {a: np.concatenate([m[g][a][level] for g in self.results]) for a in self.agents}

    def _rank(self, agent: str, level: str = "T90") -> tuple[float, float]:
        """Sort key: the mean ``level`` over all maps, then the larger mean AUC (when no one reaches it)."""
        m = self.metrics()
        auc = np.concatenate([m[g][agent]["AUC"] for g in self.results])
        return float(np.mean(self.t90(level)[agent])), -float(np.mean(auc))

    def best(self, candidates: Iterable[str], level: str = "T90") -> str:
        """The candidate with the smallest mean ``level`` over all maps (ties: the larger mean AUC, then the
        first)."""
        names = [a for a in candidates if a in self.agents]
        if not names:
            raise ValueError("candidates: none of them ran")
        return min(names, key=lambda a: (*self._rank(a, level), names.index(a)))

    def success(self, agent: str, level: str = "S90") -> float:
        """Share of all maps on which ``agent`` reached the level (``S90``: 0.9 certified coverage)."""
        m = self.metrics()
        return float(np.mean(np.concatenate([m[g][agent][level] for g in self.results])))

    def table(self, baselines: Sequence[str]) -> str:
        """The leaderboard (Markdown), agents sorted by mean T90 over all maps (then AUC); the ratio column is
        ``mean T90(best baseline) / mean T90(agent)`` (> 1: faster than the best baseline) with its paired
        bootstrap 95 % interval."""
        m, t = self.metrics(), self.t90()
        best = self.best(baselines) if any(b in t for b in baselines) else None
        gens = list(self.results)
        head = ["agent"] + [f"T90 {g} (success)" for g in gens]
        head += ["T90 all (success)", "AUC", "final tube (m)", "T90 best baseline / T90 [95 % CI]"]
        lines = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
        for a in sorted(self.agents, key=self._rank):
            cells = [a]
            for g in gens:
                cells.append(f"{np.mean(m[g][a]['T90']):.0f} ({np.mean(m[g][a]['S90']):.0%})")
            auc = np.concatenate([m[g][a]["AUC"] for g in gens])
            tube = np.concatenate([m[g][a]["final_tube"] for g in gens])
            cells.append(f"{np.mean(t[a]):.0f} ({self.success(a):.0%})")
            cells += [f"{np.mean(auc):.3f}", f"{np.nanmean(tube):.3f}" if np.isfinite(tube).any() else "n/a"]
            if best is None:
                cells.append("n/a")
            else:
                r, lo, hi = paired_bootstrap_ratio(t[best], t[a])
                cells.append(f"{r:.3f} [{lo:.3f}, {hi:.3f}]" + (" (best baseline)" if a == best else ""))
            lines.append("| " + " | ".join(cells) + " |")
        return "\n".join(lines)

    def figure(self, path: str | Path) -> Path:
        """T90 per generator (bars, mean over the maps, with the spread as error bars) beside the mean
        certified coverage against steps (all maps of all generators, ± one standard deviation); returns the
        path written (matplotlib, Agg)."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        m, gens, agents = self.metrics(), list(self.results), self.agents
        fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11.0, 4.0), dpi=110)
        width = 0.8 / max(len(agents), 1)
        for k, a in enumerate(agents):
            mean = [float(np.mean(m[g][a]["T90"])) for g in gens]
            sd = [float(np.std(m[g][a]["T90"])) for g in gens]
            ax0.bar(np.arange(len(gens)) + (k - (len(agents) - 1) / 2) * width, mean, width, yerr=sd,
                    label=a, color=f"C{k}", capsize=2)  # fmt: skip
            curves = np.concatenate([self.results[g].curves[a] for g in gens])
            mu, s = curves.mean(axis=0), curves.std(axis=0)
            x = np.arange(mu.size)
            ax1.plot(x, mu, color=f"C{k}", label=a)
            ax1.fill_between(x, np.clip(mu - s, 0, 1), np.clip(mu + s, 0, 1), color=f"C{k}", alpha=0.15)
        ax0.set_xticks(np.arange(len(gens)), gens)
        ax0.set_ylabel(f"T90 (steps; {self.steps} = not reached)")
        ax0.set_title("steps to 0.9 certified coverage")
        ax1.axhline(0.9, color="grey", lw=0.8, ls=":")
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
                               "metrics": {a: {k: v.tolist() for k, v in mm.items()}
                                           for a, mm in r.metrics().items()}}
                           for g, r in self.results.items()},
        }  # fmt: skip
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(data))
        return out


def run_suite(
    policies: Mapping[str, Any],
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
        groups = [(plain, {})] if plain else []
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


def steps_per_second(policy: Any, env_id: str = "digslam/DigCoverage-v0", steps: int = 2000, seed: int = 0,
                     env_kwargs: Mapping[str, Any] | None = None) -> float:  # fmt: skip
    """Observed environment steps per second of ``policy`` driving one environment in this process (the
    policy's own time included), resetting to the next level whenever an episode ends; timed after one
    untimed step (compiled kernels loaded)."""
    import time

    from digslam.agents.evaluation.evaluate import make_env

    env = make_env(env_id, steps + 1, {**SUITE_KWARGS, **dict(env_kwargs or {})})
    try:
        obs, _ = env.reset(seed=seed)
        obs = env.step(np.asarray(policy.predict(obs)[0], np.float32))[0]
        t0 = time.perf_counter()
        for _ in range(steps):
            action = np.asarray(policy.predict(obs)[0], np.float32)
            obs, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                seed += 1
                obs, _ = env.reset(seed=seed)
        return steps / (time.perf_counter() - t0)
    finally:
        env.close()


__all__ = [
    "GENERATORS",
    "SUITE_KWARGS",
    "SuiteResult",
    "check_generators",
    "merge_agents",
    "run_suite",
    "steps_per_second",
    "suite_plan",
]
