"""Per-generator target levels: the certified coverage each generator's headline time ``T_level`` is taken at.

One level for every generator would measure noise on some: at the default odometry noise the pose box caps
what the rooms generator lets any planner certify (the cells along walls dug while the box was wide), and
the time to 0.9 there is the time the drift allows, not the planner's. So each generator has its own level,
fixed once on the **validation** split (never on the test maps it is reported on):

    the highest of :data:`CANDIDATE_LEVELS` (0.80, 0.85, 0.90, 0.95) that the best baseline reaches on at
    least :data:`LEVEL_SHARE` (90 %) of :data:`LEVEL_MAPS` (24) validation levels within
    :data:`LEVEL_STEPS` (3000) steps at the default settings,

where the best baseline for a level is the one that reaches it on the most levels (ties: the smaller mean
time to it). :data:`TARGET_LEVELS` holds the result; ``benchmarks/bench_levels.py`` recomputes it (and an
``expensive`` test checks the table against a fresh run). ``T_level`` of an episode is then its time to its
generator's level (:func:`level_metric`: ``"T85"`` for 0.85), the leaderboard's headline column and the
basis of every speedup ratio.

>>> level_metric(0.85), level_metric("rocks")
('T85', 'T90')
>>> curves = {"a": np.array([[0.0, 0.9, 0.96], [0.0, 0.5, 0.86]])}
>>> choose_level(curves, steps=2, share=0.5)
(0.95, 'a', 0.5)
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from digslam.agents.evaluation.metrics import level_name, time_to

#: The levels a generator's target is chosen from.
CANDIDATE_LEVELS = (0.8, 0.85, 0.9, 0.95)
#: Share of the validation levels on which the best baseline must reach a level for it to be the target.
LEVEL_SHARE = 0.9
#: Validation levels per generator, and the step budget, of the choice.
LEVEL_MAPS, LEVEL_STEPS = 24, 3000

#: Generator -> target level (certified coverage), chosen on the validation split as the module says
#: (``python benchmarks/bench_levels.py``; the share of the 24 levels each level was reached on, and by which
#: baseline, is in :data:`LEVEL_EVIDENCE`).
TARGET_LEVELS: dict[str, float] = {"room": 0.95, "rocks": 0.9, "caves": 0.9, "rooms": 0.85, "floorplan": 0.9}
#: Generator -> (the baseline that fixed its level, the share of the validation levels it reached it on).
#: The next level up was reached on: room none above 0.95; rocks 0.95 on 21 % (distance advantage); caves
#: 0.95 on 62 %; rooms 0.9 on 8 % (frontier); floorplan 0.95 on 62 % (frontier).
LEVEL_EVIDENCE: dict[str, tuple[str, float]] = {
    "room": ("frontier", 1.0),
    "rocks": ("distance_advantage", 1.0),
    "caves": ("distance_advantage", 22 / 24),
    "rooms": ("frontier", 22 / 24),
    "floorplan": ("distance_advantage", 22 / 24),
}


def level_metric(level: float | str) -> str:
    """The metric name of a level (``0.9`` -> ``"T90"``) or of a generator's target level."""
    if isinstance(level, str):
        if level not in TARGET_LEVELS:
            raise ValueError(f"level: unknown generator {level!r}; known: {sorted(TARGET_LEVELS)}")
        level = TARGET_LEVELS[level]
    return level_name(float(level))


def reach_shares(curves: Mapping[str, np.ndarray], steps: int, levels: tuple[float, ...] = CANDIDATE_LEVELS
                 ) -> dict[str, dict[float, tuple[float, float]]]:  # fmt: skip
    """agent -> level -> (share of the episodes that reach the level within ``steps``, mean time to it, an
    unreached level counting ``steps``), from ``(n, >= steps + 1)`` certified-coverage curves."""
    out: dict[str, dict[float, tuple[float, float]]] = {}
    for agent, c in curves.items():
        rows = np.atleast_2d(np.asarray(c, dtype=np.float64))[:, : steps + 1]
        out[agent] = {}
        for lv in levels:
            hits = [time_to(r, lv, steps) for r in rows]
            out[agent][lv] = (float(np.mean([ok for _, ok in hits])), float(np.mean([t for t, _ in hits])))
    return out


def choose_level(curves: Mapping[str, np.ndarray], steps: int = LEVEL_STEPS, share: float = LEVEL_SHARE,
                 levels: tuple[float, ...] = CANDIDATE_LEVELS) -> tuple[float, str, float]:  # fmt: skip
    """``(level, baseline, its share)``: the highest of ``levels`` that some baseline reaches on at least
    ``share`` of the episodes within ``steps`` steps, with the baseline that reaches it most often (ties: the
    smaller mean time); the lowest level, with its best baseline, when none qualifies.

    Raises:
        ValueError: no curves.
    """
    if not curves:
        raise ValueError("curves: need at least one baseline's curves")
    shares = reach_shares(curves, steps, levels)
    for lv in sorted(levels, reverse=True):
        agent = min(shares, key=lambda a: (-shares[a][lv][0], shares[a][lv][1]))
        if shares[agent][lv][0] >= share - 1e-12:
            return float(lv), agent, shares[agent][lv][0]
    lv = min(levels)
    agent = min(shares, key=lambda a: (-shares[a][lv][0], shares[a][lv][1]))
    return float(lv), agent, shares[agent][lv][0]


def choose_levels(suite: Any, baselines: list[str] | None = None, share: float = LEVEL_SHARE
                  ) -> dict[str, tuple[float, str, float]]:  # fmt: skip
    """generator -> :func:`choose_level` of a :class:`~.suite.SuiteResult` (the ``baselines`` among its
    agents, all of them for None)."""
    out = {}
    for g, r in suite.results.items():
        names = [a for a in r.curves if baselines is None or a in baselines]
        out[g] = choose_level({a: r.curves[a] for a in names}, suite.steps, share)
    return out


def format_levels(levels: Mapping[str, float]) -> str:
    """``room:0.95,rocks:0.9,...`` (the benchmark's ``target_levels=`` line)."""
    return ",".join(f"{g}:{float(v):g}" for g, v in levels.items())


__all__ = [
    "CANDIDATE_LEVELS",
    "LEVEL_EVIDENCE",
    "LEVEL_MAPS",
    "LEVEL_SHARE",
    "LEVEL_STEPS",
    "TARGET_LEVELS",
    "choose_level",
    "choose_levels",
    "format_levels",
    "level_metric",
    "reach_shares",
]
