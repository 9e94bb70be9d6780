"""Mounted sensors, readings off the record's instant and no compass (``digslam.observer.online.mount_jit``).

The truth here is computed without the observer's code: a robot on an exact circular arc in a square room
``[-5, 5]²``, a ring of narrow cones mounted ahead of its centre, each reading taken a random instant after
its record (its slack), the exact distance from the cone's apex to the walls in closed form (a convex room:
the nearest wall point in a sector is ``h / cos Δ``, ``Δ`` the angle from the wall's normal to the sector).
Every claim of both observers is checked against it: the pose in every box, every dug cell inside the room,
every clear cell seen by some true cone, no dark cell seen.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from digslam.observer.online.dig_types import PoseBox
from digslam.observer.online.mount_jit import apex, centre_of, centre_ranges, mount_kind
from digslam.observer.online.observer import OnlineConfig, OnlineDigSlam
from digslam.observer.online.smoother import dig_slam
from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord
from digslam.observer.slam.digslam import DigSlamConfig, thesis_dig_slam
from digslam.observer.thick.cells import CLEAR, DARK

HALF = 5.0  # the room is [-HALF, HALF]²
WALLS = ((0.0, HALF), (math.pi / 2, HALF), (math.pi, HALF), (-math.pi / 2, HALF))  # (normal angle, offset)
V, W, PSI0, X0 = 0.5, 0.15, 0.3, (-2.0, -1.0)
MOUNT = (0.5, 0.1)
N_CONES, GAMMA, R_MAX = 12, 0.06, 4.0
B_RANGE, B_SPEED, B_YAW = 0.02, 0.01, 0.005
MARGIN = 1e-9


def pose(t: float) -> tuple[float, float, float]:
    """The exact arc: speed ``V``, yaw rate ``W``."""
    psi = PSI0 + W * t
    return (
        X0[0] + V / W * (math.sin(psi) - math.sin(PSI0)),
        X0[1] - V / W * (math.cos(psi) - math.cos(PSI0)),
        psi,
    )


def sector_distance(px: float, py: float, phi: float, gamma: float) -> float:
    """Distance from ``p`` (inside the room) to the walls within the sector ``phi ± gamma``."""
    best = math.inf
    for normal, off in WALLS:
        h = off - (px * math.cos(normal) + py * math.sin(normal))
        delta = abs(math.remainder(normal - phi, 2 * math.pi))
        delta = max(0.0, delta - gamma)
        if delta < math.pi / 2:
            best = min(best, h / math.cos(delta))
    return best


def mission(mount: tuple[float, float], seed: int = 0, n: int = 121, dt: float = 0.1,
            told_mount: tuple[float, float] | None = None) -> tuple[MissionRecord, list]:  # fmt: skip
    """The record (``told_mount``: what the record says of the mount, default the truth) and, per record,
    the truth ``(x, y, psi)`` at ``t_k`` and each reading's true apex, direction and range."""
    rng = np.random.default_rng(seed)
    told = mount if told_mount is None else told_mount
    alpha = np.linspace(-math.pi, math.pi, N_CONES, endpoint=False)
    recs, truth = [], []
    for k in range(n):
        t = k * dt
        lag = rng.uniform(0.0, 0.05, N_CONES) if k else np.zeros(N_CONES)
        rows, seen = [], []
        for j in range(N_CONES):
            x, y, psi = pose(t + lag[j])
            ax = x + math.cos(psi) * mount[0] - math.sin(psi) * mount[1]
            ay = y + math.sin(psi) * mount[0] + math.cos(psi) * mount[1]
            d = sector_distance(ax, ay, psi + alpha[j], GAMMA)
            seen.append((ax, ay, psi + alpha[j], min(d, R_MAX)))
            if d > R_MAX:
                rows.append((R_MAX, math.inf, True))
            else:
                m = d + rng.uniform(-1, 1) * B_RANGE
                rows.append((m - B_RANGE - MARGIN, m + B_RANGE + MARGIN, False))
        slack = (
            np.stack([V * lag * (1 + 1e-6) + MARGIN, W * lag * (1 + 1e-6) + MARGIN], axis=1) if k else None
        )
        s, w = V + rng.uniform(-1, 1) * B_SPEED, W + rng.uniform(-1, 1) * B_YAW
        heading = [PSI0, PSI0] if k == 0 else [-math.inf, math.inf]  # no compass
        recs.append(MissionRecord(
            t=t, speed=[s - B_SPEED - MARGIN, s + B_SPEED + MARGIN], yaw_rate=[w - B_YAW - MARGIN, w + B_YAW + MARGIN],
            heading=heading, alpha=alpha, gamma=np.full(N_CONES, GAMMA), r_max=np.full(N_CONES, R_MAX),
            range=[r[:2] for r in rows], no_echo=[r[2] for r in rows], outlier=np.zeros(N_CONES, bool),
            mount=np.tile(told, (N_CONES, 1)), slack=slack if slack is not None else np.zeros((N_CONES, 2)),
        ))  # fmt: skip
        truth.append((pose(t), seen))
    return MissionRecord.stack(recs), truth


