"""The log reader (digslam.observer.record.bag): bags written with rosbags' writers, read into records whose
intervals hold the truth they were made from; one line for each bad input."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags")

from bag_factory import FORMATS, BagFactory  # noqa: E402  (needs rosbags)

from digslam.observer.record import UNMEASURED, LogError, log_topics, parse_bounds, read_log  # noqa: E402

T0 = 1_700_000_000 * 10**9  # ns
V, W = 0.5, 0.3  # the truth: a circle at constant speed and yaw rate

LASER = """
[odometry]
topic = "/odom"
source = "pose"
speed = [0.02, 0.05]
unicycle = true
yaw_rate = [0.005, 0.05]
max_speed = 1.5
max_yaw_rate = 2.0
[[ranges]]
topic = "/scan"
bound = [0.0, 0.0]
beams = 37
max_range = 20.0
q = 2
"""

AUV = """
[odometry]
topic = "/dvl"
source = "twist"
speed = [0.01, 0.01]
lateral = [0.01, 0.01]
yaw_rate = [0.002, 0.01]
max_speed = 2.5
max_yaw_rate = 0.5
[heading]
topic = "/imu"
bound = 0.02
[start]
x = [-5.0, 5.0]
y = [-5.0, 5.0]
heading = [6.2, 6.4]
[[ranges]]
topic = "/sonar"
bound = [0.1, 0.02]
max_range = 40.0
q = 1
mount = [1.2, 0.0, 1.5707963267948966]
"""


def pose(t: float | np.ndarray, yaw0: float = 0.0) -> tuple:
    """The true pose at ``t`` (s since T0) on the circle."""
    return (V / W * (np.sin(yaw0 + W * t) - math.sin(yaw0)), V / W * (math.cos(yaw0) - np.cos(yaw0 + W * t)),
            yaw0 + W * t)  # fmt: skip


def laser_robot(
    fmt: str, tmp: Path, n: int = 60, offset_ns: int = 20_000_000
) -> tuple[Path, list[np.ndarray]]:
    """The issue's robot: /odom pose at 4 Hz, /scan (361 beams over 180 deg, range_max 80, NaN and inf
    beams) ``offset_ns`` after each odometry message, /tf_static base_link -> laser 0.78 m ahead."""
    rng = np.random.default_rng(1)
    f = BagFactory(fmt)
    f.tf_static(T0, [("base_link", "laser", 0.78, 0.0, 0.25, 0.0)])
    truths = []
    for k in range(n):
        ns = T0 + k * 250_000_000
        x, y, yaw = pose(k * 0.25)
        f.odom(ns, x, y, math.remainder(yaw, 2 * math.pi), V, 0.0, W)
        truth = rng.uniform(0.5, 30.0, 361)
        r = truth.copy()
        r[rng.integers(0, 361, 20)] = np.nan
        r[::50] = np.inf
        truths.append(np.where(np.isfinite(r), truth, r))
        f.scan(ns + offset_ns, r, -math.pi / 2, math.pi / 360, 80.0)
    return f.write(tmp / f"laser_{fmt}"), truths


@pytest.mark.parametrize("fmt", FORMATS)
def test_the_laser_robot(fmt: str, tmp_path: Path) -> None:
    path, truths = laser_robot(fmt, tmp_path)
    log = read_log(path, parse_bounds(LASER))
    r, n = log.records, 59  # the last scan falls after the last odometry message: dropped
    # 37 kept beams, then the scan's 37 merged readings (one instant, tiling cones: observer.record.scan_merge)
    assert len(r) == n and r.n_sensors == 74 and log.dropped["outside_odometry"] == 1
    assert log.frame_id == "odom" and log.topics == {
        "odometry": "/odom",
        "ranges[0]": "/scan",
        "tf_static": "/tf_static",
    }
    assert (
        log.t0 == T0 * 1e-9
        and np.allclose(np.diff(log.stamps), 0.25)
        and np.allclose(r.t, np.arange(n) * 0.25)
    )
    assert (
        log.mounts["/scan"] == pytest.approx((0.78, 0.0, 0.0)) and log.mount_sources["/scan"] == "tf_static"
    )
    assert np.allclose(r.mount, [0.78, 0.0]) and not r.centred and log.q == 4
    idx = np.round(np.linspace(0, 360, 37)).astype(int)
    inc = float(np.float32(math.pi / 360))
    assert np.allclose(r.alpha[3, :37], float(np.float32(-math.pi / 2)) + idx * inc)
    assert np.allclose(r.gamma[:, :37], inc / 2) and np.median(r.gamma[:, 37:]) >= 4 * inc
    # no compass: the start heading, then nothing
    assert (
        r.heading[0].tolist() == [0.0, 0.0]
        and np.all(r.heading[1:, 0] == -np.inf)
        and np.all(r.heading[1:, 1] == np.inf)
    )
    assert log.x0_lo.tolist() == [0.0, 0.0, 0.0] and log.x0_hi.tolist() == [0.0, 0.0, 0.0]
    # odometry holds the truth, across the yaw's wrap at pi
    assert np.all((r.speed[1:, 0] <= V) & (V <= r.speed[1:, 1])) and np.all(r.lateral == 0.0)
    assert np.all((r.yaw_rate[1:, 0] <= W) & (W <= r.yaw_rate[1:, 1]))
    t = np.arange(n) * 0.25
    x, y, yaw = pose(t)
    dx, dy = np.diff(x), np.diff(y)
    inc_fwd = (np.cos(yaw[:-1]) * dx + np.sin(yaw[:-1]) * dy) / 0.25
    assert np.all((r.mean_velocity[1:, 0, 0] <= inc_fwd) & (inc_fwd <= r.mean_velocity[1:, 0, 1]))
    assert np.array_equal(r.mean_velocity[0], UNMEASURED)
    # readings: bound [0, 0], so only the float32 widening holds the float64 truth
    for k in range(n):
        tr = np.concatenate([truths[k][idx], np.full(37, -1.0)])  # the kept beams (the merged ones below)
        echo = np.isfinite(tr) & (tr < 20.0) & (tr >= 0)
        assert np.all((r.range[k, echo, 0] <= tr[echo]) & (tr[echo] <= r.range[k, echo, 1]))
        assert np.all(r.range[k, echo, 1] > r.range[k, echo, 0])  # widened although the bound is 0
        assert np.all(r.no_echo[k, np.isposinf(tr)]) and np.all(r.r_max[k, np.isposinf(tr)] == 20.0)
        nan = np.isnan(tr)
        assert np.all(r.range[k, nan] == [0.0, np.inf]) and not r.no_echo[k, nan].any()
        far = np.isfinite(tr) & (tr >= 20.0)
        assert (
            np.all(r.no_echo[k, far])
            and np.all(r.r_max[k, far] <= 20.0)
            and np.all(r.r_max[k, far] <= tr[far])
        )
    assert log.dropped["nan_beams"] == sum(int(np.isnan(tt).sum()) for tt in truths[:n])  # every beam read
    # each merged reading holds the nearest truth of the beams it spans, and digs no further than any of them
    a0 = float(np.float32(-math.pi / 2))
    for k in range(n):
        for g in range(37, 74):
            first = round((r.alpha[k, g] - r.gamma[k, g] - a0 + inc / 2) / inc)
            last = round((r.alpha[k, g] + r.gamma[k, g] - a0 - inc / 2) / inc)
            tr = truths[k][first : last + 1]
            assert not np.isnan(tr).any()  # a run of beams that read
            near = min(float(np.min(tr)), 20.0)
            assert r.range[k, g, 0] <= near and (r.no_echo[k, g] or near <= r.range[k, g, 1])
    # asynchronous stamps: 20 ms after the record, slack = 0.02 s times the limits, rounded up
    assert np.all(r.slack[..., 0] >= 0.02 * 1.5) and np.all(r.slack[..., 0] <= 0.02 * 1.5 * (1 + 1e-9))
    assert np.all(r.slack[..., 1] >= 0.02 * 2.0)
    xs, ys, ps = pose(t + 0.02)
    assert np.all(np.abs(xs - x) <= r.slack[:, 0, 0]) and np.all(np.abs(ps - yaw) <= r.slack[:, 0, 1])
    assert log.max_range >= 0.78 + 20.0


def test_the_increment_bound_for_the_pose_source(tmp_path: Path) -> None:
    """``increment`` bounds ``mean_velocity`` (both rows, ``+ err`` for the float of ``dp / dt``); the speed,
    lateral and yaw-rate intervals are as without it."""
    path, _ = laser_robot("mcap", tmp_path, n=12)
    plain = read_log(path, parse_bounds(LASER)).records
    r = read_log(path, parse_bounds(LASER.replace("unicycle", "increment = [0.001, 0.01]\nunicycle"))).records
    for f in ("speed", "lateral", "yaw_rate", "t"):
        assert np.array_equal(getattr(r, f), getattr(plain, f)), f
    x, y, yaw = pose(np.arange(len(r)) * 0.25)  # the truth's increment: the circle's chord, turned back
    dx, dy = np.diff(x), np.diff(y)
    c, s = np.cos(yaw[:-1]), np.sin(yaw[:-1])
    inc = np.stack([c * dx + s * dy, -s * dx + c * dy], 1) / 0.25
    assert np.all(np.abs(inc[:, 1]) > 0.01)  # a turning unicycle's increment has a leftward row
    # without it: the speed bound forward and, for a unicycle, [-max_speed, max_speed] leftward
    assert np.all(plain.mean_velocity[1:, 1] == [-1.5, 1.5])
    width = plain.mean_velocity[1:, 0, 1] - plain.mean_velocity[1:, 0, 0]
    assert np.allclose(width, 2 * (0.02 + 0.05 * inc[:, 0]), rtol=0, atol=1e-12)
    mv = r.mean_velocity[1:]
    half = 0.5 * (mv[..., 1] - mv[..., 0])
    assert np.all((mv[..., 0] <= inc) & (inc <= mv[..., 1]))
    assert np.all(half >= 0.001 + 0.01 * np.abs(inc))  # the bound, plus err (< 1e-12 here)
    assert np.allclose(half, 0.001 + 0.01 * np.abs(inc), rtol=0, atol=1e-12)
    assert np.array_equal(r.mean_velocity[0], UNMEASURED)


def test_a_bare_mcap_file_and_db3_file_read_as_their_folder(tmp_path: Path) -> None:
    for fmt, ext in (("mcap", "mcap"), ("sqlite3", "db3")):
        folder, _ = laser_robot(fmt, tmp_path, n=8)
        (file,) = folder.glob(f"*.{ext}")
        a, b = read_log(folder, parse_bounds(LASER)), read_log(file, parse_bounds(LASER))
        assert a.records == b.records


def test_mounts_compose_along_the_tf_chain_and_fold_the_yaw(tmp_path: Path) -> None:
    f = BagFactory("mcap")
    f.tf_static(
        T0, [("base_link", "mast", 0.2, 0.1, 0.5, math.pi / 2), ("mast", "laser", 0.5, 0.0, 0.0, 0.0)]
    )
    for k in range(4):
        f.odom(T0 + k * 10**8, 0.0, 0.0, 0.0)
        f.scan(T0 + k * 10**8, np.full(3, 2.0), -0.1, 0.1, 10.0)
    log = read_log(f.write(tmp_path / "b"), parse_bounds(LASER.replace("beams = 37\n", "")))
    assert log.mounts["/scan"] == pytest.approx((0.2, 0.6, math.pi / 2))
    assert np.allclose(log.records.alpha[1], math.pi / 2 + np.float32(-0.1) + np.arange(3) * np.float32(0.1))
    assert np.all(log.records.slack == 0.0)  # the scan's stamp is the record's


def auv(tmp: Path, covariance: bool = True) -> Path:
    """DVL twist at 5 Hz, IMU yaw at 20 Hz (13 ms late), sonar Range at 2 Hz; the true yaw starts at 2 pi
    and turns by 8 rad: the compass wraps twice."""
    f = BagFactory("mcap")
    for k in range(101):
        f.twist(T0 + k * 200_000_000, V, 0.0, 0.4, covariance=covariance)
    for k in range(400):
        f.imu(T0 + k * 50_000_000 + 13_000_000, 0.4 * (k * 0.05 + 0.013))
    for k in range(40):
        f.range(T0 + k * 500_000_000 + 1_000_000, 12.0 if k % 3 else math.inf, 0.3, 0.5, 50.0)
    return f.write(tmp / "auv")


@pytest.mark.parametrize("covariance", [True, False])
def test_the_auv_twist_compass_and_sonar(covariance: bool, tmp_path: Path) -> None:
    log = read_log(auv(tmp_path, covariance), parse_bounds(AUV.replace("/dvl", "/dvl")))
    r = log.records
    assert len(r) == 40 and r.n_sensors == 1 and log.frame_id == "start" and log.q == 1
    assert log.mount_sources["/sonar"] == "bounds" and np.allclose(r.mount, [1.2, 0.0])
    assert np.allclose(r.alpha, math.pi / 2) and np.allclose(r.gamma, np.float32(0.3) / 2)
    assert np.all(r.r_max == 40.0)  # min(max_range, the message's 50)
    assert np.all(r.no_echo[1::3] == False) and np.all(r.no_echo[::3, 0])  # noqa: E712
    assert np.all((r.range[1::3, 0, 0] <= 12.0) & (12.0 <= r.range[1::3, 0, 1]))
    assert np.all((r.speed[1:, 0] <= V) & (V <= r.speed[1:, 1])) and np.all(
        (r.lateral[1:, 0] <= 0) & (0 <= r.lateral[1:, 1])
    )
    assert np.all((r.yaw_rate[1:, 0] <= 0.4) & (0.4 <= r.yaw_rate[1:, 1]))
    assert np.all(np.isinf(r.mean_velocity)), "a twist source measures no increment"
    assert log.x0_lo[:2].tolist() == [-5.0, -5.0] and log.x0_hi[:2].tolist() == [5.0, 5.0]
    # the compass, unwrapped on the start box's branch, holds the continuous truth 2 pi + 0.4 t
    truth = 2 * math.pi + 0.4 * (log.stamps - T0 * 1e-9)
    assert np.all((r.heading[:, 0] <= truth) & (truth <= r.heading[:, 1]))
    assert np.all(np.diff(r.heading[:, 0]) > 0) and r.heading[-1, 0] > 4 * math.pi
    assert 6.2 <= log.x0_lo[2] <= log.x0_hi[2] <= 6.4
    assert np.all(r.slack[:, 0, 0] > 0) and np.all(r.slack[:, 0, 0] <= 0.2 * 2.5 + 1e-9)


def test_several_scans_per_record_repeat_the_slots(tmp_path: Path) -> None:
    f = BagFactory("sqlite3")
    for k in range(9):
        f.odom(T0 + k * 250_000_000, V * k * 0.25, 0.0, 0.0, V, 0.0, 0.0)
    for k in range(-1, 20):  # the scan at -0.1 s falls before the odometry: dropped
        f.scan(T0 + k * 100_000_000, np.full(5, 3.0), -0.2, 0.1, 10.0)
    log = read_log(f.write(tmp_path / "b"), parse_bounds(LASER.replace("beams = 37\n", "")))
    r = log.records
    assert r.n_sensors == 15 and log.q == 6 and log.slot_topics == ("/scan",) * 15
    assert log.dropped["outside_odometry"] == 1  # the scan before the first odometry message
    assert np.all(np.isfinite(r.range[0, :, 1])), "stamps 0, 0.1, 0.2 s attach to record 0"
    assert np.array_equal(r.range[1, 10:], np.tile([0.0, np.inf], (5, 1))), "two scans: the third is padding"
    assert r.slack[0, 10, 0] >= 0.2 * 1.5


def test_rep117_values_and_time_increment(tmp_path: Path) -> None:
    f = BagFactory("mcap")
    f.odom(T0, 0.0, 0.0, 0.0)
    f.odom(T0 + 10**9, 0.0, 0.0, 0.0)
    ranges = [math.nan, math.inf, -math.inf, 0.05, 25.0, 5.0, 20.00001]
    f.scan(T0, ranges, 0.0, 0.1, 30.0, range_min=0.1, time_increment=0.001)
    text = LASER.replace("beams = 37\n", "").replace("bound = [0.0, 0.0]", "bound = [0.1, 0.0]")
    log = read_log(f.write(tmp_path / "b"), parse_bounds(text))
    r = log.records
    none = [0.0, np.inf]
    assert (
        r.range[0, 0].tolist() == none and r.range[0, 2].tolist() == none and r.range[0, 3].tolist() == none
    )
    assert r.no_echo[0].tolist() == [False, True, False, False, True, False, True]
    assert r.range[0, 1].tolist() == [20.0, np.inf] and r.r_max[0, 1] == 20.0  # inf: free to max_range
    assert r.r_max[0, 4] == 20.0  # 25 m: free to max_range only
    assert (
        r.r_max[0, 6] < 20.0 and r.r_max[0, 6] <= np.float32(20.00001) - 0.1
    )  # free only to its lower bound
    assert r.range[0, 5, 0] < 4.9 < 5.1 < r.range[0, 5, 1]
    assert log.dropped == {"nan_beams": 1, "too_close": 1, "below_range_min": 1, "outside_odometry": 0}
    assert r.slack[0, 0, 0] == 0.0 and np.all(np.diff(r.slack[0, :, 0]) > 0)  # later beams, later instants
    assert r.slack[0, 6, 0] == pytest.approx(0.006 * 1.5, rel=1e-6)


def test_log_topics(tmp_path: Path) -> None:
    path, _ = laser_robot("bag", tmp_path, n=3)
    assert log_topics(path) == {"/odom": "nav_msgs/msg/Odometry", "/scan": "sensor_msgs/msg/LaserScan",
                                "/tf_static": "tf2_msgs/msg/TFMessage"}  # fmt: skip


# --- one line for each bad input ---------------------------------------------------------------------


def _fails(path: Path, text: str = LASER) -> str:
    with pytest.raises(LogError) as exc:
        read_log(path, parse_bounds(text))
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith(str(path))
    return msg


def test_a_missing_topic_names_the_topics_the_log_has(tmp_path: Path) -> None:
    path, _ = laser_robot("mcap", tmp_path, n=3)
    msg = _fails(path, LASER.replace('"/scan"', '"/laser"'))
    assert (
        "no topic /laser (ranges[0])" in msg
        and "/odom (nav_msgs/Odometry)" in msg
        and "/scan (sensor_msgs/LaserScan)" in msg
    )


def test_a_type_that_does_not_fit_its_role(tmp_path: Path) -> None:
    path, _ = laser_robot("mcap", tmp_path, n=3)
    assert "/scan is sensor_msgs/LaserScan, odometry needs nav_msgs/Odometry or" in _fails(
        path, LASER.replace('"/odom"', '"/scan"')
    )
    dvl = auv(tmp_path)
    assert 'source = "pose" needs nav_msgs/Odometry' in _fails(
        dvl, AUV.replace('source = "twist"', 'source = "pose"')
    )
    assert "/sonar is sensor_msgs/Range, heading needs sensor_msgs/Imu" in _fails(
        dvl, AUV.replace('"/imu"', '"/sonar"')
    )


@pytest.mark.parametrize("topic", ["/odom", "/scan"])
def test_stamps_that_go_backwards(topic: str, tmp_path: Path) -> None:
    f = BagFactory("mcap")
    for k in range(4):
        ns = T0 + k * 10**8 - (2 * 10**8 if k == 3 else 0)  # message 3 is stamped before message 2
        recv = T0 + k * 10**8
        if topic == "/odom":
            f.odom(ns, 0.0, 0.0, 0.0, recv=recv)
            f.scan(recv, np.ones(3), 0.0, 0.1, 10.0)
        else:
            f.odom(recv, 0.0, 0.0, 0.0)
            f.scan(ns, np.ones(3), 0.0, 0.1, 10.0, recv=recv)
    assert f"{topic}: stamps go backwards: 1700000000.100000000 after 1700000000.200000000" in _fails(
        f.write(tmp_path / "b")
    )


def test_a_scan_whose_ranges_disagree_with_its_angles(tmp_path: Path) -> None:
    f = BagFactory("mcap")
    f.odom(T0, 0.0, 0.0, 0.0)
    f.scan(T0, np.ones(100), -math.pi / 2, math.pi / 360, 80.0, angle_max=math.pi / 2)
    assert (
        "/scan at stamp 1700000000.000000000: LaserScan ranges has 100 beams, its angles need 361.0"
        in _fails(f.write(tmp_path / "b"))
    )


def test_an_empty_log(tmp_path: Path) -> None:
    path = BagFactory("mcap").write(tmp_path / "b", connections=(("/odom", "nav_msgs/msg/Odometry"),))
    assert "the log holds no messages" in _fails(path)


def test_a_file_rosbags_cannot_open_and_a_missing_path(tmp_path: Path) -> None:
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not a bag at all")
    assert "rosbags cannot open it as a bag" in _fails(junk)
    (tmp_path / "folder").mkdir()
    assert "rosbags cannot open it as a bag" in _fails(tmp_path / "folder")
    assert _fails(tmp_path / "nope.bag").endswith("nope.bag: no such file or folder")


def test_the_log_is_never_modified(tmp_path: Path) -> None:
    path, _ = laser_robot("sqlite3", tmp_path, n=5)
    before = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in path.iterdir()}
    read_log(path, parse_bounds(LASER))
    assert {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in path.iterdir()} == before


def test_the_record_package_imports_without_rosbags(tmp_path: Path) -> None:
    code = (
        "import sys; sys.modules['rosbags'] = None\n"
        "import digslam.observer, digslam.observer.record as r\n"
        "assert not [m for m in sys.modules if m.startswith('rosbags') and sys.modules[m] is not None]\n"
        "try:\n    r.read_log(sys.argv[1], sys.argv[2])\n"
        "except r.LogError as e:\n    print(e)\n"
    )
    bounds = tmp_path / "b.toml"
    bounds.write_text(LASER)
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "x.mcap"), str(bounds)], capture_output=True,
                         text=True, cwd=tmp_path, check=True)  # fmt: skip
    assert "install the ros extra: pip install 'digslam[ros]'" in out.stdout


def test_an_odometry_pose_as_compass_and_an_imu_without_orientation(tmp_path: Path) -> None:
    f = BagFactory("mcap")
    for k in range(5):
        f.odom(T0 + k * 10**8, 0.0, 0.0, 3.1 + 0.05 * k)  # crosses pi: unwrapped, no [start]: first branch
        f.scan(T0 + k * 10**8, np.ones(3), 0.0, 0.1, 10.0)
    text = LASER.replace("beams = 37\n", "") + '[heading]\ntopic = "/odom"\nbound = 0.01\n'
    log = read_log(f.write(tmp_path / "b"), parse_bounds(text))
    truth = 3.1 + 0.05 * np.arange(5)
    assert np.all((log.records.heading[:, 0] <= truth) & (truth <= log.records.heading[:, 1]))
    g = BagFactory("mcap")
    g.odom(T0, 0.0, 0.0, 0.0)
    g.scan(T0, np.ones(3), 0.0, 0.1, 10.0)
    g.imu(T0, 0.0)
    g.msgs[-1][3].orientation_covariance[0] = -1.0
    text = LASER.replace("beams = 37\n", "") + '[heading]\ntopic = "/imu"\nbound = 0.01\n'
    assert "/imu at stamp 1700000000.000000000: the Imu has no orientation" in _fails(
        g.write(tmp_path / "c"), text
    )


@pytest.mark.parametrize(("beams", "merge", "slots"), [(None, 37, 361 + 37), (None, None, 361), (37, 0, 37),
                                                         (10, 20, 30)])  # fmt: skip
def test_merged_readings_are_counted_apart_from_the_kept_beams(
    tmp_path: Path, beams: int | None, merge: int | None, slots: int
) -> None:
    """``merge`` sets how many merged readings a scan gives, whatever ``beams`` keeps (default: ``beams``
    when below the scan's count); ``q`` counts twice when there are some."""
    path, _ = laser_robot("mcap", tmp_path, n=6)
    text = LASER.replace("beams = 37\n", "" if beams is None else f"beams = {beams}\n")
    text += "" if merge is None else f"merge = {merge}\n"
    log = read_log(path, parse_bounds(text))
    assert log.records.n_sensors == slots and log.q == (4 if slots > 361 or 0 < slots - (beams or 361) else 2)
