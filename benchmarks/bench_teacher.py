"""The look-ahead teacher's headroom over the frontier agent: how much a learner that imitated it could gain.

On the first ``--levels`` validation levels (``digslam.envs.splits``) of each generator of ``--generators``
(:data:`digslam.agents.evaluation.suite.GENERATORS`; room, caves and rocks by default: the rooms are not
certified to 0.9 in 3000 steps by anyone, so they add ratios of 1), the goal env
(``digslam/DigCoverageGoals-v0``, ``target`` 0.9, ``max_steps`` 3000) is played three ways:

* ``frontier``: candidate 0 at every decision, the frontier agent (the peer);
* ``rollout``: :class:`digslam.agents.goals.teacher.RolloutTeacher`, a look-ahead on copies of the simulator
  that also draw the episode's noise to come;
* ``rollout_fresh_noise``: the same look-ahead, each copy drawing noise of its own (``fresh_noise=True``).

A level's T90 is the low-level step at which its episode reached 0.9 certified coverage (``max_steps`` when
it did not). The script prints a line per level, then per generator the geometric mean of
T90(frontier) / T90(teacher), and ends with ``fresh_noise_speedup_t90=`` and ``rollout_speedup_t90=`` (the
geometric means over every level, with their paired bootstrap 95 % intervals). The teachers see the
simulator, so these are not agents' figures: they bound what imitating the teacher could give, and their
gap says how much of it came from knowing the noise to come.

Usage: ``python benchmarks/bench_teacher.py [--quick] [--levels 6] [--generators G ...] [--workers 2]``.
``--quick`` runs 2 room levels (about half a minute); the default (6 levels of 3 generators) about 8
minutes on a 2-core machine, most of it the teachers on the rocks. Measured (default):
``rollout_speedup_t90=1.1556 [1.0032, 1.3358]`` (room 1.111, caves 1.124, rocks 1.235) and
``fresh_noise_speedup_t90=1.1758 [1.0199, 1.3565]`` (room 1.089, caves 1.210, rocks 1.233; the fresh-noise
teacher's streams are seeded by the level).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from multiprocessing import get_context
from typing import Any

import numpy as np

from digslam.agents.evaluation.metrics import paired_bootstrap_geomean
from digslam.agents.evaluation.suite import GENERATORS, check_generators
from digslam.envs.splits import seeds

MODES = ("frontier", "rollout", "rollout_fresh_noise")
GOAL_ID = "digslam/DigCoverageGoals-v0"
TARGET = 0.9


def play(job: tuple[str, int, str, int]) -> dict[str, Any]:
    """Worker: one level of ``generator`` played by ``mode``; its T90, final coverage, non-first picks."""
    generator, seed, mode, max_steps = job
    import gymnasium as gym

    import digslam.agents.goals  # noqa: F401  (registers the goal ids)
    from digslam.agents.goals.teacher import teacher

    env = gym.make(GOAL_ID, target=TARGET, max_steps=max_steps, **GENERATORS[generator][1])
    choose = teacher(mode, seed=seed)
    t0 = time.perf_counter()
    obs, info = env.reset(seed=seed)
    done = cut = False
    picks = 0
    while not (done or cut):
        a = int(choose(env, obs))
        picks += a != 0
        obs, _, done, cut, info = env.step(a)
    cov = float(info["certified_coverage"])
    t90 = int(info["elapsed"]) if cov >= TARGET else max_steps
    return {"generator": generator, "seed": seed, "mode": mode, "t90": t90, "certified": round(cov, 4),
            "not_first": int(picks), "wall_s": round(time.perf_counter() - t0, 1)}  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="2 room levels")
    ap.add_argument("--levels", type=int, default=6, help="validation levels per generator")
    ap.add_argument("--generators", nargs="+", default=["room", "caves", "rocks"])
    ap.add_argument("--steps", type=int, default=3000, help="low-level step budget of an episode")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args(argv)
    try:
        gens = check_generators(["room"] if args.quick else args.generators)
        n = 2 if args.quick else args.levels
        if not (n >= 1 and args.steps >= 1 and args.workers >= 1):
            raise ValueError("--levels, --steps, --workers: must be >= 1")
        jobs = [(g, s, m, args.steps) for g in gens for s in seeds("validation", n) for m in MODES]
    except ValueError as e:
        print(f"bench_teacher: {e}", file=sys.stderr)
        return 2
    t90: dict[tuple[str, int, str], int] = {}
    with get_context("spawn").Pool(args.workers) as pool:
        for row in pool.imap_unordered(play, jobs):
            print(json.dumps(row), flush=True)
            t90[(row["generator"], row["seed"], row["mode"])] = row["t90"]
    keys = [(g, s) for g in gens for s in seeds("validation", n)]
    base = np.array([t90[(g, s, "frontier")] for g, s in keys], float)
    out: dict[str, str] = {}
    for mode, name in (("rollout", "rollout"), ("rollout_fresh_noise", "fresh_noise")):
        t = np.array([t90[(g, s, mode)] for g, s in keys], float)
        for g in gens:
            m = np.array([k[0] == g for k in keys])
            out[f"{name}_speedup_t90_{g}"] = f"{math.exp(np.mean(np.log(base[m] / t[m]))):.4f}"
        gm, lo, hi = paired_bootstrap_geomean(base, t)
        out[f"{name}_speedup_t90"] = f"{gm:.4f} [{lo:.4f}, {hi:.4f}]"
    out["levels"] = str(len(keys))
    for k in sorted(out, key=lambda k: (k.endswith("t90"), k)):
        print(f"{k}={out[k]}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
