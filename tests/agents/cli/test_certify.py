"""``digslam certify`` (:mod:`digslam.agents.cli.certify`): a simulated bag certified end to end, the outputs
consistent with each other, bounds ten times too tight reported in one line at the right record, partial
results, the log untouched, and one line for each bad input."""

from __future__ import annotations

import copy
import dataclasses as dc
import json
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags")
pytest.importorskip("matplotlib")

from digslam.agents.cli import certify_run as cr  # noqa: E402
from digslam.agents.cli.certify import certify_log  # noqa: E402
from digslam.agents.cli.main import main  # noqa: E402
from digslam.envs.sim.logs import LaserSpec, SimNoise, simulate_log  # noqa: E402
from digslam.observer.record.bounds import Bound, parse_bounds  # noqa: E402
from digslam.observer.thick.polygons import polygon_area  # noqa: E402

NOISE = SimNoise(speed=0.05, yaw_rate=0.02, heading=0.05, range=(0.1, 0.0))


def _bag(tmp_path: Path, tight: bool) -> tuple[Path, Path, object]:
    """A simulated 8 s log with a compass and a laser 0.5 m ahead, as MCAP, and its bounds file (with
    ``tight``, the odometry's and the laser's bounds ten times too tight)."""
    log = simulate_log(duration=8.0, odom_rate=10.0, laser=LaserSpec(beams=19, mount=(0.5, 0.0, 0.0)),
                       compass=True, noise=NOISE, seed=0)  # fmt: skip
    bag = log.write(tmp_path / "log.mcap", "mcap")
    b = parse_bounds(log.bounds(resolution=0.1))
    if tight:
        f = lambda x: Bound(x.abs / 10, x.rel / 10)  # noqa: E731
        o = b.odometry
        o = dc.replace(o, speed=f(o.speed), lateral=f(o.lateral), yaw_rate=f(o.yaw_rate))
        b = dc.replace(b, odometry=o, ranges=tuple(dc.replace(r, bound=f(r.bound)) for r in b.ranges))
    toml = tmp_path / "bounds.toml"
    toml.write_text(b.to_toml())
    return bag, toml, log


def _fingerprint(p: Path) -> list[tuple[str, bytes, int]]:
    files = sorted(p.rglob("*")) if p.is_dir() else [p]
    return [(str(f), f.read_bytes(), f.stat().st_mtime_ns) for f in files if f.is_file()]


