"""Scaffolding shared by the example scripts of this folder (not part of the ``digslam`` package).

* :func:`parser`: the command line, ``--out`` (output folder) and the options several scripts share
  (``--eps``, ``--duration``, ``--steps``, ``--seed``), each with the script's own default;
* :func:`out_dir` creates the output folder; :func:`save_figure` writes a figure into it and closes it;
* :func:`report` prints a result dict as ``key: value`` lines.

A script run as ``python examples/<name>.py`` has this folder on ``sys.path``, so ``from _common import
...`` works; ``tests/example_loader.py`` and ``benchmarks/bench_localization.py`` put it there before
importing a script by path.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

__all__ = ["DPI", "out_dir", "parser", "report", "save_figure"]

#: resolution of the saved figures (that of :func:`digslam.observer.paving.draw.save_figure`)
DPI = 150


def parser(
    doc: str | None,
    *,
    out: str | None = "out",
    eps: float | None = None,
    eps_help: str | None = None,
    duration: float | None = None,
    steps: int | None = None,
    seed: int | None = None,
) -> argparse.ArgumentParser:
    """An :class:`~argparse.ArgumentParser` described by ``doc`` (kept as written) with the common options.

    ``--out`` (the output folder, default ``out``; ``out=None``: the script declares its own) and, for each
    of ``eps`` (``--eps``, paver precision; ``eps_help`` replaces its help text), ``duration``
    (``--duration``, mission length in s), ``steps`` (``--steps``) and ``seed`` (``--seed``, simulation
    seed) that is not ``None``, that option with this default. The script adds its own options after them.
    """
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    if out is not None:
        ap.add_argument("--out", default=out, help=f"output folder (default: {out}/)")
    if eps is not None:
        help_eps = eps_help or f"paver precision ε (default {eps:g})"
        ap.add_argument("--eps", type=float, default=eps, help=help_eps)
    if duration is not None:
        help_duration = f"mission length in s (default {duration:g})"
        ap.add_argument("--duration", type=float, default=duration, help=help_duration)
    if steps is not None:
        ap.add_argument("--steps", type=int, default=steps, help=f"number of steps (default {steps})")
    if seed is not None:
        ap.add_argument("--seed", type=int, default=seed, help=f"simulation seed (default {seed})")
    return ap


def out_dir(path: str | Path) -> Path:
    """``path`` as a :class:`~pathlib.Path`, the folder created (with its parents) if missing."""
    path = Path(path)
    path.mkdir(parents=True, exist_ok=True)
    return path


def save_figure(fig: Any, out: str | Path, name: str, *, dpi: int = DPI) -> Path:
    """Save the matplotlib figure ``fig`` as ``out/name`` (creating ``out``), close it; return the path.

    Closing only matters for a :mod:`matplotlib.pyplot` figure (it would stay registered); a figure of
    :func:`~digslam.observer.paving.draw.new_figure` is freed with its last reference.
    """
    path = out_dir(out) / name
    fig.savefig(path, dpi=dpi)
    plt = sys.modules.get("matplotlib.pyplot")
    if plt is not None:
        plt.close(fig)
    return path


def report(result: Mapping[str, Any], *, skip: Iterable[str] = ()) -> None:
    """Print one ``key: value`` line per item of ``result``, leaving out the keys in ``skip``."""
    for key, value in result.items():
        if key not in skip:
            print(f"{key}: {value}")
