"""Per-message decoding for the log reader (:mod:`.bag`): ROS messages to plain numbers.

Each decoder takes one deserialized message (rosbags' dataclasses; no rosbags import here) and returns
numbers: stamps in integer nanoseconds (``header.stamp``), yaw from a quaternion, an odometry message's pose
and body-frame twist, a compass's yaw, a range message (``sensor_msgs/LaserScan`` or ``sensor_msgs/Range``)
as a :class:`RangeMsg` of float32 ranges with its angles, and the ``/tf_static`` tree's planar mounts
(:func:`mount_of`). A message that does not fit raises :class:`ValueError` with the reason; the reader turns
it into one :class:`~digslam.observer.record.bag.LogError` line that names the topic and the stamp.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

#: The message types each role accepts (rosbags' names; ROS 1 bags are read under the same names).
ODOMETRY = "nav_msgs/msg/Odometry"
TWISTS = ("geometry_msgs/msg/TwistStamped", "geometry_msgs/msg/TwistWithCovarianceStamped")
IMU = "sensor_msgs/msg/Imu"
SCAN = "sensor_msgs/msg/LaserScan"
RANGE = "sensor_msgs/msg/Range"
TF = "tf2_msgs/msg/TFMessage"
ROLES: dict[str, tuple[str, ...]] = {
    "odometry": (ODOMETRY, *TWISTS),
    "heading": (IMU, ODOMETRY),
    "ranges": (SCAN, RANGE),
}


class RangeMsg(NamedTuple):
    """One range message: beam ``i`` points at ``angle_min + i·angle_increment`` (rad, sensor frame) and is
    taken at ``ns + i·time_increment``; ``ranges`` are float32 as the message stores them; ``gamma`` is the
    beam's default half-aperture (``|angle_increment| / 2`` for a scan, ``field_of_view / 2`` for a cone)."""

    ns: int
    frame_id: str
    angle_min: float
    angle_increment: float
    time_increment: float
    ranges: np.ndarray
    range_min: float
    range_max: float
    gamma: float


def stamp_ns(msg: Any) -> int:
    """``header.stamp`` in integer nanoseconds."""
    s = msg.header.stamp
    return int(s.sec) * 1_000_000_000 + int(s.nanosec)


def yaw_of(q: Any) -> float:
    """Yaw (rad, in ``(-pi, pi]``) of the quaternion ``q`` (``x, y, z, w``): the rotation about z of its
    ZYX Euler angles."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def odometry(msg: Any, msgtype: str) -> tuple[float, float, float, float, float, float]:
    """``(x, y, yaw, v1, v2, w)``: the pose (``nan`` for the twist types) and the body-frame twist."""
    if msgtype == ODOMETRY:
        p = msg.pose.pose
        x, y, yaw = float(p.position.x), float(p.position.y), yaw_of(p.orientation)
        tw = msg.twist.twist
    else:
        x = y = yaw = math.nan
        tw = msg.twist.twist if msgtype == TWISTS[1] else msg.twist
    return x, y, yaw, float(tw.linear.x), float(tw.linear.y), float(tw.angular.z)


def heading(msg: Any, msgtype: str) -> float:
    """A compass message's yaw (rad): an ``Imu``'s orientation or an ``Odometry``'s pose."""
    if msgtype == IMU:
        if msg.orientation_covariance[0] == -1.0:
            raise ValueError("the Imu has no orientation (orientation_covariance[0] = -1)")
        return yaw_of(msg.orientation)
    return yaw_of(msg.pose.pose.orientation)


