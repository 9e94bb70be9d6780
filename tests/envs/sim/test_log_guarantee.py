"""The asynchronous simulated log of issue #47: no false claim, checked against the simulator's truth.

A laser at 10 Hz (phase 13 ms), odometry at 50 Hz, no compass, the laser mounted 0.5 m ahead of the centre,
in walled worlds (the thesis room, a ``rooms`` and a ``caves`` level), read with ``source = "pose"`` and
``"twist"`` and ``beams`` below the scan's count (so the reader keeps the scan's merged readings too,
:mod:`digslam.observer.record.scan_merge`). The log is simulated, written as an MCAP bag, read back with
:func:`~digslam.observer.record.bag.read_log`, and both observers run on the grid of
:func:`~digslam.observer.online.frame.frame_of`: the offline fixpoint ``dig_slam`` and the online filter.

Every claim is checked here against the simulator's truth, with none of the observer's code:

a. the true position at each record's stamp lies in the record's pose box (online) and gate (offline), the
   true heading in its heading interval (the simulator's position error, ``~1e-12`` m, counted against the
   claim);
b. every cell of ``M⁻`` and every CLEAR cell holds no obstacle point: no world edge meets the closed cell box
   (an exact rational test near the edges, :func:`auditor._box_edge_fraction`), the box lies in the world's
   frame and its centre is free by the even-odd rule;
c. every CLEAR cell was seen: its corners, edge midpoints and centre each lie in the true sensed cone of a
   beam that the record holds (the true apex and heading at the scan's stamp, up to ``min(true range,
   r_max)``), a merged reading holding the beams of its run (their union, each up to its own true range);
d. no DARK cell was seen: points along and across each held beam's cone, strictly below its true range,
   lie in no DARK cell's interior.

Which beams a record holds is derived from the reader's documented rule (``beams`` kept evenly spread, then
per group of the scan the longest run of beams with a reading), and checked against the record's slots.
"""

from __future__ import annotations

import dataclasses as dc
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from auditor import assert_cells_free as check_free
from auditor import grid_cell_boxes as cell_boxes

from digslam.envs.sim.logs import LaserSpec, SimLog, simulate_log
from digslam.observer.online.frame import frame_of
from digslam.observer.online.observer import OnlineConfig, OnlineDigSlam
from digslam.observer.online.smoother import dig_slam
from digslam.observer.record.bounds import parse_bounds
from digslam.observer.record.grid import Grid
from digslam.observer.slam.digslam import DigSlamConfig
from digslam.observer.thick.cells import CLEAR, DARK

pytest.importorskip("rosbags")
from digslam.observer.record.bag import Log, read_log  # noqa: E402
from digslam.observer.record.bag_write import write_log  # noqa: E402

BEAMS, KEPT, MOUNT, RANGE_MAX, DURATION = 181, 19, (0.5, 0.0, 0.0), 8.0, 30.0
#: Float margins of the "was seen" test (m, rad): far below a cell (0.1 m) and a beam (8.7e-3 rad).
MARGIN_R, MARGIN_A = 1e-9, 1e-9


def simulate(world: str | None, seed: int) -> SimLog:
    laser = LaserSpec(beams=BEAMS, mount=MOUNT, range_max=RANGE_MAX, rate=10.0, phase=0.013)
    return simulate_log(world=world, duration=DURATION, odom_rate=50.0, laser=laser, compass=False, seed=seed)


def write_and_read(
    log: SimLog, tmp: Path, source: str, streams: Any = None, bounds: str | None = None
) -> Log:
    (tmp / "bounds.toml").write_text(bounds if bounds is not None else log.bounds(source, beams=KEPT))
    if streams is None:
        bag = log.write(tmp / "log.mcap", "mcap")
    else:
        bag = write_log(tmp / "log.mcap", "mcap", streams)
    return read_log(bag, tmp / "bounds.toml")


