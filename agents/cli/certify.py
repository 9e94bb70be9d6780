"""``digslam certify LOG --bounds B.toml --out DIR``: a guaranteed explored-zone report from a robot's log.

:func:`certify` reads the bounds file (:func:`digslam.observer.record.bounds.read_bounds`) and the log
(:func:`digslam.observer.record.bag.read_log`: ROS 2 MCAP or sqlite3, ROS 1 ``.bag``), then
:func:`certify_log` runs the offline Dig-SLAM fixpoint (:func:`digslam.observer.online.smoother.dig_slam`,
thesis §6.4) on the records in the frame of :func:`.certify_run.frame_grid`, with the online filter as a
cross-check (:func:`.certify_run.cross_check`), and writes ``summary.json``, ``map.png``, ``zones.geojson``
and ``raster.npz`` (:mod:`.report`) into a scratch folder moved into ``DIR`` when complete. The log is only
read.

When the data contradict the bounds, :func:`certify_log` finds the first failing record and the claim that
broke (:mod:`.certify_diagnose`), certifies the records before it, marks the summary ``partial`` and puts the
one-line explanation in ``summary["failure"]["message"]``; the command prints it and exits 1.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from digslam.agents.cli import certify_diagnose as dg
from digslam.agents.cli import certify_run as cr
from digslam.agents.cli.common import UserError, commit, first_line, out_path, staged
from digslam.agents.cli.report import Certified, write_all
from digslam.observer.record.mission import MissionRecord
from digslam.observer.thick.cells import CLEAR, PENUMBRA

#: The map's cell side (m) when the bounds file has no ``[map] resolution``.
DEFAULT_RESOLUTION = 0.1


class LogLike(Protocol):
    """What :func:`certify_log` reads of a :class:`digslam.observer.record.bag.Log`."""

    records: MissionRecord
    t0: float
    x0_lo: np.ndarray
    x0_hi: np.ndarray
    q: int
    max_range: float
    frame_id: str
    topics: dict[str, str]
    stamps: np.ndarray


def _columns(log: Any) -> dict[str, np.ndarray]:
    """Range topic -> its sensor columns in the records (from the log's ``slot_topics``; without them, the
    one range topic, or every column as one group)."""
    slots = getattr(log, "slot_topics", None)
    if slots:
        names = list(dict.fromkeys(slots))
        return {t: np.flatnonzero(np.asarray(slots) == t) for t in names}
    ranges = [t for role, t in log.topics.items() if role.startswith("range")]
    name = ranges[0] if len(ranges) == 1 else "the range sensors"
    return {name: np.arange(log.records.n_sensors)}


def _resolution(log: Any, given: float | None) -> float:
    if given is not None:
        return float(given)
    res = getattr(getattr(getattr(log, "bounds", None), "map", None), "resolution", None)
    return float(res) if res else DEFAULT_RESOLUTION


def _certified(rec: MissionRecord, log: Any, res: float, q: int, cross: bool, bar: Any) -> tuple[Any, ...]:
    """Offline (and online) on ``rec``: ``(offline result, grid, online run or None, seconds each)``."""
    grid = cr.frame_grid(rec, log.x0_lo, log.x0_hi, log.max_range, res)
    t = time.perf_counter()
    on = cr.run_online(rec, grid, log.x0_lo, log.x0_hi, q, bar) if cross else None
    t_on, t = time.perf_counter() - t, time.perf_counter()
    off = cr.run_offline(rec, grid, log.x0_lo, log.x0_hi, q)
    return off, grid, on, t_on, time.perf_counter() - t


def _stamp(log: Any, k: int) -> dict[str, float]:
    return {"record": k, "stamp": float(log.stamps[k]), "seconds": float(log.records.t[k] - log.records.t[0])}


def certify_log(log: LogLike, out_dir: str | Path, *, progress: bool = False, cross_check: bool = True,
                resolution: float | None = None, paths: tuple[str, str] = ("", "")
                ) -> dict[str, Any]:  # fmt: skip
    """Certify a read log into ``out_dir`` (see the module docstring); return the summary written."""
    start, out = time.perf_counter(), out_path(out_dir, "--out")
    rec, q, res = log.records, int(log.q), _resolution(log, resolution)
    n = len(rec)
    if n < 2:
        raise UserError(f"{paths[0] or 'the log'}: {n} record(s); certify needs at least two")
    bar = _bar(progress, n - 1 if cross_check else 0, "certify (online filter, then the fixpoint)", "record")
    failure, k_ok = None, n
    try:
        off, grid, on, t_on, t_off = _certified(rec, log, res, q, cross_check, bar)
        if not off.consistent:
            upper = on.failed_at if on is not None and not on.consistent else None
            ok = lambda k: cr.is_consistent(rec[: k + 1], log.x0_lo, log.x0_hi, q, log.max_range, res)  # noqa: E731
            k_ok = dg.first_failure(ok, n, upper)
            why = dg.culprit(
                rec[: k_ok + 1], log.x0_lo, log.x0_hi, q, log.max_range, res, _columns(log), log.topics, rec
            )
            failure = {**_stamp(log, k_ok), "sensor": why.name, "key": why.key, "factor": why.factor}
            failure["message"] = (f"inconsistent at record {k_ok} (stamp {failure['stamp']:.6f}, "
                                  f"{failure['seconds']:.2f} s into the log): "
                                  f"{dg.describe(why)}")  # fmt: skip
            off = on = None
            if k_ok >= 2:
                off, grid, on, t_on, t_off = _certified(rec[:k_ok], log, res, q, cross_check, None)
    finally:
        if bar is not None:
            bar.close()
    summary = _summary(log, off, on, grid if off is not None else None, k_ok, failure, paths)
    summary.update(seconds_online=t_on if on is not None else None, seconds_offline=t_off)
    cert = None
    if off is not None and off.consistent:
        assert off.tube is not None and off.dig is not None and off.explored is not None
        cert = Certified(grid, off.explored, off.dig.free, rec.t[:k_ok], off.tube.gate_lo, off.tube.gate_hi,
                         np.concatenate([off.heading.gate_lo, off.heading.gate_hi], axis=1))  # fmt: skip
    with staged(out) as tmp:
        title = f"{Path(paths[0]).name or 'log'}: {summary['records']} records, {summary['duration_s']:.1f} s"
        names = write_all(tmp, cert, summary, np.asarray(log.stamps)[:k_ok], log.frame_id, title, start)
        commit({tmp / f: out / f for f in names})
    return summary


def _summary(log: Any, off: Any, on: Any, grid: Any, k: int, failure: Any, paths: tuple[str, str]) -> dict:
    """The summary's fields (areas in m², widths in m)."""
    import importlib.metadata as md

    try:
        version = md.version("digslam")
    except md.PackageNotFoundError:
        version = "unknown"
    rec = log.records
    s: dict[str, Any] = {"digslam_version": version, "log": paths[0], "bounds": paths[1],
                         "frame_id": log.frame_id, "records": k, "records_in_log": len(rec),
                         "duration_s": float(rec.t[max(k, 1) - 1] - rec.t[0]), "t0": float(log.stamps[0]),
                         "consistent": failure is None, "partial": failure is not None,
                         "failure": failure, "q": int(log.q), "topics": dict(log.topics),
                         "dropped": dict(getattr(log, "dropped", {}) or {})}  # fmt: skip
    s.update(area_explored_m2=0.0, area_free_m2=0.0, area_certified_m2=0.0, area_penumbra_m2=0.0)
    if off is None or not off.consistent:
        return s
    a = grid.cell_size[0] * grid.cell_size[1]
    code, free = off.explored, off.dig.free
    w = np.max(off.tube.gate_hi - off.tube.gate_lo, axis=1)
    s.update(area_explored_m2=float(np.sum(code == CLEAR)) * a, area_free_m2=float(np.sum(free)) * a,
             area_certified_m2=float(np.sum((code == CLEAR) & free)) * a,
             area_penumbra_m2=float(np.sum(code == PENUMBRA)) * a,
             widest_pose_box_m={"width": float(w.max()), **_stamp(log, int(np.argmax(w)))},
             widest_heading_rad=float(np.max(off.heading.gate_hi - off.heading.gate_lo)),
             frame={"lo": list(grid.lo), "hi": list(grid.hi), "shape": list(grid.shape),
                    "resolution": list(grid.cell_size)}, iterations=off.iterations)  # fmt: skip
    if on is not None:
        s["cross_check"] = cr.cross_check(off, on, a)
    return s