GRID = Grid((-6.0, -6.0), (6.0, 6.0), (120, 120))


def cell_boxes(mask: np.ndarray) -> np.ndarray:
    """``(m, 4)`` the closed boxes ``x0, y0, x1, y1`` of the cells set in ``mask`` (row 0 at the top)."""
    r, c = np.nonzero(mask)
    xs, ys = GRID.xs, GRID.ys
    return np.stack([xs[c], ys[r + 1], xs[c + 1], ys[r]], axis=1)


def seen_by(px: np.ndarray, py: np.ndarray, truth: list) -> np.ndarray:
    """Whether each point lies in some true sensed cone (closed, below the true range), with a margin."""
    out = np.zeros(px.shape, bool)
    for _, seen in truth:
        for ax, ay, phi, r in seen:
            dx, dy = px - ax, py - ay
            near = np.hypot(dx, dy) <= r + 1e-7
            ang = np.abs(np.remainder(np.arctan2(dy, dx) - phi + math.pi, 2 * math.pi) - math.pi)
            out |= near & (ang <= GAMMA + 1e-7)
    return out


def check_claims(lo: np.ndarray, hi: np.ndarray, free: np.ndarray, code: np.ndarray, truth: list) -> None:
    """Every claim against the truth (see the module docstring)."""
    for k, ((x, y, _), _) in enumerate(truth):
        assert lo[k, 0] <= x <= hi[k, 0] and lo[k, 1] <= y <= hi[k, 1], f"pose {k} outside its box"
    b = cell_boxes(free)
    assert b.size and np.all((b[:, :2] > -HALF) & (b[:, 2:] < HALF)), "a dug cell meets a wall"
    c = cell_boxes(code == CLEAR)
    assert c.size
    for fx in (0.0, 0.5, 1.0):
        for fy in (0.0, 0.5, 1.0):
            px, py = c[:, 0] + fx * (c[:, 2] - c[:, 0]), c[:, 1] + fy * (c[:, 3] - c[:, 1])
            assert seen_by(px, py, truth).all(), "a clear cell was not seen"
    dark = cell_boxes(code == DARK)
    hit = np.zeros(len(dark), bool)
    for _, seen in truth:  # points of each true cone (below its range) must not lie in a dark cell
        for ax, ay, phi, r in seen:
            for f in np.linspace(0.0, 1.0, 9):
                for g in np.linspace(-GAMMA, GAMMA, 5):
                    qx, qy = ax + f * r * math.cos(phi + g), ay + f * r * math.sin(phi + g)
                    hit |= (dark[:, 0] < qx) & (qx < dark[:, 2]) & (dark[:, 1] < qy) & (qy < dark[:, 3])
    assert not hit.any(), "a dark cell was seen"


def run_online(rec: MissionRecord) -> tuple[OnlineDigSlam, np.ndarray, np.ndarray]:
    obs = OnlineDigSlam(GRID, OnlineConfig(cones=True))
    obs.reset(X0, X0, rec[0])
    lo, hi = [obs.pose_lo.copy()], [obs.pose_hi.copy()]
    for k in range(1, len(rec)):
        obs.update(rec[k])
        lo.append(obs.pose_lo.copy())
        hi.append(obs.pose_hi.copy())
    return obs, np.array(lo), np.array(hi)


@pytest.mark.parametrize("seed", [0, 7])
def test_mounted_cones_with_slack_and_no_compass_claim_nothing_false(seed: int) -> None:
    rec, truth = mission(MOUNT, seed)
    assert not rec.centred
    obs, lo, hi = run_online(rec)
    assert obs.consistent
    check_claims(lo, hi, obs.dig.free, obs.explored(), truth)
    res = dig_slam(rec, GRID, X0, X0, DigSlamConfig(cones=True))
    assert res.consistent and res.tube is not None and res.dig is not None and res.explored is not None
    check_claims(res.tube.gate_lo, res.tube.gate_hi, res.dig.free, res.explored, truth)
    assert res.dig.free.sum() >= obs.dig.free.sum()  # the fixpoint is at least as sharp as the filter


