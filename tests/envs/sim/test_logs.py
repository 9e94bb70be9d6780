"""Simulated logs: every recorded value holds its bound against the truth, checked with geometry written here
(plain numpy, none of the simulator's code); the mount and the asynchronous stamps are respected."""

from __future__ import annotations

import numpy as np
import pytest

from digslam.envs.sim.logs import LaserSpec, SimNoise, simulate_log
from digslam.observer.record.bounds import parse_bounds


def sector_distance(apex: np.ndarray, direction: float, half: float, edges: np.ndarray) -> float:
    """Distance from ``apex`` to the nearest point of the edges inside the cone (``half < pi/2``): on each edge
    the part inside the cone is a sub-segment, along which the distance is convex, so the minimum is at an
    end of it (an endpoint inside, or where a boundary ray crosses) or at the foot of the perpendicular."""
    p0, p1 = edges[:, :2] - apex, edges[:, 2:] - apex
    u = np.array([np.cos(direction), np.sin(direction)])

    def inside(p: np.ndarray) -> np.ndarray:
        n = np.hypot(p[:, 0], p[:, 1])
        return (p @ u) >= n * np.cos(half) - 1e-12

    cands = [np.where(inside(p), np.hypot(p[:, 0], p[:, 1]), np.inf) for p in (p0, p1)]
    d = p1 - p0
    s = np.clip(-(p0 * d).sum(1) / np.maximum((d * d).sum(1), 1e-300), 0, 1)
    foot = p0 + s[:, None] * d
    cands.append(np.where(inside(foot), np.hypot(foot[:, 0], foot[:, 1]), np.inf))
    for side in (-half, half):
        r = np.array([np.cos(direction + side), np.sin(direction + side)])
        den = r[0] * d[:, 1] - r[1] * d[:, 0]  # solve t r - s d = p0 (Cramer)
        with np.errstate(divide="ignore", invalid="ignore"):
            s_ = (p0[:, 0] * r[1] - p0[:, 1] * r[0]) / den
            t_ = (p0[:, 0] * d[:, 1] - p0[:, 1] * d[:, 0]) / den
        ok = (np.abs(den) > 1e-15) & (s_ >= 0) & (s_ <= 1) & (t_ >= 0)
        cands.append(np.where(ok, t_, np.inf))
    return float(np.min(np.stack(cands)))


def _check_scans(log, mount: tuple[float, float, float], bound: tuple[float, float], trust: float) -> int:
    """Every beam's truth inside the interval the bounds file gives its float32 value; returns how many
    beams would break it if the sensor sat at the robot's centre."""
    scan = log.streams.scans[0]
    pose, _ = log.truth_at(scan.stamps)
    n = scan.ranges.shape[1]
    alpha = (np.float64(np.float32(scan.angle_min)) + np.arange(n) * np.float64(np.float32(scan.angle_increment))
             + mount[2])  # fmt: skip
    half = np.float64(np.float32(scan.angle_increment)) / 2
    wrong_if_centred = 0
    for k in range(len(scan)):
        x, y, th = pose[k]
        c, s = np.cos(th), np.sin(th)
        ap = np.array([x + mount[0] * c - mount[1] * s, y + mount[0] * s + mount[1] * c])
        for j in range(n):
            v = scan.ranges[k, j]
            if np.isnan(v):
                continue
            d = sector_distance(ap, th + alpha[j], half, log.world.edges)
            if np.isinf(v):
                assert d > trust, (k, j, d)
                continue
            lo = np.float64(np.nextafter(v, np.float32(0)))
            hi = np.float64(np.nextafter(v, np.float32(np.inf)))
            b_lo = bound[0] + bound[1] * lo
            assert lo - b_lo <= d <= hi + bound[0] + bound[1] * hi, (k, j, d, v)
            dc = sector_distance(np.array([x, y]), th + alpha[j], half, log.world.edges)
            wrong_if_centred += not (lo - b_lo <= dc <= hi + bound[0] + bound[1] * hi)
    return wrong_if_centred


@pytest.mark.parametrize("mount,noise", [((0.5, 0.0, 0.0), SimNoise()),
                                         ((0.3, -0.1, 0.4), SimNoise(range=(0.02, 0.01)))])  # fmt: skip
