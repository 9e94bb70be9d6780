"""The bounds file: the user's error bounds and premises for a robot's log, read from TOML.

A log's messages are values; the bounds file says how far each may be from the truth (``bound = abs +
rel·|value|``, :class:`Bound`) and states what the data cannot show: the speed and yaw-rate limits that
bridge two stamps, the start box, the outliers ``q`` allowed per record, the mounts when ``/tf_static`` lacks
them and the longest range to trust. :func:`read_bounds` reads a file, :func:`parse_bounds` a text, and
:meth:`Bounds.to_toml` writes one that :func:`parse_bounds` reads back to an equal :class:`Bounds`::

    [odometry]
    topic = "/odom"            # nav_msgs/Odometry, geometry_msgs/TwistStamped or TwistWithCovarianceStamped
    source = "pose"            # or "twist" (the only choice for the twist types); default "pose"
    speed = [0.02, 0.05]       # forward velocity v1: abs, rel (m/s)
    lateral = [0.02, 0.05]     # leftward v2; omitted or "none": |v2| <= max_speed; unicycle = true: v2 = 0
    yaw_rate = [0.005, 0.05]   # rad/s
    increment = [0.001, 0.0]   # optional (source = "pose"): the pose increment's mean velocity, m/s
    max_speed = 2.0            # m/s, premise that bridges stamps
    max_yaw_rate = 2.0         # rad/s
    [heading]                  # optional: sensor_msgs/Imu orientation or nav_msgs/Odometry pose yaw
    topic = "/imu"
    bound = 0.02               # rad (or [abs, rel])
    [start]                    # optional intervals [lo, hi], each key optional
    x = [0.0, 0.0]
    y = [0.0, 0.0]
    heading = [0.0, 0.0]
    [map]
    resolution = 0.1           # m per cell (default 0.1)
    [[ranges]]                 # one table per range topic, at least one
    topic = "/scan"            # sensor_msgs/LaserScan or sensor_msgs/Range
    bound = [0.03, 0.01]       # m
    beams = 37                 # LaserScan: beams kept, evenly spread (default all)
    merge = 37                 # LaserScan: merged readings per scan (default: beams, when below the count)
    aperture = 0.0087          # LaserScan: a beam's half-aperture (rad), default angle_increment / 2
    max_range = 20.0           # trust readings up to here (default the message's range_max)
    q = 2                      # outliers allowed per record on this sensor (default 0)
    mount = [0.78, 0.0, 0.0]   # forward, leftward (m), yaw (rad): used when /tf_static lacks the frame

Every error is a :class:`BoundsError`, one line that names the file: an unknown key (with the nearest known
key), a bad value (the key, what it got, what it needs), a missing required key.

``speed``, ``lateral`` and ``yaw_rate`` bound the instantaneous velocity and yaw rate over each odometry
slice. ``increment`` (optional, ``source = "pose"`` only) bounds the pose increment's mean body velocity
``R(-psi_prev) (p - p_prev) / dt`` (rows forward and leftward, both with this bound): odometry that reports
pose increments knows them far better than the instantaneous velocity within a slice (a wheel slipping on
contact). Without it the increment takes the ``speed`` and ``lateral`` bounds (``[-max_speed, max_speed]``
for a row without one).
"""

from __future__ import annotations

import difflib
import importlib
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any


class BoundsError(ValueError):
    """A bounds file that cannot be used, in one line that names the file."""


@dataclass(frozen=True)
class Bound:
    """An error bound ``abs + rel·|value|`` (both ``>= 0``)."""

    abs: float
    rel: float = 0.0

    def of(self, value: float) -> float:
        """``abs + rel·|value|`` rounded upward (never below the exact real), so ``value ± of(value)`` holds
        every value the claim allows."""
        if self.rel == 0.0:
            return self.abs
        p = math.nextafter(self.rel * abs(value), math.inf)
        return math.nextafter(self.abs + p, math.inf)


