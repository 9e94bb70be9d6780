"""The per-generator target levels: which certified coverage the best baseline reaches on 90 % of the
validation levels (:mod:`digslam.agents.evaluation.levels`).

Runs the frontier-planning baselines (``--agents``, default frontier, tour_frontier and distance_advantage)
on the first ``--maps`` (24) levels of the **validation** split of every generator, ``--steps`` (3000) steps
each at the default settings, and prints, per generator, the share of the levels each baseline reaches each
candidate level on (0.80, 0.85, 0.90, 0.95) with its mean time, then the chosen level and the baseline that
fixed it. ``--generators G ...`` runs some generators only; ``--set KEY=VALUE`` gives every episode an
environment keyword (``--generators floorplan --set world_size=7.5``: the floorplan levels on 15 m windows
instead of the suite's, the run that chooses the window size). ``--from F ...`` reads suite JSONs written
by this script or by ``bench_agents.py`` (runs of other agents on the same levels merge) instead of running. The last lines are ``target_levels=room:…,rocks:…``,
``shipped_levels=`` (:data:`~digslam.agents.evaluation.levels.TARGET_LEVELS`, what the benchmark uses) and
``levels_match=1`` when the two agree.

Usage: ``python benchmarks/bench_levels.py [--quick] [--maps 24] [--steps 3000] [--agents A ...] [--out DIR]
[--generators G ...] [--set KEY=VALUE ...] [--from F ...]``. The full run is 3 baselines x 5 generators x
24 levels x 3000 steps (about 1.1 M steps, some 12 minutes a baseline on one core; the floorplan levels
alone about 2 minutes for the three); ``--quick`` runs 2 room levels of 300 steps with the frontier agent.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import gymnasium as gym

import digslam.envs  # noqa: F401  (registers the environments)
from digslam.agents.baselines.registry import BASELINES, make_baseline
from digslam.agents.evaluation.levels import (
    CANDIDATE_LEVELS,
    LEVEL_MAPS,
    LEVEL_SHARE,
    LEVEL_STEPS,
    TARGET_LEVELS,
    choose_levels,
    format_levels,
    reach_shares,
)
from digslam.agents.evaluation.suite import SuiteResult, check_generators, merge, run_suite

ENV_ID = "digslam/DigCoverage-v0"
#: The baselines the levels are chosen over (the planners; random and lawnmower are far behind).
CANDIDATES = ("frontier", "tour_frontier", "distance_advantage")


def env_settings(items: list[str]) -> dict[str, Any]:
    """``--set KEY=VALUE`` items as environment keywords (values parsed as TOML literals, else strings;
    ValueError naming ``--set`` for an item without ``=``)."""
    from digslam.observer.core.config import parse_assignment

    return dict(parse_assignment(item, "--set") for item in items)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--maps", type=int, default=LEVEL_MAPS, help=f"validation levels per generator ({LEVEL_MAPS})"
    )
    ap.add_argument("--steps", type=int, default=LEVEL_STEPS, help=f"steps per episode ({LEVEL_STEPS})")
    ap.add_argument("--agents", nargs="+", default=list(CANDIDATES), metavar="A", help="the baselines to run")
    ap.add_argument("--quick", action="store_true", help="a smoke run: 2 room levels, 300 steps, frontier")
    ap.add_argument("--out", type=Path, default=Path("out/levels"), help="where to write suite.json")
    ap.add_argument("--generators", nargs="+", default=None, metavar="G",
                    help="run these generators only (default: every generator of the suite)")  # fmt: skip
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="an environment keyword for every agent and generator, e.g. world_size=7.5 "
                         "(repeatable; values parsed as TOML literals)")  # fmt: skip
    ap.add_argument("--from", dest="sources", nargs="+", type=Path, default=None, metavar="F",
                    help="suite JSONs to read instead of running (merged)")  # fmt: skip
    args = ap.parse_args()
    unknown = [a for a in args.agents if a not in BASELINES]
    if unknown:
        ap.error(f"--agents: unknown {unknown}; known: {sorted(BASELINES)}")
    if args.maps < 1 or args.steps < 1:
        ap.error(f"--maps, --steps: must be >= 1, got {args.maps}, {args.steps}")
    try:
        common = env_settings(args.set)
        gym.make(ENV_ID, **common).close()  # an unknown key or a bad value: one line, before any episode
        check_generators(args.generators)
    except ValueError as exc:
        ap.error(str(exc).splitlines()[0])
    t0 = time.perf_counter()
    if args.sources:
        missing = [str(p) for p in args.sources if not p.is_file()]
        if missing:
            ap.error(f"--from: no such file {missing[0]}")
        try:
            res = merge([SuiteResult.from_json(p) for p in args.sources])
        except ValueError as exc:
            ap.error(str(exc).splitlines()[0])
        names = [a for a in res.agents if a in BASELINES]
    else:
        maps, steps = (2, 300) if args.quick else (args.maps, args.steps)
        names = ["frontier"] if args.quick else list(args.agents)
        env = gym.make(ENV_ID)
        policies = {n: make_baseline(n, env, seed=0) for n in names}
        env.close()
        gens = ["room"] if args.quick else args.generators
        extra = {n: dict(common) for n in names} if common else None
        res = run_suite(policies, n_maps=maps, steps=steps, split="validation", generators=gens,
                        agent_env_kwargs=extra, progress=True)  # fmt: skip
        args.out.mkdir(parents=True, exist_ok=True)
        print(f"wrote {res.to_json(args.out / 'suite.json')}")
    print(f"{len(res.seeds)} validation levels per generator (seeds {res.seeds[0]}..{res.seeds[-1]}), "
          f"{res.steps} steps; {time.perf_counter() - t0:.0f} s")  # fmt: skip
    chosen = choose_levels(res, names, LEVEL_SHARE)
    head = (
        "| generator | baseline | " + " | ".join(f"{lv:g}: share (mean T)" for lv in CANDIDATE_LEVELS) + " |"
    )
    print(head + "\n" + "|---" * (2 + len(CANDIDATE_LEVELS)) + "|")
    for g, r in res.results.items():
        shares = reach_shares({a: r.curves[a] for a in names}, res.steps)
        for a in names:
            cells = [f"{shares[a][lv][0]:.0%} ({shares[a][lv][1]:.0f})" for lv in CANDIDATE_LEVELS]
            print(f"| {g} | {a} | " + " | ".join(cells) + " |")
    for g, (lv, agent, share) in chosen.items():
        print(f"level_{g}={lv:g} (reached by {agent} on {share:.0%} of the levels)")
    levels = {g: lv for g, (lv, _, _) in chosen.items()}
    print(f"target_levels={format_levels(levels)}")
    print(f"shipped_levels={format_levels({g: TARGET_LEVELS[g] for g in levels if g in TARGET_LEVELS})}")
    print(f"levels_match={int(all(TARGET_LEVELS.get(g) == lv for g, lv in levels.items()))}")


if __name__ == "__main__":
    main()
