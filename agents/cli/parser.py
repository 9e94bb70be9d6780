"""The ``digslam`` argument parser: one subparser per subcommand, each with ``func`` set to its ``cmd_*``.

>>> build_parser().parse_args(["demo", "--steps", "20"]).steps
20
"""

from __future__ import annotations

import argparse

from digslam.agents.cli.certify import add_certify_parser
from digslam.agents.cli.commands import cmd_benchmark, cmd_demo, cmd_evaluate, cmd_train, cmd_warmup
from digslam.agents.cli.distributed import add_ray_options, add_sweep_parser
from digslam.agents.cli.episodes import cmd_record, cmd_replay
from digslam.agents.learning.models import DEFAULT_ENV


def agent_options(p: argparse.ArgumentParser, default: str) -> None:
    """Add ``--agent`` (default ``default``), ``--model``, ``--env`` and ``--seed`` to ``p``."""
    p.add_argument("--agent", default=default,
                   help="best (the best agent of the shipped leaderboard), ppo (the pretrained policy) or "
                        "a baseline: random, lawnmower, frontier, uncertainty_frontier, tour_frontier, "
                        "distance_advantage, predictive_frontier (the frontier agent on the shipped map "
                        "predictor) or predictive_chooser (the learned chooser of its gains) "
                        "(default %(default)s)")  # fmt: skip
    p.add_argument("--model", default=None, help="saved PPO model (.zip; a goal-level one for "
                   "predictive_chooser), or map predictor (.pt) of predictive_frontier, instead of the "
                   "shipped one")  # fmt: skip
    p.add_argument("--env", default=DEFAULT_ENV, help="environment id (default %(default)s)")
    p.add_argument("--seed", type=int, default=0, help="episode seed (default %(default)s)")


def build_parser() -> argparse.ArgumentParser:
    """The ``digslam`` argument parser."""
    ap = argparse.ArgumentParser(prog="digslam", description="Guaranteed Dig-SLAM: certified coverage demo, "
                                 "training, evaluation and episode tools.")  # fmt: skip
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser(
        "demo", help="run the best agent of the leaderboard; write a GIF and the coverage figure"
    )
    agent_options(p, "best")
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
    p.add_argument("--model", default=None, help="saved PPO model (.zip; a goal-level one for "
                   "predictive_chooser), or map predictor (.pt) of predictive_frontier, instead of the "
                   "shipped one")  # fmt: skip
    p.add_argument("--env", default=DEFAULT_ENV, help="environment id (default %(default)s)")
    p.add_argument("--maps", type=int, default=5, help="held-out maps (default %(default)s)")
    p.add_argument("--steps", type=int, default=1000, help="steps per episode (default %(default)s)")
    p.add_argument("--seed", type=int, default=1000, help="first map seed (default %(default)s)")
    p.add_argument("--out", default="out", help="output folder (default %(default)s)")
    add_ray_options(p)  # --ray, --address, --ray-cpus
    p.set_defaults(func=cmd_evaluate)

    p = sub.add_parser("record", help="record an agent's episode to a MissionRecord .npz or a ROS bag")
    agent_options(p, "frontier")
    p.add_argument("--steps", type=int, default=300, help="episode length (default %(default)s)")
    p.add_argument("--out", default="out/episode.npz", help="output file (default %(default)s; with a bag "
                   "format its .npz suffix is dropped)")  # fmt: skip
    p.add_argument("--format", default="npz", choices=["npz", "mcap", "sqlite3", "bag"],
                   help="npz (a MissionRecord episode, default), or a ROS bag: mcap or sqlite3 (ROS 2 "
                   "bag folder), bag (ROS 1); a bag comes with bounds.toml beside it, matching the env's "
                   "noise")  # fmt: skip
    p.add_argument("--no-progress", dest="progress", action="store_false", help="hide the progress bar")
    p.set_defaults(func=cmd_record)

    p = sub.add_parser("replay", help="replay a recorded episode, check it is identical, run dig_slam")
    p.add_argument("file", help="episode .npz written by `digslam record`")
    p.add_argument("--digslam", action="store_true", help="re-run the offline Dig-SLAM observer on it")
    p.add_argument("--grid", type=int, default=64, help="dig_slam grid side in cells (default %(default)s)")
    p.add_argument("--max-iter", type=int, default=3, help="dig_slam iterations (default %(default)s)")
    p.set_defaults(func=cmd_replay)

    add_sweep_parser(sub)  # sweep CONFIG [--address A] [--resume] [--num-cpus N]
    add_certify_parser(sub)  # certify LOG --bounds B.toml --out DIR

    p = sub.add_parser(
        "warmup",
        help="compile the numba kernels into the kernel store (pip install does it; a minute on 2 cores)",
        description="Compile the numba kernels of the environments, the observer, the interval library "
        "and the planning agents into the kernel store beside their sources (or numba's cache where the "
        "store is off), in parallel processes, so that the first demo, reset or paving does not wait for "
        "them. pip install runs it on the wheel it builds; run it after an editable install, or after "
        "installing with DIGSLAM_BUILD_KERNELS=0. Measured on 2 cores with nothing compiled: 67 s "
        "(two jobs at a time); with the kernels stored it only loads them (a few seconds).",
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


__all__ = ["agent_options", "build_parser"]
