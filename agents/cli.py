"""The ``digslam`` command: demo, train, evaluate, record, replay and benchmark.

``digslam demo`` runs ``digslam/DigCoverage-v0`` with the pretrained PPO policy shipped in
``digslam/agents/data`` (the frontier agent if the model or torch is unavailable), writes the episode GIF
and the certified-coverage figure to ``--out`` and prints the certified coverage reached. Every
subcommand has ``--help``; heavy imports (torch, SB3, matplotlib) happen only when a subcommand needs them.

>>> build_parser().parse_args(["demo", "--steps", "20"]).steps
20
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any

from . import ray_eval, sweep

DATA = Path(__file__).parent / "data"
#: The shipped policy and the environment keywords it was trained with (``<model>.json``).
PRETRAINED = DATA / "ppo_digcoverage.zip"
DEFAULT_ENV = "digslam/DigCoverage-v0"


def model_env_kwargs(model: Path = PRETRAINED) -> dict[str, Any]:
    """Environment keywords of a saved model (its ``.json`` sidecar; ``{}`` if none)."""
    side = Path(model).with_suffix(".json")
    if not side.is_file():
        return {}
    kw = dict(json.loads(side.read_text()).get("env_kwargs", {}))
    kw.pop("fixed_world", None)  # a training choice, not part of the observation
    return kw


def load_agent(name: str, env: Any, model: Path | None = None) -> Any:
    """A policy with SB3's ``predict``: ``"ppo"`` (a saved PPO model, default the shipped one) or a
    baseline name of :data:`digslam.agents.baselines.BASELINES`.

    Raises:
        ValueError: unknown ``name``; FileNotFoundError / ImportError: no model or no SB3 for ``"ppo"``.
    """
    if name == "ppo":
        path = Path(model) if model is not None else PRETRAINED
        if not path.is_file():
            raise FileNotFoundError(f"model: no saved policy at {str(path)!r}")
        from stable_baselines3 import PPO

        from .train import pin_threads

        pin_threads(1)
        return PPO.load(path, device="cpu")
    from .baselines import make_baseline

    return make_baseline(name, env)


def resolve_agent(name: str, env_id: str, model: Path | None) -> tuple[str, Any, dict[str, Any]]:
    """``(name, policy, env_kwargs)``, falling back from ``"ppo"`` to ``"frontier"`` when the model, torch
    or stable-baselines3 is unavailable (with a warning)."""
    import gymnasium as gym

    import digslam.envs  # noqa: F401

    kwargs = model_env_kwargs(Path(model) if model else PRETRAINED) if name == "ppo" else {}
    env = gym.make(env_id, **kwargs)
    try:
        return name, load_agent(name, env, model), kwargs
    except (FileNotFoundError, ImportError) as exc:
        if name != "ppo":
            raise
        warnings.warn(f"PPO policy unavailable ({exc}); using the frontier agent", stacklevel=2)
        return "frontier", load_agent("frontier", env), kwargs
    finally:
        env.close()


# --- subcommands --------------------------------------------------------------------------------
def cmd_demo(args: argparse.Namespace) -> int:
    from .evaluate import coverage_figure, evaluate, record_episode_gif

    name, policy, kwargs = resolve_agent(args.agent, args.env, args.model)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"agent: {name}; env: {args.env} {kwargs}; {args.steps} steps, seed {args.seed}")
    gif = record_episode_gif(policy, args.env, out / "episode.gif", steps=args.steps, seed=args.seed,
                             env_kwargs=kwargs, fps=args.fps, stride=args.stride)  # fmt: skip
    res = evaluate({name: policy}, args.env, n_maps=1, seed=args.seed, steps=args.steps, env_kwargs=kwargs)
    fig = coverage_figure(res, out / "coverage.png")
    import numpy as np

    cov = float(np.asarray(res.curves[name])[..., -1].mean())
    true = float(np.asarray(res.true_curves[name])[..., -1].mean())
    print(f"wrote {gif} and {fig}")
    print(f"certified coverage after {args.steps} steps: {cov:.3f} (ground truth {true:.3f})")
    return 0


def cmd_train(args: argparse.Namespace) -> int:
    from .train import TrainConfig, train

    config, overrides = args.config, list(args.overrides)
    if config is not None and "=" in config and not Path(config).is_file():  # only overrides were given
        config, overrides = None, [config, *overrides]
    cfg = TrainConfig.from_file(config, overrides)
    print(f"training: {cfg}")
    path = train(cfg)
    print(f"saved {path}")
    return 0


def cmd_evaluate(args: argparse.Namespace) -> int:
    from .evaluate import coverage_figure, evaluate

    if args.ray:
        res = args.ray_evaluate(args)
    else:
        model = Path(args.model) if args.model else PRETRAINED
        kwargs = model_env_kwargs(model) if "ppo" in args.agents else {}
        policies: dict[str, Any] = {}
        for a in args.agents:
            name, pol, _ = resolve_agent(a, args.env, args.model)
            policies[name] = pol
        res = evaluate(policies, args.env, n_maps=args.maps, seed=args.seed, steps=args.steps,
                       env_kwargs=kwargs, progress=True)  # fmt: skip
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    at = tuple(s for s in (1000, 3000) if s <= args.steps) or (args.steps,)
    print(res.table(at=at))
    res.to_json(out / "evaluation.json")
    print(f"wrote {coverage_figure(res, out / 'coverage.png')} and {out / 'evaluation.json'}")
    return 0


def cmd_record(args: argparse.Namespace) -> int:
    import gymnasium as gym
    import numpy as np
    from tqdm import tqdm

    import digslam.envs  # noqa: F401
    from digslam.envs.episode import Episode, GroundTruth
    from digslam.observer.record import MissionRecord

    name, policy, kwargs = resolve_agent(args.agent, args.env, args.model)
    env = gym.make(args.env, max_episode_steps=args.steps, **kwargs)
    obs, info = env.reset(seed=args.seed)
    recs, truths, actions = [info["record"]], [info["truth"]], []
    for _ in tqdm(range(args.steps), desc=f"record {name}", disable=not args.progress):
        a, _ = policy.predict(obs, deterministic=True)
        a = np.asarray(a, dtype=np.float32).reshape(2)
        obs, _, term, trunc, info = env.step(a)
        actions.append(a)
        recs.append(info["record"])
        truths.append(info["truth"])
        if term or trunc:
            break
    ep = Episode(env.unwrapped.config, int(args.seed), np.array(actions, np.float32).reshape(-1, 2),
                 MissionRecord.stack(recs), GroundTruth.stack(truths))  # fmt: skip
    env.close()
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    ep.save(out)
    print(f"agent {name}: {len(ep.actions)} steps, certified coverage {info['certified_coverage']:.3f}; "
          f"wrote {out}")  # fmt: skip
    return 0


def same_episode(a: Any, b: Any) -> bool:
    """Whether two episodes have the same actions, measurement records and ground truth."""
    import numpy as np

    ra, rb = a.records.to_arrays(), b.records.to_arrays()
    return (
        np.array_equal(a.actions, b.actions)
        and ra.keys() == rb.keys()
        and all(np.array_equal(ra[k], rb[k], equal_nan=True) for k in ra)
        and a.truth == b.truth
    )


def cmd_replay(args: argparse.Namespace) -> int:
    import numpy as np

    from digslam.envs.episode import Episode, replay

    ep = Episode.load(args.file)
    again = replay(ep)
    ok = same_episode(ep, again)
    print(f"{args.file}: {len(ep.actions)} steps, seed {ep.seed}; replay identical: {ok}")
    if args.digslam:
        from digslam.observer.digslam import DigSlamConfig, dig_slam
        from digslam.observer.grid import Grid

        s = float(ep.config.world_size)
        grid = Grid((-s, -s), (s, s), (args.grid, args.grid))
        start = ep.truth.pose[0, :2]
        res = dig_slam(ep.records, grid, start, start, DigSlamConfig(max_iter=args.max_iter))
        if not res.consistent:
            print(f"dig_slam: inconsistent at gate {res.first_empty}")
        else:
            w = res.tube.widths()
            inside = bool(np.all(res.tube.contains(ep.records.t, ep.truth.pose[:, :2])))
            dr = res.dead_reckoning
            dr_txt = f"{float(np.max(dr)):.3f}" if dr is not None else "n/a"
            print(f"dig_slam: {res.iterations} iterations; tube width max {float(np.max(w)):.3f} m, "
                  f"final {float(np.ravel(w)[-1]):.3f} m (dead reckoning max {dr_txt} m); "
                  f"truth inside the tube: {inside}")  # fmt: skip
    return 0 if ok else 1


def benchmarks_dir() -> Path | None:
    """The repository's ``benchmarks/`` folder (source checkout), or None when installed without it."""
    for base in (Path(__file__).resolve().parents[1], Path.cwd()):
        if (base / "benchmarks").is_dir():
            return base / "benchmarks"
    return None