# --- what the records hold -------------------------------------------------------------------------------
def held_beams(log: SimLog, out: Log) -> list[np.ndarray]:
    """Per scan, the beams whose cones the record holds: the kept ones and the merged runs (the reader's
    documented rule), each checked against the record's slots (direction and half-aperture)."""
    scan = log.streams.scans[0]
    n = scan.ranges.shape[1]
    kept = np.unique(np.round(np.linspace(0, n - 1, KEPT)).astype(np.int64))
    rec, odo = out.records, log.streams.odometry.stamps
    rec_ns = odo[0] + np.round(rec.t * 1e9).astype(np.int64)
    assert np.isin(rec_ns, odo).all()
    row = np.searchsorted(rec_ns, scan.stamps, side="right") - 1  # the record each scan is attached to
    assert np.array_equal(row, np.arange(len(scan)))  # one scan per record (10 Hz laser, 50 Hz odometry)
    beam_gamma = float(log.gamma[0])
    held = []
    for s in range(len(scan)):
        reading = ~np.isnan(scan.ranges[s]) & (scan.ranges[s] >= scan.range_min)
        mine = [kept[reading[kept]]]
        a, g = rec.alpha[row[s]], rec.gamma[row[s]]
        assert np.allclose(a[: len(kept)], log.alpha[kept], rtol=0, atol=1e-12)
        for j, idx in enumerate(np.array_split(np.arange(n), len(kept))):
            best, run = (0, 0), None
            for k in [*idx.tolist(), None]:
                if k is not None and reading[k]:
                    run = k if run is None else run
                elif run is not None:
                    end = k if k is not None else int(idx[-1]) + 1
                    best = (run, end) if end - run > best[1] - best[0] else best
                    run = None
            if best[1] > best[0]:
                i0, i1 = best[0], best[1] - 1
                slot = len(kept) + j
                assert a[slot] == pytest.approx(0.5 * (log.alpha[i0] + log.alpha[i1]), abs=1e-12)
                assert 0 < 0.5 * (log.alpha[i1] - log.alpha[i0]) + beam_gamma - g[slot] < 1e-12
                mine.append(np.arange(i0, i1 + 1))
        held.append(np.unique(np.concatenate(mine)))
    assert sum(len(h) for h in held) > 3 * KEPT * len(scan)  # the merged runs are there
    return held


class Cones:
    """Each scan's true sensed region: per held beam, the cone at the true apex and heading up to
    ``min(true range, r_max)`` (the lower end of the simulator's rigorous truth box)."""

    def __init__(self, log: SimLog, out: Log) -> None:
        scan = log.streams.scans[0]
        pose, _ = log.truth_at(scan.stamps)
        self.apex, self.heading = log.apex, pose[:, 2]
        assert np.all(log.apex_error < 1e-9)
        assert np.allclose(log.apex, pose[:, :2] + 0.5 * np.c_[np.cos(pose[:, 2]), np.sin(pose[:, 2])])
        r_max = float(out.records.r_max.max())  # the trusted range, below the laser's range_max
        assert r_max < RANGE_MAX and np.all(out.records.r_max <= r_max)
        self.rho = np.minimum(log.scan_bounds[..., 0], r_max)  # (S, n)
        self.alpha, self.gamma = log.alpha, float(log.gamma[0])
        self.held = held_beams(log, out)

    def seen(self, px: np.ndarray, py: np.ndarray) -> np.ndarray:
        """Whether each point lies in some held beam's closed true cone (with the float margins)."""
        ok = np.zeros(px.shape, bool)
        inc, a0, n = 2 * self.gamma, self.alpha[0], len(self.alpha)
        for s, beams in enumerate(self.held):
            todo = np.flatnonzero(~ok)
            if not todo.size:
                break
            on = np.zeros(n, bool)
            on[beams] = True
            dx, dy = px[todo] - self.apex[s, 0], py[todo] - self.apex[s, 1]
            r = np.hypot(dx, dy)
            rel = np.remainder(np.arctan2(dy, dx) - self.heading[s] - a0 + math.pi, 2 * math.pi) - math.pi
            centre = np.rint(rel / inc).astype(np.int64)
            for k in (centre - 1, centre, centre + 1):  # the beam whose cone holds the angle, or a neighbour
                kk = np.clip(k, 0, n - 1)
                da = np.abs(rel - (self.alpha[kk] - a0))
                hit = (k == kk) & on[kk] & (da <= self.gamma + MARGIN_A) & (r <= self.rho[s, kk] + MARGIN_R)
                ok[todo[hit]] = True
        return ok

    def samples(self, step: float, chunk: int = 25) -> Any:
        """Points of every held beam's true cone, strictly below its true range: along the axis and at
        0.9 of the half-aperture each side, every ``step`` metres; ``(x, y)`` arrays, ``chunk`` scans at a
        time."""
        f = np.arange(0.0, 1.0, step / RANGE_MAX)  # fractions of the range, 1 excluded
        for s0 in range(0, len(self.held), chunk):
            xs, ys = [], []
            for s in range(s0, min(s0 + chunk, len(self.held))):
                beams = self.held[s]
                r = f[None, :] * self.rho[s, beams][:, None]
                for side in (-0.9, 0.0, 0.9):
                    phi = self.heading[s] + self.alpha[beams] + side * self.gamma
                    xs.append((self.apex[s, 0] + r * np.cos(phi)[:, None]).ravel())
                    ys.append((self.apex[s, 1] + r * np.sin(phi)[:, None]).ravel())
            yield np.concatenate(xs), np.concatenate(ys)


