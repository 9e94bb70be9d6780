"""Simulated robot logs with exact truth, in the streams a robot records (ROS bags through
:func:`~digslam.observer.record.bag_write.write_log`).

The robot drives a scripted path (:mod:`.path`: a tour of the world's reachable space, pure pursuit) on the
project's exact arcs (:mod:`~digslam.envs.sim.arc_jit`). Time is integer nanoseconds: odometry every
``1/odom_rate`` s, laser scans every ``1/laser.rate`` s from ``laser.phase``; the truth is a chain of arcs
between consecutive stamps of either kind. The command ``(v, w)`` is set at each odometry stamp and held until
the next, so the true speed is constant over an odometry slice and the true yaw rate moves only by rounding
between its pieces (each piece's rate is bounded outward, and the real duration ``D`` of a piece differs from
its float ``τ`` by at most ``u D``: the yaw rate is widened by ``2⁻⁵¹`` relative and the position error grows
by ``2u v τ``).

What is recorded (noise uniform inside each bound, :class:`SimNoise`):

* ``/odom`` (``nav_msgs/Odometry``): the twist is the measured body velocity, ``v1 = v + e``, ``v2 = 0``,
  ``w = ŵ + e'`` (``ŵ`` the midpoint of the slice's yaw-rate hull); the pose is the integral of the measured
  twist by the same arcs, from the true start pose. So ``source = "twist"`` holds under the noise bound, and
  ``source = "pose"`` under it plus the arc's geometry (:mod:`.bounds`).
* ``/scan`` (``sensor_msgs/LaserScan``): beam ``j`` is the cone along ``angle_min + j·angle_increment`` (the
  message's float32 fields, summed in float64, plus the mount's yaw) of half-aperture ``angle_increment/2``;
  its value is the exact sector distance from the apex ``x + R(ψ) m`` plus noise, stored as float32; +inf
  where the value would exceed ``range_max`` or nothing lies within it (REP 117), NaN where the truth cannot
  be decided (its rigorous box is open or wider than 1e-6 m: an obstacle point within the pose error of the
  cone's edge or of the range limit). The apex's rigorous box: the proved
  position error plus the rounding of ``R(ψ) m`` (:func:`apex`), fed to
  :meth:`~digslam.envs.sim.sensors.SensorSuite.range_bounds`.
* ``/imu`` (``sensor_msgs/Imu``, ``compass=True``): the heading plus noise, at the odometry stamps.
* ``/tf_static``: the laser's mount; ``/digslam/truth``: the true pose at every stamp.

:meth:`SimLog.bounds` writes the matching bounds file (:mod:`.bounds`).

>>> log = simulate_log(duration=1.0, laser=LaserSpec(beams=5), seed=0)
>>> len(log.streams.odometry), len(log.streams.scans[0]), log.scan_bounds.shape
(51, 10, (10, 5, 2))
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from digslam.envs.sim.arc_jit import advance, arc_move, yaw_rate_bounds
from digslam.envs.sim.generators import GENERATORS, ThesisRoom
from digslam.envs.sim.logs.path import PurePursuit, tour
from digslam.envs.sim.missions import THESIS_LOOP
from digslam.envs.sim.sensors import SensorSuite
from digslam.envs.sim.world import World
from digslam.observer.core.rounding import LIBM_ULPS
from digslam.observer.core.scalar_jit import add_up, mul_up
from digslam.observer.record.streams import (
    HeadingStream,
    LogStreams,
    Mount,
    OdometryStream,
    PoseStream,
    ScanStream,
)

_U, _ETA = 2.0**-53, 5e-324
_F32 = np.float32
#: A beam whose truth box is wider than this (m) reads NaN: an obstacle point lies within the pose error of
#: the cone's edge, so the truth is one of two far-apart distances (millions of beams meet a few).
_UNDECIDED = 1e-6


@dataclass(frozen=True)
class LaserSpec:
    """A laser scanner: ``beams`` over ``fov`` (first to last beam, centred on the mount's axis), at ``rate``
    Hz from ``phase`` s after the first odometry message, mounted at ``mount = (forward, leftward, yaw)``."""

    beams: int = 37
    fov: float = math.pi
    range_max: float = 20.0
    range_min: float = 0.05
    rate: float = 10.0
    phase: float = 0.013
    mount: tuple[float, float, float] = (0.0, 0.0, 0.0)
    topic: str = "/scan"
    frame_id: str = "laser"

    def angles(self) -> tuple[float, float]:
        """``(angle_min, angle_increment)`` as the message stores them (float32 values)."""
        inc = self.fov / (self.beams - 1) if self.beams > 1 else max(self.fov, 1e-3)
        return float(_F32(-self.fov / 2 if self.beams > 1 else 0.0)), float(_F32(inc))


@dataclass(frozen=True)
class SimNoise:
    """Noise bounds: odometry ``speed`` (m/s) and ``yaw_rate`` (rad/s), compass ``heading`` (rad) and
    ``range = (abs, rel)`` (m: ``|v - r| <= abs + rel·|v|``); each error is uniform inside its bound."""

    speed: float = 0.02
    yaw_rate: float = 0.005
    heading: float = 0.02
    range: tuple[float, float] = (0.03, 0.0)


@dataclass(eq=False)
class SimLog:
    """A simulated log and its truth.

    Attributes:
        streams: what the robot recorded (:class:`~digslam.observer.record.streams.LogStreams`).
        stamps: ``(m,)`` every stamp (ns since the epoch), odometry and laser merged.
        pose: ``(m, 3)`` the true pose at each stamp (the heading exact); error: ``(m,)`` the proved bound of
            the position's error per coordinate.
        speed, yaw_rate: ``(N + 1,)`` and ``(N + 1, 2)`` the true speed and the bounds of the true yaw rate
            over the slice that ends at each odometry message (message 0: at rest).
        scan_bounds: ``(S, n, 2)`` rigorous bounds of each beam's true sector distance.
        scan_values: ``(S, n)`` each beam's value in float64, before the message rounds it to float32.
        apex: ``(S, 2)`` each scan's apex and apex_error ``(S,)`` its proved error per coordinate.
        alpha, gamma: ``(n,)`` the beams' directions (the mount's yaw included) and half-apertures.
        laser, noise, speed_max, yaw_rate_max, compass: the settings.
    """

    streams: LogStreams
    stamps: np.ndarray
    pose: np.ndarray
    error: np.ndarray
    speed: np.ndarray
    yaw_rate: np.ndarray
    scan_bounds: np.ndarray
    scan_values: np.ndarray
    apex: np.ndarray
    apex_error: np.ndarray
    alpha: np.ndarray
    gamma: np.ndarray
    laser: LaserSpec
    noise: SimNoise
    speed_max: float
    yaw_rate_max: float
    compass: bool
    world: World = field(repr=False)

    def bounds(self, source: str = "pose", resolution: float = 0.1, beams: int | None = None) -> str:
        """The bounds file (TOML) that this log satisfies (:func:`.bounds.bounds_text`)."""
        from digslam.envs.sim.logs.bounds import bounds_text

        return bounds_text(self, source, resolution, beams)

    def write(self, path: str | Path, fmt: str) -> Path:
        """Write the log as a bag (:func:`~digslam.observer.record.bag_write.write_log`)."""
        from digslam.observer.record.bag_write import write_log

        return write_log(path, fmt, self.streams)

    def truth_at(self, stamps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(pose (k, 3), error (k,))`` at some of :attr:`stamps` (KeyError for another stamp)."""
        i = np.minimum(np.searchsorted(self.stamps, stamps), len(self.stamps) - 1)
        if np.any(self.stamps[i] != stamps):
            raise KeyError("stamps: not a stamp of this log")
        return self.pose[i], self.error[i]


