"""Writes a robot's log (:class:`~digslam.observer.record.streams.LogStreams`) as a ROS bag.

Formats: ``"mcap"`` and ``"sqlite3"`` are ROS 2 bags (``rosbags.rosbag2.Writer`` with that storage plugin,
CDR messages of ROS 2 Humble): a bag folder (``metadata.yaml`` plus ``NAME.mcap`` or ``NAME.db3``), or the
one storage file when ``path`` ends in ``.mcap`` or ``.db3``; ``"bag"`` is a ROS 1 bag
(``rosbags.rosbag1.Writer``, ROS 1 Noetic messages), a ``.bag`` file. Messages go out in stamp order
(ties: odometry, scans, ranges, heading, truth); the record timestamp is the header stamp. The mounts form
one ``tf2_msgs/TFMessage`` on ``/tf_static`` at the first stamp. ``rosbags`` (the ``[ros]`` extra) is
imported only when a bag is written. The bag is written under a temporary name beside ``path`` and renamed
when complete; an existing ``path`` is never overwritten.
"""

from __future__ import annotations

import math
import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from digslam.observer.record.streams import LogStreams

FORMATS = ("mcap", "sqlite3", "bag")
_SUFFIX = {"mcap": ".mcap", "sqlite3": ".db3"}
_TF = "geometry_msgs/TransformStamped[] transforms\n"


class LogWriteError(ValueError):
    """A log that cannot be written (one line: what and how to fix it)."""


def _rosbags() -> Any:
    """The ``rosbags`` package, or a one-line :class:`LogWriteError` saying how to install it."""
    try:
        import rosbags.rosbag1
        import rosbags.rosbag2
        import rosbags.typesys
    except ImportError:
        raise LogWriteError("writing ROS bags needs rosbags: pip install 'digslam[ros]'") from None
    return rosbags


def write_log(path: str | Path, fmt: str, streams: LogStreams) -> Path:
    """Write ``streams`` to ``path`` in ``fmt`` (see the module); returns ``path``.

    Raises:
        LogWriteError: an unknown format, ``path`` exists, a ROS 1 bag not named ``.bag``, or no rosbags.
    """
    if fmt not in FORMATS:
        raise LogWriteError(f"format: must be one of {', '.join(FORMATS)}, got {fmt!r}")
    path = Path(path)
    if path.exists() or path.is_symlink():
        raise LogWriteError(f"{path}: exists already; give a new name (a log is never overwritten)")
    if fmt == "bag" and path.suffix != ".bag":
        raise LogWriteError(f"{path}: a ROS 1 bag must end in .bag (rosbags tells ROS 1 from ROS 2 by it)")
    if fmt != "bag" and path.suffix in (".mcap", ".db3") and path.suffix != _SUFFIX[fmt]:
        raise LogWriteError(f"{path}: a {fmt} storage file ends in {_SUFFIX[fmt]}, not {path.suffix}")
    rb = _rosbags()
    streams.topics()  # one topic per stream
    if not path.parent.is_dir():
        raise LogWriteError(f"{path.parent}: no such folder")
    tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent))
    try:
        single = fmt != "bag" and path.suffix == _SUFFIX[fmt]
        inner = tmp / (path.stem if single else path.name)
        _write(rb, inner, fmt, streams)
        done = inner / (inner.name + _SUFFIX[fmt]) if single else inner
        if path.exists() or path.is_symlink():
            raise LogWriteError(f"{path}: appeared while the log was written; not overwritten")
        os.rename(done, path)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return path