# --- the checks ------------------------------------------------------------------------------------------
def check_pose(lo: np.ndarray, hi: np.ndarray, psi: np.ndarray, truth: np.ndarray, err: np.ndarray) -> None:
    """(a) The true position (error ``err`` counted against the claim) and heading in every box."""
    inside = np.all((lo <= truth[:, :2] - err[:, None]) & (truth[:, :2] + err[:, None] <= hi), axis=1)
    assert inside.all(), f"record {int(np.argmin(inside))}: the true position is outside its pose box"
    ok = (psi[:, 0] <= truth[:, 2]) & (truth[:, 2] <= psi[:, 1])
    assert ok.all(), f"record {int(np.argmin(ok))}: the true heading is outside its interval"


def check_seen(grid: Grid, clear: np.ndarray, cones: Cones) -> None:
    """(c) Every CLEAR cell's corners, edge midpoints and centre were seen by a held beam."""
    lo, hi = cell_boxes(grid, clear)
    for fx in (0.0, 0.5, 1.0):
        for fy in (0.0, 0.5, 1.0):
            px, py = lo[:, 0] + fx * (hi[:, 0] - lo[:, 0]), lo[:, 1] + fy * (hi[:, 1] - lo[:, 1])
            seen = cones.seen(px, py)
            assert seen.all(), f"CLEAR cell {lo[int(np.argmin(seen))]}: its point ({fx}, {fy}) was never seen"


def check_dark(grid: Grid, dark: np.ndarray, cones: Cones) -> None:
    """(d) No point of a held beam's true cone lies inside a DARK cell."""
    xs, nys = np.asarray(grid.xs), -np.asarray(grid.ys)
    ny, nx = grid.shape
    for px, py in cones.samples(0.05):
        c, r = np.searchsorted(xs, px, "right") - 1, np.searchsorted(nys, -py, "right") - 1
        ok = (c >= 0) & (c < nx) & (r >= 0) & (r < ny)
        c, r, px, py = c[ok], r[ok], px[ok], py[ok]
        interior = (xs[c] < px) & (px < xs[c + 1]) & (nys[r] < -py) & (-py < nys[r + 1])
        bad = interior & dark[r, c]
        assert not bad.any(), f"a DARK cell holds the seen point {(px[bad][0], py[bad][0])}"