def apex(pose: np.ndarray, error: float, mount: tuple[float, float, float]) -> tuple[np.ndarray, float]:
    """The sensor's apex ``fl(x + R(ψ) m)`` and a proved bound of its error per coordinate: the position's
    ``error`` plus the rounding of ``R(ψ) m`` (``ψ`` exact; libm's cos/sin within ``2 L u``, then two
    products, a sum and the final sum, each ``|r - exact| <= 2u|r| + η``), doubled as in
    :mod:`~digslam.envs.sim.arc_jit`."""
    f, left = float(mount[0]), float(mount[1])
    if f == 0.0 and left == 0.0:
        return np.array([pose[0], pose[1]]), float(error)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    ax, ay = pose[0] + (f * c - left * s), pose[1] + (f * s + left * c)
    m = abs(f) + abs(left)
    rot = mul_up(m, (2 * LIBM_ULPS + 8) * _U)
    tail = add_up(mul_up(2 * _U, max(abs(ax), abs(ay))), 8 * _ETA)
    return np.array([ax, ay]), add_up(float(error), 2.0 * add_up(rot, tail))


def _world(world: World | str | None, size: float, seed: int) -> World:
    if isinstance(world, World):
        return world
    if world is None:
        return ThesisRoom().generate(0)
    if world not in GENERATORS:
        raise ValueError(f"world: must be a World or one of {sorted(GENERATORS)}, got {world!r}")
    return GENERATORS[world](size=size).generate(seed)  # type: ignore[call-arg]  # every generator takes size


