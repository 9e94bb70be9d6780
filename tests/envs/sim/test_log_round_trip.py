"""Simulate a log, write it as a ROS 2 bag, read it back (``read_log``): every reading's interval holds the
simulator's truth and equals the direct record's up to the float32 of the range messages.

The direct record of a beam is ``[v - b, v + b]`` with ``v`` the simulator's float64 value. The bag stores
``v32 = fl32(v)``; the reader widens it to its neighbouring float32s ``[v32⁻, v32⁺]`` (which hold ``v``)
before the bound, and takes ``b`` at ``|v32⁺|``. So the bag's interval contains the direct one and exceeds
it on each side by at most ``1.5 ulp32(v)`` (half an ulp from ``v`` to ``v32``, one to the neighbour) plus
``rel·ulp32`` and the reader's outward roundings: allowed ``2 ulp32(v) + 1e-12`` m.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from digslam.envs.sim.logs import LaserSpec, SimNoise, simulate_log

pytest.importorskip("rosbags")
bag = pytest.importorskip("digslam.observer.record.bag")


@pytest.mark.parametrize("fmt", ["mcap", "sqlite3"])
@pytest.mark.parametrize("source", ["pose", "twist"])
def test_round_trip(tmp_path: Path, fmt: str, source: str) -> None:
    laser = LaserSpec(beams=25, mount=(0.5, 0.0, 0.0), range_max=8.0, phase=0.013)
    log = simulate_log(duration=8.0, laser=laser, noise=SimNoise(range=(0.03, 0.01)), seed=2)
    (tmp_path / "bounds.toml").write_text(log.bounds(source))
    out = bag.read_log(log.write(tmp_path / "log", fmt), tmp_path / "bounds.toml")
    rec, scan = out.records, log.streams.scans[0]
    assert (
        len(rec) == len(scan) and rec.n_sensors == 25
    )  # each scan attaches to the odometry message before it
    odo = (scan.stamps - log.stamps[0]) // 20_000_000 * 20_000_000
    assert np.allclose(rec.t, odo / 1e9, rtol=0, atol=1e-9)
    assert np.all(rec.mount[..., 0] == 0.5) and np.all(rec.slack[1:, :, 0] > 0)
    a, z = log.scan_bounds[..., 0], log.scan_bounds[..., 1]
    echo = np.isfinite(rec.range[..., 1])
    assert echo.sum() > 200 and rec.no_echo.sum() > 20
    assert np.all(rec.range[..., 0][echo] <= a[echo]) and np.all(z[echo] <= rec.range[..., 1][echo])
    assert np.all(a[rec.no_echo] >= rec.r_max[rec.no_echo])  # free up to r_max: nothing nearer
    v = log.scan_values[echo]
    ab, rel = 0.03 + 1e-9, 0.01
    direct = np.stack([v - (ab + rel * np.abs(v)), v + (ab + rel * np.abs(v))], axis=-1)
    got = rec.range[echo]
    ulp = np.spacing(v.astype(np.float32)).astype(np.float64)
    assert np.all(got[:, 0] <= direct[:, 0] + 1e-15) and np.all(got[:, 1] >= direct[:, 1] - 1e-15)
    assert np.all(np.abs(got - direct) <= 2 * ulp[:, None] + 1e-12)
    # odometry: each record's interval holds the true speed and yaw rate of its slices
    m = odo // 20_000_000  # each record's odometry message
    for k in range(1, len(rec)):
        sl = slice(m[k - 1] + 1, m[k] + 1)  # the slices the record spans
        assert rec.speed[k, 0] <= log.speed[sl].min() and log.speed[sl].max() <= rec.speed[k, 1]
        assert (
            rec.yaw_rate[k, 0] <= log.yaw_rate[sl, 0].min()
            and log.yaw_rate[sl, 1].max() <= rec.yaw_rate[k, 1]
        )
    assert np.all(rec.heading[1:] == [-np.inf, np.inf])  # no compass
    assert np.array_equal(out.x0_lo, log.pose[0]) and np.array_equal(out.x0_hi, log.pose[0])
