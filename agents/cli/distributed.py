"""The Ray side of the command line: ``digslam evaluate --ray`` and ``digslam sweep``.

:func:`add_ray_options` adds ``--ray``, ``--address`` and ``--ray-cpus`` to the ``evaluate`` subparser and
stores its handler as the ``ray_evaluate`` default (:func:`~digslam.agents.evaluation.ray_eval.evaluate_ray`
on the parsed agents); :func:`add_sweep_parser` adds ``sweep CONFIG [--address A] [--resume]
[--num-cpus N]`` (:func:`~digslam.agents.learning.sweep.run_sweep`). Both return their handler.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

from digslam.agents.cli.common import require_ray


def add_ray_options(parser: argparse.ArgumentParser) -> Callable[[argparse.Namespace], Any]:
    """Add ``--ray``, ``--address`` and ``--ray-cpus`` to the ``evaluate`` subparser; return its handler.

    The handler (also stored as the parser default ``ray_evaluate``) takes the parsed ``evaluate``
    arguments (``agents``, ``model``, ``env``, ``maps``, ``seed``, ``steps``) and returns the
    ``EvalResult`` of :func:`~digslam.agents.evaluation.ray_eval.evaluate_ray` (a pool of long-lived actors,
    one per CPU, taking batches of episodes; the result is the sequential one): ``"ppo"`` is the ``--model``
    path (default the shipped policy, with the environment keywords of its sidecar), any other agent a
    baseline name (:func:`~digslam.agents.evaluation.specs.agent_specs`).
    """
    parser.add_argument("--ray", action="store_true", help="run the episodes on Ray actors (batches)")
    parser.add_argument(
        "--address", default=None, help="Ray cluster to attach to (e.g. auto, host:6379); default: local"
    )
    parser.add_argument("--ray-cpus", type=int, default=None, help="CPUs of the local Ray instance")

    def handler(args: argparse.Namespace) -> Any:
        if (args.address is not None or args.ray_cpus is not None) and not args.ray:
            raise ValueError("--address/--ray-cpus: only with --ray")
        from digslam.agents.evaluation import ray_eval, specs  # on use: the command line starts light

        named, kwargs = specs.agent_specs(args.agents, args.model)
        return ray_eval.evaluate_ray(named, env_id=args.env, n_maps=args.maps, seed=args.seed,
                                     steps=args.steps, env_kwargs=kwargs, address=args.address,
                                     num_cpus=args.ray_cpus)  # fmt: skip

    parser.set_defaults(ray_evaluate=handler)
    return handler


def cmd_sweep(args: argparse.Namespace) -> int:
    """``digslam sweep``: check that Ray is there, then run the sweep handler."""
    require_ray("digslam sweep")
    return int(args.sweep_handler(args))


def add_sweep_parser(subparsers: Any) -> Callable[[argparse.Namespace], int]:
    """Add ``sweep CONFIG [--address A] [--resume] [--num-cpus N]`` to ``subparsers``; return the handler
    (also set as the parser's ``sweep_handler`` default; ``func`` is :func:`cmd_sweep`), which runs the
    sweep, prints the table and the CSV path and returns 0."""
    p = subparsers.add_parser("sweep", help="hyper-parameter and seed sweep of the PPO recipe on Ray Tune")
    p.add_argument(
        "config", help="sweep configuration (.toml or .json), see agents/configs/sweep_example.toml"
    )
    p.add_argument("--address", default=None, help="Ray cluster to attach to (e.g. auto); default: local")
    p.add_argument("--resume", action="store_true", help="restore an interrupted sweep of the same name")
    p.add_argument("--num-cpus", type=int, default=None, help="CPUs of the local Ray instance")

    def handler(args: argparse.Namespace) -> int:
        from digslam.agents.learning.sweep import SweepConfig, run_sweep

        table, csv_path = run_sweep(SweepConfig.from_file(args.config), address=args.address,
                                    resume=args.resume, num_cpus=args.num_cpus)  # fmt: skip
        print(table)
        print(f"results: {csv_path}")
        return 0

    p.set_defaults(func=cmd_sweep, sweep_handler=handler)
    return handler


__all__ = ["add_ray_options", "add_sweep_parser", "cmd_sweep"]