def simulate_log(
    world: World | str | None = None,
    duration: float = 60.0,
    odom_rate: float = 50.0,
    laser: LaserSpec | None = None,
    compass: bool = False,
    noise: SimNoise | None = None,
    speed: float = 0.5,
    max_yaw_rate: float = 0.6,
    seed: int = 0,
    world_size: float = 10.0,
    path: np.ndarray | None = None,
    t0: int = 1_700_000_000_000_000_000,
) -> SimLog:
    """Simulate a log (see the module). ``world``: a :class:`~.world.World`, a generator name (its level
    ``seed`` at half-width ``world_size``) or None (the thesis room, driving :data:`~.missions.THESIS_LOOP`);
    ``path``: a closed polyline to follow (default: the room's loop, or a seeded tour of the world);
    ``t0``: the first stamp (ns since the epoch). Raises ValueError on a bad setting."""
    laser, noise = laser or LaserSpec(), noise or SimNoise()
    if not (duration > 0 and odom_rate > 0 and laser.rate > 0 and speed > 0 and max_yaw_rate > 0):
        raise ValueError("duration, odom_rate, laser.rate, speed, max_yaw_rate: must be > 0")
    if laser.beams < 1 or not 0 < laser.range_min < laser.range_max or laser.phase < 0:
        raise ValueError(f"laser: needs beams >= 1, 0 < range_min < range_max, phase >= 0; got {laser}")
    rng = np.random.default_rng(seed)
    wld = _world(world, world_size, seed)
    wp = THESIS_LOOP if path is None and world is None else path
    drive = PurePursuit(tour(wld, rng) if wp is None else np.vstack([wp, wp[:1]]), speed, max_yaw_rate)
    p_o, p_l = int(round(1e9 / odom_rate)), int(round(1e9 / laser.rate))
    n = int(round(duration * 1e9 / p_o))
    odo = np.arange(n + 1, dtype=np.int64) * p_o
    scans = np.arange(int(round(laser.phase * 1e9)), n * p_o, p_l, dtype=np.int64)
    stamps = np.union1d(odo, scans)
    a0, inc = laser.angles()
    alpha = (a0 + np.arange(laser.beams) * inc) + float(laser.mount[2])
    gamma = np.full(laser.beams, inc / 2)
    r_max = float(_F32(laser.range_max))
    suite = SensorSuite(alpha, gamma, np.full(laser.beams, r_max))
    pose, err = drive.start(), 0.0
    poses, errors, v_true, w_true = [pose], [0.0], [0.0], [(0.0, 0.0)]
    sb, apexes, apex_err = [], [], []
    scan_set = set(scans.tolist())
    v = w = 0.0
    hull = [math.inf, -math.inf]
    for i, s in enumerate(stamps.tolist()):
        if s in scan_set:
            ap, e_ap = apex(pose, err, laser.mount)
            sb.append(suite.range_bounds(wld, np.array([ap[0], ap[1], pose[2]]), e_ap))
            apexes.append(ap)
            apex_err.append(e_ap)
        if i + 1 == len(stamps):
            break
        if s % p_o == 0:  # an odometry stamp: the next slice's command
            v, wr = drive.command(pose)
            w, hull = wr, [math.inf, -math.inf]
        tau = (int(stamps[i + 1]) - s) / 1e9
        x1, y1, th1, e = advance(float(pose[0]), float(pose[1]), float(pose[2]), v, w, tau)
        lo, hi = yaw_rate_bounds(float(pose[2]), th1, tau)
        hull = [min(hull[0], lo - abs(lo) * 2.0**-51), max(hull[1], hi + abs(hi) * 2.0**-51)]
        err = add_up(add_up(err, e), mul_up(mul_up(abs(v), tau), 2 * _U))
        pose = np.array([x1, y1, th1])
        poses.append(pose)
        errors.append(err)
        if int(stamps[i + 1]) % p_o == 0:
            v_true.append(v)
            w_true.append((hull[0], hull[1]))
    P, speeds, yaws = np.array(poses), np.array(v_true), np.array(w_true)
    bounds = np.array(sb).reshape(-1, laser.beams, 2)
    at_odo = P[np.isin(stamps, odo)]
    streams, values = _record(
        at_odo, speeds, yaws, bounds, odo, scans, stamps, P, laser, noise, compass, rng, t0
    )
    return SimLog(streams, stamps + t0, P, np.array(errors), speeds, yaws, bounds, values,
                  np.array(apexes).reshape(-1, 2), np.array(apex_err), alpha, gamma, laser, noise, speed,
                  max_yaw_rate, compass, wld)  # fmt: skip


