"""The subcommands that run agents and tools: ``demo``, ``train``, ``evaluate``, ``warmup``, ``benchmark``.

Each ``cmd_*`` takes the parsed arguments of its subparser (:mod:`.parser`) and returns the exit status;
heavy imports (torch, SB3, matplotlib) happen inside them. ``record`` and ``replay`` are in
:mod:`.episodes`, ``sweep`` and ``evaluate --ray`` in :mod:`.distributed`.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path
from typing import Any

from digslam.agents.cli.agents import agent_names, model_env_kwargs, resolve_agent
from digslam.agents.cli.common import (
    UserError,
    check_env_id,
    commit,
    coverage_target,
    make_env,
    out_path,
    require_ray,
    staged,
)
from digslam.agents.learning import models


def cmd_demo(args: argparse.Namespace) -> int:
    """``digslam demo``: one episode of an agent; writes the GIF and the coverage figure."""
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
    """``digslam train``: PPO (or, for a ``kind = "map_predictor"`` file, the map predictor) from a config
    file plus ``key=value`` overrides."""
    from digslam.agents.learning.train import TrainingInterrupted, train
    from digslam.agents.learning.train_config import TrainConfig

    config, overrides = args.config, list(args.overrides)
    if config is not None and "=" in config and not Path(config).is_file():  # only overrides were given
        config, overrides = None, [config, *overrides]
    if config is not None and Path(config).is_dir():
        raise UserError(f"{config}: is a folder; give a .toml or .json training configuration")
    from digslam.agents.prediction.fit import PredictorConfig, fit, is_predictor_config

    if is_predictor_config(config):  # kind = "map_predictor": the map predictor, not a PPO run
        pcfg = PredictorConfig.from_file(config, overrides)
        out_path(pcfg.out_dir, "out_dir")
        try:
            import torch  # noqa: F401
        except ImportError:
            raise UserError('the map predictor needs torch; pip install "digslam[train]"') from None
        print(f"training: {pcfg}")
        print(f"saved {fit(pcfg, command=' '.join(['digslam train', config, *overrides]))}")
        return 0
    cfg = TrainConfig.from_file(config, overrides)
    check_env_id(cfg.env_id, "train", opt="env_id", goals=True)
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
    """``digslam evaluate``: every agent on the same held-out maps (on Ray with ``--ray``)."""
    if args.ray or args.address is not None or args.ray_cpus is not None:
        require_ray("--ray" if args.ray else "--address/--ray-cpus")
    check_env_id(args.env, "evaluate")
    out = out_path(args.out, "--out")
    args.agents = [models.best_agent()[0] if a == "best" else a for a in args.agents]
    for a in args.agents:
        if a not in agent_names():
            raise UserError(f"--agents: unknown agent {a!r}; known: {', '.join(agent_names())}")
    if args.model is not None and "ppo" not in args.agents:
        raise UserError("--model: only with ppo among --agents")
    model = Path(args.model) if args.model else models.PRETRAINED
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


def cmd_warmup(args: argparse.Namespace) -> int:
    """``digslam warmup``: compile the numba kernels once."""
    from digslam.agents.cli.warmup import warmup

    return warmup(jobs=args.jobs, verbose=True)


def benchmarks_dir() -> Path | None:
    """The repository's ``benchmarks/`` folder (source checkout), or None when installed without it."""
    for base in (Path(__file__).resolve().parents[2], Path.cwd()):
        if (base / "benchmarks").is_dir():
            return base / "benchmarks"
    return None


def cmd_benchmark(args: argparse.Namespace) -> int:
    """``digslam benchmark NAME``: run ``benchmarks/NAME.py`` (or ``bench_NAME.py``)."""
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


__all__ = ["benchmarks_dir", "cmd_benchmark", "cmd_demo", "cmd_evaluate", "cmd_train", "cmd_warmup"]