def test_truth_inside_every_reading(mount: tuple[float, float, float], noise: SimNoise) -> None:
    log = simulate_log(duration=6.0, laser=LaserSpec(beams=19, mount=mount, range_max=8.0), noise=noise,
                       compass=True, seed=3)  # fmt: skip
    b = parse_bounds(log.bounds())
    (rb,) = b.ranges
    assert rb.mount == mount and rb.bound.rel == noise.range[1]
    assert (rb.bound.abs - noise.range[0]) <= 1e-6
    ranges = log.streams.scans[0].ranges
    assert np.isinf(ranges).any() and np.isfinite(ranges).sum() > 50  # both kinds of beams checked
    assert _check_scans(log, mount, (rb.bound.abs, rb.bound.rel), rb.max_range) > 0  # the mount matters


def test_odometry_and_compass_inside_their_bounds() -> None:
    """Twist and pose increments against the truth's poses (recomputed here from the truth stream)."""
    log = simulate_log(duration=8.0, laser=LaserSpec(beams=3), compass=True, seed=1)
    o, h, truth = log.streams.odometry, log.streams.heading, log.streams.truth
    tp = np.column_stack([truth.x, truth.y, truth.yaw])[np.isin(truth.stamps, o.stamps)]
    dt = np.diff(o.stamps) / 1e9
    step = np.diff(tp[:, :2], axis=0)
    true_speed = np.hypot(step[:, 0], step[:, 1]) / dt  # chord speed: within 1e-3 of the arc's here
    true_yaw = np.diff(tp[:, 2]) / dt
    for source in ("twist", "pose"):
        b = parse_bounds(log.bounds(source)).odometry
        if source == "twist":
            v, w = o.v1[1:], o.yaw_rate[1:]
            assert b.unicycle and np.all(o.v2 == 0)
        else:
            c, s = np.cos(o.yaw[:-1]), np.sin(o.yaw[:-1])
            dx, dy = np.diff(o.x), np.diff(o.y)
            v, lat = (c * dx + s * dy) / dt, (-s * dx + c * dy) / dt
            w = np.diff(o.yaw) / dt
            assert np.all(np.abs(lat) <= b.lateral.abs)
        assert np.all(np.abs(v - true_speed) <= b.speed.abs + 1e-3)
        assert np.all(np.abs(w - true_yaw) <= b.yaw_rate.abs + 1e-9)
        assert np.max(np.abs(v - true_speed)) > 0.5 * b.speed.abs - 1e-3  # the noise fills its bound
    hb = parse_bounds(log.bounds()).heading
    assert hb is not None and np.all(np.abs(h.yaw - tp[:, 2]) <= hb.bound.abs)
    assert np.all(np.abs(true_speed) <= parse_bounds(log.bounds()).odometry.max_speed + 1e-12)


def test_asynchronous_stamps() -> None:
    log = simulate_log(duration=3.0, odom_rate=50.0, laser=LaserSpec(beams=3, rate=10.0, phase=0.013), seed=0)
    o, scan = log.streams.odometry, log.streams.scans[0]
    t0 = o.stamps[0]
    assert np.array_equal(o.stamps - t0, np.arange(151) * 20_000_000)
    assert np.array_equal(scan.stamps - t0, 13_000_000 + np.arange(30) * 100_000_000)
    assert not np.isin(scan.stamps, o.stamps).any()
    assert np.array_equal(log.stamps, np.union1d(o.stamps, scan.stamps))
    assert np.array_equal(log.streams.truth.stamps, log.stamps) and log.streams.heading is None
    pose, err = log.truth_at(scan.stamps)  # at a laser stamp: on the arc between odometry stamps
    i = np.searchsorted(o.stamps, scan.stamps)
    before, after = log.truth_at(o.stamps[i - 1])[0], log.truth_at(o.stamps[i])[0]
    assert np.all(np.hypot(*(pose[:, :2] - before[:, :2]).T) <= np.hypot(*(after[:, :2] - before[:, :2]).T))
    assert np.all(err < 1e-12) and log.error[0] == 0.0


def test_bad_settings() -> None:
    with pytest.raises(ValueError, match="duration"):
        simulate_log(duration=0.0)
    with pytest.raises(ValueError, match="laser"):
        simulate_log(duration=1.0, laser=LaserSpec(range_min=5.0, range_max=4.0))
    with pytest.raises(ValueError, match="world"):
        simulate_log(world="moon", duration=1.0)
