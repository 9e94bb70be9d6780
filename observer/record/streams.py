"""A robot's log as plain arrays (numpy only): what :func:`~digslam.observer.record.bag_write.write_log`
writes as ROS messages, one stream per topic.

Stamps are integer nanoseconds since the epoch (``int64``), one per message, non-decreasing within a
stream. Angles are radians, lengths metres, velocities in the body frame (``v1`` forward, ``v2`` leftward).
The ROS messages store some fields as float32 (``LaserScan`` and ``Range``: ranges, angles, limits): the
writer rounds them, so a simulator that wants its truth to match the log bit for bit gives float32 values.

>>> s = np.array([0, 20_000_000], dtype=np.int64)
>>> odo = OdometryStream(s, x=[0.0, 0.02], y=[0.0, 0.0], yaw=[0.0, 0.0], v1=[1.0, 1.0], v2=[0.0, 0.0],
...                      yaw_rate=[0.0, 0.0])
>>> len(odo), LogStreams(odometry=odo).topics()
(2, {'/odom': 'nav_msgs/msg/Odometry'})
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np


def _arrays(obj: object, names: tuple[str, ...], dtype: type = np.float64, ndim: int = 1) -> int:
    """Convert the fields ``names`` of the frozen ``obj`` (and its ``stamps``) to arrays; check that they are
    as long as the stamps and that the stamps do not go backwards; the message count."""
    stamps = np.asarray(obj.stamps, dtype=np.int64).reshape(-1)  # type: ignore[attr-defined]  # every stream has stamps
    object.__setattr__(obj, "stamps", stamps)
    if np.any(np.diff(stamps) < 0):
        k = int(np.argmax(np.diff(stamps) < 0)) + 1
        raise ValueError(f"stamps: message {k} goes backwards ({stamps[k - 1]} then {stamps[k]} ns)")
    for name in names:
        arr: np.ndarray = np.asarray(getattr(obj, name), dtype=dtype)
        if arr.ndim != ndim or arr.shape[0] != len(stamps):
            raise ValueError(f"{name}: expected {len(stamps)} rows (one per stamp), got shape {arr.shape}")
        object.__setattr__(obj, name, arr)
    return len(stamps)


@dataclass(frozen=True, eq=False)
class OdometryStream:
    """``nav_msgs/Odometry``: the integrated pose ``(x, y, yaw)`` in ``frame_id`` and the body twist."""

    stamps: np.ndarray
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    v1: np.ndarray
    v2: np.ndarray
    yaw_rate: np.ndarray
    topic: str = "/odom"
    frame_id: str = "odom"
    child_frame_id: str = "base_link"

    def __post_init__(self) -> None:
        _arrays(self, ("x", "y", "yaw", "v1", "v2", "yaw_rate"))

    def __len__(self) -> int:
        return len(self.stamps)


@dataclass(frozen=True, eq=False)
class ScanStream:
    """``sensor_msgs/LaserScan``: ``ranges (m, n)`` (NaN: an erroneous beam, +inf: no return, REP 117); beam
    ``j`` points at ``angle_min + j angle_increment`` in ``frame_id``."""

    stamps: np.ndarray
    ranges: np.ndarray
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    frame_id: str = "laser"
    topic: str = "/scan"
    time_increment: float = 0.0
    scan_time: float = 0.0

    def __post_init__(self) -> None:
        _arrays(self, ("ranges",), np.float32, ndim=2)

    def __len__(self) -> int:
        return len(self.stamps)


@dataclass(frozen=True, eq=False)
class RangeStream:
    """``sensor_msgs/Range``: one cone of full angle ``field_of_view`` along ``frame_id``'s x axis."""

    stamps: np.ndarray
    ranges: np.ndarray
    field_of_view: float
    min_range: float
    max_range: float
    frame_id: str
    topic: str
    radiation_type: int = 0  # ULTRASOUND

    def __post_init__(self) -> None:
        _arrays(self, ("ranges",), np.float32)

    def __len__(self) -> int:
        return len(self.stamps)


@dataclass(frozen=True, eq=False)
class HeadingStream:
    """``sensor_msgs/Imu`` carrying a compass: its orientation is the yaw (the rest left zero)."""

    stamps: np.ndarray
    yaw: np.ndarray
    topic: str = "/imu"
    frame_id: str = "base_link"

    def __post_init__(self) -> None:
        _arrays(self, ("yaw",))

    def __len__(self) -> int:
        return len(self.stamps)


@dataclass(frozen=True, eq=False)
class PoseStream:
    """``geometry_msgs/PoseStamped``: a planar pose per stamp (the ground truth of a simulated log)."""

    stamps: np.ndarray
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    topic: str = "/digslam/truth"
    frame_id: str = "odom"

    def __post_init__(self) -> None:
        _arrays(self, ("x", "y", "yaw"))

    def __len__(self) -> int:
        return len(self.stamps)


@dataclass(frozen=True)
class Mount:
    """A static transform ``parent -> frame_id`` on ``/tf_static``: the sensor ``forward``, ``leftward`` (m)
    of the robot's centre, turned by ``yaw`` (rad)."""

    frame_id: str
    forward: float = 0.0
    leftward: float = 0.0
    yaw: float = 0.0
    parent: str = "base_link"


@dataclass(frozen=True, eq=False)
class LogStreams:
    """Every stream of a log; empty tuples and None are left out of the bag."""

    odometry: OdometryStream | None = None
    scans: tuple[ScanStream, ...] = ()
    ranges: tuple[RangeStream, ...] = ()
    heading: HeadingStream | None = None
    mounts: tuple[Mount, ...] = ()
    truth: PoseStream | None = None

    def topics(self) -> dict[str, str]:
        """Topic -> ROS 2 message type of every stream present."""
        kinds = {"odometry": "nav_msgs/msg/Odometry", "scans": "sensor_msgs/msg/LaserScan",
                 "ranges": "sensor_msgs/msg/Range", "heading": "sensor_msgs/msg/Imu",
                 "truth": "geometry_msgs/msg/PoseStamped"}  # fmt: skip
        out: dict[str, str] = {}
        for f in fields(self):
            if f.name not in kinds:
                continue
            v = getattr(self, f.name)
            for s in v if isinstance(v, tuple) else (() if v is None else (v,)):
                if s.topic in out:
                    raise ValueError(f"topic: {s.topic!r} is used by two streams")
                out[s.topic] = kinds[f.name]
        if self.mounts:
            out["/tf_static"] = "tf2_msgs/msg/TFMessage"
        return out


__all__ = [
    "HeadingStream",
    "LogStreams",
    "Mount",
    "OdometryStream",
    "PoseStream",
    "RangeStream",
    "ScanStream",
]