def _record(odo_pose: np.ndarray, v: np.ndarray, w: np.ndarray, sb: np.ndarray, odo: np.ndarray,
            scans: np.ndarray, stamps: np.ndarray, P: np.ndarray, laser: LaserSpec, noise: SimNoise,
            compass: bool, rng: np.random.Generator, t0: int) -> tuple[LogStreams, np.ndarray]:  # fmt: skip
    """The measured streams from the truth (see the module) and the beams' float64 values."""
    m = len(odo)
    v_m = v + rng.uniform(-1.0, 1.0, m) * noise.speed
    w_m = 0.5 * (w[:, 0] + w[:, 1]) + rng.uniform(-1.0, 1.0, m) * noise.yaw_rate
    x, y, th = np.empty(m), np.empty(m), np.empty(m)
    x[0], y[0], th[0] = odo_pose[0]
    for k in range(1, m):
        dt = (int(odo[k]) - int(odo[k - 1])) / 1e9
        th[k] = th[k - 1] + w_m[k] * dt
        x[k], y[k], _ = arc_move(x[k - 1], y[k - 1], th[k - 1], th[k], v_m[k], dt)
    o = OdometryStream(odo + t0, x, y, th, v_m, np.zeros(m), w_m)
    a, z = sb[..., 0], sb[..., 1]
    c = np.where(np.isfinite(z), 0.5 * (a + z), a)
    ab, rel = noise.range
    val = c + rng.uniform(-1.0, 1.0, c.shape) * ((ab + rel * c) / (1.0 + rel))
    val = np.where(z - a <= _UNDECIDED, val, np.nan)  # undecided truth (a wide or open box): erroneous
    val = np.where((a > float(_F32(laser.range_max))) | (val > float(_F32(laser.range_max))), np.inf, val)
    a0, inc = laser.angles()
    scan = ScanStream(scans + t0, val.astype(np.float32), a0, inc, laser.range_min, laser.range_max,
                      laser.frame_id, laser.topic)  # fmt: skip
    heading = None
    if compass:
        heading = HeadingStream(odo + t0, odo_pose[:, 2] + rng.uniform(-1.0, 1.0, m) * noise.heading)
    mount = Mount(laser.frame_id, float(laser.mount[0]), float(laser.mount[1]), float(laser.mount[2]))
    truth = PoseStream(stamps + t0, P[:, 0], P[:, 1], P[:, 2])
    return LogStreams(odometry=o, scans=(scan,), heading=heading, mounts=(mount,), truth=truth), val


__all__ = ["LaserSpec", "SimLog", "SimNoise", "apex", "simulate_log"]
