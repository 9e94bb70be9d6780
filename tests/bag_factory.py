"""Small ROS bags for the log reader's tests, written with rosbags' own writers (not the project's writer).

:class:`BagFactory` collects messages (built from the typestore's classes: ROS 2 Humble for ``mcap`` and
``sqlite3``, ROS 1 Noetic for ``bag``) and :meth:`BagFactory.write` writes them as a ROS 2 bag folder (MCAP or
sqlite3 storage) or a ROS 1 ``.bag``. Each message's receive time defaults to its header stamp.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

FORMATS = ("mcap", "sqlite3", "bag")


class BagFactory:
    """Messages to write, in the order added (``(topic, msgtype, receive ns, message)``)."""

    def __init__(self, fmt: str = "mcap") -> None:
        self.fmt = fmt
        self.store = get_typestore(Stores.ROS1_NOETIC if fmt == "bag" else Stores.ROS2_HUMBLE)
        if "tf2_msgs/msg/TFMessage" not in self.store.types:  # ROS 1's store lacks it: tf2_msgs/TFMessage
            self.store.register(
                get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage")
            )
        self.T = self.store.types
        self.msgs: list[tuple[str, str, int, Any]] = []

    def _add(self, topic: str, msgtype: str, ns: int, msg: Any, recv: int | None) -> None:
        self.msgs.append((topic, msgtype, ns if recv is None else recv, msg))

    def header(self, ns: int, frame: str) -> Any:
        stamp = self.T["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
        if self.fmt == "bag":
            return self.T["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id=frame)
        return self.T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)

    def quat(self, yaw: float) -> Any:
        return self.T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))

    def vec(self, x: float = 0.0, y: float = 0.0, z: float = 0.0) -> Any:
        return self.T["geometry_msgs/msg/Vector3"](x=float(x), y=float(y), z=float(z))

    def twist_msg(self, v1: float, v2: float, w: float) -> Any:
        return self.T["geometry_msgs/msg/Twist"](linear=self.vec(v1, v2), angular=self.vec(0, 0, w))

    def odom(
        self,
        ns: int,
        x: float,
        y: float,
        yaw: float,
        v1: float = 0.0,
        v2: float = 0.0,
        w: float = 0.0,
        topic: str = "/odom",
        recv: int | None = None,
    ) -> None:
        T = self.T
        pose = T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=0.0), orientation=self.quat(yaw)
        )
        msg = T["nav_msgs/msg/Odometry"](
            header=self.header(ns, "odom"),
            child_frame_id="base_link",
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](
                twist=self.twist_msg(v1, v2, w), covariance=np.zeros(36)
            ),
        )
        self._add(topic, "nav_msgs/msg/Odometry", ns, msg, recv)

    def twist(
        self, ns: int, v1: float, v2: float, w: float, topic: str = "/dvl", covariance: bool = True
    ) -> None:
        T = self.T
        if covariance:
            tw = T["geometry_msgs/msg/TwistWithCovariance"](
                twist=self.twist_msg(v1, v2, w), covariance=np.zeros(36)
            )
            msg = T["geometry_msgs/msg/TwistWithCovarianceStamped"](
                header=self.header(ns, "base_link"), twist=tw
            )
            self._add(topic, "geometry_msgs/msg/TwistWithCovarianceStamped", ns, msg, None)
        else:
            msg = T["geometry_msgs/msg/TwistStamped"](
                header=self.header(ns, "base_link"), twist=self.twist_msg(v1, v2, w)
            )
            self._add(topic, "geometry_msgs/msg/TwistStamped", ns, msg, None)

    def imu(self, ns: int, yaw: float, topic: str = "/imu") -> None:
        msg = self.T["sensor_msgs/msg/Imu"](
            header=self.header(ns, "imu"),
            orientation=self.quat(yaw),
            orientation_covariance=np.zeros(9),
            angular_velocity=self.vec(),
            angular_velocity_covariance=np.zeros(9),
            linear_acceleration=self.vec(),
            linear_acceleration_covariance=np.zeros(9),
        )
        self._add(topic, "sensor_msgs/msg/Imu", ns, msg, None)

    def scan(
        self,
        ns: int,
        ranges: np.ndarray,
        angle_min: float,
        angle_increment: float,
        range_max: float,
        topic: str = "/scan",
        frame: str = "laser",
        angle_max: float | None = None,
        time_increment: float = 0.0,
        range_min: float = 0.0,
        recv: int | None = None,
    ) -> None:
        r = np.asarray(ranges, dtype=np.float32)
        if angle_max is None:
            angle_max = angle_min + (len(r) - 1) * angle_increment
        msg = self.T["sensor_msgs/msg/LaserScan"](
            header=self.header(ns, frame),
            angle_min=angle_min,
            angle_max=angle_max,
            angle_increment=angle_increment,
            time_increment=time_increment,
            scan_time=0.0,
            range_min=range_min,
            range_max=range_max,
            ranges=r,
            intensities=np.zeros(0, dtype=np.float32),
        )
        self._add(topic, "sensor_msgs/msg/LaserScan", ns, msg, recv)

    def range(
        self,
        ns: int,
        r: float,
        fov: float,
        min_range: float,
        max_range: float,
        topic: str = "/sonar",
        frame: str = "sonar",
    ) -> None:
        msg = self.T["sensor_msgs/msg/Range"](
            header=self.header(ns, frame),
            radiation_type=0,
            field_of_view=fov,
            min_range=min_range,
            max_range=max_range,
            range=float(np.float32(r)),
        )
        self._add(topic, "sensor_msgs/msg/Range", ns, msg, None)

    def tf_static(self, ns: int, edges: list[tuple[str, str, float, float, float, float]]) -> None:
        """One ``TFMessage`` with ``(parent, child, x, y, z, yaw)`` edges."""
        T = self.T
        tfs = [T["geometry_msgs/msg/TransformStamped"](
            header=self.header(ns, parent), child_frame_id=child,
            transform=T["geometry_msgs/msg/Transform"](translation=self.vec(x, y, z), rotation=self.quat(yaw)))
            for parent, child, x, y, z, yaw in edges]  # fmt: skip
        self._add(
            "/tf_static", "tf2_msgs/msg/TFMessage", ns, T["tf2_msgs/msg/TFMessage"](transforms=tfs), None
        )

    def write(self, path: Path, connections: tuple[tuple[str, str], ...] = ()) -> Path:
        """Write the bag at ``path`` (a folder for ROS 2, ``path`` with suffix ``.bag`` for ROS 1); extra
        ``connections`` (topic, msgtype) are declared without messages. Returns the path written."""
        topics = dict(connections)
        for topic, msgtype, _, _ in self.msgs:
            topics.setdefault(topic, msgtype)
        order = sorted(range(len(self.msgs)), key=lambda i: self.msgs[i][2])
        if self.fmt == "bag":
            path = path.with_suffix(".bag")
            with Writer1(path) as w:
                conns = {t: w.add_connection(t, m, typestore=self.store) for t, m in topics.items()}
                for i in order:
                    topic, msgtype, recv, msg = self.msgs[i]
                    w.write(conns[topic], recv, self.store.serialize_ros1(msg, msgtype))
            return path
        plugin = StoragePlugin.MCAP if self.fmt == "mcap" else StoragePlugin.SQLITE3
        with Writer2(path, version=9, storage_plugin=plugin) as w:
            conns = {t: w.add_connection(t, m, typestore=self.store) for t, m in topics.items()}
            for i in order:
                topic, msgtype, recv, msg = self.msgs[i]
                w.write(conns[topic], recv, self.store.serialize_cdr(msg, msgtype))
        return path
