"""Benchmark metrics of coverage episodes: times to coverage levels, AUC, path length, paired ratios.

Per episode, from the certified-coverage curve (``curve[k]``: the coverage after ``k`` steps, ``curve[0]``
at reset, as :class:`~digslam.agents.evaluation.evaluate.EvalResult` keeps it) and the episode's ``info``:

* ``T80``, ``T85``, ``T90``, ``T95``: the first step ``k`` with ``curve[k] >= 0.8`` (0.85, 0.9, 0.95); a level
  the episode never reaches counts as the step ``budget`` and its success flag (``S80``, ...) is 0; each
  generator's headline level is one of them (:mod:`.levels`);
* ``AUC``: the mean certified coverage over steps 1 to 1000; a curve that ends earlier (the episode
  terminated, e.g. on reaching its target, or the step budget was smaller) holds its last value, as the
  evaluator pads its curves: what was certified stays certified;
* ``path_length``: metres the true robot travelled (from ``info["truth"]``: ground truth is fine in a
  metric), ``collisions`` (bumps) and ``final_tube`` (the widest side of the last pose box, m).

Per set of episodes: mean, median and success rate (:func:`summarize`), and :func:`paired_bootstrap_ratio`,
the ratio of two agents' means on the same maps with a seeded percentile-bootstrap 95 % interval that
resamples maps (pairs), so the map-to-map spread that both agents share cancels.

>>> curve = np.array([0.0, 0.5, 0.85, 0.92, 0.92])
>>> m = episode_metrics(curve, budget=10)
>>> m["T80"], m["T90"], m["T95"], m["S95"]
(2.0, 3.0, 10.0, 0.0)
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

#: Certified-coverage levels of the time-to-level metrics.
LEVELS = (0.8, 0.85, 0.9, 0.95)
#: Steps over which :func:`auc` averages.
AUC_STEPS = 1000


def level_name(level: float) -> str:
    """``"T90"`` for 0.9 (the success flag is ``"S90"``)."""
    return f"T{round(100 * level)}"


def time_to(curve: np.ndarray, level: float, budget: int | None = None) -> tuple[int, bool]:
    """``(first step whose coverage reaches level, reached)``; ``(budget, False)`` when no step does
    (``budget`` defaults to the curve's steps, ``len(curve) - 1``)."""
    c = np.asarray(curve, dtype=np.float64)
    if c.ndim != 1 or c.size == 0:
        raise ValueError(f"curve: expected a non-empty 1-D array, got shape {c.shape}")
    hit = np.flatnonzero(c >= level)
    if hit.size:
        return int(hit[0]), True
    return (c.size - 1 if budget is None else int(budget)), False


def auc(curve: np.ndarray, steps: int = AUC_STEPS) -> float:
    """Mean of ``curve[1 : steps + 1]``, the last value held past the curve's end (see the module)."""
    c = np.asarray(curve, dtype=np.float64)
    if c.ndim != 1 or c.size == 0 or steps < 1:
        raise ValueError(f"curve, steps: need a non-empty 1-D curve and steps >= 1, got {c.shape}, {steps}")
    seen = c[1 : steps + 1]
    held = steps - seen.size
    return float((seen.sum() + held * c[-1]) / steps)


def path_length(positions: np.ndarray) -> float:
    """Length (m) of the polyline through ``(n, 2)`` true positions (e.g. ``info["truth"].pose[:2]`` after
    reset and each step)."""
    p = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
    return float(np.hypot(*np.diff(p, axis=0).T).sum()) if len(p) > 1 else 0.0


def episode_metrics(curve: np.ndarray, budget: int | None = None, levels: Sequence[float] = LEVELS,
                    auc_steps: int = AUC_STEPS, path: float = np.nan, collisions: float = np.nan,
                    final_tube: float = np.nan) -> dict[str, float]:  # fmt: skip
    """The metrics of one episode (module docstring): ``T..`` and ``S..`` per level, ``AUC``, and the
    given ``path_length``, ``collisions``, ``final_tube`` (nan when unknown)."""
    out: dict[str, float] = {}
    for level in levels:
        t, ok = time_to(curve, level, budget)
        out[level_name(level)], out["S" + level_name(level)[1:]] = float(t), float(ok)
    out["AUC"] = auc(curve, auc_steps)
    out["path_length"], out["collisions"] = float(path), float(collisions)
    out["final_tube"] = float(final_tube)
    return out


def episodes_metrics(
    curves: np.ndarray, budget: int | None = None, **per_episode: Any
) -> dict[str, np.ndarray]:
    """:func:`episode_metrics` of every row of ``(n, steps + 1)`` curves, as arrays over episodes;
    ``per_episode`` holds ``(n,)`` arrays of ``path``, ``collisions``, ``final_tube`` (missing: nan)."""
    c = np.atleast_2d(np.asarray(curves, dtype=np.float64))
    rows = []
    for i in range(c.shape[0]):
        extra: dict[str, Any] = {k: float(np.asarray(v, dtype=np.float64)[i]) for k, v in per_episode.items()}
        rows.append(episode_metrics(c[i], budget, **extra))
    return {k: np.array([r[k] for r in rows]) for k in rows[0]} if rows else {}


def summarize(values: Mapping[str, np.ndarray]) -> dict[str, dict[str, float]]:
    """metric -> ``{"mean", "median", "n"}`` over its finite values (success flags: their mean is the
    success rate)."""
    out = {}
    for k, v in values.items():
        x = np.asarray(v, dtype=np.float64)
        x = x[np.isfinite(x)]
        out[k] = {"mean": float(x.mean()) if x.size else np.nan,
                  "median": float(np.median(x)) if x.size else np.nan, "n": float(x.size)}  # fmt: skip
    return out


def _pairs(a: np.ndarray, b: np.ndarray, n_boot: int, confidence: float) -> tuple[np.ndarray, np.ndarray]:
    """``a``, ``b`` as flat float arrays, checked to pair up, with the bootstrap's settings checked."""
    x, y = np.asarray(a, dtype=np.float64).ravel(), np.asarray(b, dtype=np.float64).ravel()
    if x.shape != y.shape:
        raise ValueError(f"a, b: must pair up (same length), got {x.size} and {y.size}")
    if not (isinstance(n_boot, int) and n_boot >= 1 and 0.0 < confidence < 1.0):
        raise ValueError(
            f"n_boot, confidence: need n_boot >= 1 and 0 < confidence < 1, got {n_boot}, {confidence}"
        )
    return x, y


def paired_bootstrap_ratio(a: np.ndarray, b: np.ndarray, n_boot: int = 10_000, seed: int = 0,
                           confidence: float = 0.95) -> tuple[float, float, float]:  # fmt: skip
    """``(mean(a) / mean(b), low, high)``: the ratio of two agents' means over the same maps (``a[i]`` and
    ``b[i]`` on map ``i``; pairs with a non-finite value are dropped) and its percentile-bootstrap interval
    at ``confidence``, resampling maps with replacement (``n_boot`` draws of ``numpy``'s default generator
    seeded with ``seed``: the same inputs give the same interval).

    Raises:
        ValueError: ``a`` and ``b`` differ in length, no finite pair is left, or a bad ``n_boot`` /
            ``confidence``.
    """
    x, y = _pairs(a, b, n_boot, confidence)
    keep = np.isfinite(x) & np.isfinite(y)
    x, y = x[keep], y[keep]
    if x.size == 0:
        raise ValueError("a, b: no pair of finite values")
    idx = np.random.default_rng(seed).integers(0, x.size, size=(n_boot, x.size))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios = x[idx].mean(axis=1) / y[idx].mean(axis=1)
        ratio = float(x.mean() / y.mean())
    tail = 50.0 * (1.0 - confidence)
    lo, hi = np.nanpercentile(ratios, [tail, 100.0 - tail])
    return ratio, float(lo), float(hi)


def paired_bootstrap_geomean(a: np.ndarray, b: np.ndarray, n_boot: int = 10_000, seed: int = 0,
                             confidence: float = 0.95) -> tuple[float, float, float]:  # fmt: skip
    """``(exp(mean(log(a / b))), low, high)``: the geometric mean over the same maps of the per-map ratios
    ``a[i] / b[i]`` (e.g. ``T90(best baseline) / T90(learned)``: > 1 when the learned agent is faster) and
    its percentile-bootstrap interval, as :func:`paired_bootstrap_ratio` (pairs with a non-finite or
    non-positive value are dropped).

    >>> paired_bootstrap_geomean(np.array([2.0, 8.0]), np.array([1.0, 1.0]))[0]  # sqrt(2 * 8)
    4.0

    Raises:
        ValueError: as :func:`paired_bootstrap_ratio`.
    """
    x, y = _pairs(a, b, n_boot, confidence)
    keep = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    logs = np.log(x[keep]) - np.log(y[keep])
    if logs.size == 0:
        raise ValueError("a, b: no pair of finite positive values")
    idx = np.random.default_rng(seed).integers(0, logs.size, size=(n_boot, logs.size))
    tail = 50.0 * (1.0 - confidence)
    lo, hi = np.percentile(logs[idx].mean(axis=1), [tail, 100.0 - tail])
    return float(np.exp(logs.mean())), float(np.exp(lo)), float(np.exp(hi))


def metrics_table(per_agent: Mapping[str, Mapping[str, np.ndarray]], levels: Sequence[float] = LEVELS) -> str:
    """Markdown table, one row per agent: mean / median of each ``T..`` with its success rate, ``AUC``, path
    length, collisions and the final pose box's width (means)."""
    names = [level_name(v) for v in levels]
    head = [f"{n} mean / median (success)" for n in names]
    head += ["AUC", "path (m)", "collisions", "final pose box (m)"]
    lines = ["| agent | " + " | ".join(head) + " |", "|---" * (len(head) + 1) + "|"]
    for agent, values in per_agent.items():
        s = summarize(values)
        cells = [f"{s[n]['mean']:.0f} / {s[n]['median']:.0f} ({s['S' + n[1:]]['mean']:.0%})" for n in names]
        cells += [f"{s['AUC']['mean']:.3f}"] + [
            "n/a" if not np.isfinite(s[k]["mean"]) else f"{s[k]['mean']:{f}}"
            for k, f in (("path_length", ".1f"), ("collisions", ".1f"), ("final_tube", ".3f"))
        ]
        lines.append(f"| {agent} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


__all__ = [
    "AUC_STEPS",
    "paired_bootstrap_geomean",
    "LEVELS",
    "auc",
    "episode_metrics",
    "episodes_metrics",
    "level_name",
    "metrics_table",
    "paired_bootstrap_ratio",
    "path_length",
    "summarize",
    "time_to",
]
