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
import contextlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from digslam.agents.evaluation import ray_eval
from digslam.agents.learning import sweep

DATA = Path(__file__).parents[1] / "data"
#: The shipped policy and the environment keywords it was trained with (``<model>.json``).
PRETRAINED = DATA / "ppo_digcoverage.zip"
DEFAULT_ENV = "digslam/DigCoverage-v0"
#: What to do when Ray is missing (``--ray``, ``sweep``).
RAY_HINT = 'install the ray extra: pip install "digslam[ray]"'


class UserError(Exception):
    """A mistake in what the user gave (a path, an id, a key, a number): :func:`main` prints it as one line
    on stderr (``digslam COMMAND: message``) and exits with status 2."""


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def require_ray(what: str) -> None:
    """Raise :class:`UserError` naming the extra to install when Ray is not importable."""
    try:
        import ray  # noqa: F401
    except ImportError:
        raise UserError(f"{what} needs Ray, which is not installed; {RAY_HINT}") from None


def check_env_id(env_id: str, command: str, opt: str = "--env") -> None:
    """Accept the certified-coverage ids (the agents read the observer's map); otherwise raise
    :class:`UserError` listing the ids ``digslam COMMAND`` takes."""
    import gymnasium as gym

    from digslam import envs

    if env_id in envs.COVERAGE_IDS:
        return
    ids = ", ".join(envs.COVERAGE_IDS)
    if env_id in gym.registry:
        raise UserError(f"{opt} {env_id}: `digslam {command}` takes the certified-coverage environments "
                        f"(the agents read the observer's map): {ids}")  # fmt: skip
    raise UserError(f"{opt} {env_id!r}: no such environment; `digslam {command}` takes {ids} "
                    f"(raw exploration environments: {', '.join(envs.ENV_IDS)})")  # fmt: skip


def make_env(env_id: str, kwargs: dict[str, Any], what: str = "environment", **extra: Any) -> Any:
    """``gym.make(env_id, **kwargs, **extra)``; a bad keyword or value raises :class:`UserError`."""
    import gymnasium as gym

    import digslam.envs  # noqa: F401

    try:
        return gym.make(env_id, **kwargs, **extra)
    except (ValueError, TypeError, gym.error.Error) as exc:
        raise UserError(f"{what}: {_first_line(exc)}") from None


def out_path(path: str | Path, opt: str, folder: bool = True) -> Path:
    """Check that ``path`` (a folder, or a file with ``folder=False``) can be written, without writing."""
    p = Path(path).expanduser()
    if folder and p.exists() and not p.is_dir():
        raise UserError(f"{opt} {p}: exists and is not a folder; give a folder")
    if not folder and p.is_dir():
        raise UserError(f"{opt} {p}: is a folder; give a file name, e.g. {p / 'episode.npz'}")
    base = p if folder else p.parent
    while not base.exists() and base != base.parent:
        base = base.parent
    if not base.is_dir():
        raise UserError(f"{opt} {p}: {base} is a file, not a folder; give a path you can write to")
    if not os.access(base, os.W_OK | os.X_OK) or (p.exists() and not os.access(p, os.W_OK)):
        raise UserError(f"{opt} {p}: cannot write there (permission denied); give a path you can write to")
    return p


@contextlib.contextmanager
def staged(folder: Path) -> Iterator[Path]:
    """A scratch folder beside ``folder`` for outputs moved into it only on success (nothing half-written)."""
    base = folder
    while not base.exists() and base != base.parent:
        base = base.parent
    try:
        tmp = Path(tempfile.mkdtemp(prefix=".digslam-", dir=base))
    except OSError as exc:
        why = exc.strerror
        raise UserError(f"{folder}: cannot write there ({why}); give a path you can write to") from None
    try:
        yield tmp
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def commit(files: dict[Path, Path]) -> None:
    """Move staged files to their destinations (``{staged: final}``)."""
    for src, dst in files.items():
        try:
            dst.parent.mkdir(parents=True, exist_ok=True)
            os.replace(src, dst)
        except OSError as exc:
            why = exc.strerror
            raise UserError(f"{dst}: cannot write it ({why}); give a path you can write to") from None


def model_env_kwargs(model: Path = PRETRAINED) -> dict[str, Any]:
    """Environment keywords of a saved model (its ``.json`` sidecar; ``{}`` if none)."""
    side = Path(model).with_suffix(".json")
    if not side.is_file():
        return {}
    try:
        kw = dict(json.loads(side.read_text()).get("env_kwargs", {}))
    except (OSError, ValueError, AttributeError, TypeError) as exc:
        raise UserError(f"{side}: not a model sidecar written by `digslam train` ({_first_line(exc)}); "
                        "fix or delete it") from None  # fmt: skip
    kw.pop("fixed_world", None)  # a training choice, not part of the observation
    return kw


