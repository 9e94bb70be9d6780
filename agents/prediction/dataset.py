"""Snapshots for the map predictor: what the observer shows on training levels, and the layout behind it.

One level gives one ``.npz`` file (:func:`generate_level`): the ``"map"`` images of the base observation
(clear / penumbra / dark / pose box, ``uint8 (K, 4, m, m)``) taken along an episode of the goal env
(:mod:`digslam.agents.goals.env`), their ``"state"`` vectors, and one label, ``free (m, m)`` float32: the
share of the map pixel's observer cells that are **certifiable reachable free**
(:func:`~digslam.envs.dig_coverage.wrapper.reachable_free`, the denominator of certified coverage).

The episodes are driven by the frontier agent's own pick (candidate 0) mixed with random picks among the
valid candidates, with a share ``explore`` drawn per level from :data:`EXPLORE_SHARES`: the inputs cover
what an agent will see, not just the frontier agent's paths. A snapshot is taken at the first decision at
least ``every`` low-level steps after the last one.

**Ground truth only in the label.** ``free`` comes from the world's raster; the ``map`` and ``state`` come
from the observer, as any agent's observation. :func:`generate` writes ``<generator>_<seed>.npz`` files and
skips those already there (resumable), with a progress bar; it refuses test-split seeds.

>>> d = generate_level("room", 0, steps=60, every=30)
>>> d["map"].shape[1:], d["free"].shape, d["free"].dtype.name, bool(0 < d["free"].mean() < 1)
((4, 64, 64), (64, 64), 'float32', True)
"""

from __future__ import annotations

import zipfile
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from digslam.envs.observation import BASE_CHANNELS
from digslam.envs.splits import check_not_test

#: Shares of random candidate picks (one drawn per level): the frontier agent's picks and perturbed ones.
EXPLORE_SHARES = (0.0, 0.25, 0.5)


def free_labels(reachable: np.ndarray, m: int) -> np.ndarray:
    """``(m, m)`` float32: per map pixel, the share of its observer cells in ``reachable`` (the blocks of
    the map's conservative downsampling, :func:`digslam.envs.dig_coverage.maps_jit.block_starts`)."""
    from digslam.envs.dig_coverage.maps_jit import block_starts

    r = np.asarray(reachable, dtype=np.float64)
    rows, cols = block_starts(r.shape[0], m), block_starts(r.shape[1], m)
    sums = np.add.reduceat(np.add.reduceat(r, rows, axis=0), cols, axis=1)
    sizes = np.outer(np.diff(np.append(rows, r.shape[0])), np.diff(np.append(cols, r.shape[1])))
    return (sums / sizes).astype(np.float32)


def generate_level(generator: str, seed: int, steps: int = 2000, every: int = 60,
                   explore: float | None = None, map_size: int = 64) -> dict[str, Any]:  # fmt: skip
    """Snapshots of one level (module docstring): ``map``, ``state``, ``t`` (low-level step of each),
    ``free``, ``generator``, ``seed`` and ``explore``."""
    from digslam.agents.evaluation.suite import GENERATORS
    from digslam.agents.goals.env import GoalSelectionEnv
    from digslam.envs.stack import observer_of

    check_not_test("seed", [seed])
    env_id, kw = GENERATORS[generator]
    rng = np.random.default_rng((seed, 7919))
    share = float(rng.choice(EXPLORE_SHARES)) if explore is None else float(explore)
    env = GoalSelectionEnv(base_id=env_id, max_steps=steps, fixed_world=False, map_size=map_size, target=1.0,
                           **kw)  # fmt: skip
    try:
        obs, _ = env.reset(seed=seed)
        free = free_labels(observer_of(env).reachable, map_size)
        maps, states, ts, last = [], [], [], -every
        done = False
        while not done:
            t = env.elapsed
            base = env.base_observation
            if t - last >= every and base is not None:
                maps.append(np.array(base["map"][:BASE_CHANNELS]))
                states.append(np.array(base["state"]))
                ts.append(t)
                last = t
            mask = env.action_masks()
            valid = np.flatnonzero(mask)
            a = int(rng.choice(valid)) if (rng.random() < share and len(valid) > 1) else int(valid[0])
            obs, _, term, trunc, _ = env.step(a)
            done = term or trunc
    finally:
        env.close()
    return {"map": np.stack(maps), "state": np.stack(states).astype(np.float32),
            "t": np.asarray(ts, dtype=np.int32), "free": free, "generator": generator, "seed": seed,
            "explore": share}  # fmt: skip


def level_path(root: str | Path, generator: str, seed: int) -> Path:
    """The file of one level under ``root``."""
    return Path(root) / f"{generator}_{seed}.npz"


def generate(root: str | Path, generators: Sequence[str], seeds: Iterable[int], progress: bool = True,
             workers: int = 1, **kw: Any) -> list[Path]:  # fmt: skip
    """Write :func:`generate_level` for every generator and seed under ``root`` (one file each), skipping
    the files already there; the paths of all of them. ``workers > 1`` writes the levels in that many
    processes (spawned: each imports digslam afresh), with the same files as one process."""
    seeds = list(seeds)
    check_not_test("seeds", seeds)
    if not (isinstance(workers, int) and workers >= 1):
        raise ValueError(f"workers: must be an integer >= 1, got {workers!r}")
    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    paths = [level_path(root, g, s) for s in seeds for g in generators]
    todo = [(str(level_path(root, g, s)), g, s, kw) for s in seeds for g in generators
            if not _readable(level_path(root, g, s))]  # fmt: skip
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(paths), initial=len(paths) - len(todo), desc="snapshots", unit="level")
    if workers > 1 and len(todo) > 1:
        import multiprocessing

        with multiprocessing.get_context("spawn").Pool(min(workers, len(todo))) as pool:
            for _ in pool.imap_unordered(_write_level, todo):
                if bar is not None:
                    bar.update()
    else:
        for job in todo:
            _write_level(job)
            if bar is not None:
                bar.update()
    if bar is not None:
        bar.close()
    return paths


def _write_level(job: tuple[str, str, int, dict[str, Any]]) -> str:
    """Write one level's file atomically (there whole or not at all: an interrupted run resumes)."""
    path, generator, seed, kw = job
    d = generate_level(generator, seed, **kw)
    tmp = Path(path).with_suffix(".tmp.npz")
    np.savez_compressed(tmp, **d)
    tmp.replace(path)
    return path


def _readable(path: Path) -> bool:
    if not path.exists():
        return False
    try:
        with np.load(path) as d:
            return "free" in d.files
    except (OSError, ValueError, zipfile.BadZipFile):
        return False


def load(paths: Iterable[str | Path]) -> dict[str, np.ndarray]:
    """The snapshots of ``paths`` stacked: ``map (N, 4, m, m)`` uint8, ``free (N, m, m)`` float32 (each
    snapshot's level label), ``level (N,)`` (index into ``paths``) and ``generator (N,)``."""
    maps, free, level, gen = [], [], [], []
    for i, p in enumerate(paths):
        with np.load(p) as d:
            k = len(d["map"])
            maps.append(d["map"])
            free.append(np.broadcast_to(d["free"], (k, *d["free"].shape)))
            level += [i] * k
            gen += [str(d["generator"])] * k
    return {"map": np.concatenate(maps), "free": np.concatenate(free).astype(np.float32),
            "level": np.asarray(level), "generator": np.asarray(gen)}  # fmt: skip


__all__ = ["EXPLORE_SHARES", "free_labels", "generate", "generate_level", "level_path", "load"]
