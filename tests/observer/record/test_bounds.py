"""The bounds file (digslam.observer.record.bounds): keys, defaults, round trip, one-line errors."""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.observer.record import Bound, Bounds, BoundsError, parse_bounds, read_bounds

EXAMPLES = Path(__file__).resolve().parents[3] / "examples" / "bounds"

MINIMAL = """
[odometry]
topic = "/odom"
speed = [0.02, 0.05]
yaw_rate = [0.005, 0.05]
max_speed = 2.0
max_yaw_rate = 2.0
[[ranges]]
topic = "/scan"
bound = [0.03, 0.01]
"""


def test_the_issue_keys_read_with_their_defaults() -> None:
    b = parse_bounds(
        MINIMAL + 'beams = 37\nmax_range = 20.0\nq = 2\n[heading]\ntopic = "/imu"\nbound = 0.02\n'
    )
    assert b.odometry.source == "pose" and b.odometry.lateral is None and not b.odometry.unicycle
    assert b.odometry.speed == Bound(0.02, 0.05) and b.odometry.max_yaw_rate == 2.0
    assert b.heading is not None and b.heading.bound == Bound(0.02, 0.0)
    r = b.ranges[0]
    assert (r.beams, r.max_range, r.q, r.aperture, r.mount) == (37, 20.0, 2, None, None)
    assert b.map.resolution == 0.1 and b.start.x is None and b.q == 2


def test_q_sums_over_the_sensors() -> None:
    text = MINIMAL + 'q = 2\n[[ranges]]\ntopic = "/sonar"\nbound = 0.1\nq = 3\n'
    assert parse_bounds(text).q == 5


@pytest.mark.parametrize("name", ["laser.toml", "auv.toml"])
def test_the_examples_read_and_round_trip(name: str) -> None:
    b = read_bounds(EXAMPLES / name)
    assert isinstance(b, Bounds)
    assert parse_bounds(b.to_toml()) == b


def test_every_key_round_trips() -> None:
    text = MINIMAL.replace("speed", 'source = "twist"\nlateral = [0.1, 0.2]\nspeed', 1) + (
        "beams = 5\nmerge = 3\naperture = 0.01\nmax_range = 7.5\nq = 1\nmount = [0.5, -0.25, 0.1]\n"
        '[heading]\ntopic = "/imu"\nbound = [0.01, 0.001]\n'
        "[start]\nx = [-1.0, 1.0]\ny = [0.5, 0.75]\nheading = [3.0, 3.25]\n[map]\nresolution = 0.05\n"
    )
    b = parse_bounds(text)
    assert b.odometry.lateral == Bound(0.1, 0.2) and b.start.heading == (3.0, 3.25) and b.ranges[0].merge == 3
    assert parse_bounds(b.to_toml()) == b


def test_the_increment_key_reads_and_round_trips() -> None:
    assert parse_bounds(MINIMAL).odometry.increment is None  # default: the speed and lateral bounds
    b = parse_bounds(MINIMAL.replace("speed", "increment = [0.001, 0.01]\nspeed", 1))
    assert b.odometry.increment == Bound(0.001, 0.01) and b.odometry.source == "pose"
    assert "increment = [0.001, 0.01]" in b.to_toml() and parse_bounds(b.to_toml()) == b
    one = parse_bounds(
        MINIMAL.replace("speed", 'source = "pose"\nunicycle = true\nincrement = 0.002\nspeed', 1)
    )
    assert one.odometry.increment == Bound(0.002, 0.0) and parse_bounds(one.to_toml()) == one
    assert "increment" not in parse_bounds(MINIMAL).to_toml()


def test_unicycle_and_lateral_none() -> None:
    assert parse_bounds(MINIMAL + "").odometry.lateral is None
    b = parse_bounds(MINIMAL.replace("speed", 'lateral = "none"\nunicycle = true\nspeed', 1))
    assert b.odometry.unicycle and b.odometry.lateral is None and parse_bounds(b.to_toml()) == b


def _error(text: str) -> str:
    with pytest.raises(BoundsError) as exc:
        parse_bounds(text, "b.toml")
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("b.toml: ")
    return msg


def test_an_unknown_key_names_the_nearest() -> None:
    assert "unknown key 'spead'; did you mean 'speed'?" in _error(MINIMAL.replace("speed", "spead"))
    assert "did you mean 'max_range'?" in _error(MINIMAL + "max_rang = 3.0\n")
    assert "did you mean 'odometry'?" in _error(MINIMAL.replace("[odometry]", "[odometri]"))
    assert "unknown key 'zzz' (known:" in _error(MINIMAL + "zzz = 1\n")