def _bar(progress: bool, total: int, desc: str, unit: str) -> Any:
    """A tqdm bar on stderr (None without ``progress`` or tqdm)."""
    if not progress or total <= 0:
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None
    return tqdm(total=total, desc=desc, unit=unit, leave=False)


def _advance(bar: Any) -> Any:
    """The reader's ``progress(done, total)`` moving ``bar``."""

    def progress(done: int, total: int) -> None:
        bar.total = total
        bar.update(done - bar.n)

    return progress


def _with_beams(bounds: Any, beams: int) -> Any:
    """The bounds with every range topic's ``beams`` set to ``beams`` (a ``Range`` topic has one anyway)."""
    import dataclasses

    if beams < 1:
        raise UserError(f"--beams must be >= 1, got {beams}")
    return dataclasses.replace(
        bounds, ranges=tuple(dataclasses.replace(r, beams=beams) for r in bounds.ranges)
    )


def read(
    log_path: str | Path, bounds_path: str | Path, beams: int | None = None, progress: bool = False
) -> Any:
    """The bounds and the log read (reader errors as :class:`UserError` lines)."""
    try:
        from digslam.observer.record.bag import LogError, read_log
        from digslam.observer.record.bounds import BoundsError, read_bounds
    except ModuleNotFoundError as exc:
        if (exc.name or "").startswith("rosbags"):
            raise UserError('reading ROS logs needs rosbags; pip install "digslam[ros]"') from None
        raise
    lp, bp = Path(log_path).expanduser(), Path(bounds_path).expanduser()
    if not lp.exists():
        raise UserError(f"{lp}: no such log; give a ROS 2 bag folder, a .mcap or .db3 file, or a ROS 1 .bag")
    if not bp.is_file():
        raise UserError(f"--bounds {bp}: " + ("is a folder" if bp.is_dir() else "no such file") +
                        "; give a bounds .toml (see docs/certify.md)")  # fmt: skip
    try:
        bounds = read_bounds(bp)
        if beams is not None:
            bounds = _with_beams(bounds, beams)
        bar = _bar(progress, 1, "read log", "message")
        try:
            return read_log(lp, bounds, progress=None if bar is None else _advance(bar))
        finally:
            if bar is not None:
                bar.close()
    except (BoundsError, LogError) as exc:
        raise UserError(first_line(exc)) from None


