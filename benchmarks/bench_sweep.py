"""Distributed evaluation on Ray against the sequential one (issue 11).

Evaluates ``--episodes`` episodes (maps ``seed, seed + 1, ...``) of the frontier agent, ``--steps`` steps
each (``--target 1.0`` by default, so no episode ends early), twice in one run: sequentially with :func:`digslam.agents.evaluation.evaluate.evaluate`, then with
:func:`digslam.agents.evaluation.ray_eval.evaluate_ray` on a local Ray instance with ``--workers`` CPUs (one task per
episode). The Ray time counts everything: starting the instance, the workers' imports, the episodes and
the shutdown; the time without the start-up is printed too. Both results must be identical.

Last line: ``speedup=<sequential time / Ray time>`` (goal >= 1.6 with 2 workers on 2 cores).

    python benchmarks/bench_sweep.py [--episodes 16] [--steps 2000] [--workers 2] [--target 1.0]
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from digslam.agents.evaluation.evaluate import evaluate
from digslam.agents.evaluation.ray_eval import build_policy, evaluate_ray, start_ray

ENV = "digslam/DigCoverage-v0"


def same(a: object, b: object) -> bool:
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
    ap.add_argument("--episodes", type=int, default=16, help="episodes (maps) of the frontier agent")
    ap.add_argument("--steps", type=int, default=2000, help="steps per episode")
    ap.add_argument("--workers", type=int, default=2, help="CPUs of the local Ray instance")
    ap.add_argument("--seed", type=int, default=1000, help="first map seed")
    ap.add_argument("--target", type=float, default=1.0,
                    help="coverage share that ends an episode (1.0: every episode runs all its steps)")  # fmt: skip
    args = ap.parse_args()
    kw = {"target": args.target}

    import ray

    t0 = time.perf_counter()
    seq = evaluate({"frontier": build_policy("frontier", ENV, kw)}, ENV, n_maps=args.episodes, seed=args.seed,
                   steps=args.steps, env_kwargs=kw)  # fmt: skip
    t_seq = time.perf_counter() - t0
    steps = int(seq.lengths["frontier"].sum())
    print(
        f"sequential: {args.episodes} episodes, {steps} steps in {t_seq:.1f} s ({1e3 * t_seq / steps:.2f} ms/step)"
    )

    t0 = time.perf_counter()
    start_ray(None, args.workers)  # evaluate_ray attaches to it; timed separately
    t_init = time.perf_counter() - t0
    try:
        dist = evaluate_ray(
            ["frontier"], ENV, n_maps=args.episodes, seed=args.seed, steps=args.steps, env_kwargs=kw
        )
        t_run = time.perf_counter() - t0 - t_init
    finally:
        t1 = time.perf_counter()
        ray.shutdown()
        t_down = time.perf_counter() - t1
    t_ray = time.perf_counter() - t0
    print(
        f"ray ({args.workers} workers): start {t_init:.1f} s, episodes {t_run:.1f} s, shutdown {t_down:.1f} s, "
        f"total {t_ray:.1f} s"
    )
    print(f"identical results: {same(seq, dist)}")
    print(f"mean certified coverage after {args.steps} steps: {seq.curves['frontier'][:, -1].mean():.3f}")
    print(f"speedup without the start-up and shutdown: {t_seq / t_run:.2f}")
    print(f"speedup={t_seq / t_ray:.2f}")


if __name__ == "__main__":
    main()