def test_mixed_mounts_claim_nothing_false() -> None:
    """Every other cone at the centre: each reading digs from its own apex box, the impacts use the widened
    radius and the cones are skipped."""
    rec, truth = mission(MOUNT, 3)
    mixed, truth_c = mission((0.0, 0.0), 3)
    mount = rec.mount.copy()
    mount[:, ::2] = 0.0
    rng, no_echo = rec.range.copy(), rec.no_echo.copy()
    rng[:, ::2], no_echo[:, ::2] = mixed.range[:, ::2], mixed.no_echo[:, ::2]
    fields = rec.as_dict() | {"mount": mount, "range": rng, "no_echo": no_echo}
    rec2 = MissionRecord(**fields)
    seen = [(p, [s_c if j % 2 == 0 else s for j, (s, s_c) in enumerate(zip(a, b, strict=True))])
            for (p, a), (_, b) in zip(truth, truth_c, strict=True)]  # fmt: skip
    obs, lo, hi = run_online(rec2)
    assert obs.consistent
    check_claims(lo, hi, obs.dig.free, obs.explored(), seen)
    res = dig_slam(rec2, GRID, X0, X0)
    assert res.consistent and res.tube is not None and res.dig is not None and res.explored is not None
    check_claims(res.tube.gate_lo, res.tube.gate_hi, res.dig.free, res.explored, seen)


def test_a_mount_left_out_is_caught() -> None:
    """The same log told that the sensor sits at the centre: the checker finds a false claim or the observer
    finds the data inconsistent (this test's checks have teeth)."""
    rec, truth = mission((1.5, 0.0), 1, told_mount=(0.0, 0.0))
    obs, lo, hi = run_online(rec)
    if obs.consistent:
        with pytest.raises(AssertionError):
            check_claims(lo, hi, obs.dig.free, obs.explored(), truth)


def test_apex_and_centre_boxes_hold_the_truth() -> None:
    rng = np.random.default_rng(1)
    for _ in range(2000):
        x0, y0 = rng.uniform(-3, 3, 2)
        w, h, p0, pw = rng.uniform(0, 0.5), rng.uniform(0, 0.5), rng.uniform(-7, 7), rng.uniform(0, 0.4)
        m1, m2, sp, spsi = rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0, 0.1), rng.uniform(0, 0.1)
        box = PoseBox(x0, y0, x0 + w, y0 + h, p0, p0 + pw)
        a = apex(box, m1, m2, sp, spsi)
        x, y, psi = x0 + rng.uniform(0, 1) * w, y0 + rng.uniform(0, 1) * h, p0 + rng.uniform(0, 1) * pw
        e1, e2, epsi = rng.uniform(-1, 1, 3) * (sp, sp, spsi)
        ax = x + e1 + math.cos(psi + epsi) * m1 - math.sin(psi + epsi) * m2
        ay = y + e2 + math.sin(psi + epsi) * m1 + math.cos(psi + epsi) * m2
        assert a.x_lo <= ax <= a.x_hi and a.y_lo <= ay <= a.y_hi
        assert a.psi_lo <= psi + epsi <= a.psi_hi
        c = centre_of(box.x_lo, box.y_lo, box.x_hi, box.y_hi, a, m1, m2, sp)
        assert c[0] <= x <= c[2] and c[1] <= y <= c[3]


def test_mount_kinds_and_widened_ranges() -> None:
    z = np.zeros((3, 2))
    assert mount_kind(z, z) == 0 and mount_kind(np.zeros((0, 2)), np.zeros((0, 2))) == 0
    m = np.tile([0.3, 0.4], (3, 1))
    assert mount_kind(m, z) == 1
    m[1] = 0.0
    assert mount_kind(m, z) == 2
    wide = centre_ranges(np.array([[1.0, 2.0]] * 3), m, np.tile([0.1, 0.0], (3, 1)))
    assert (
        wide[0, 0] == 1.0
        and wide[0, 1] >= 2.5 + math.sqrt(2) * 0.1
        and wide[1, 1] >= 2.0 + 0.1 * math.sqrt(2)
    )


def test_the_centred_only_paths_refuse_mounted_records() -> None:
    rec, _ = mission(MOUNT, 0, n=5)
    with pytest.raises(ValueError, match="centred"):
        thesis_dig_slam(rec, GRID, list(X0), list(X0))
    with pytest.raises(ValueError, match="centred"):
        dig_slam(rec, GRID, X0, X0, DigSlamConfig(explored=True))