def certify(
    log_path: str | Path,
    bounds_path: str | Path,
    out_dir: str | Path,
    *,
    beams: int | None = None,
    progress: bool = False,
    cross_check: bool = True,
    resolution: float | None = None,
) -> dict[str, Any]:
    """Certify the log at ``log_path`` under the bounds at ``bounds_path`` into ``out_dir``; return the
    summary (``summary["consistent"]``, ``summary["failure"]["message"]`` when not). Raises :class:`UserError`
    on bad input (a missing log or bounds file, a bounds or log error, an ``out_dir`` that is a file)."""
    out_path(out_dir, "--out")
    log = read(log_path, bounds_path, beams, progress)
    return certify_log(log, out_dir, progress=progress, cross_check=cross_check, resolution=resolution,
                       paths=(str(log_path), str(bounds_path)))  # fmt: skip


def glance(s: dict[str, Any], out: str | Path) -> list[str]:
    """The lines a person reads at a glance."""
    lines = [
        f"records: {s['records']} of {s['records_in_log']}, {s['duration_s']:.1f} s of log",
        f"area certified explored: {s['area_explored_m2']:.1f} m2; "
        f"proved free (M-): {s['area_free_m2']:.1f} m2",
    ]
    if "widest_pose_box_m" in s:
        w = s["widest_pose_box_m"]
        lines.append(f"widest pose box: {w['width']:.3f} m at record {w['record']} ({w['seconds']:.1f} s)")
    cc = s.get("cross_check")
    if cc and cc.get("online_consistent"):
        ratio = cc["offline_over_online_coverage"]
        lines.append(f"consistent: {s['consistent']} (online filter too; offline/online coverage "
                     f"{'n/a' if ratio is None else f'{ratio:.3f}'}, offline boxes inside online: "
                     f"{cc['offline_boxes_inside_online']})")  # fmt: skip
    else:
        lines.append(f"consistent: {s['consistent']}")
    lines.append(f"{s['seconds']:.1f} s; wrote {Path(out)}/{{summary.json,map.png,zones.geojson,raster.npz}}")
    return lines


def cmd_certify(args: argparse.Namespace) -> int:
    """``digslam certify``: exit 0 when the log is consistent with its bounds, 1 (one line) when not."""
    s = certify(args.log, args.bounds, args.out, beams=args.beams, progress=args.progress,
                cross_check=args.cross_check, resolution=args.resolution)  # fmt: skip
    if s["failure"] is not None:
        print(f"digslam certify: {s['failure']['message']}; partial results (records 0-{s['records'] - 1}) "
              f"in {args.out}", file=sys.stderr)  # fmt: skip
        return 1
    print("\n".join(glance(s, args.out)))
    return 0


def add_certify_parser(sub: Any) -> None:
    """Add ``certify`` to the subparsers ``sub``."""
    p = sub.add_parser("certify", help="certify the zone a robot explored from its ROS log and a bounds file",
                       description="Run the guaranteed offline Dig-SLAM observer on a ROS 2 (MCAP, "
                       "sqlite3) or ROS 1 log under the error bounds of a TOML file; write map.png, "
                       "zones.geojson, raster.npz and summary.json to --out. Exit 1 with one line when the "
                       "data contradict the bounds (see docs/certify.md).")  # fmt: skip
    p.add_argument("log", help="the log: a ROS 2 bag folder, a .mcap or .db3 file, or a ROS 1 .bag")
    p.add_argument("--bounds", required=True, help="the bounds file (TOML): error bounds and premises")
    p.add_argument("--out", default="out/certify", help="output folder (default %(default)s)")
    p.add_argument("--beams", type=int, default=None, help="LaserScan beams kept, evenly spread (overrides "
                   "the bounds file)")  # fmt: skip
    p.add_argument("--resolution", type=float, default=None, help="cell side of the map in m (overrides "
                   f"[map] resolution; default {DEFAULT_RESOLUTION})")  # fmt: skip
    p.add_argument("--no-cross-check", dest="cross_check", action="store_false",
                   help="skip the online filter's cross-check")  # fmt: skip
    p.add_argument("--no-progress", dest="progress", action="store_false", help="hide the progress bar")
    p.set_defaults(func=cmd_certify)


__all__ = ["DEFAULT_RESOLUTION", "LogLike", "add_certify_parser", "certify", "certify_log", "cmd_certify",
           "glance", "read"]  # fmt: skip