@dataclass(frozen=True)
class OdometryBounds:
    """``[odometry]``: the topic, what it is read from, the velocity bounds and the bridging premises."""

    topic: str
    speed: Bound
    yaw_rate: Bound
    max_speed: float
    max_yaw_rate: float
    source: str = "pose"
    lateral: Bound | None = None  # None: |v2| <= max_speed (or 0 with unicycle)
    unicycle: bool = False
    increment: Bound | None = None  # None: the increment's rows take speed and lateral


@dataclass(frozen=True)
class HeadingBounds:
    """``[heading]``: a compass topic and its bound (rad)."""

    topic: str
    bound: Bound


@dataclass(frozen=True)
class RangeBounds:
    """One ``[[ranges]]`` table: a range topic, its bound (m) and its premises."""

    topic: str
    bound: Bound
    beams: int | None = None
    aperture: float | None = None
    max_range: float | None = None
    q: int = 0
    mount: tuple[float, float, float] | None = None
    merge: int | None = None


@dataclass(frozen=True)
class StartBounds:
    """``[start]``: the start box in the odometry frame; ``None`` where the log decides (see the reader)."""

    x: tuple[float, float] | None = None
    y: tuple[float, float] | None = None
    heading: tuple[float, float] | None = None


@dataclass(frozen=True)
class MapBounds:
    """``[map]``: the certified map's cell size (m)."""

    resolution: float = 0.1


@dataclass(frozen=True)
class Bounds:
    """A whole bounds file."""

    odometry: OdometryBounds
    ranges: tuple[RangeBounds, ...]
    heading: HeadingBounds | None = None
    start: StartBounds = field(default_factory=StartBounds)
    map: MapBounds = field(default_factory=MapBounds)

    @property
    def q(self) -> int:
        """Outliers allowed per record, summed over the range sensors."""
        return sum(r.q for r in self.ranges)

    def to_toml(self) -> str:
        """The TOML text of these bounds (:func:`parse_bounds` reads it back to an equal :class:`Bounds`)."""
        o = self.odometry
        lines = ["[odometry]", f"topic = {_s(o.topic)}", f"source = {_s(o.source)}", f"speed = {_b(o.speed)}"]
        if o.lateral is not None:
            lines.append(f"lateral = {_b(o.lateral)}")
        if o.unicycle:
            lines.append("unicycle = true")
        lines.append(f"yaw_rate = {_b(o.yaw_rate)}")
        if o.increment is not None:
            lines.append(f"increment = {_b(o.increment)}")
        lines += [f"max_speed = {o.max_speed!r}", f"max_yaw_rate = {o.max_yaw_rate!r}"]
        if self.heading is not None:
            lines += [
                "",
                "[heading]",
                f"topic = {_s(self.heading.topic)}",
                f"bound = {_b(self.heading.bound)}",
            ]
        start = [
            (k, getattr(self.start, k)) for k in ("x", "y", "heading") if getattr(self.start, k) is not None
        ]
        if start:
            lines += ["", "[start]"] + [f"{k} = [{v[0]!r}, {v[1]!r}]" for k, v in start]
        lines += ["", "[map]", f"resolution = {self.map.resolution!r}"]
        for r in self.ranges:
            lines += ["", "[[ranges]]", f"topic = {_s(r.topic)}", f"bound = {_b(r.bound)}", f"q = {r.q}"]
            for key in ("beams", "merge", "aperture", "max_range"):
                if getattr(r, key) is not None:
                    lines.append(f"{key} = {getattr(r, key)!r}")
            if r.mount is not None:
                lines.append(f"mount = [{r.mount[0]!r}, {r.mount[1]!r}, {r.mount[2]!r}]")
        return "\n".join(lines) + "\n"