def _write(rb: Any, path: Path, fmt: str, s: LogStreams) -> None:
    """Write every message of ``s`` to a new bag at ``path``."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ros1 = fmt == "bag"
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    if ros1 and "tf2_msgs/msg/TFMessage" not in ts.types:
        ts.register(get_types_from_msg(_TF, "tf2_msgs/msg/TFMessage"))
    m = _Messages(ts, ros1)
    jobs = _jobs(m, s)
    if ros1:
        writer: Any = rb.rosbag1.Writer(path)
    else:
        plugin = rb.rosbag2.StoragePlugin.MCAP if fmt == "mcap" else rb.rosbag2.StoragePlugin.SQLITE3
        writer = rb.rosbag2.Writer(path, version=9, storage_plugin=plugin)
    serialize = ts.serialize_ros1 if ros1 else ts.serialize_cdr
    with writer:
        conns = []
        for topic, msgtype, _, _ in jobs:
            extra = {"latching": 1} if ros1 and topic == "/tf_static" else {}
            conns.append(writer.add_connection(topic, msgtype, typestore=ts, **extra))
        stamps = np.concatenate([j[2] for j in jobs]) if jobs else np.zeros(0, np.int64)
        which = np.concatenate([np.full(len(j[2]), i) for i, j in enumerate(jobs)]) if jobs else stamps
        index = np.concatenate([np.arange(len(j[2])) for j in jobs]) if jobs else stamps
        for k in np.lexsort((index, which, stamps)):
            topic, msgtype, st, build = jobs[which[k]]
            writer.write(conns[which[k]], int(st[index[k]]), serialize(build(int(index[k])), msgtype))


Job = tuple[str, str, np.ndarray, Callable[[int], object]]


def _jobs(m: _Messages, s: LogStreams) -> list[Job]:
    """``(topic, msgtype, stamps, message of index i)`` of every stream, in the tie-break order."""
    jobs: list[Job] = []
    if s.odometry is not None:
        jobs.append((s.odometry.topic, "nav_msgs/msg/Odometry", s.odometry.stamps, m.odometry(s.odometry)))
    for sc in s.scans:
        jobs.append((sc.topic, "sensor_msgs/msg/LaserScan", sc.stamps, m.scan(sc)))
    for r in s.ranges:
        jobs.append((r.topic, "sensor_msgs/msg/Range", r.stamps, m.range(r)))
    if s.heading is not None:
        jobs.append((s.heading.topic, "sensor_msgs/msg/Imu", s.heading.stamps, m.imu(s.heading)))
    if s.truth is not None:
        jobs.append((s.truth.topic, "geometry_msgs/msg/PoseStamped", s.truth.stamps, m.pose(s.truth)))
    if s.mounts:
        first = min((int(j[2][0]) for j in jobs if len(j[2])), default=0)
        jobs.insert(0, ("/tf_static", "tf2_msgs/msg/TFMessage", np.array([first], np.int64), m.tf(s, first)))
    return jobs


class _Messages:
    """Builders of the message objects of one typestore (ROS 1 headers carry a ``seq``)."""

    def __init__(self, ts: Any, ros1: bool) -> None:
        self.t, self.ros1 = ts.types, ros1

    def header(self, stamp: int, frame: str, seq: int = 0) -> object:
        sec, nsec = divmod(int(stamp), 1_000_000_000)
        time = self.t["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec)
        h = self.t["std_msgs/msg/Header"]
        return h(seq=seq, stamp=time, frame_id=frame) if self.ros1 else h(stamp=time, frame_id=frame)

    def quat(self, yaw: float) -> object:
        return self.t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))

    def vec(self, x: float = 0.0, y: float = 0.0, z: float = 0.0) -> object:
        return self.t["geometry_msgs/msg/Vector3"](x=x, y=y, z=z)

    def pose_of(self, x: float, y: float, yaw: float) -> object:
        point = self.t["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=0.0)
        return self.t["geometry_msgs/msg/Pose"](position=point, orientation=self.quat(float(yaw)))

    def odometry(self, o: Any) -> Callable[[int], object]:
        t, cov = self.t, np.zeros(36)

        def build(i: int) -> object:
            pose = t["geometry_msgs/msg/PoseWithCovariance"](pose=self.pose_of(o.x[i], o.y[i], o.yaw[i]),
                                                            covariance=cov)  # fmt: skip
            tw = t["geometry_msgs/msg/Twist"](linear=self.vec(float(o.v1[i]), float(o.v2[i])),
                                              angular=self.vec(z=float(o.yaw_rate[i])))  # fmt: skip
            twist = t["geometry_msgs/msg/TwistWithCovariance"](twist=tw, covariance=cov)
            head = self.header(o.stamps[i], o.frame_id, i)
            return t["nav_msgs/msg/Odometry"](
                header=head, child_frame_id=o.child_frame_id, pose=pose, twist=twist
            )

        return build

    def scan(self, s: Any) -> Callable[[int], object]:
        n, f32 = s.ranges.shape[1], np.float32
        a0, inc = float(f32(s.angle_min)), float(f32(s.angle_increment))
        a1 = float(f32(a0 + (n - 1) * inc))

        def build(i: int) -> object:
            return self.t["sensor_msgs/msg/LaserScan"](
                header=self.header(s.stamps[i], s.frame_id, i), angle_min=a0, angle_max=a1,
                angle_increment=inc,
                time_increment=float(s.time_increment), scan_time=float(s.scan_time),
                range_min=float(s.range_min), range_max=float(s.range_max), ranges=s.ranges[i],
                intensities=np.zeros(0, np.float32))  # fmt: skip

        return build

    def range(self, r: Any) -> Callable[[int], object]:
        def build(i: int) -> object:
            return self.t["sensor_msgs/msg/Range"](
                header=self.header(r.stamps[i], r.frame_id, i), radiation_type=int(r.radiation_type),
                field_of_view=float(r.field_of_view), min_range=float(r.min_range),
                max_range=float(r.max_range), range=float(r.ranges[i]))  # fmt: skip

        return build

    def imu(self, h: Any) -> Callable[[int], object]:
        cov = np.zeros(9)
        unknown = np.array([-1.0] + [0.0] * 8)  # REP 145: element 0 = -1, this estimate is absent

        def build(i: int) -> object:
            return self.t["sensor_msgs/msg/Imu"](
                header=self.header(h.stamps[i], h.frame_id, i), orientation=self.quat(float(h.yaw[i])),
                orientation_covariance=cov, angular_velocity=self.vec(), angular_velocity_covariance=unknown,
                linear_acceleration=self.vec(), linear_acceleration_covariance=unknown)  # fmt: skip

        return build

    def pose(self, p: Any) -> Callable[[int], object]:
        def build(i: int) -> object:
            head = self.header(p.stamps[i], p.frame_id, i)
            return self.t["geometry_msgs/msg/PoseStamped"](
                header=head, pose=self.pose_of(p.x[i], p.y[i], p.yaw[i])
            )

        return build

    def tf(self, s: LogStreams, stamp: int) -> Callable[[int], object]:
        t = self.t

        def build(i: int) -> object:
            out = []
            for mt in s.mounts:
                at = self.vec(float(mt.forward), float(mt.leftward))
                tr = t["geometry_msgs/msg/Transform"](translation=at, rotation=self.quat(float(mt.yaw)))
                out.append(
                    t["geometry_msgs/msg/TransformStamped"](
                        header=self.header(stamp, mt.parent), child_frame_id=mt.frame_id, transform=tr
                    )
                )
            return t["tf2_msgs/msg/TFMessage"](transforms=out)

        return build


__all__ = ["FORMATS", "LogWriteError", "write_log"]
