"""Evaluation of coverage agents on held-out maps: curves, table, figure and an episode GIF.

:func:`evaluate` runs every agent on the same maps and seeds (map ``i`` is ``reset(seed=seed + i)`` with the
world regenerated at each reset, ``fixed_world=False``) and records, after each step, the certified coverage
(the guaranteed observer's claim, ``info["certified_coverage"]``) and the ground-truth coverage
(``info["true_coverage"]``), both shares of the same area, the reachable free area (free cells connected to
the start, :func:`digslam.envs.dig_coverage.wrapper.reachable_free`), so certified <= ground truth; padded
with the last value once the episode ends; plus the collisions (``info["bumps"]``), the final tube
width (widest side of the pose box, m) and the true path length (m). :meth:`EvalResult.metrics` turns them
into the benchmark metrics of :mod:`.metrics` (T80 / T90 / T95, AUC, ...). Policies are
:class:`~digslam.agents.common.policy.PolicyPredictor` objects (SB3's ``predict``): the baselines of
:mod:`digslam.agents.baselines`, the goal agent or stable-baselines3 models.

>>> r = EvalResult(curves={"a": np.array([[0.1, 0.2, 0.3]])}, true_curves={"a": np.array([[0.1, 0.3, 0.4]])},
...                collisions={"a": np.array([0])}, final_tube_width={"a": np.array([0.05])})
>>> print(r.table(at=(2,)).splitlines()[2])
| a | 0.300 ± 0.000 | 0.400 ± 0.000 | 0.0 ± 0.0 | 0.050 ± 0.000 |
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from digslam.agents.common.policy import PolicyFactory, PolicyPredictor, reset_policy
from digslam.agents.evaluation.metrics import episodes_metrics, path_length

if TYPE_CHECKING:  # gymnasium is imported with the environments, on use
    import gymnasium as gym

#: Environment keyword arguments that :func:`evaluate` sets unless ``env_kwargs`` does.
EVAL_DEFAULTS: dict[str, Any] = {"fixed_world": False}


@dataclass
class EvalResult:
    """Per-agent results of :func:`evaluate` (arrays over episodes).

    Attributes:
        curves: agent -> ``(n_episodes, n_steps + 1)`` certified coverage after each step (column 0: reset).
        true_curves: the same for the ground-truth coverage.
        collisions: agent -> ``(n_episodes,)`` bumps over the episode.
        final_tube_width: agent -> ``(n_episodes,)`` widest side (m) of the last pose box (nan if the
            observer found the data inconsistent).
        lengths: agent -> ``(n_episodes,)`` steps actually run (termination or truncation ends earlier).
        env_id, seed, n_maps: what was evaluated.
        path_lengths: agent -> ``(n_episodes,)`` metres the true robot travelled (empty when not measured).
    """

    curves: dict[str, np.ndarray]
    true_curves: dict[str, np.ndarray]
    collisions: dict[str, np.ndarray]
    final_tube_width: dict[str, np.ndarray]
    lengths: dict[str, np.ndarray] = field(default_factory=dict)
    env_id: str = ""
    seed: int = 0
    n_maps: int = 0
    path_lengths: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def n_steps(self) -> int:
        """Steps of the curves (their length minus one)."""
        return max((c.shape[1] for c in self.curves.values()), default=1) - 1

    def at(self, step: int, truth: bool = False) -> dict[str, np.ndarray]:
        """agent -> ``(n_episodes,)`` coverage after ``step`` steps (clamped to the curves' length)."""
        src = self.true_curves if truth else self.curves
        return {a: c[:, min(max(int(step), 0), c.shape[1] - 1)] for a, c in src.items()}

    def metrics(self) -> dict[str, dict[str, np.ndarray]]:
        """agent -> metric -> ``(n_episodes,)``: :func:`.metrics.episodes_metrics` of the certified curves,
        the step budget being the curves' steps (an unmeasured path length is nan)."""
        out = {}
        for a, c in self.curves.items():
            extra = {"collisions": self.collisions[a], "final_tube": self.final_tube_width[a]}
            if a in self.path_lengths:
                extra["path"] = self.path_lengths[a]
            out[a] = episodes_metrics(c, c.shape[1] - 1, **extra)
        return out

    def table(self, at: Sequence[int] = (1000, 3000)) -> str:
        """Markdown table, mean ± std over episodes: certified coverage at each step of ``at`` that the
        curves reach (the last step if none does), ground-truth coverage at the last of them, collisions and
        final tube width."""
        steps = [int(s) for s in at if 0 <= int(s) <= self.n_steps] or [self.n_steps]
        head = [f"certified @ {s}" for s in steps] + [
            f"true @ {steps[-1]}",
            "collisions",
            "final pose box (m)",
        ]
        lines = ["| agent | " + " | ".join(head) + " |", "|---" * (len(head) + 1) + "|"]

        def ms(x: np.ndarray, fmt: str) -> str:
            x = np.asarray(x, dtype=np.float64)
            x = x[np.isfinite(x)]
            if x.size == 0:
                return "n/a"
            return f"{x.mean():{fmt}} ± {x.std():{fmt}}"

        for a in self.curves:
            cells = [ms(self.at(s)[a], ".3f") for s in steps]
            cells += [ms(self.at(steps[-1], truth=True)[a], ".3f"), ms(self.collisions[a], ".1f"),
                      ms(self.final_tube_width[a], ".3f")]  # fmt: skip
            lines.append(f"| {a} | " + " | ".join(cells) + " |")
        return "\n".join(lines)

    def to_json(self, path: str | Path) -> Path:
        """Write the result as JSON (arrays as nested lists, nan as null)."""

        def enc(d: dict[str, np.ndarray]) -> dict[str, Any]:
            return {a: np.where(np.isfinite(v), v, np.nan).tolist() for a, v in d.items()}

        data = {
            "curves": enc(self.curves),
            "true_curves": enc(self.true_curves),
            "collisions": enc(self.collisions),
            "final_tube_width": enc(self.final_tube_width),
            "lengths": enc(self.lengths),
            "env_id": self.env_id,
            "seed": self.seed,
            "n_maps": self.n_maps,
            "path_lengths": enc(self.path_lengths),
        }
        p = Path(path)
        p.parent.mkdir(parents=True, exist_ok=True)
        txt = json.dumps(data, allow_nan=True).replace("NaN", "null")
        p.write_text(txt)
        return p

    @classmethod
    def from_json(cls, path: str | Path) -> EvalResult:
        """Read a result written by :meth:`to_json`."""
        data = json.loads(Path(path).read_text())

        def dec(d: dict[str, Any]) -> dict[str, np.ndarray]:
            return {a: np.array(v, dtype=np.float64) for a, v in d.items()}

        try:
            return cls(
                curves=dec(data["curves"]),
                true_curves=dec(data["true_curves"]),
                collisions=dec(data["collisions"]),
                final_tube_width=dec(data["final_tube_width"]),
                lengths=dec(data.get("lengths", {})),
                env_id=str(data.get("env_id", "")),
                seed=int(data.get("seed", 0)),
                n_maps=int(data.get("n_maps", 0)),
                path_lengths=dec(data.get("path_lengths", {})),
            )
        except KeyError as exc:
            raise ValueError(f"path: {path} is not an EvalResult JSON (missing {exc})") from None


def make_env(env_id: str, steps: int, env_kwargs: dict[str, Any] | None, render: bool = False) -> gym.Env:
    """The env of an evaluation: ``gym.make(env_id)`` with :data:`EVAL_DEFAULTS`, ``max_episode_steps=steps``
    and ``env_kwargs`` (``render_mode="rgb_array"`` with ``render``)."""
    import gymnasium as gym

    import digslam.envs  # noqa: F401  (registers the environments)

    kw = {**EVAL_DEFAULTS, "max_episode_steps": steps, **(env_kwargs or {})}
    if render:
        kw["render_mode"] = "rgb_array"
    return gym.make(env_id, **kw)


def run_episode(
    policy: PolicyPredictor, env: gym.Env, seed: int, steps: int
) -> tuple[np.ndarray, np.ndarray, int, float, int, float]:
    """One episode: certified and true coverage after each step (padded), bumps, final tube width, length,
    true path length (m)."""
    reset_policy(policy)
    obs, info = env.reset(seed=seed)
    cert, true = np.empty(steps + 1), np.empty(steps + 1)
    cert[0], true[0] = info["certified_coverage"], info["true_coverage"]
    positions = [np.asarray(info["truth"].pose[:2], dtype=np.float64)]
    state, start, n = None, np.ones(1, dtype=bool), 0
    for n in range(1, steps + 1):
        action, state = policy.predict(obs, state=state, episode_start=start, deterministic=True)
        start = np.zeros(1, dtype=bool)
        action = np.clip(np.asarray(action, dtype=np.float32).reshape(env.action_space.shape), -1.0, 1.0)
        obs, _, terminated, truncated, info = env.step(action)
        cert[n], true[n] = info["certified_coverage"], info["true_coverage"]
        positions.append(np.asarray(info["truth"].pose[:2], dtype=np.float64))
        if terminated or truncated:
            cert[n + 1 :], true[n + 1 :] = cert[n], true[n]
            break
    box = np.asarray(info.get("pose_box", np.full((2, 2), np.nan)), dtype=np.float64)
    tube = float(np.max(box[1] - box[0])) if np.all(np.isfinite(box)) else math.nan
    return cert, true, int(info.get("bumps", 0)), tube, n, path_length(np.array(positions))


def evaluate(
    policies: dict[str, PolicyPredictor | PolicyFactory],
    env_id: str = "digslam/DigCoverage-v0",
    n_maps: int = 20,
    seed: int = 1000,
    steps: int = 3000,
    env_kwargs: dict[str, Any] | None = None,
    progress: bool = False,
) -> EvalResult:
    """Every policy on the same ``n_maps`` held-out maps (map ``i``: ``reset(seed=seed + i)``), ``steps``
    steps each (``max_episode_steps=steps`` and ``fixed_world=False`` unless ``env_kwargs`` says otherwise).
    A policy may also be a factory ``env -> policy``, called once on the env it plays (the true-map
    diagnosis of :mod:`digslam.agents.prediction.oracle` reads that env's ground truth).

    Raises:
        ValueError: no policies, a policy without ``predict``, or a non-positive ``n_maps``/``steps``.
    """
    if not policies:
        raise ValueError("policies: need at least one agent")
    for name, p in policies.items():
        if not (callable(getattr(p, "predict", None)) or callable(p)):
            raise ValueError(f"policies: {name!r} has no predict(obs) method and is no factory env -> policy")
    if not (isinstance(n_maps, int) and n_maps >= 1):
        raise ValueError(f"n_maps: must be an integer >= 1, got {n_maps!r}")
    if not (isinstance(steps, int) and steps >= 1):
        raise ValueError(f"steps: must be an integer >= 1, got {steps!r}")
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(policies) * n_maps, desc="evaluate", unit="episode")
    out: dict[str, dict[str, np.ndarray]] = {k: {} for k in "ctbwnp"}
    for name, policy in policies.items():
        env = make_env(env_id, steps, env_kwargs)
        agent = policy if isinstance(policy, PolicyPredictor) else policy(env)  # a factory: built on its env
        try:
            rows = []
            for i in range(n_maps):
                rows.append(run_episode(agent, env, seed + i, steps))
                if bar is not None:
                    bar.set_postfix(agent=name, coverage=f"{rows[-1][0][-1]:.3f}")
                    bar.update()
        finally:
            env.close()
        for key, j in zip("ctbwnp", range(6), strict=True):
            out[key][name] = np.array([r[j] for r in rows], dtype=np.float64)
    if bar is not None:
        bar.close()
    return EvalResult(out["c"], out["t"], out["b"], out["w"], out["n"], env_id, seed, n_maps, out["p"])