def cmd_benchmark(args: argparse.Namespace) -> int:
    folder = benchmarks_dir()
    if folder is None:
        print("benchmark: the benchmarks/ folder ships with the source checkout only; clone the repository "
              "and run `digslam benchmark NAME` from it")  # fmt: skip
        return 2
    stem = args.name.removesuffix(".py")
    cands = [folder / f"{stem}.py", folder / f"bench_{stem}.py"]
    script = next((c for c in cands if c.is_file()), None)
    if script is None:
        names = sorted(p.stem for p in folder.glob("bench_*.py"))
        print(f"benchmark: no benchmark {args.name!r}; known: {', '.join(names)}")
        return 2
    return subprocess.call([sys.executable, str(script), *args.args])


# --- parser --------------------------------------------------------------------------------
def _agent_opts(p: argparse.ArgumentParser, default: str) -> None:
    p.add_argument("--agent", default=default,
                   help="ppo (the pretrained policy) or a baseline: random, lawnmower, frontier, "
                        "uncertainty_frontier (default %(default)s)")  # fmt: skip
    p.add_argument("--model", default=None, help="saved PPO model (.zip) instead of the shipped one")
    p.add_argument("--env", default=DEFAULT_ENV, help="environment id (default %(default)s)")
    p.add_argument("--seed", type=int, default=0, help="episode seed (default %(default)s)")


