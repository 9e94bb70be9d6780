"""What every subcommand shares: the one-line user error, environment and output-path checks, staged writes.

A mistake in what the user gave raises :class:`UserError`; :func:`~digslam.agents.cli.main.main` prints it
as one line on stderr and exits with status 2. Outputs are written in a scratch folder (:func:`staged`) and
moved into place only on success (:func:`commit`), so a failed command leaves nothing half-written.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

#: What to do when Ray is missing (``--ray``, ``sweep``).
RAY_HINT = 'install the ray extra: pip install "digslam[ray]"'

#: The extra that provides each optional top-level module.
EXTRAS = {"torch": "train", "stable_baselines3": "train", "tensorboard": "train", "tqdm": "train",
          "rich": "train", "matplotlib": "viz", "imageio": "viz", "PIL": "viz", "pymunk": "sim",
          "gymnasium": "sim", "pygame": "sim", "ray": "ray"}  # fmt: skip


class UserError(Exception):
    """A mistake in what the user gave (a path, an id, a key, a number): :func:`main` prints it as one line
    on stderr (``digslam COMMAND: message``) and exits with status 2."""


def first_line(exc: BaseException) -> str:
    """The first line of an exception's message (its type name when the message is empty)."""
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def require_ray(what: str) -> None:
    """Raise :class:`UserError` naming the extra to install when Ray is not importable."""
    try:
        import ray  # noqa: F401
    except ImportError:
        raise UserError(f"{what} needs Ray, which is not installed; {RAY_HINT}") from None


def check_env_id(env_id: str, command: str, opt: str = "--env", goals: bool = False) -> None:
    """Accept the certified-coverage ids (the agents read the observer's map), and with ``goals`` the
    goal-selection ids of :mod:`digslam.agents.goals`; otherwise raise :class:`UserError` listing the ids
    ``digslam COMMAND`` takes."""
    import gymnasium as gym

    from digslam import envs

    known = list(envs.COVERAGE_IDS)
    if goals:
        from digslam.agents.goals.registry import GOAL_IDS

        known += list(GOAL_IDS)
    if env_id in known:
        return
    ids = ", ".join(known)
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
        raise UserError(f"{what}: {first_line(exc)}") from None


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


__all__ = [
    "EXTRAS",
    "RAY_HINT",
    "UserError",
    "check_env_id",
    "commit",
    "coverage_target",
    "first_line",
    "make_env",
    "out_path",
    "require_ray",
    "staged",
]