def agent_names() -> list[str]:
    """Names ``--agent`` takes: ``ppo`` and the baselines."""
    from digslam.agents.baselines.registry import BASELINES

    return ["ppo", *BASELINES]


def load_ppo(path: Path, env: Any) -> Any:
    """The saved PPO model at ``path``, checked against ``env``'s spaces (:class:`UserError` otherwise)."""
    if not path.is_file():
        what = "is a folder" if path.is_dir() else "does not exist"
        raise UserError(f"--model {path}: {what}; give a .zip saved by `digslam train` "
                        "(or leave --model out for the shipped policy)")  # fmt: skip
    try:
        from stable_baselines3 import PPO
    except ImportError:
        raise UserError("--model needs stable-baselines3 and torch; install the train extra: "
                        'pip install "digslam[train]"') from None  # fmt: skip
    from digslam.agents.learning.train import pin_threads

    pin_threads(1)
    try:
        model = PPO.load(path, device="cpu")
    except Exception as exc:  # noqa: BLE001 - any failure to read the file is the user's file
        raise UserError(f"--model {path}: not a PPO model saved by `digslam train` "
                        f"({type(exc).__name__}: {_first_line(exc)})") from None  # fmt: skip
    if model.observation_space != env.observation_space:
        raise UserError(f"--model {path}: trained on observations {model.observation_space}, but the "
                        f"environment gives {env.observation_space}; pass the environment keywords it was "
                        f"trained with in {path.with_suffix('.json')}")  # fmt: skip
    return model


def load_agent(name: str, env: Any, model: Path | None = None) -> Any:
    """A policy with SB3's ``predict``: ``"ppo"`` (a saved PPO model, default the shipped one) or a
    baseline name of :data:`digslam.agents.baselines.registry.BASELINES`.

    Raises:
        UserError: unknown ``name``, or a model that cannot be loaded for ``env``.
    """
    if name == "ppo":
        return load_ppo(Path(model) if model is not None else PRETRAINED, env)
    if name not in agent_names():
        raise UserError(f"--agent {name!r}: unknown agent; known: {', '.join(agent_names())}")
    from digslam.agents.baselines.registry import make_baseline

    return make_baseline(name, env)


def resolve_agent(name: str, env_id: str, model: Path | None) -> tuple[str, Any, dict[str, Any]]:
    """``(name, policy, env_kwargs)``. A ``--model`` the user names must load (:class:`UserError`
    otherwise); without one, ``"ppo"`` falls back to ``"frontier"`` (with a warning) when the shipped policy,
    torch or stable-baselines3 is unavailable."""
    if name not in agent_names():
        raise UserError(f"--agent {name!r}: unknown agent; known: {', '.join(agent_names())}")
    if model is not None and name != "ppo":
        raise UserError(f"--model: only with --agent ppo (got --agent {name})")
    path = Path(model) if model is not None else PRETRAINED
    kwargs = model_env_kwargs(path) if name == "ppo" else {}
    env = make_env(env_id, kwargs, f"{path.with_suffix('.json')}" if kwargs else "--env")
    try:
        if name == "ppo" and model is None:
            try:
                import stable_baselines3  # noqa: F401
            except ImportError:
                warnings.warn("the shipped PPO policy needs stable-baselines3 and torch (pip install "
                              '"digslam[train]"); using the frontier agent', stacklevel=2)  # fmt: skip
                return "frontier", load_agent("frontier", env), kwargs
            if not PRETRAINED.is_file():
                warnings.warn(
                    f"no shipped PPO policy at {PRETRAINED}; using the frontier agent", stacklevel=2
                )
                return "frontier", load_agent("frontier", env), kwargs
        return name, load_agent(name, env, model), kwargs
    finally:
        env.close()


# --- subcommands --------------------------------------------------------------------------------
def coverage_target(env_id: str, kwargs: dict[str, Any]) -> float | None:
    """The ``target`` certified coverage of a certified-coverage environment (None if it has none)."""
    import gymnasium as gym

    from digslam.envs.dig_coverage.config import DigCoverageConfig

    try:
        merged = {**gym.spec(env_id).kwargs, **kwargs}
        merged = {k: v for k, v in merged.items() if k not in ("render_mode", "max_episode_steps")}
        return float(DigCoverageConfig.split(merged).target)
    except (ValueError, TypeError, gym.error.Error):
        return None