def range_msg(msg: Any, msgtype: str) -> RangeMsg:
    """A ``LaserScan`` or a ``Range`` as a :class:`RangeMsg` (a ``Range`` is one beam along the x axis).

    Raises:
        ValueError: a scan whose ``ranges`` length is more than one beam away from its angles'
            ``(angle_max - angle_min) / angle_increment + 1`` (one beam of slack: drivers round either way,
            and beam ``i``'s angle depends on ``angle_min`` and ``angle_increment`` only).
    """
    ns, frame = stamp_ns(msg), str(msg.header.frame_id)
    if msgtype == RANGE:
        fov = float(msg.field_of_view)
        ranges = np.array([msg.range], dtype=np.float32)
        return RangeMsg(ns, frame, 0.0, 0.0, 0.0, ranges, float(msg.min_range), float(msg.max_range),
                        min(abs(fov) / 2.0, math.pi))  # fmt: skip
    ranges = np.asarray(msg.ranges, dtype=np.float32)
    a0, a1, inc = float(msg.angle_min), float(msg.angle_max), float(msg.angle_increment)
    n = len(ranges)
    expected = (a1 - a0) / inc + 1.0 if inc != 0.0 else 1.0
    if not (n >= 1 and math.isfinite(expected) and abs(n - expected) <= 1.0 + 1e-6):
        raise ValueError(
            f"LaserScan ranges has {n} beams, its angles need {expected:.1f} "
            f"(angle_min {a0:.6g}, angle_max {a1:.6g}, angle_increment {inc:.6g})"
        )
    return RangeMsg(ns, frame, a0, inc, float(msg.time_increment), ranges, float(msg.range_min),
                    float(msg.range_max), abs(inc) / 2.0)  # fmt: skip


def transforms(msg: Any) -> list[tuple[str, str, np.ndarray]]:
    """A ``TFMessage``'s edges ``(parent, child, T)``, ``T`` the 4×4 homogeneous transform parent <- child."""
    out = []
    for tf in msg.transforms:
        t, q = tf.transform.translation, tf.transform.rotation
        x, y, z, w = float(q.x), float(q.y), float(q.z), float(q.w)
        n = math.sqrt(x * x + y * y + z * z + w * w) or 1.0
        x, y, z, w = x / n, y / n, z / n, w / n
        m = np.eye(4)
        m[:3, :3] = [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
        m[:3, 3] = [float(t.x), float(t.y), float(t.z)]
        out.append((str(tf.header.frame_id).lstrip("/"), str(tf.child_frame_id).lstrip("/"), m))
    return out


def _to_root(tree: dict[str, tuple[str, np.ndarray]], frame: str) -> tuple[str, np.ndarray]:
    """The root of ``frame``'s chain and the transform root <- frame (composed along the chain)."""
    m, seen = np.eye(4), {frame}
    while frame in tree:
        parent, edge = tree[frame]
        m = edge @ m
        frame = parent
        if frame in seen:  # a cycle: no root
            break
        seen.add(frame)
    return frame, m


def mount_of(
    tree: dict[str, tuple[str, np.ndarray]], base: str, sensor: str
) -> tuple[float, float, float] | None:
    """The planar mount ``(forward, leftward, yaw)`` of frame ``sensor`` in frame ``base`` through the static
    tree ``child -> (parent, T)`` (any chain: both frames up to a common root, then base <- root <- sensor),
    or ``None`` when they are not connected. The 3-D transform is projected on the base's plane: its x, y and
    the yaw of its rotation (a tilted sensor's tilt is not modelled)."""
    base, sensor = base.lstrip("/"), sensor.lstrip("/")
    rb, mb = _to_root(tree, base)
    rs, ms = _to_root(tree, sensor)
    if rb != rs:
        return None
    m = np.linalg.inv(mb) @ ms
    return float(m[0, 3]), float(m[1, 3]), math.atan2(m[1, 0], m[0, 0])


__all__ = [
    "IMU",
    "ODOMETRY",
    "RANGE",
    "ROLES",
    "SCAN",
    "TF",
    "TWISTS",
    "RangeMsg",
    "heading",
    "mount_of",
    "odometry",
    "range_msg",
    "stamp_ns",
    "transforms",
    "yaw_of",
]
