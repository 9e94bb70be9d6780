"""An environment episode as a robot's log (``digslam record --format mcap|sqlite3|bag``): the streams of
:mod:`digslam.observer.record.streams` and the bounds file they satisfy.

Every env step is one stamp (``t0 + round(t·1e9)`` ns): its odometry on ``/odom`` (the twist is each
interval's midpoint, ``source = "twist"``; the pose integrates it by the exact arcs, for display), the compass
on ``/imu``, each sonar cone on its own ``sensor_msgs/Range`` topic ``/sonar<j>`` (frame ``sonar<j>``, mounted
at the centre turned by its direction) and the omnidirectional sensor as a one-beam ``LaserScan`` on
``/omni``, the true pose on ``/digslam/truth``. A no-echo reading is +inf (REP 117); an echo stores the
midpoint ``m`` of the env's interval as float32.

The env's intervals are ``[m - b, m + b]`` widened by 4 ulps of ``max(|m|, b)`` (:mod:`.noise_jit`), and
odometry hulls (pymunk's substeps) by their half-width. So each bound is the noise bound ``b`` of
:class:`~digslam.envs.config.NoiseConfig` plus a pad: ``1e-9``, or ``1.01`` times the episode's largest
excess of ``max(m - lo, hi - m)`` over ``b`` rounded up to two digits when that is larger (4 ulps: under
``1e-14`` at 10 m; a pymunk hull: its half-width, up to about half the yaw-rate range when the robot turns
hard within a step). The readers take ``b`` at the float32 neighbours, which hold ``m``, so the float32
needs nothing more. Apertures are stated exactly in the bounds file (``aperture``), since a ``Range``
message's ``field_of_view`` is float32. Premises: ``max_speed`` and ``max_yaw_rate`` are the larger of the
config's limits and every recorded interval's magnitude; the start box is the true start pose. The stamps
round ``t`` to whole nanoseconds (a step of 0.1 s then lasts 0.1 s up to float rounding, ``< 1e-15`` s).
"""

from __future__ import annotations

import math

import numpy as np

from digslam.envs.config import ExploreConfig
from digslam.envs.sim.arc_jit import arc_move
from digslam.envs.sim.sensors import SensorSuite
from digslam.observer.record.bounds import (
    Bound,
    Bounds,
    HeadingBounds,
    MapBounds,
    OdometryBounds,
    RangeBounds,
    StartBounds,
)
from digslam.observer.record.mission import MissionRecord
from digslam.observer.record.streams import (
    HeadingStream,
    LogStreams,
    Mount,
    OdometryStream,
    PoseStream,
    RangeStream,
    ScanStream,
)


def _mid(iv: np.ndarray) -> tuple[np.ndarray, float]:
    """Midpoints of intervals ``(..., 2)`` and the largest ``max(m - lo, hi - m)``."""
    m = 0.5 * (iv[..., 0] + iv[..., 1])
    return m, float(np.max(np.maximum(m - iv[..., 0], iv[..., 1] - m), initial=0.0))


def _pad(excess: float) -> float:
    """``1e-9``, or above it ``1.01 excess`` rounded up to two significant digits."""
    if excess * 1.01 <= 1e-9:
        return 1e-9
    unit = 10.0 ** (math.floor(math.log10(excess * 1.01)) - 1)
    return math.ceil(excess * 1.01 / unit) * unit