def test_a_simulated_bag_is_certified(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag, toml, _ = _bag(tmp_path, tight=False)
    before, out = _fingerprint(bag), tmp_path / "out"
    assert main(["certify", str(bag), "--bounds", str(toml), "--out", str(out), "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "area certified explored" in text and "widest pose box" in text and str(out) in text
    assert _fingerprint(bag) == before  # the log is never modified
    assert sorted(p.name for p in out.iterdir()) == ["map.png", "raster.npz", "summary.json", "zones.geojson"]
    assert not list(tmp_path.glob(".digslam-*"))  # the staged folder is gone
    s = json.loads((out / "summary.json").read_text())
    assert s["consistent"] and not s["partial"] and s["records"] == s["records_in_log"] > 50
    assert s["area_explored_m2"] > 10 and s["area_free_m2"] >= s["area_certified_m2"] > 10
    cc = s["cross_check"]
    assert cc["online_consistent"] and cc["offline_boxes_inside_online"] and cc["offline_at_least_as_sharp"]
    assert cc["offline_over_online_coverage"] >= 1.0
    zones = json.loads((out / "zones.geojson").read_text())
    areas = {f["properties"]["zone"]: sum(polygon_area([np.array(r) for r in p])
                                          for p in f["geometry"]["coordinates"])
             for f in zones["features"]}  # fmt: skip
    assert areas["clear"] == pytest.approx(s["area_explored_m2"], rel=1e-9)
    assert areas["free"] == pytest.approx(s["area_free_m2"], rel=1e-9)
    assert areas["penumbra"] == pytest.approx(s["area_penumbra_m2"], rel=1e-9)
    r = np.load(out / "raster.npz")
    cell = float(np.prod(r["resolution"]))
    assert r["code"].shape == tuple(r["shape"]) and r["tube_lo"].shape == (s["records"], 2)
    assert float(r["free"].sum()) * cell == pytest.approx(s["area_free_m2"])


def test_bounds_ten_times_too_tight_give_one_line_and_partial_results(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag, toml, _ = _bag(tmp_path, tight=True)
    before, out = _fingerprint(bag), tmp_path / "out"
    assert main(["certify", str(bag), "--bounds", str(toml), "--out", str(out), "--no-progress"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "yaw rate of /odom" in err[0] and "[odometry] yaw_rate" in err[0]
    s = json.loads((out / "summary.json").read_text())
    k, fail = s["records"], s["failure"]
    assert s["partial"] and not s["consistent"] and fail["record"] == k
    assert f"record {k} (stamp {fail['stamp']:.6f}, {fail['seconds']:.2f} s into the log)" in err[0]
    assert (out / "map.png").is_file() and (out / "zones.geojson").is_file()
    assert _fingerprint(bag) == before
    # the right record: the records before it pass the offline observer, with it they do not
    from digslam.observer.record.bag import read_log

    log = read_log(bag, toml)
    assert fail["stamp"] == pytest.approx(float(log.stamps[k]))
    ok = [cr.is_consistent(log.records[: j + 1], log.x0_lo, log.x0_hi, log.q, log.max_range, 0.1)
          for j in (k - 1, k)]  # fmt: skip
    assert ok == [True, False]


@dc.dataclass
class _Log:
    """A :class:`~digslam.observer.record.bag.Log`-like object over a simulated record."""

    records: object
    x0_lo: np.ndarray
    x0_hi: np.ndarray
    stamps: np.ndarray
    t0: float = 1.7e9
    q: int = 0
    max_range: float = 8.0
    frame_id: str = "odom"
    topics: dict = dc.field(
        default_factory=lambda: {"odometry": "/odom", "heading": "/imu", "ranges[0]": "/scan"}
    )
    slot_topics: tuple = ("/scan",) * 10


def test_a_biased_range_topic_is_named(tmp_path: Path) -> None:
    from digslam.envs.config import NoiseConfig
    from digslam.envs.sim.missions import loop_mission
    from digslam.envs.sim.sensors import SensorSuite

    a = np.append(np.linspace(-math.pi / 2, math.pi / 2, 9), math.pi)  # nine beams ahead, one cone behind
    suite = SensorSuite(a, np.append(np.full(9, 0.01), 0.3), np.full(10, 8.0))
    rec, truth = loop_mission(suite=suite, duration=30, dt=0.25, seed=1,
                              noise=NoiseConfig(speed=0.01, yaw_rate=0.005, heading=0.01, range=0.03))  # fmt: skip
    rec = copy.deepcopy(rec)
    echo = ~rec.no_echo[:, 4]
    rec.range[echo, 4] = np.maximum(rec.range[echo, 4] - 1.0, 0.0)  # the front beam reads 1 m short
    x0 = np.array([*truth[0, :2], truth[0, 2]])
    s = certify_log(_Log(rec, x0, x0, 1.7e9 + rec.t), tmp_path / "out")
    fail = s["failure"]
    assert fail is not None and s["partial"] and "/scan" in fail["sensor"] and "[[ranges]]" in fail["key"]
    k = fail["record"]
    assert cr.is_consistent(rec[:k], x0, x0, 0, 8.0, 0.1) and not cr.is_consistent(
        rec[: k + 1], x0, x0, 0, 8.0, 0.1
    )


def test_bad_input_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag, toml, _ = _bag(tmp_path, tight=False)
    bad = tmp_path / "bad.toml"
    bad.write_text('[odometry]\ntopik = "/odom"\n')
    afile = tmp_path / "afile"
    afile.write_text("")
    cases = {
        (str(tmp_path / "nolog.mcap"), str(toml), "o"): "no such log",
        (str(bag), str(tmp_path / "no.toml"), "o"): "no such file",
        (str(bag), str(bad), "o"): "did you mean 'topic'",
        (str(bag), str(toml), str(afile)): "is not a folder",
    }
    for (log, b, out), words in cases.items():
        assert main(["certify", log, "--bounds", b, "--out", str(tmp_path / out), "--no-progress"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("digslam certify: ") and words in err[0], err
