"""The ``digslam`` command: demo, train, evaluate, record, replay, sweep, certify, warmup and benchmark.

``digslam demo`` runs ``digslam/DigCoverage-v0`` with the best agent of the leaderboard shipped in
``digslam/agents/data/leaderboard.json`` (``--agent best``, the default; it prints which agent that is and
why; ``--agent ppo`` runs the shipped learned agent), writes the episode GIF and the certified-coverage figure
to ``--out`` and prints the certified coverage reached. Every
subcommand has ``--help``; heavy imports (torch, SB3, matplotlib) happen only when a subcommand needs them.

:func:`main` is the entry point (also ``python -m digslam.agents.cli.main``); the command line is split over
:mod:`.parser` (the parser), :mod:`.common` (:class:`UserError`, path and environment checks),
:mod:`digslam.agents.cli.agents` (``--agent``, saved models), :mod:`.commands`, :mod:`.episodes` and
:mod:`.distributed` (the subcommands). Their public names are re-exported here. The model registry (the
shipped policy, its environment) is :mod:`digslam.agents.learning.models`.

The console script ``digslam`` is :func:`main` (``digslam.agents.cli.main:main``).

>>> build_parser().parse_args(["demo", "--steps", "20"]).steps
20
"""

from __future__ import annotations

import sys
import warnings
from typing import Any

from digslam.agents.cli.agents import agent_names, load_agent, load_ppo, model_env_kwargs, resolve_agent
from digslam.agents.cli.certify import cmd_certify
from digslam.agents.cli.commands import (
    benchmarks_dir,
    cmd_benchmark,
    cmd_demo,
    cmd_evaluate,
    cmd_train,
    cmd_warmup,
)
from digslam.agents.cli.common import (
    EXTRAS,
    RAY_HINT,
    UserError,
    check_env_id,
    commit,
    coverage_target,
    first_line,
    make_env,
    out_path,
    require_ray,
    staged,
)
from digslam.agents.cli.distributed import cmd_sweep
from digslam.agents.cli.episodes import cmd_record, cmd_replay, load_episode, same_episode
from digslam.agents.cli.parser import build_parser
from digslam.agents.learning.models import DEFAULT_ENV


def _one_line_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                      file: Any = None, line: str | None = None) -> None:  # fmt: skip
    print(f"digslam: warning: {message}", file=sys.stderr if file is None else file)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``digslam`` console script: a mistake in the user's input is one line on stderr
    and exit status 2, never a traceback."""
    from digslam.observer.cache import origin

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
            print(f"{cmd}: {first_line(exc)}", file=sys.stderr)
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
            print(f"{cmd}: {where}{exc.strerror or first_line(exc)}", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())


__all__ = [
    "DEFAULT_ENV",
    "EXTRAS",
    "RAY_HINT",
    "UserError",
    "agent_names",
    "benchmarks_dir",
    "build_parser",
    "check_env_id",
    "cmd_benchmark",
    "cmd_certify",
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
