"""Certified coverage of the coverage agents on held-out maps of ``digslam/DigCoverage-v0``.

Every baseline of :data:`digslam.agents.baselines.registry.BASELINES` (and the PPO policy
``agents/data/ppo_digcoverage.zip`` when it exists, on the env keywords of its ``.json`` sidecar: they
change the observation, not the maps) runs on the same ``--maps`` maps, map ``i`` being
``reset(seed=--seed + i)`` with the world regenerated, for ``--steps`` steps. The env keeps its defaults,
including its termination at the target coverage (0.8): a curve stays at its last value once its episode
ended (``--target 1.0`` removes that cap). Prints the table (mean ± std of the certified coverage at 1000
and 3000 steps, or at ``--steps``), each agent's means, and on the last line
``ppo_vs_best_baseline=<PPO mean / best baseline mean at the last reported step>`` (``nan`` without a model).

Usage: ``python benchmarks/bench_agents.py [--maps 20] [--steps 3000] [--seed 2000000] [--target T]
[--model PATH] [--out DIR]``. The env runs at roughly 250 steps/s on one core: the full benchmark (4
baselines x 20 maps x 3000 steps) takes about half an hour or more; ``--maps 3 --steps 1000`` runs smaller.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path
from typing import Any

import gymnasium as gym

import digslam.envs  # noqa: F401  (registers the environments)
from digslam.agents.baselines.registry import BASELINES, make_baseline
from digslam.agents.evaluation.evaluate import EvalResult, coverage_figure, evaluate
from digslam.envs.splits import TEST

ENV_ID = "digslam/DigCoverage-v0"
MODEL = Path(__file__).resolve().parents[1] / "agents" / "data" / "ppo_digcoverage.zip"


def model_kwargs(model: Path) -> dict[str, Any]:
    """Env keywords of a saved model (its ``.json`` sidecar's ``env_kwargs``, ``fixed_world`` dropped)."""
    side = model.with_suffix(".json")
    if not side.is_file():
        return {}
    kw = dict(json.loads(side.read_text()).get("env_kwargs", {}))
    kw.pop("fixed_world", None)
    kw.pop("max_episode_steps", None)
    return kw


def load_ppo(model: Path) -> Any:
    """The PPO policy at ``model`` (torch on one thread), or None with a printed note."""
    if not model.is_file():
        print(f"note: no PPO model at {model}; PPO skipped")
        return None
    try:
        import torch
        from stable_baselines3 import PPO
    except ImportError as exc:
        print(f"note: stable-baselines3 unavailable ({exc}); PPO skipped")
        return None
    torch.set_num_threads(1)
    return PPO.load(str(model), device="cpu")


def merge(a: EvalResult, b: EvalResult) -> EvalResult:
    """``a`` with ``b``'s agents added."""
    return EvalResult(
        {**a.curves, **b.curves},
        {**a.true_curves, **b.true_curves},
        {**a.collisions, **b.collisions},
        {**a.final_tube_width, **b.final_tube_width},
        {**a.lengths, **b.lengths},
        a.env_id,
        a.seed,
        a.n_maps,
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--maps", type=int, default=20, help="held-out maps (default 20)")
    ap.add_argument("--steps", type=int, default=3000, help="steps per episode (default 3000)")
    ap.add_argument(
        "--seed", type=int, default=TEST.start, help=f"seed of map 0 (default {TEST.start}: the test split)"
    )
    ap.add_argument("--target", type=float, default=None, help="env's termination coverage (default: env's)")
    ap.add_argument("--model", type=Path, default=MODEL, help="PPO model (.zip)")
    ap.add_argument("--out", type=Path, default=None, help="also write coverage.png and evaluation.json here")
    args = ap.parse_args()
    kw: dict[str, Any] = {} if args.target is None else {"target": args.target}
    env = gym.make(ENV_ID, **kw)
    policies = {name: make_baseline(name, env, seed=0) for name in BASELINES}
    env.close()
    t0 = time.perf_counter()
    res = evaluate(policies, ENV_ID, n_maps=args.maps, seed=args.seed, steps=args.steps, env_kwargs=kw,
                   progress=True)  # fmt: skip
    ppo = load_ppo(args.model)
    if ppo is not None:
        pkw = {**model_kwargs(args.model), **kw}
        print(f"PPO env keywords: {pkw}")
        part = evaluate({"ppo": ppo}, ENV_ID, n_maps=args.maps, seed=args.seed, steps=args.steps,
                        env_kwargs=pkw, progress=True)  # fmt: skip
        res = merge(res, part)
    wall = time.perf_counter() - t0
    at = [s for s in (1000, 3000) if s <= args.steps] or [args.steps]
    print(f"{ENV_ID}: {args.maps} maps (seeds {args.seed}..{args.seed + args.maps - 1}), {args.steps} steps, "
          f"env keywords {kw or 'default'}; {wall:.0f} s")  # fmt: skip
    print(res.table(at=at))
    for s in at:
        means = {a: float(v.mean()) for a, v in res.at(s).items()}
        print(f"certified_coverage@{s}: " + ", ".join(f"{a}={m:.4f}" for a, m in means.items()))
    print("mean episode length (steps; < --steps when the target was reached): "
          + ", ".join(f"{a}={float(v.mean()):.0f}" for a, v in res.lengths.items()))  # fmt: skip
    if args.out is not None:
        print(f"wrote {coverage_figure(res, args.out / 'coverage.png')} and "
              f"{res.to_json(args.out / 'evaluation.json')}")  # fmt: skip
    last = {a: float(v.mean()) for a, v in res.at(at[-1]).items()}
    best = max((m for a, m in last.items() if a != "ppo"), default=math.nan)
    ratio = last["ppo"] / best if "ppo" in last and best > 0 else math.nan
    print(f"ppo_vs_best_baseline={ratio:.4f}" if math.isfinite(ratio) else "ppo_vs_best_baseline=nan")


if __name__ == "__main__":
    main()