@pytest.mark.parametrize(
    ("old", "new", "says"),
    [
        ("speed = [0.02, 0.05]", "speed = [-0.02, 0.05]", "speed: got [-0.02, 0.05], needs [abs, rel]"),
        ("speed = [0.02, 0.05]", 'speed = "fast"', "speed: got 'fast', needs [abs, rel]"),
        ("max_speed = 2.0", "max_speed = 0", "max_speed: got 0, needs a finite number > 0"),
        ("max_speed = 2.0", "max_speed = inf", "max_speed: got inf, needs a finite number > 0"),
        ("max_yaw_rate = 2.0", "max_yaw_rate = true", "max_yaw_rate: got True, needs a finite number > 0"),
        ('topic = "/odom"', "topic = 3", "topic: got 3, needs a topic name"),
        ("bound = [0.03, 0.01]", "bound = [0.03, 0.01]\nbeams = 0", "beams: got 0, needs an integer >= 1"),
        ("bound = [0.03, 0.01]", "bound = [0.03, 0.01]\nq = 1.5", "q: got 1.5, needs an integer >= 0"),
        (
            "bound = [0.03, 0.01]",
            "bound = [0.03, 0.01]\naperture = 4.0",
            "aperture: got 4.0, needs a half-aperture",
        ),
        ("bound = [0.03, 0.01]", "bound = [0.03, 0.01]\nmount = [1, 2]", "mount: got [1, 2], needs [forward"),
        (
            'topic = "/odom"',
            'topic = "/odom"\nsource = "imu"',
            'source: got \'imu\', needs "pose" or "twist"',
        ),
        (
            'topic = "/odom"',
            'topic = "/odom"\nunicycle = true\nlateral = [0.1, 0.0]',
            "lateral: got [0.1, 0.0]",
        ),
        (
            'topic = "/odom"',
            'topic = "/odom"\nincrement = [-0.001, 0.0]',
            "increment: got [-0.001, 0.0], needs [abs",
        ),
        (
            'topic = "/odom"',
            'topic = "/odom"\nincrement = [0.1, 0.2, 0.3]',
            "increment: got [0.1, 0.2, 0.3], needs",
        ),
        (
            'topic = "/odom"',
            'topic = "/odom"\nincrement = "tight"',
            "increment: got 'tight', needs [abs, rel]",
        ),
        (
            'topic = "/odom"',
            'topic = "/odom"\nsource = "twist"\nincrement = [0.001, 0.0]',
            'increment: got [0.001, 0.0], needs source = "pose" (a twist carries no increment)',
        ),
        (
            "[[ranges]]",
            "[[ranges]]\nmerge = -1",
            "merge: got -1, needs an integer >= 0",
        ),
        (
            'topic = "/odom"',
            'topic = "/odom"\nincrements = 0.1',
            "unknown key 'increments'; did you mean 'increment'?",
        ),
    ],
)
def test_a_bad_value_says_key_got_and_needs(old: str, new: str, says: str) -> None:
    assert says in _error(MINIMAL.replace(old, new, 1))


def test_bad_start_and_map_values() -> None:
    assert "[start] x: got [1.0, 0.0], needs [lo, hi]" in _error(MINIMAL + "[start]\nx = [1.0, 0.0]\n")
    assert "[map] resolution: got -1.0" in _error(MINIMAL + "[map]\nresolution = -1.0\n")
    assert "ranges: got ['/scan', '/scan'], needs each topic once" in _error(
        MINIMAL + '[[ranges]]\ntopic = "/scan"\nbound = 0.1\n'
    )


@pytest.mark.parametrize("key", ["topic", "speed", "yaw_rate", "max_speed", "max_yaw_rate"])
def test_a_missing_required_key_is_named(key: str) -> None:
    text = "\n".join(line for line in MINIMAL.splitlines() if not line.startswith(key + " "))
    assert f"[odometry] missing the required key {key!r}" in _error(text)


def test_missing_tables_and_bad_toml() -> None:
    assert "missing the required key 'odometry'" in _error('[[ranges]]\ntopic = "/s"\nbound = 0.1\n')
    assert "missing the required key 'ranges'" in _error(MINIMAL.split("[[ranges]]")[0])
    assert "[[ranges]] #1 missing the required key 'bound'" in _error(
        MINIMAL.replace("bound = [0.03, 0.01]", "")
    )
    assert "not valid TOML" in _error("[odometry\n")


def test_read_bounds_names_a_missing_file(tmp_path: Path) -> None:
    with pytest.raises(BoundsError, match="nope.toml: cannot read the bounds file"):
        read_bounds(tmp_path / "nope.toml")


@settings(max_examples=200, deadline=None)
@given(
    st.floats(0, 10, allow_nan=False),
    st.floats(0, 1, allow_nan=False),
    st.floats(-1e6, 1e6, allow_nan=False),
)
def test_bound_of_is_never_below_the_exact_real(a: float, r: float, v: float) -> None:
    got = Bound(a, r).of(v)
    assert Fraction(got) >= Fraction(a) + Fraction(r) * abs(Fraction(v))
    assert got <= (a + r * abs(v)) * (1 + 1e-12) + 1e-300 or math.isclose(got, a + r * abs(v))