def cmd_demo(args: argparse.Namespace) -> int:
    check_env_id(args.env, "demo")
    out = out_path(args.out, "--out")
    name, policy, kwargs = resolve_agent(args.agent, args.env, args.model)
    from digslam.agents.evaluation.evaluate import coverage_figure
    from digslam.agents.evaluation.pictures import demo_episode

    print(f"agent: {name}; env: {args.env} {kwargs}; {args.steps} steps, seed {args.seed}")
    with staged(out) as tmp:
        res = demo_episode(policy, args.env, tmp / "episode.gif", steps=args.steps, seed=args.seed,
                           env_kwargs=kwargs, fps=args.fps, stride=args.stride, name=name)  # fmt: skip
        coverage_figure(res, tmp / "coverage.png", target=coverage_target(args.env, kwargs))
        gif, fig = out / "episode.gif", out / "coverage.png"
        commit({tmp / "episode.gif": gif, tmp / "coverage.png": fig})
    import numpy as np

    cov = float(np.asarray(res.curves[name])[..., -1].mean())
    true = float(np.asarray(res.true_curves[name])[..., -1].mean())
    n = int(res.lengths[name][0])
    print(f"wrote {gif} and {fig}")
    print(f"certified coverage after {n} steps: {cov:.3f} (ground truth {true:.3f})")
    return 0


class _NoSigint:
    """Ignore SIGINT while worker processes start (they inherit it: Ctrl-C reaches the main process only)."""

    def __enter__(self) -> None:
        import signal

        self.old = signal.signal(signal.SIGINT, signal.SIG_IGN)

    def __exit__(self, *exc: object) -> None:
        import signal

        signal.signal(signal.SIGINT, self.old)


def cmd_train(args: argparse.Namespace) -> int:
    from digslam.agents.learning.train import TrainConfig, TrainingInterrupted, train

    config, overrides = args.config, list(args.overrides)
    if config is not None and "=" in config and not Path(config).is_file():  # only overrides were given
        config, overrides = None, [config, *overrides]
    if config is not None and Path(config).is_dir():
        raise UserError(f"{config}: is a folder; give a .toml or .json training configuration")
    cfg = TrainConfig.from_file(config, overrides)
    check_env_id(cfg.env_id, "train", opt="env_id")
    make_env(cfg.env_id, dict(cfg.env_kwargs), "env_kwargs").close()  # here, before any worker starts
    out_path(cfg.out_dir, "out_dir")
    try:
        import stable_baselines3  # noqa: F401
    except ImportError:
        raise UserError('training needs stable-baselines3 and torch; pip install "digslam[train]"') from None
    print(f"training: {cfg}")
    try:
        path = train(cfg, worker_guard=_NoSigint())
    except TrainingInterrupted as exc:
        ckpt = Path(cfg.out_dir) / "checkpoints"
        more = f" (checkpoints in {ckpt})" if ckpt.is_dir() else ""
        raise UserError(f"interrupted after {exc.timesteps} timesteps; saved {exc.path}{more}") from None
    print(f"saved {path}")
    return 0


def cmd_evaluate(args: argparse.Namespace) -> int:
    if args.ray or args.address is not None or args.ray_cpus is not None:
        require_ray("--ray" if args.ray else "--address/--ray-cpus")
    check_env_id(args.env, "evaluate")
    out = out_path(args.out, "--out")
    for a in args.agents:
        if a not in agent_names():
            raise UserError(f"--agents: unknown agent {a!r}; known: {', '.join(agent_names())}")
    if args.model is not None and "ppo" not in args.agents:
        raise UserError("--model: only with ppo among --agents")
    model = Path(args.model) if args.model else PRETRAINED
    from digslam.agents.evaluation.evaluate import coverage_figure, evaluate

    if args.ray:
        if "ppo" in args.agents and not model.is_file():
            raise UserError(f"--model {model}: does not exist; give a .zip saved by `digslam train`")
        res = args.ray_evaluate(args)
    else:
        kwargs = model_env_kwargs(model) if "ppo" in args.agents else {}
        policies: dict[str, Any] = {}
        for a in args.agents:
            name, pol, _ = resolve_agent(a, args.env, args.model if a == "ppo" else None)
            policies[name if name not in policies else f"{a} ({name})"] = pol
        res = evaluate(policies, args.env, n_maps=args.maps, seed=args.seed, steps=args.steps,
                       env_kwargs=kwargs, progress=True)  # fmt: skip
    kwargs = model_env_kwargs(model) if "ppo" in args.agents else {}
    at = tuple(s for s in (1000, 3000) if s <= args.steps) or (args.steps,)
    print(res.table(at=at))
    with staged(out) as tmp:
        res.to_json(tmp / "evaluation.json")
        coverage_figure(res, tmp / "coverage.png", target=coverage_target(args.env, kwargs))
        commit({tmp / "evaluation.json": out / "evaluation.json", tmp / "coverage.png": out / "coverage.png"})
    print(f"wrote {out / 'coverage.png'} and {out / 'evaluation.json'}")
    return 0


