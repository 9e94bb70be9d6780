"""An environment episode as a robot's log (``digslam record --format mcap|sqlite3|bag``): the streams of
:mod:`digslam.observer.record.streams` and the bounds file they satisfy.

Every env step is one stamp (``t0 + round(t·1e9)`` ns): its odometry on ``/odom``, the compass on ``/imu``,
each sonar cone on its own ``sensor_msgs/Range`` topic ``/sonar<j>`` (frame ``sonar<j>``, mounted at the
centre turned by its direction) and the omnidirectional sensor as a one-beam ``LaserScan`` on ``/omni``, the
true pose on ``/digslam/truth``. A no-echo reading is +inf (REP 117); an echo stores the midpoint ``m`` of
the env's interval as float32.

The odometry's twist is each interval's midpoint. Its pose:

- **Unicycle** (no ``mean_velocity``): ``source = "twist"``; the pose integrates the twist by the exact arcs,
  for display.
- **Pymunk** (records that measure the odometry increment ``mean_velocity``): ``source = "pose"``; the yaw
  integrates the yaw rate's midpoints and the position the increments' midpoints ``m̄``: ``p_k = p_{k-1} +
  dt R(psi_{k-1}) m̄_k``, with ``dt`` and ``psi`` as the reader takes them (the stamps' difference, the yaw
  through the message's quaternion, unwrapped). The reader's increment ``R(-psi_{k-1}) (p_k - p_{k-1}) / dt``
  is then ``m̄_k`` up to float rounding, which its own ``err`` term covers (checked here). The bounds file
  states it as ``increment``: the env's velocity bound plus the pad its intervals need (below; ``1e-9`` when
  they are the noise interval and the float widening only, as pymunk's are). The reader takes ``speed`` and
  ``lateral`` from the chord, ``R(-psi_mid) (p_k - p_{k-1}) / dt``, the increment turned by half the step's
  turn, and the yaw rate from ``dpsi / dt``: their excesses below are measured around those values, not the
  intervals' midpoints (the chord may lie up to a hull's width from the hull's midpoint, so the speed pad
  grows: ``~0.41`` m/s where the twist's was ``~0.27``).

The env's intervals are ``[m - b, m + b]`` widened by 4 ulps of ``max(|m|, b)`` (:mod:`.noise_jit`), and
odometry hulls (pymunk's substeps) by their half-width. So each bound is the noise bound ``b`` of
:class:`~digslam.envs.config.NoiseConfig` plus a pad: ``1e-9``, or ``1.01`` times the episode's largest
excess of ``max(c - lo, hi - c)`` over ``b`` rounded up to two digits when that is larger, ``c`` the value
the reader computes: the midpoint ``m``, or the pose's values above (4 ulps: under ``1e-14`` at 10 m; a
pymunk hull: its half-width, up to about half the yaw-rate range when the robot turns hard within a step).
The readers take ``b`` at the float32 neighbours, which hold ``m``, so the float32 needs nothing more.
Apertures are stated exactly in the bounds file (``aperture``), since a ``Range`` message's ``field_of_view``
is float32. Premises: ``max_speed`` and ``max_yaw_rate`` are the larger of the config's limits and every
recorded interval's magnitude; the start box is the true start pose. The stamps round ``t`` to whole
nanoseconds (a step of 0.1 s then lasts 0.1 s up to float rounding, ``< 1e-15`` s).
:func:`episode_streams` reads the odometry back as the reader does (:mod:`digslam.observer.record.bag_bridge`)
and raises RuntimeError where a derived bound misses an env interval (a bug, never a property of the data).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from digslam.envs.config import ExploreConfig
from digslam.envs.sim.arc_jit import arc_move
from digslam.envs.sim.sensors import SensorSuite
from digslam.observer.record.bag_bridge import slice_odometry
from digslam.observer.record.bag_messages import yaw_of
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


class _Quat(NamedTuple):
    x: float
    y: float
    z: float
    w: float


def _read_yaw(th: np.ndarray) -> np.ndarray:
    """The yaws the reader decodes from ``th``: through the quaternion the writer stores (``z = sin(th/2)``,
    ``w = cos(th/2)``, :mod:`digslam.observer.record.bag_write`) and :func:`yaw_of`, in ``(-pi, pi]``."""
    return np.array([yaw_of(_Quat(0.0, 0.0, math.sin(a / 2), math.cos(a / 2))) for a in th.tolist()])


def _read_odometry(b: Bounds, odo: OdometryStream) -> tuple[np.ndarray, ...]:
    """The reader's per-slice intervals (speed, lateral, yaw_rate, mean_velocity; row 0 unused) of ``odo``
    under the odometry bounds of ``b`` (:mod:`digslam.observer.record.bag_bridge`)."""
    pose = np.column_stack([odo.x, odo.y, _read_yaw(odo.yaw)])
    return slice_odometry(b, odo.stamps, pose, np.column_stack([odo.v1, odo.v2, odo.yaw_rate]))


def _excess(c: np.ndarray, iv: np.ndarray) -> float:
    """The largest ``max(c - lo, hi - c)`` (>= 0)."""
    return float(np.max(np.maximum(c - iv[..., 0], iv[..., 1] - c), initial=0.0))


def _check(b: Bounds, odo: OdometryStream, rec: MissionRecord) -> None:
    """RuntimeError unless the reader's odometry intervals (each slice's) hold the env's; and, for the pose
    source with ``increment``, unless its increments are the env's midpoints up to its float ``err`` term."""
    got = _read_odometry(b, odo)
    env = (rec.speed, rec.lateral, rec.yaw_rate, rec.mean_velocity)
    names = ("speed", "lateral", "yaw_rate", "increment")
    for name, g, e in zip(names, got, env):
        if name == "increment" and b.odometry.source != "pose":
            continue
        out = (g[1:, ..., 0] > e[1:, ..., 0]) | (e[1:, ..., 1] > g[1:, ..., 1])
        if out.any():
            k = int(np.argwhere(out)[0][0]) + 1
            raise RuntimeError(f"{name}: the bounds file's interval {g[k].tolist()} misses the env's "
                               f"{e[k].tolist()} at step {k} (a bug)")  # fmt: skip
    if b.odometry.source == "pose" and b.odometry.increment is not None:
        zero = Bound(0.0)
        o0 = replace(b.odometry, speed=zero, lateral=zero, yaw_rate=zero, increment=zero)
        c = _read_odometry(replace(b, odometry=o0), odo)[3][1:]  # [d - err, d + err], rounded outward
        m = 0.5 * (rec.mean_velocity[1:, ..., 0] + rec.mean_velocity[1:, ..., 1])
        off = (m < c[..., 0]) | (c[..., 1] < m)
        if off.any():
            k = int(np.argwhere(off)[0][0]) + 1
            raise RuntimeError(
                f"increment: the pose's increment {c[k - 1].tolist()} misses the env's midpoint "
                f"{m[k - 1].tolist()} at step {k} by more than float rounding (a bug)"
            )


