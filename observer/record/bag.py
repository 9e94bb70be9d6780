"""Reading a robot's log (a ROS 2 bag folder, a ``.mcap`` or ``.db3`` file, or a ROS 1 ``.bag``) into records.

:func:`read_log` reads a log with the bounds file's claims (:mod:`.bounds`) into a :class:`Log`: the stacked
:class:`~digslam.observer.record.mission.MissionRecord` the observers take, the start box and the premises
(how the records are built: :mod:`.bag_bridge`; how each message is decoded: :mod:`.bag_messages`).
:func:`log_topics` lists a log's topics. Mounts come from ``/tf_static`` (the base frame: the odometry's
``child_frame_id``, else ``base_link``, else ``base_footprint``, to each range message's ``frame_id``), else
the bounds file's ``mount``, else zeros; a mount's yaw is folded into ``alpha``.

``rosbags`` (the ``[ros]`` extra) is imported inside the functions, so importing this module needs numpy only.
Every failure is a :class:`LogError`, one line that names the log. The log is opened read-only.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from . import bag_messages as bm
from .bag_bridge import Sensor, assemble
from .bounds import Bounds, read_bounds
from .mission import MissionRecord

_INSTALL = "install the ros extra: pip install 'digslam[ros]'"


class LogError(ValueError):
    """A log that cannot be read with its bounds, in one line that names the log."""


@dataclass(frozen=True, eq=False)
class Log:
    """A log read with its bounds.

    Attributes:
        records: The mission, ``t`` in seconds since the first record.
        t0: The first record's stamp (s since the epoch).
        x0_lo, x0_hi: The start box ``(x, y, psi)`` at the first record, in the odometry frame.
        q: Outliers allowed per record (each sensor's ``q`` times its most messages in one record).
        max_range: How far from a record's pose centre a reading can reach (m): mount plus longest trusted
            range or echo plus the slack; the tube's hull widened by it holds every cone.
        frame_id: The map's frame: the odometry's ``header.frame_id`` (``start`` for the twist types: the
            frame where the robot starts in the start box).
        topics: Role (``odometry``, ``heading``, ``ranges[i]``, ``tf_static``) to topic.
        dropped: What was left out: ``nan_beams``, ``too_close`` (-inf), ``below_range_min`` beams,
            ``outside_odometry`` range messages.
        bounds: The bounds read with.
        stamps: Each record's ROS stamp (s since the epoch).
        mounts: Range topic to its ``(forward, leftward, yaw)`` mount.
        mount_sources: Range topic to where its mount came from: ``tf_static``, ``bounds`` or ``none``.
        slot_topics: The range topic of each sensor slot of :attr:`records`.
    """

    records: MissionRecord
    t0: float
    x0_lo: np.ndarray
    x0_hi: np.ndarray
    q: int
    max_range: float
    frame_id: str
    topics: dict[str, str]
    dropped: dict[str, int]
    bounds: Bounds
    stamps: np.ndarray
    mounts: dict[str, tuple[float, float, float]]
    mount_sources: dict[str, str]
    slot_topics: tuple[str, ...]


def _open(path: str | Path) -> Any:
    """An opened ``AnyReader`` on ``path`` (its ``close()`` is the caller's)."""
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise LogError(f"{path}: reading a ROS log needs rosbags: {_INSTALL}") from None
    p = Path(path)
    if not p.exists():
        raise LogError(f"{p}: no such file or folder")
    try:
        store = get_typestore(Stores.ROS1_NOETIC if p.suffix == ".bag" else Stores.ROS2_HUMBLE)
        reader = AnyReader([p], default_typestore=store)
        reader.open()
    except Exception as exc:  # rosbags' errors have no common base: every one is "cannot open"
        why = " ".join(str(exc).split()) or type(exc).__name__
        raise LogError(f"{p}: rosbags cannot open it as a bag ({why})") from None
    return reader


def log_topics(path: str | Path) -> dict[str, str]:
    """Topic -> message type (rosbags' names: ``sensor_msgs/msg/LaserScan``) of the log at ``path``."""
    reader = _open(path)
    try:
        return {t: str(info.msgtype) for t, info in reader.topics.items()}
    finally:
        reader.close()


def _roles(b: Bounds, topics: dict[str, str], path: str) -> dict[str, str]:
    """Role -> topic, after checking that each topic is there with a type that fits its role."""
    roles = {"odometry": b.odometry.topic}
    if b.heading is not None:
        roles["heading"] = b.heading.topic
    roles.update({f"ranges[{i}]": r.topic for i, r in enumerate(b.ranges)})
    for role, topic in roles.items():
        if topic not in topics:
            have = ", ".join(f"{t} ({topics[t].replace('/msg/', '/')})" for t in sorted(topics))
            raise LogError(f"{path}: no topic {topic} ({role}) in the log; it has {have}")
        kinds = bm.ROLES[role.split("[")[0]]
        if topics[topic] not in kinds:
            need = " or ".join(k.replace("/msg/", "/") for k in kinds)
            raise LogError(f"{path}: {topic} is {topics[topic].replace('/msg/', '/')}, {role} needs {need}")
    if b.odometry.source == "pose" and topics[b.odometry.topic] != bm.ODOMETRY:
        raise LogError(f'{path}: {b.odometry.topic} is {topics[b.odometry.topic].replace("/msg/", "/")}, '
                       f'source = "pose" needs nav_msgs/Odometry: set source = "twist"')  # fmt: skip
    return roles


def read_log(path: str | Path, bounds: Bounds | str | Path,
             progress: Callable[[int, int], None] | None = None) -> Log:  # fmt: skip
    """The log at ``path`` read with ``bounds`` (a :class:`Bounds` or a bounds file's path).

    ``progress(done, total)`` is called every 1000 messages and at the end (messages read of the topics used).
    Raises :class:`LogError` (one line): no such path, rosbags cannot open it, an empty log, a missing topic
    (naming the log's topics), a type that does not fit its role, stamps that go backwards on a topic (or
    repeat on the odometry), a malformed message (a ``LaserScan`` whose ``ranges`` disagree with its angles).
    """
    b = bounds if isinstance(bounds, Bounds) else read_bounds(bounds)
    name = str(path)
    reader = _open(path)
    try:
        topics = {t: str(info.msgtype) for t, info in reader.topics.items()}
        if reader.message_count == 0 or not topics:
            raise LogError(f"{name}: the log holds no messages")
        roles = _roles(b, topics, name)
        if "/tf_static" in topics and topics["/tf_static"] == bm.TF:
            roles["tf_static"] = "/tf_static"
        data = _read(reader, roles, topics, name, progress)
    finally:
        reader.close()
    return _build(b, roles, topics, data, name)


def _read(reader: Any, roles: dict[str, str], topics: dict[str, str], name: str,
          progress: Callable[[int, int], None] | None) -> dict[str, list[Any]]:  # fmt: skip
    """Each used topic's decoded messages, in the log's order; stamps checked per topic."""
    wanted = set(roles.values())
    conns = [c for c in reader.connections if c.topic in wanted]
    total = sum(int(c.msgcount) for c in conns)
    out: dict[str, list[Any]] = {t: [] for t in wanted}
    last: dict[str, int] = {}
    store = reader.typestore
    uses = {t: {r.split("[")[0] for r, tt in roles.items() if tt == t} for t in wanted}
    for done, (conn, _, raw) in enumerate(reader.messages(connections=conns), 1):
        topic, kind = conn.topic, topics[conn.topic]
        ns: int | None = None
        try:
            msg = reader.deserialize(raw, conn.msgtype) if conn.msgtype in store.fielddefs else None
            if msg is None:
                raise ValueError(f"the log has no definition of {conn.msgtype}")
            if "tf_static" in uses[topic]:
                out[topic].extend(bm.transforms(msg))
                continue
            ns = bm.stamp_ns(msg)
            if ns < last.get(topic, ns) or ("odometry" in uses[topic] and ns == last.get(topic)):
                raise LogError(
                    f"{name}: {topic}: stamps go backwards: {_when(ns)} after {_when(last[topic])}"
                    + (" (the odometry's must increase)" if ns == last[topic] else "")
                )
            last[topic] = ns
            item: dict[str, Any] = {"ns": ns}
            if "odometry" in uses[topic]:
                item["odometry"] = bm.odometry(msg, kind)
                item["frame"] = (str(msg.header.frame_id), str(getattr(msg, "child_frame_id", "")))
            if "heading" in uses[topic]:
                item["heading"] = bm.heading(msg, kind)
            if "ranges" in uses[topic]:
                item["range"] = bm.range_msg(msg, kind)
            out[topic].append(item)
        except LogError:
            raise
        except (ValueError, AttributeError, TypeError) as exc:
            stamp = f" at stamp {_when(ns)}" if ns is not None else ""
            raise LogError(f"{name}: {topic}{stamp}: {exc}") from None
        except Exception as exc:  # rosbags' deserialization errors (AnyReaderError): a message it cannot read
            raise LogError(f"{name}: {topic}: rosbags cannot read a message ({exc})") from None
        if progress is not None and (done % 1000 == 0 or done == total):
            progress(done, total)
    return out


def _when(ns: int) -> str:
    """A stamp in seconds since the epoch, every nanosecond shown."""
    return f"{ns // 1_000_000_000}.{ns % 1_000_000_000:09d}"


def _build(b: Bounds, roles: dict[str, str], topics: dict[str, str], data: dict[str, list[Any]],
           name: str) -> Log:  # fmt: skip
    """The :class:`Log` from the decoded messages."""
    odo = data[roles["odometry"]]
    if not odo:
        raise LogError(f"{name}: {roles['odometry']} holds no messages")
    ns = np.array([m["ns"] for m in odo], dtype=np.int64)
    arr = np.array([m["odometry"] for m in odo], dtype=np.float64)
    parent, child = odo[0]["frame"]
    tree = {c: (p, m) for p, c, m in data.get("/tf_static", [])} if "tf_static" in roles else {}
    sensors, mounts, sources = [], {}, {}
    for i, spec in enumerate(b.ranges):
        msgs = [m["range"] for m in data[roles[f"ranges[{i}]"]]]
        mount, src = None, "none"
        if msgs and tree:
            for base in (child, "base_link", "base_footprint"):
                if base and (mount := bm.mount_of(tree, base, msgs[0].frame_id)) is not None:
                    src = "tf_static"
                    break
        if mount is None and spec.mount is not None:
            mount, src = spec.mount, "bounds"
        mounts[spec.topic], sources[spec.topic] = mount or (0.0, 0.0, 0.0), src
        sensors.append(Sensor(spec, msgs, mounts[spec.topic]))
    compass = None
    if b.heading is not None:
        h = data[roles["heading"]]
        if not h:
            raise LogError(f"{name}: {roles['heading']} holds no messages")
        compass = (np.array([m["ns"] for m in h], dtype=np.int64), np.array([m["heading"] for m in h]))
    try:
        a = assemble(b, ns, arr[:, :3], arr[:, 3:], compass, sensors)
    except ValueError as exc:
        raise LogError(f"{name}: {exc}") from None
    frame = parent if topics[roles["odometry"]] == bm.ODOMETRY and parent else "start"
    stamps = a.stamps_ns * 1e-9
    return Log(
        records=a.records, t0=float(stamps[0]), x0_lo=a.x0_lo, x0_hi=a.x0_hi, q=a.q, max_range=a.max_range,
        frame_id=frame, topics=roles, dropped=a.dropped, bounds=b, stamps=stamps, mounts=mounts,
        mount_sources=sources, slot_topics=a.slot_topics,
    )  # fmt: skip


__all__ = ["Log", "LogError", "log_topics", "read_log"]