def run_both(out: Log, grid: Grid) -> tuple[Any, dict[str, np.ndarray] | None]:
    """The offline fixpoint and the online filter (its boxes and headings at every record; None when it
    finds the data inconsistent)."""
    rec, lo0, hi0 = out.records, out.x0_lo[:2], out.x0_hi[:2]
    off = dig_slam(rec, grid, lo0, hi0, DigSlamConfig(q=out.q))
    obs = OnlineDigSlam(grid, OnlineConfig(q=out.q))
    obs.reset(lo0, hi0, rec[0])
    lo, hi, psi = [obs.pose_lo.copy()], [obs.pose_hi.copy()], [(obs.heading_lo, obs.heading_hi)]
    for k in range(1, len(rec)):
        obs.update(rec[k])
        if not obs.consistent:
            return off, None
        lo.append(obs.pose_lo.copy())
        hi.append(obs.pose_hi.copy())
        psi.append((obs.heading_lo, obs.heading_hi))
    on = {"lo": np.array(lo), "hi": np.array(hi), "psi": np.array(psi), "free": obs.dig.free.copy(),
          "code": obs.explored()}  # fmt: skip
    return off, on


def check_all(log: SimLog, out: Log, grid: Grid, off: Any, on: dict[str, np.ndarray]) -> None:
    rec_ns = log.streams.odometry.stamps[0] + np.round(out.records.t * 1e9).astype(np.int64)
    truth, err = log.truth_at(rec_ns)
    cones = Cones(log, out)
    psi_off = np.stack([np.ravel(off.heading.gate_lo), np.ravel(off.heading.gate_hi)], axis=1)
    results = (
        ("offline", off.tube.gate_lo, off.tube.gate_hi, psi_off, off.dig.free, off.explored),
        ("online", on["lo"], on["hi"], on["psi"], on["free"], on["code"]),
    )
    for _, lo, hi, psi, free, code in results:
        check_pose(lo, hi, psi, truth, err)
        check_free(grid, free | (code == CLEAR), log.world)
        check_seen(grid, code == CLEAR, cones)
        check_dark(grid, code == DARK, cones)


CASES = [(None, "pose", 0), ("rooms", "twist", 1), ("caves", "pose", 2), (None, "twist", 3),
         ("rooms", "pose", 4), ("caves", "twist", 5)]  # fmt: skip


@pytest.mark.parametrize("world,source,seed", CASES)
def test_asynchronous_mounted_log_without_compass_claims_nothing_false(
    tmp_path: Path, world: str | None, source: str, seed: int
) -> None:
    log = simulate(world, seed)
    assert log.streams.heading is None and len(log.streams.odometry) == 50 * DURATION + 1
    out = write_and_read(log, tmp_path, source)
    assert out.mount_sources == {"/scan": "tf_static"} and out.mounts["/scan"] == MOUNT
    rec = out.records
    assert np.all(rec.mount[..., 0] == 0.5) and np.all(rec.slack[1:, :, 0] > 0)  # mounted, off the record
    assert np.all(np.isinf(rec.heading[1:])) and out.dropped["outside_odometry"] == 0
    grid = frame_of(rec, out.x0_lo[:2], out.x0_hi[:2], out.max_range, 0.1)
    off, on = run_both(out, grid)
    assert off.consistent and on is not None  # the premise holds: neither observer may find it broken
    assert off.dig.free.sum() > 300 and (off.explored == CLEAR).sum() > 300 and (off.explored == DARK).any()
    check_all(log, out, grid, off, on)


def test_a_mount_left_out_of_the_record_is_caught(tmp_path: Path) -> None:
    """The same log without ``/tf_static`` and with no mount in its bounds (the reader puts the laser at the
    centre): an observer finds the data inconsistent, or the checker finds a false claim."""
    log = simulate(None, 0)
    b = parse_bounds(log.bounds("pose", beams=KEPT))
    b = dc.replace(b, ranges=tuple(dc.replace(r, mount=None) for r in b.ranges))
    out = write_and_read(log, tmp_path, "pose", dc.replace(log.streams, mounts=()), b.to_toml())
    assert out.mount_sources == {"/scan": "none"} and not np.any(out.records.mount)
    grid = frame_of(out.records, out.x0_lo[:2], out.x0_hi[:2], out.max_range, 0.1)
    off, on = run_both(out, grid)
    if off.consistent and on is not None:
        with pytest.raises(
            AssertionError, match="outside its|meets edge|inside an obstacle|never seen|DARK cell"
        ):
            check_all(log, out, grid, off, on)