def cmd_record(args: argparse.Namespace) -> int:
    import numpy as np

    from digslam.envs.explore.episode import Episode, GroundTruth
    from digslam.observer.slam.record import MissionRecord

    check_env_id(args.env, "record")
    out = Path(args.out)
    out_path(out, "--out", folder=False)
    if out.suffix != ".npz":  # numpy would add it anyway: say so by writing the name we print
        out = out.with_name(out.name + ".npz")
    out = out_path(out, "--out", folder=False)
    name, policy, kwargs = resolve_agent(args.agent, args.env, args.model)
    env = make_env(args.env, kwargs, "--env", max_episode_steps=args.steps)
    try:
        obs, info = env.reset(seed=args.seed)
        recs, truths, actions = [info["record"]], [info["truth"]], []
        bar = None
        if args.progress:
            from tqdm import tqdm

            bar = tqdm(total=args.steps, desc=f"record {name}")
        for _ in range(args.steps):
            a, _ = policy.predict(obs, deterministic=True)
            a = np.asarray(a, dtype=np.float32).reshape(2)
            obs, _, term, trunc, info = env.step(a)
            actions.append(a)
            recs.append(info["record"])
            truths.append(info["truth"])
            if bar is not None:
                bar.update()
            if term or trunc:
                break
        if bar is not None:
            bar.close()
        ep = Episode(env.unwrapped.config, int(args.seed), np.array(actions, np.float32).reshape(-1, 2),
                     MissionRecord.stack(recs), GroundTruth.stack(truths))  # fmt: skip
    finally:
        env.close()
    with staged(out.parent) as tmp:
        ep.save(tmp / out.name)
        commit({tmp / out.name: out})
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


def load_episode(path: str | Path) -> Any:
    """:meth:`Episode.load` with every way a file can be wrong turned into one :class:`UserError` line."""
    import zipfile

    from digslam.envs.explore.episode import Episode

    p = Path(path)
    fix = "give an episode .npz written by `digslam record`"
    if not p.exists():
        raise UserError(f"{p}: no such file; {fix} (e.g. digslam record --out {p})")
    if p.is_dir():
        raise UserError(f"{p}: is a folder; {fix}")
    if not os.access(p, os.R_OK):
        raise UserError(f"{p}: cannot read it (permission denied)")
    if not zipfile.is_zipfile(p):
        raise UserError(f"{p}: not an .npz archive; {fix}")
    try:
        return Episode.load(p)
    except KeyError as exc:
        why = f"no {exc.args[0]!r} array" if exc.args else "an array is missing"
    except zipfile.BadZipFile as exc:
        why = f"damaged archive: {_first_line(exc)}"
    except ValueError as exc:
        why = "it holds pickled objects" if "pickle" in str(exc) else _first_line(exc)
    except (OSError, EOFError, TypeError, AttributeError, IndexError) as exc:
        why = f"{type(exc).__name__}: {_first_line(exc)}"
    raise UserError(f"{p}: not an episode ({why}); {fix}")


def cmd_replay(args: argparse.Namespace) -> int:
    import numpy as np

    from digslam.envs.explore.episode import replay

    ep = load_episode(args.file)
    try:
        again = replay(ep)
    except ValueError as exc:
        raise UserError(f"{args.file}: cannot be replayed ({_first_line(exc)}); {args.file} is damaged or "
                        "from another version; record it again") from None  # fmt: skip
    ok = same_episode(ep, again)
    print(f"{args.file}: {len(ep.actions)} steps, seed {ep.seed}; replay identical: {ok}")
    if args.digslam:
        from digslam.observer.slam.digslam import DigSlamConfig, dig_slam
        from digslam.observer.slam.grid import Grid

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


def cmd_warmup(args: argparse.Namespace) -> int:
    from digslam.agents.cli.warmup import warmup

    return warmup(jobs=args.jobs, verbose=True)


def cmd_sweep(args: argparse.Namespace) -> int:
    require_ray("digslam sweep")
    return int(args.sweep_handler(args))


def benchmarks_dir() -> Path | None:
    """The repository's ``benchmarks/`` folder (source checkout), or None when installed without it."""
    for base in (Path(__file__).resolve().parents[2], Path.cwd()):
        if (base / "benchmarks").is_dir():
            return base / "benchmarks"
    return None