def episode_streams(rec: MissionRecord, pose: np.ndarray, cfg: ExploreConfig,
                    t0: int = 1_700_000_000_000_000_000) -> tuple[LogStreams, str]:  # fmt: skip
    """The streams of an episode (records ``rec``, true poses ``pose (T, 3)``) and its bounds file (TOML)."""
    stamps = t0 + np.round(rec.t * 1e9).astype(np.int64)
    nz = cfg.noise
    v1, e_v = _mid(rec.speed)
    v2, e_l = _mid(rec.lateral)
    w, e_w = _mid(rec.yaw_rate)
    yaw, e_h = _mid(rec.heading)
    x, y, th = np.empty(len(rec)), np.empty(len(rec)), np.empty(len(rec))
    x[0], y[0], th[0] = pose[0]
    for k in range(1, len(rec)):
        dt = float(rec.t[k] - rec.t[k - 1])
        th[k] = th[k - 1] + w[k] * dt
        x[k], y[k], _ = arc_move(x[k - 1], y[k - 1], th[k - 1], th[k], v1[k], dt)
    odo = OdometryStream(stamps, x, y, th, v1, v2, w)
    suite = SensorSuite.from_config(cfg)
    ranges: list[RangeStream] = []
    scans: list[ScanStream] = []
    mounts: list[Mount] = []
    tables: list[RangeBounds] = []
    e_r = 0.0
    for j in range(suite.n):
        iv = rec.range[:, j]
        ok = ~rec.no_echo[:, j] & ~rec.outlier[:, j]
        m, e = _mid(iv[ok])
        e_r = max(e_r, e)
        val = np.full(len(rec), np.inf)
        val[ok] = m
        val[rec.outlier[:, j]] = 0.5 * (iv[rec.outlier[:, j], 0] + iv[rec.outlier[:, j], 1])
        omni = bool(suite.gamma[j] == math.pi)
        name = "omni" if omni else f"sonar{j}"
        r_max = float(suite.r_max[j])
        if omni:
            scans.append(ScanStream(stamps, val[:, None], 0.0, 2 * math.pi, 0.0, r_max, name, "/" + name))
        else:
            ranges.append(RangeStream(stamps, val, 2 * float(suite.gamma[j]), 0.0, r_max, name, "/" + name))
        mounts.append(Mount(name, 0.0, 0.0, float(suite.alpha[j])))
        tables.append(RangeBounds("/" + name, Bound(0.0), aperture=float(suite.gamma[j]), max_range=r_max,
                                  mount=(0.0, 0.0, float(suite.alpha[j]))))  # fmt: skip
    p_r = _pad(e_r - nz.range)
    q = nz.max_outliers if nz.outlier_prob > 0 and nz.max_outliers is not None else 0
    tables = [RangeBounds(t.topic, Bound(nz.range + p_r), None, t.aperture, t.max_range, q if i == 0 else 0,
                          t.mount) for i, t in enumerate(tables)]  # fmt: skip
    unicycle = cfg.dynamics == "unicycle"
    p_v = _pad(max(e_v, 0.0 if unicycle else e_l) - nz.speed)
    top_v = max(cfg.max_speed, float(np.max(np.abs(rec.speed))), float(np.max(np.abs(rec.lateral))))
    top_w = max(cfg.max_yaw_rate, float(np.max(np.abs(rec.yaw_rate))))
    odb = OdometryBounds("/odom", Bound(nz.speed + p_v), Bound(nz.yaw_rate + _pad(e_w - nz.yaw_rate)), top_v,
                         top_w, "twist", None if unicycle else Bound(nz.speed + p_v), unicycle)  # fmt: skip
    hb = HeadingBounds("/imu", Bound(nz.heading + _pad(e_h - nz.heading)))
    x0, y0, h0 = (float(c) for c in pose[0])
    b = Bounds(odb, tuple(tables), hb, StartBounds((x0, x0), (y0, y0), (h0, h0)), MapBounds(0.1))
    streams = LogStreams(odometry=odo, scans=tuple(scans), ranges=tuple(ranges),
                         heading=HeadingStream(stamps, yaw), mounts=tuple(mounts),
                         truth=PoseStream(stamps, pose[:, 0], pose[:, 1], pose[:, 2]))  # fmt: skip
    head = (
        f"# bounds of a digslam env episode ({cfg.dynamics}): the env's noise bounds plus a pad for the\n"
        "# float widening and odometry hulls (see digslam.envs.sim.logs.episode)\n"
    )
    return streams, head + b.to_toml()


__all__ = ["episode_streams"]