def coverage_figure(result: EvalResult, path: str | Path, target: float | None = None) -> Path:
    """Certified (solid) and ground-truth (dashed) coverage against steps, both shares of the reachable free
    area, mean ± std bands (matplotlib, Agg); returns the path written.

    ``target`` (the environment's, e.g. 0.8) is drawn as a dotted line; an episode that ended early is drawn
    up to its end and marked there (x); agents with identical curves stay visible (each has its own
    marker, offset along the curve, and the earlier ones are drawn wider); the legend sits outside the axes.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.8, 4.2), dpi=120)
    n_agents, markers = len(result.curves), "osD^vP*"
    for k, (name, c) in enumerate(result.curves.items()):
        colour, lw = f"C{k}", 1.4 + 1.6 * (n_agents - 1 - k)  # wider first: identical curves stay visible
        lengths = np.asarray(result.lengths.get(name, np.full(c.shape[0], c.shape[1] - 1)), dtype=np.int64)
        end = int(lengths.max()) if c.shape[0] == 1 else c.shape[1] - 1  # one episode: drawn to its end
        x = np.arange(end + 1)
        every = max((end + 1) // 8, 1)
        for curves, style, alpha in ((c, "-", 0.2), (result.true_curves[name], "--", 0.08)):
            mu, sd = curves.mean(axis=0)[: end + 1], curves.std(axis=0)[: end + 1]
            label = name if style == "-" else None
            ax.plot(x, mu, style, color=colour, lw=lw, label=label, marker=markers[k % len(markers)],
                    markevery=(k * every // max(n_agents, 1), every), ms=5)  # fmt: skip
            lo, hi = np.clip(mu - sd, 0, 1), np.clip(mu + sd, 0, 1)
            ax.fill_between(x, lo, hi, color=colour, alpha=alpha, lw=0)
        early = lengths < c.shape[1] - 1
        if early.any():  # episodes that ended (target reached or claims withdrawn) before the last step
            ax.plot(lengths[early], c[early, lengths[early]], "x", color=colour, ms=9, mew=2)
    if any((np.asarray(v) < result.n_steps).any() for v in result.lengths.values()):
        ax.plot([], [], "kx", ms=8, mew=2, label="episode ended")
    if target is not None:
        ax.axhline(target, color="0.35", lw=1.2, ls=":", label=f"target {target:.2f} (the episode ends)")
    ax.plot([], [], "k-", label="certified (proved free and sensed)")
    ax.plot([], [], "k--", label="ground truth (truly sensed)")
    ax.set_xlabel("steps")
    ax.set_ylabel("share of the reachable free area")
    ax.set_ylim(0, 1)
    ran = [int(v.max()) for v in result.lengths.values() if np.size(v)]
    ax.set_xlim(0, max(max(ran) if ran else result.n_steps, 1))  # to the last step any episode ran
    n = next(iter(result.curves.values())).shape[0] if result.curves else 0
    over = "1 episode" if n == 1 else f"mean ± std over {n} episodes (one per map)"
    ax.set_title(f"{result.env_id or 'coverage'}: coverage of the reachable free area, {over}", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=8)
    fig.tight_layout()
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(p)
    plt.close(fig)
    return p


__all__ = [
    "EVAL_DEFAULTS",
    "EvalResult",
    "coverage_figure",
    "evaluate",
    "make_env",
    "run_episode",
]