def cmd_benchmark(args: argparse.Namespace) -> int:
    folder = benchmarks_dir()
    if folder is None:
        raise UserError("the benchmarks/ folder ships with the source checkout only; clone the repository "
                        "and run `digslam benchmark NAME` from it")  # fmt: skip
    stem = args.name.removesuffix(".py")
    cands = [folder / f"{stem}.py", folder / f"bench_{stem}.py"]
    script = next((c for c in cands if c.is_file()), None)
    if script is None:
        names = sorted(p.stem for p in folder.glob("bench_*.py"))
        raise UserError(f"no benchmark {args.name!r}; known: {', '.join(names)}")
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

    handler = sweep.add_cli(sub)  # sweep CONFIG [--address A] [--resume] [--num-cpus N]
    sub.choices["sweep"].set_defaults(func=cmd_sweep, sweep_handler=handler)

    p = sub.add_parser(
        "warmup",
        help="compile the numba kernels once (about a minute on 2 cores)",
        description="Compile the numba kernels of the environments, the observer and the "
        "interval library into their on-disk cache, in parallel processes, so that the first "
        "demo, reset or paving does not wait for them. Run it once after installing.",
    )
    p.add_argument(
        "--jobs", type=int, default=None, help="parallel processes (default: the CPU count, at most 3)"
    )
    p.set_defaults(func=cmd_warmup)

    p = sub.add_parser("benchmark", help="run benchmarks/<NAME>.py (source checkout only)")
    p.add_argument("name", help="benchmark name, e.g. agents or bench_agents")
    p.add_argument("args", nargs=argparse.REMAINDER, help="arguments passed to the benchmark")
    p.set_defaults(func=cmd_benchmark)
    return ap


#: The extra that provides each optional top-level module.
EXTRAS = {"torch": "train", "stable_baselines3": "train", "tensorboard": "train", "tqdm": "train",
          "rich": "train", "matplotlib": "viz", "imageio": "viz", "PIL": "viz", "pymunk": "sim",
          "gymnasium": "sim", "pygame": "sim", "ray": "ray"}  # fmt: skip


def _one_line_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                      file: Any = None, line: str | None = None) -> None:  # fmt: skip
    print(f"digslam: warning: {message}", file=sys.stderr if file is None else file)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``digslam`` console script: a mistake in the user's input is one line on stderr
    and exit status 2, never a traceback."""
    from digslam.observer.core import origin

    origin.warn_if_shadowed()
    args = build_parser().parse_args(argv)
    for name in ("steps", "maps", "grid", "max_iter", "fps", "stride", "jobs", "num_cpus", "ray_cpus"):
        v = getattr(args, name, None)
        if v is not None and v < 1:
            opt = name.replace("_", "-")
            print(f"digslam {args.command}: --{opt} must be >= 1, got {v}", file=sys.stderr)
            return 2
    if getattr(args, "seed", 0) < 0:
        print(f"digslam {args.command}: --seed must be >= 0, got {args.seed}", file=sys.stderr)
        return 2
    cmd = f"digslam {args.command}"
    with warnings.catch_warnings():
        warnings.showwarning = _one_line_warning
        try:
            return int(args.func(args) or 0)
        except (UserError, ValueError) as exc:
            print(f"{cmd}: {_first_line(exc)}", file=sys.stderr)
        except ModuleNotFoundError as exc:
            top = (exc.name or "").split(".")[0]
            extra = EXTRAS.get(top)
            if extra is None:
                raise
            hint = f'pip install "digslam[{extra}]"'
            print(f"{cmd}: needs {top}, which is not installed; {hint}", file=sys.stderr)
        except KeyboardInterrupt:
            print(f"{cmd}: interrupted; nothing written", file=sys.stderr)
        except OSError as exc:
            where = f"{exc.filename}: " if exc.filename else ""
            print(f"{cmd}: {where}{exc.strerror or _first_line(exc)}", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())


__all__ = [
    "DATA",
    "DEFAULT_ENV",
    "EXTRAS",
    "PRETRAINED",
    "RAY_HINT",
    "UserError",
    "agent_names",
    "benchmarks_dir",
    "build_parser",
    "check_env_id",
    "cmd_benchmark",
    "cmd_demo",
    "cmd_evaluate",
    "cmd_record",
    "cmd_replay",
    "cmd_sweep",
    "cmd_train",
    "cmd_warmup",
    "commit",
    "coverage_target",
    "load_agent",
    "load_episode",
    "load_ppo",
    "main",
    "make_env",
    "model_env_kwargs",
    "out_path",
    "require_ray",
    "resolve_agent",
    "same_episode",
    "staged",
]