def episode_streams(rec: MissionRecord, pose: np.ndarray, cfg: ExploreConfig,
                    t0: int = 1_700_000_000_000_000_000) -> tuple[LogStreams, str]:  # fmt: skip
    """The streams of an episode (records ``rec``, true poses ``pose (T, 3)``) and its bounds file (TOML)."""
    stamps = t0 + np.round(rec.t * 1e9).astype(np.int64)
    nz = cfg.noise
    v1, e_v = _mid(rec.speed)
    v2, e_l = _mid(rec.lateral)
    w, e_w = _mid(rec.yaw_rate)
    yaw, e_h = _mid(rec.heading)
    mean = bool(np.isfinite(rec.mean_velocity[1:]).all()) and len(rec) > 1  # pymunk: the increment measured
    x, y, th = np.empty(len(rec)), np.empty(len(rec)), np.empty(len(rec))
    x[0], y[0], th[0] = pose[0]
    for k in range(1, len(rec)):
        dt = float(rec.t[k] - rec.t[k - 1])
        th[k] = th[k - 1] + w[k] * dt
        if not mean:
            x[k], y[k], _ = arc_move(x[k - 1], y[k - 1], th[k - 1], th[k], v1[k], dt)
    if mean:  # p_k = p_{k-1} + dt R(psi_{k-1}) m̄_k, with the reader's dt and psi, summed in order
        m1, m2 = (0.5 * (rec.mean_velocity[1:, j, 0] + rec.mean_velocity[1:, j, 1]) for j in (0, 1))
        dts = np.diff(stamps).astype(np.float64) * 1e-9
        psi = np.unwrap(_read_yaw(th))[:-1]  # as bag_bridge unwraps it
        c, s = np.cos(psi), np.sin(psi)
        x[:] = np.add.accumulate(np.concatenate([[x[0]], (c * m1 - s * m2) * dts]))
        y[:] = np.add.accumulate(np.concatenate([[y[0]], (s * m1 + c * m2) * dts]))
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
    top_v = max(cfg.max_speed, float(np.max(np.abs(rec.speed))), float(np.max(np.abs(rec.lateral))))
    top_w = max(cfg.max_yaw_rate, float(np.max(np.abs(rec.yaw_rate))))
    increment = None
    if mean:  # the reader's values: the chord, dpsi/dt and the increment (bounds 0: its centres, +- err)
        zero = Bound(0.0)
        probe = OdometryBounds("/odom", zero, zero, top_v, top_w, "pose", zero, False, zero)
        got = _read_odometry(Bounds(probe, ()), odo)
        cv, cl, cw, cm = (0.5 * (g[1:, ..., 0] + g[1:, ..., 1]) for g in got)
        e_v, e_l = _excess(cv, rec.speed[1:]), _excess(cl, rec.lateral[1:])
        e_w = _excess(cw, rec.yaw_rate[1:])
        e_m = _excess(cm, rec.mean_velocity[1:])
        increment = Bound(nz.speed + _pad(e_m - nz.speed))
    p_v = _pad(max(e_v, 0.0 if unicycle else e_l) - nz.speed)
    odb = OdometryBounds("/odom", Bound(nz.speed + p_v), Bound(nz.yaw_rate + _pad(e_w - nz.yaw_rate)), top_v,
                         top_w, "pose" if mean else "twist", None if unicycle else Bound(nz.speed + p_v),
                         unicycle, increment)  # fmt: skip
    hb = HeadingBounds("/imu", Bound(nz.heading + _pad(e_h - nz.heading)))
    x0, y0, h0 = (float(c) for c in pose[0])
    b = Bounds(odb, tuple(tables), hb, StartBounds((x0, x0), (y0, y0), (h0, h0)), MapBounds(0.1))
    _check(b, odo, rec)
    streams = LogStreams(odometry=odo, scans=tuple(scans), ranges=tuple(ranges),
                         heading=HeadingStream(stamps, yaw), mounts=tuple(mounts),
                         truth=PoseStream(stamps, pose[:, 0], pose[:, 1], pose[:, 2]))  # fmt: skip
    head = (
        f"# bounds of a digslam env episode ({cfg.dynamics}): the env's noise bounds plus a pad for the\n"
        "# float widening and odometry hulls (see digslam.envs.sim.logs.episode)\n"
    )
    return streams, head + b.to_toml()


__all__ = ["episode_streams"]
