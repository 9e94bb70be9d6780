"""Distributed evaluation on Ray against the sequential one (issues 11 and 18), on a workload of the suite's size.

Runs the benchmark suite (:func:`digslam.agents.evaluation.suite.run_suite`) for ``--agent`` (the frontier
agent) on ``--maps`` test levels of each of ``--generators``, ``target=1.0`` and ``--steps`` steps per
episode; by default the whole suite for that agent, 4 generators (room, rocks, caves, rooms) x 30 test maps
x 3000 steps = 360,000 environment steps (about three minutes on one free core), twice in one run: sequentially in this process, then with
:func:`digslam.agents.evaluation.ray_eval.run_suite_ray` on a local Ray instance with ``--workers`` CPUs (a
pool of long-lived actors, each keeping its environments warm and taking blocks of episodes). The Ray time
counts everything: starting the instance, creating and warming the actors, the episodes and the shutdown;
the time without the instance's start and shutdown is printed too. Both results must be identical (every
curve, collision count, tube width, length and path length).

Last line: ``speedup=<sequential time / Ray time>`` (goal >= 1.6 with 2 workers on 2 cores).

    python benchmarks/bench_sweep.py [--maps 30] [--steps 3000] [--generators room rocks caves rooms] [--workers 2]

``--quick``: one map of room and of rocks, 200 steps (a smoke run; Ray's start-up dominates it).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time

import numpy as np

from digslam.agents.evaluation.ray_eval import run_suite_ray
from digslam.agents.evaluation.ray_pool import start_ray
from digslam.agents.evaluation.specs import build_policy
from digslam.agents.evaluation.suite import GENERATORS, run_suite

ENV = "digslam/DigCoverage-v0"


def same(a: object, b: object) -> bool:
    """Every field of two EvalResults equal (arrays bit for bit, nan equal to nan)."""
    for f in dataclasses.fields(a):
        va, vb = getattr(a, f.name), getattr(b, f.name)
        if isinstance(va, dict):
            if list(va) != list(vb) or not all(np.array_equal(va[k], vb[k], equal_nan=True) for k in va):
                return False
        elif va != vb:
            return False
    return True


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--agent", default="frontier", help="baseline to evaluate (default frontier)")
    ap.add_argument("--maps", type=int, default=30, help="test levels per generator (default 30)")
    ap.add_argument("--steps", type=int, default=3000, help="steps per episode (default 3000)")
    ap.add_argument(
        "--generators", nargs="+", default=list(GENERATORS), help="suite generators (default all)"
    )
    ap.add_argument("--workers", type=int, default=2, help="CPUs of the local Ray instance (one actor each)")
    ap.add_argument("--quick", action="store_true", help="a smoke run: 1 map of room and rocks, 200 steps")
    args = ap.parse_args()
    if args.quick:
        args.maps, args.steps, args.generators = 1, 200, ["room", "rocks"]
    gens, total = args.generators, len(args.generators) * args.maps * args.steps
    print(f"workload: {args.agent} on {len(gens)} generators ({', '.join(gens)}) x {args.maps} test maps x "
          f"{args.steps} steps = {total} env steps, target 1.0; load average {os.getloadavg()[0]:.2f} "
          f"on {os.cpu_count()} cores")  # fmt: skip

    try:
        import ray
    except ImportError:
        raise SystemExit("bench_sweep: needs Ray (pip install 'digslam[ray]')") from None

    t0 = time.perf_counter()
    policy = build_policy(args.agent, ENV, None, seed=0)
    seq = run_suite({args.agent: policy}, n_maps=args.maps, steps=args.steps, generators=gens)
    t_seq = time.perf_counter() - t0
    steps = int(sum(r.lengths[args.agent].sum() for r in seq.results.values()))
    print(f"sequential: {steps} steps in {t_seq:.1f} s ({1e3 * t_seq / steps:.3f} ms/step)")

    t0 = time.perf_counter()
    start_ray(None, args.workers)  # run_suite_ray uses it; timed separately
    t_init = time.perf_counter() - t0
    try:
        dist = run_suite_ray([args.agent], n_maps=args.maps, steps=args.steps, generators=gens,
                             workers=args.workers)  # fmt: skip
        t_run = time.perf_counter() - t0 - t_init
    finally:
        t1 = time.perf_counter()
        ray.shutdown()
        t_down = time.perf_counter() - t1
    t_ray = time.perf_counter() - t0
    print(f"ray ({args.workers} actors): start {t_init:.1f} s, actors + episodes {t_run:.1f} s, "
          f"shutdown {t_down:.1f} s, total {t_ray:.1f} s")  # fmt: skip
    ok = list(seq.results) == list(dist.results) and all(same(seq.results[g], dist.results[g]) for g in gens)
    ok = ok and (seq.steps, seq.seeds) == (dist.steps, dist.seeds)
    print(f"identical results: {ok}")
    for g in gens:
        print(f"{g}: mean certified coverage after {args.steps} steps "
              f"{seq.results[g].curves[args.agent][:, -1].mean():.3f}")  # fmt: skip
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    print(f"speedup without the start-up and shutdown: {t_seq / t_run:.2f}")
    print(f"speedup={t_seq / t_ray:.2f}")
    if not ok:
        raise SystemExit("the Ray result differs from the sequential one")


if __name__ == "__main__":
    main()
