"""The bag writer: every format reads back bit for bit through rosbags, written under a temporary name and
renamed, never over an existing path."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from digslam.observer.record import bag_write
from digslam.observer.record.bag_write import LogWriteError, write_log
from digslam.observer.record.streams import (
    HeadingStream,
    LogStreams,
    Mount,
    OdometryStream,
    PoseStream,
    RangeStream,
    ScanStream,
)

pytest.importorskip("rosbags")
T0 = 1_700_000_000_123_456_789


def _streams() -> LogStreams:
    rng = np.random.default_rng(0)
    s = T0 + np.arange(6, dtype=np.int64) * 20_000_000
    odo = OdometryStream(s, *rng.normal(size=(6, 6)).T)
    ranges = rng.uniform(0.1, 10, (3, 5)).astype(np.float32)
    ranges[0, 1], ranges[1, 2] = np.nan, np.inf
    scan = ScanStream(s[::2] + 13_000_000, ranges, angle_min=-0.3, angle_increment=0.15, range_min=0.05,
                      range_max=80.0, time_increment=1e-4)  # fmt: skip
    sonar = RangeStream(s, rng.uniform(0, 5, 6), field_of_view=0.5, min_range=0.1, max_range=5.0,
                        frame_id="sonar0", topic="/sonar0")  # fmt: skip
    return LogStreams(
        odometry=odo, scans=(scan,), ranges=(sonar,), heading=HeadingStream(s, rng.normal(size=6)),
        mounts=(Mount("laser", 0.78, 0.0, 0.0), Mount("sonar0", 0.1, -0.2, 1.5)),
        truth=PoseStream(s, *rng.normal(size=(3, 6))),
    )  # fmt: skip


def _read(path: Path) -> dict[str, list[tuple[int, object]]]:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ts = None
    if path.suffix == ".bag":
        ts = get_typestore(Stores.ROS1_NOETIC)
        ts.register(
            get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage")
        )
    out: dict[str, list[tuple[int, object]]] = {}
    with AnyReader([path], default_typestore=ts) as r:
        for c, t, raw in r.messages():
            out.setdefault(c.topic, []).append((t, r.deserialize(raw, c.msgtype)))
    return out


def _ns(h: object) -> int:
    return int(h.stamp.sec) * 1_000_000_000 + int(h.stamp.nanosec)  # type: ignore[attr-defined]


def _yaw(q: object) -> float:
    return 2 * np.arctan2(q.z, q.w)  # type: ignore[attr-defined]


@pytest.mark.parametrize("fmt,name", [("mcap", "log"), ("mcap", "log.mcap"), ("sqlite3", "log"),
                                      ("sqlite3", "log.db3"), ("bag", "log.bag")])  # fmt: skip
def test_round_trip_bit_exact(tmp_path: Path, fmt: str, name: str) -> None:
    s = _streams()
    path = write_log(tmp_path / name, fmt, s)
    assert [p.name for p in tmp_path.iterdir()] == [name]  # no temporary left
    msgs = _read(path)
    assert set(msgs) == set(s.topics())
    o = s.odometry
    assert o is not None
    odo = msgs["/odom"]
    assert [t for t, _ in odo] == o.stamps.tolist() == [_ns(m.header) for _, m in odo]
    got = np.array([[m.pose.pose.position.x, m.pose.pose.position.y, m.twist.twist.linear.x,
                     m.twist.twist.linear.y, m.twist.twist.angular.z] for _, m in odo])  # fmt: skip
    assert np.array_equal(got, np.column_stack([o.x, o.y, o.v1, o.v2, o.yaw_rate]))
    assert np.allclose([_yaw(m.pose.pose.orientation) for _, m in odo], o.yaw, rtol=0, atol=1e-15)
    assert {m.child_frame_id for _, m in odo} == {"base_link"} and odo[0][1].header.frame_id == "odom"
    sc = s.scans[0]
    scans = msgs["/scan"]
    assert [_ns(m.header) for _, m in scans] == sc.stamps.tolist()
    got_r = np.stack([m.ranges for _, m in scans])
    assert got_r.dtype == np.float32 and np.array_equal(got_r, sc.ranges, equal_nan=True)
    m0 = scans[0][1]
    assert (m0.angle_min, m0.angle_increment) == (np.float32(-0.3), np.float32(0.15))
    assert m0.angle_max == np.float32(np.float32(-0.3) + 4 * np.float32(0.15)) and m0.range_max == 80.0
    sonar = msgs["/sonar0"]
    assert np.array_equal([m.range for _, m in sonar], s.ranges[0].ranges)
    assert sonar[0][1].field_of_view == np.float32(0.5) and sonar[0][1].max_range == 5.0
    assert s.heading is not None and s.truth is not None
    assert np.allclose([_yaw(m.orientation) for _, m in msgs["/imu"]], s.heading.yaw, rtol=0, atol=1e-15)
    truth = msgs["/digslam/truth"]
    assert np.array_equal([[m.pose.position.x, m.pose.position.y] for _, m in truth],
                          np.column_stack([s.truth.x, s.truth.y]))  # fmt: skip
    ((t_tf, tf),) = msgs["/tf_static"]
    assert t_tf == T0 and [(x.header.frame_id, x.child_frame_id) for x in tf.transforms] == [
        ("base_link", "laser"), ("base_link", "sonar0")]  # fmt: skip
    tr = tf.transforms[1].transform
    assert (tr.translation.x, tr.translation.y) == (0.1, -0.2) and abs(_yaw(tr.rotation) - 1.5) < 1e-15
    assert tf.transforms[0].transform.rotation.w == 1.0 and tf.transforms[0].transform.rotation.z == 0.0


def test_refuses_to_overwrite(tmp_path: Path) -> None:
    for name, make in (("a", Path.mkdir), ("b.bag", Path.touch)):
        make(tmp_path / name)
        with pytest.raises(LogWriteError, match="exists already") as e:
            write_log(tmp_path / name, "bag" if name.endswith("bag") else "mcap", _streams())
        assert "\n" not in str(e.value)


def test_temporary_then_rename(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A failure while writing leaves nothing: neither the log nor the temporary."""

    def broken(rb: object, path: Path, fmt: str, s: LogStreams) -> None:
        path.mkdir()
        (path / "half.mcap").write_bytes(b"x")
        raise OSError("disk full")

    monkeypatch.setattr(bag_write, "_write", broken)
    with pytest.raises(OSError, match="disk full"):
        write_log(tmp_path / "log", "mcap", _streams())
    assert list(tmp_path.iterdir()) == []


def test_bad_names_and_formats(tmp_path: Path) -> None:
    with pytest.raises(LogWriteError, match="must be one of"):
        write_log(tmp_path / "x", "rosbag", _streams())
    with pytest.raises(LogWriteError, match="must end in .bag"):
        write_log(tmp_path / "x.mcap", "bag", _streams())
    with pytest.raises(LogWriteError, match="ends in .db3"):
        write_log(tmp_path / "x.mcap", "sqlite3", _streams())
    with pytest.raises(ValueError, match="goes backwards"):
        HeadingStream(np.array([2, 1]), np.zeros(2))


def test_missing_rosbags(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import builtins

    real = builtins.__import__

    def no_rosbags(name: str, *a: object, **k: object) -> object:
        if name.startswith("rosbags"):
            raise ImportError(name)
        return real(name, *a, **k)  # type: ignore[arg-type]

    monkeypatch.setattr(builtins, "__import__", no_rosbags)
    with pytest.raises(LogWriteError, match=r"pip install 'digslam\[ros\]'"):
        write_log(tmp_path / "x", "mcap", _streams())