def build_parser() -> argparse.ArgumentParser:
    """The ``digslam`` argument parser."""
    ap = argparse.ArgumentParser(prog="digslam", description="Guaranteed Dig-SLAM: certified coverage demo, "
                                 "training, evaluation and episode tools.")  # fmt: skip
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("demo", help="run the pretrained policy; write a GIF and the coverage figure")
    _agent_opts(p, "ppo")
    p.add_argument("--steps", type=int, default=600, help="episode length (default %(default)s)")
    p.add_argument("--fps", type=int, default=15, help="GIF frames per second (default %(default)s)")
    p.add_argument("--stride", type=int, default=2, help="keep every STRIDE-th frame (default %(default)s)")
    p.add_argument("--out", default="out", help="output folder (default %(default)s)")
    p.set_defaults(func=cmd_demo)

    p = sub.add_parser("train", help="train PPO from a config file plus key=value overrides")
    p.add_argument("config", nargs="?", default=None,
                   help="TOML or JSON config (default: agents/configs/ppo_digcoverage.toml)")  # fmt: skip
    p.add_argument("overrides", nargs="*", help="key=value overrides, e.g. total_timesteps=2048 "
                   "env_kwargs.map_size=40")  # fmt: skip
    p.set_defaults(func=cmd_train)

    p = sub.add_parser("evaluate", help="every agent on the same held-out maps: table and figure")
    p.add_argument("--agents", nargs="+", default=["ppo", "frontier"], help="agents (default %(default)s)")
    p.add_argument("--model", default=None, help="saved PPO model (.zip) instead of the shipped one")
    p.add_argument("--env", default=DEFAULT_ENV, help="environment id (default %(default)s)")
    p.add_argument("--maps", type=int, default=5, help="held-out maps (default %(default)s)")
    p.add_argument("--steps", type=int, default=1000, help="steps per episode (default %(default)s)")
    p.add_argument("--seed", type=int, default=1000, help="first map seed (default %(default)s)")
    p.add_argument("--out", default="out", help="output folder (default %(default)s)")
    ray_eval.add_cli(p)  # --ray, --address, --ray-cpus
    p.set_defaults(func=cmd_evaluate)

    p = sub.add_parser("record", help="record an agent's episode to a MissionRecord .npz")
    _agent_opts(p, "frontier")
    p.add_argument("--steps", type=int, default=300, help="episode length (default %(default)s)")
    p.add_argument("--out", default="out/episode.npz", help="output file (default %(default)s)")
    p.add_argument("--no-progress", dest="progress", action="store_false", help="hide the progress bar")
    p.set_defaults(func=cmd_record)

    p = sub.add_parser("replay", help="replay a recorded episode, check it is identical, run dig_slam")
    p.add_argument("file", help="episode .npz written by `digslam record`")
    p.add_argument("--digslam", action="store_true", help="re-run the offline Dig-SLAM observer on it")
    p.add_argument("--grid", type=int, default=64, help="dig_slam grid side in cells (default %(default)s)")
    p.add_argument("--max-iter", type=int, default=3, help="dig_slam iterations (default %(default)s)")
    p.set_defaults(func=cmd_replay)

    sweep.add_cli(sub)  # sweep CONFIG [--address A] [--resume] [--num-cpus N]

    p = sub.add_parser("benchmark", help="run benchmarks/<NAME>.py (source checkout only)")
    p.add_argument("name", help="benchmark name, e.g. agents or bench_agents")
    p.add_argument("args", nargs=argparse.REMAINDER, help="arguments passed to the benchmark")
    p.set_defaults(func=cmd_benchmark)
    return ap


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``digslam`` console script."""
    args = build_parser().parse_args(argv)
    for name in ("steps", "maps", "grid", "max_iter", "fps", "stride"):
        v = getattr(args, name, None)
        if v is not None and v < 1:
            opt = name.replace("_", "-")
            print(f"digslam {args.command}: --{opt} must be >= 1, got {v}", file=sys.stderr)
            return 2
    try:
        return int(args.func(args) or 0)
    except ValueError as exc:
        print(f"digslam {args.command}: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