def _s(text: str) -> str:
    """A TOML basic string."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _b(b: Bound) -> str:
    return f"[{b.abs!r}, {b.rel!r}]"


_KEYS: dict[str, tuple[str, ...]] = {
    "": ("odometry", "heading", "start", "map", "ranges"),
    "odometry": (
        "topic",
        "source",
        "speed",
        "lateral",
        "unicycle",
        "yaw_rate",
        "increment",
        "max_speed",
        "max_yaw_rate",
    ),
    "heading": ("topic", "bound"),
    "start": ("x", "y", "heading"),
    "map": ("resolution",),
    "ranges": ("topic", "bound", "beams", "merge", "aperture", "max_range", "q", "mount"),
}


def read_bounds(path: str | Path) -> Bounds:
    """The :class:`Bounds` in the TOML file ``path`` (:class:`BoundsError` if missing or bad)."""
    p = Path(path)
    try:
        text = p.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise BoundsError(f"{p}: cannot read the bounds file ({type(exc).__name__}: {exc})") from None
    return parse_bounds(text, str(p))


def parse_bounds(text: str, name: str = "bounds") -> Bounds:
    """The :class:`Bounds` in the TOML ``text``; ``name`` (the file) starts every error line."""
    toml = _toml()
    try:
        data = toml.loads(text)
    except toml.TOMLDecodeError as exc:
        raise BoundsError(f"{name}: not valid TOML ({str(exc).splitlines()[0]})") from None
    return _Parser(name).bounds(data)


def _toml() -> Any:
    """``tomllib`` (Python 3.11+), else its backport ``tomli`` (the same API)."""
    try:
        return importlib.import_module("tomllib")
    except ModuleNotFoundError:  # Python 3.10
        return importlib.import_module("tomli")


def _number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


class _Parser:
    """Checks one file's tables; every failure is a :class:`BoundsError` line that starts with the file."""

    def __init__(self, name: str) -> None:
        self.name = name

    def fail(self, where: str, msg: str) -> BoundsError:
        return BoundsError(f"{self.name}: {where}{msg}")

    def table(self, data: Any, section: str, where: str) -> dict[str, Any]:
        if not isinstance(data, dict):
            raise self.fail(where, f"got {data!r}, needs a table")
        known = _KEYS[section]
        for key in data:
            if key not in known:
                near = difflib.get_close_matches(key, known, n=1, cutoff=0.5)
                hint = f"; did you mean {near[0]!r}?" if near else f" (known: {', '.join(known)})"
                raise self.fail(where, f"unknown key {key!r}{hint}")
        return data

    def need(self, t: dict[str, Any], key: str, where: str) -> Any:
        if key not in t:
            raise self.fail(where, f"missing the required key {key!r}")
        return t[key]

    def bad(self, where: str, key: str, got: Any, needs: str) -> BoundsError:
        return self.fail(where, f"{key}: got {got!r}, needs {needs}")

    def positive(self, t: dict[str, Any], key: str, where: str, default: Any = ...) -> Any:
        if default is not ... and key not in t:
            return default
        v = self.need(t, key, where)
        if not (_number(v) and v > 0):
            raise self.bad(where, key, v, "a finite number > 0")
        return float(v)

    def topic(self, t: dict[str, Any], where: str) -> str:
        v = self.need(t, "topic", where)
        if not isinstance(v, str) or not v:
            raise self.bad(where, "topic", v, 'a topic name such as "/scan"')
        return v

    def bound(self, t: dict[str, Any], key: str, where: str) -> Bound:
        v = self.need(t, key, where)
        if _number(v) and v >= 0:
            return Bound(float(v))
        if isinstance(v, list) and len(v) == 2 and all(_number(x) and x >= 0 for x in v):
            return Bound(float(v[0]), float(v[1]))
        raise self.bad(where, key, v, "[abs, rel] with finite abs, rel >= 0 (or one number: abs)")

    def interval(self, t: dict[str, Any], key: str, where: str) -> tuple[float, float] | None:
        if key not in t:
            return None
        v = t[key]
        if isinstance(v, list) and len(v) == 2 and all(_number(x) for x in v) and v[0] <= v[1]:
            return float(v[0]), float(v[1])
        raise self.bad(where, key, v, "[lo, hi] with finite lo <= hi")

    def bounds(self, data: dict[str, Any]) -> Bounds:
        top = self.table(data, "", "")
        odometry = self.odometry(self.table(self.need(top, "odometry", ""), "odometry", "[odometry] "))
        heading = None
        if "heading" in top:
            h = self.table(top["heading"], "heading", "[heading] ")
            heading = HeadingBounds(self.topic(h, "[heading] "), self.bound(h, "bound", "[heading] "))
        s = self.table(top.get("start", {}), "start", "[start] ")
        start = StartBounds(*(self.interval(s, k, "[start] ") for k in ("x", "y", "heading")))
        m = self.table(top.get("map", {}), "map", "[map] ")
        resolution = self.positive(m, "resolution", "[map] ", 0.1)
        tables = self.need(top, "ranges", "")
        if not isinstance(tables, list) or not tables:
            raise self.bad("", "ranges", tables, "at least one [[ranges]] table")
        ranges = tuple(self.ranges(r, f"[[ranges]] #{i + 1} ") for i, r in enumerate(tables))
        seen = [r.topic for r in ranges]
        if len(set(seen)) < len(seen):
            raise self.bad("", "ranges", seen, "each topic once")
        return Bounds(odometry, ranges, heading, start, MapBounds(resolution))

    def odometry(self, t: dict[str, Any]) -> OdometryBounds:
        w = "[odometry] "
        source = t.get("source", "pose")
        if source not in ("pose", "twist"):
            raise self.bad(w, "source", source, '"pose" or "twist"')
        unicycle = t.get("unicycle", False)
        if not isinstance(unicycle, bool):
            raise self.bad(w, "unicycle", unicycle, "true or false")
        lateral = None if t.get("lateral", "none") == "none" else self.bound(t, "lateral", w)
        if unicycle and lateral is not None:
            raise self.bad(w, "lateral", t["lateral"], 'to be omitted (or "none") with unicycle = true')
        increment = self.bound(t, "increment", w) if "increment" in t else None
        if increment is not None and source != "pose":
            raise self.bad(w, "increment", t["increment"], 'source = "pose" (a twist carries no increment)')
        return OdometryBounds(
            topic=self.topic(t, w), speed=self.bound(t, "speed", w), yaw_rate=self.bound(t, "yaw_rate", w),
            max_speed=self.positive(t, "max_speed", w), max_yaw_rate=self.positive(t, "max_yaw_rate", w),
            source=source, lateral=lateral, unicycle=unicycle, increment=increment,
        )  # fmt: skip

    def ranges(self, data: Any, w: str) -> RangeBounds:
        t = self.table(data, "ranges", w)
        beams, merge = t.get("beams"), t.get("merge")
        if beams is not None and not (isinstance(beams, int) and not isinstance(beams, bool) and beams >= 1):
            raise self.bad(w, "beams", beams, "an integer >= 1")
        if merge is not None and not (isinstance(merge, int) and not isinstance(merge, bool) and merge >= 0):
            raise self.bad(w, "merge", merge, "an integer >= 0 (0: no merged readings)")
        q = t.get("q", 0)
        if not (isinstance(q, int) and not isinstance(q, bool) and q >= 0):
            raise self.bad(w, "q", q, "an integer >= 0")
        aperture = self.positive(t, "aperture", w, None)
        if aperture is not None and aperture > math.pi:
            raise self.bad(w, "aperture", aperture, "a half-aperture in (0, pi]")
        mount = t.get("mount")
        if mount is not None:
            if not (isinstance(mount, list) and len(mount) == 3 and all(_number(x) for x in mount)):
                raise self.bad(w, "mount", mount, "[forward, leftward, yaw] of finite numbers (m, m, rad)")
            mount = (float(mount[0]), float(mount[1]), float(mount[2]))
        return RangeBounds(
            topic=self.topic(t, w), bound=self.bound(t, "bound", w), beams=beams, aperture=aperture,
            max_range=self.positive(t, "max_range", w, None), q=q, mount=mount, merge=merge,
        )  # fmt: skip


__all__ = [
    "Bound",
    "Bounds",
    "BoundsError",
    "HeadingBounds",
    "MapBounds",
    "OdometryBounds",
    "RangeBounds",
    "StartBounds",
    "read_bounds",
    "parse_bounds",
]
