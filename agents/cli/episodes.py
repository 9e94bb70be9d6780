"""The episode subcommands: ``record`` (an agent's episode to a ``.npz``) and ``replay`` (check it, re-run the
offline Dig-SLAM observer on it).

:func:`load_episode` turns every way an episode file can be wrong into one
:class:`~digslam.agents.cli.common.UserError` line.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

from digslam.agents.cli.agents import resolve_agent
from digslam.agents.cli.common import UserError, check_env_id, commit, first_line, make_env, out_path, staged


def _log_out(out: Path, fmt: str) -> tuple[Path, Path]:
    """The bag path for ``--format fmt`` (a ``.npz`` name loses its suffix; a ROS 1 bag ends in ``.bag``) and
    ``bounds.toml`` beside it; neither may exist (a log is never overwritten)."""
    if out.suffix == ".npz":
        out = out.with_suffix("")
    if fmt == "bag" and out.suffix != ".bag":
        out = out.with_name(out.name + ".bag")
    bounds = out.parent / "bounds.toml"
    for p in (out, bounds):
        if p.exists():
            raise UserError(f"{p}: exists already; give another --out (a log is never overwritten)")
    return out, bounds


def cmd_record(args: argparse.Namespace) -> int:
    """``digslam record``: run an agent for ``--steps`` and save the episode (``.npz``, or with ``--format``
    a ROS bag plus ``bounds.toml``)."""
    import numpy as np

    from digslam.envs.explore.episode import Episode, GroundTruth
    from digslam.observer.record.mission import MissionRecord

    check_env_id(args.env, "record")
    fmt = getattr(args, "format", "npz")
    out = Path(args.out)
    out_path(out, "--out", folder=False)
    if fmt != "npz":
        out, bounds_path = _log_out(out, fmt)
    elif out.suffix != ".npz":  # numpy would add it anyway: say so by writing the name we print
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
    if fmt != "npz":
        _write_bag(ep, out, bounds_path, fmt)
        out = f"{out} and {bounds_path}"  # type: ignore[assignment]  # only printed below
    else:
        with staged(out.parent) as tmp:
            ep.save(tmp / out.name)
            commit({tmp / out.name: out})
    print(f"agent {name}: {len(ep.actions)} steps, certified coverage {info['certified_coverage']:.3f}; "
          f"wrote {out}")  # fmt: skip
    return 0


def _write_bag(ep: Any, out: Path, bounds_path: Path, fmt: str) -> None:
    """Write the episode as a ROS bag and its bounds file (:mod:`digslam.envs.sim.logs.episode`)."""
    from digslam.envs.sim.logs.episode import episode_streams
    from digslam.observer.record.bag_write import LogWriteError, write_log

    streams, text = episode_streams(ep.records, ep.truth.pose, ep.config)
    try:
        bounds_path.parent.mkdir(parents=True, exist_ok=True)
        with staged(bounds_path.parent) as tmp:
            (tmp / bounds_path.name).write_text(text)
            write_log(out, fmt, streams)
            commit({tmp / bounds_path.name: bounds_path})
    except LogWriteError as exc:
        raise UserError(first_line(exc)) from None


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
        why = f"damaged archive: {first_line(exc)}"
    except ValueError as exc:
        why = "it holds pickled objects" if "pickle" in str(exc) else first_line(exc)
    except (OSError, EOFError, TypeError, AttributeError, IndexError) as exc:
        why = f"{type(exc).__name__}: {first_line(exc)}"
    raise UserError(f"{p}: not an episode ({why}); {fix}")


def cmd_replay(args: argparse.Namespace) -> int:
    """``digslam replay FILE``: replay an episode, check it is identical (exit 1 if not), ``--digslam``."""
    import numpy as np

    from digslam.envs.explore.episode import replay

    ep = load_episode(args.file)
    try:
        again = replay(ep)
    except ValueError as exc:
        raise UserError(f"{args.file}: cannot be replayed ({first_line(exc)}); {args.file} is damaged or "
                        "from another version; record it again") from None  # fmt: skip
    ok = same_episode(ep, again)
    print(f"{args.file}: {len(ep.actions)} steps, seed {ep.seed}; replay identical: {ok}")
    if args.digslam:
        from digslam.observer.online.smoother import dig_slam
        from digslam.observer.record.grid import Grid
        from digslam.observer.slam.digslam import DigSlamConfig

        s = float(ep.config.world_size)
        grid = Grid((-s, -s), (s, s), (args.grid, args.grid))
        start = ep.truth.pose[0, :2]
        res = dig_slam(ep.records, grid, start, start, DigSlamConfig(max_iter=args.max_iter))
        if not res.consistent or res.tube is None:
            print(f"dig_slam: inconsistent at gate {res.first_empty}")
        else:
            w = res.tube.widths()
            inside = bool(np.all(res.tube.contains(ep.records.t, ep.truth.pose[:, :2])))
            dr = res.dead_reckoning
            dr_txt = f"{float(np.max(dr)):.3f}" if dr is not None else "n/a"
            print(f"dig_slam: {res.iterations} iterations; pose box widest {float(np.max(w)):.3f} m, "
                  f"final {float(np.ravel(w)[-1]):.3f} m (dead reckoning widest {dr_txt} m); "
                  f"truth inside the tube: {inside}")  # fmt: skip
    return 0 if ok else 1


__all__ = ["cmd_record", "cmd_replay", "load_episode", "same_episode"]
