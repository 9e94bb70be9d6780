"""The bounds file a simulated log satisfies (:meth:`~.logs.SimLog.bounds`), derived, then checked on the log.

Every bound is the simulator's noise bound (:class:`~.logs.SimNoise`) plus terms that follow from how the log
is made, plus a pad ``p`` for floating point: ``p`` is the smallest power of ten, at least ``1e-9``, that is
twice every excess over the derived terms found on the log (each reading's rounding, the half-width of its
rigorous truth box: ``~1e-12`` m after a 30-minute mission). With ``b`` the noise bounds, ``dt`` the longest
odometry period, ``v̂ = speed + b_speed`` and ``ĥ = (max_yaw_rate + b_yaw) dt / 2`` (half the largest turn of a
slice):

* ``source = "twist"``: ``speed = b_speed + p``, ``yaw_rate = b_yaw + p``, ``unicycle = true`` (``v2 = 0``
  in the log and in the truth).
* ``source = "pose"``: the pose increment over a slice is the arc of the measured twist, so in the body
  frame at the slice's start it is ``v₁ dt sinc(h)(cos h, sin h)`` with ``h`` half the measured turn. Against
  the true ``(v, 0)``: ``|Δ₁/dt - v| <= b_speed + v̂ 2ĥ²/3`` and ``|Δ₂/dt| <= v̂ ĥ``; against the truth's own
  mean velocity (the same arc of the true values), ``b_speed + v̂ (b_yaw dt/2)(1 + ĥ/3)``. So ``speed = b_speed
  + v̂ (2ĥ²/3 + (b_yaw dt/2)(1 + ĥ/3)) + p``, ``lateral = speed + v̂ ĥ``, ``yaw_rate = b_yaw + p``.
* ``[heading]`` (a compass): ``b_heading + p``.
* ``[[ranges]]``: ``bound = [b_abs + p, b_rel]``; ``max_range = (range_max (1 - b_rel) - bound_abs)``
  rounded down: a beam reads +inf only when its value exceeds ``range_max``, so its truth exceeds that.
* Premises: ``max_speed`` and ``max_yaw_rate`` are the controller's limits times ``1 + 1e-9`` (the true yaw
  rate of a piece exceeds the commanded one by rounding only); the start box is the true start pose, which is
  the first odometry pose exactly.

:func:`check` measures every excess on the log; :func:`bounds_text` raises RuntimeError if a derived bound
fails there (a bug, never a property of the data).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from digslam.observer.record.bounds import (
    Bound,
    Bounds,
    HeadingBounds,
    MapBounds,
    OdometryBounds,
    RangeBounds,
    StartBounds,
)

#: A :class:`~digslam.envs.sim.logs.simulate.SimLog` (not imported: ``SimLog.bounds`` imports this module).
SimLog = Any


def _terms(log: SimLog) -> dict[str, float]:
    """The derived terms (module), without the pad."""
    o = log.streams.odometry
    assert o is not None
    dt = float(np.max(np.diff(o.stamps))) / 1e9 if len(o) > 1 else 0.0
    nz = log.noise
    vh = log.speed_max + nz.speed
    h = (log.yaw_rate_max + nz.yaw_rate) * dt / 2
    pose_speed = nz.speed + vh * (2 * h * h / 3 + (nz.yaw_rate * dt / 2) * (1 + h / 3))
    return {"twist_speed": nz.speed, "pose_speed": pose_speed, "pose_lateral": pose_speed + vh * h,
            "yaw_rate": nz.yaw_rate, "heading": nz.heading, "range": nz.range[0]}  # fmt: skip


def check(log: SimLog) -> dict[str, float]:
    """Each bound's worst excess on the log over its derived term (m, m/s, rad/s or rad; <= 0 where the
    term alone holds): what the pad must cover."""
    o = log.streams.odometry
    assert o is not None
    t = _terms(log)
    dt = np.diff(o.stamps) / 1e9
    out: dict[str, float] = {}
    v, lo, hi = log.speed[1:], log.yaw_rate[1:, 0], log.yaw_rate[1:, 1]
    out["twist_speed"] = float(np.max(np.abs(o.v1[1:] - v), initial=0.0)) - t["twist_speed"]
    out["yaw_rate"] = float(np.max(np.maximum(o.yaw_rate[1:] - lo, hi - o.yaw_rate[1:]), initial=0.0))
    dx, dy, th = np.diff(o.x), np.diff(o.y), o.yaw[:-1]
    d1, d2 = (np.cos(th) * dx + np.sin(th) * dy) / dt, (-np.sin(th) * dx + np.cos(th) * dy) / dt
    # the truth's mean velocity over each slice, its position error carried over the slice's length
    pose, err = log.truth_at(o.stamps)
    tx, ty, tth = np.diff(pose[:, 0]), np.diff(pose[:, 1]), pose[:-1, 2]
    m1, m2 = (np.cos(tth) * tx + np.sin(tth) * ty) / dt, (-np.sin(tth) * tx + np.cos(tth) * ty) / dt
    slack = 2 * (err[1:] + err[:-1]) / dt
    worst = lambda e: float(np.max(e, initial=0.0))  # noqa: E731
    out["pose_speed"] = max(worst(np.abs(d1 - v)), worst(np.abs(d1 - m1) + slack)) - t["pose_speed"]
    out["pose_lateral"] = max(worst(np.abs(d2)), worst(np.abs(d2 - m2) + slack)) - t["pose_lateral"]
    yaw = np.diff(o.yaw) / dt
    out["yaw_rate"] = max(out["yaw_rate"], float(np.max(np.maximum(yaw - lo, hi - yaw), initial=0.0)))
    out["yaw_rate"] -= t["yaw_rate"]
    if log.streams.heading is not None:
        out["heading"] = worst(np.abs(log.streams.heading.yaw - pose[:, 2])) - t["heading"]
    val = log.scan_values
    a, z = log.scan_bounds[..., 0], log.scan_bounds[..., 1]
    ok = np.isfinite(val)
    # the reader widens the stored float32 to its neighbours, which hold this float64 value: the bound must
    # cover the float64 value's distance to the truth box, the rel term taken at the smallest value it may use
    v64 = val[ok]
    low = np.nextafter(v64.astype(np.float32), np.float32(0)).astype(np.float64)
    need = np.maximum(v64 - a[ok], z[ok] - v64) - log.noise.range[1] * low
    out["range"] = float(np.max(need, initial=0.0)) - t["range"]
    return out


def _pad(excess: dict[str, float]) -> float:
    worst = max(excess.values(), default=0.0)
    return 10.0 ** max(-9, math.ceil(math.log10(2 * worst))) if worst > 0 else 1e-9


def bounds_text(log: SimLog, source: str = "pose", resolution: float = 0.1, beams: int | None = None) -> str:
    """The bounds file (TOML, with a comment saying how it was derived) of ``log`` read with ``source``."""
    if source not in ("pose", "twist"):
        raise ValueError(f"source: must be 'pose' or 'twist', got {source!r}")
    excess = check(log)
    p = _pad(excess)
    t = _terms(log)
    o = log.streams.odometry
    assert o is not None
    up = 1.0 + 1e-9
    speed = Bound(t[f"{source}_speed"] + p)
    lateral = Bound(t["pose_lateral"] + p) if source == "pose" else None
    odo = OdometryBounds(o.topic, speed, Bound(t["yaw_rate"] + p), log.speed_max * up, log.yaw_rate_max * up,
                         source, lateral, unicycle=source == "twist")  # fmt: skip
    ab, rel = t["range"] + p, log.noise.range[1]
    r_max = float(np.float32(log.laser.range_max))
    trust = math.nextafter((r_max * (1 - rel) - ab) * (1 - 1e-12), 0.0)
    scan = log.streams.scans[0]
    mount = (float(log.laser.mount[0]), float(log.laser.mount[1]), float(log.laser.mount[2]))
    rb = RangeBounds(scan.topic, Bound(ab, rel), beams=beams, max_range=trust, mount=mount)
    h = log.streams.heading
    heading = HeadingBounds(h.topic, Bound(t["heading"] + p)) if h is not None else None
    x, y, th = (float(c) for c in log.pose[0])
    b = Bounds(odo, (rb,), heading, StartBounds((x, x), (y, y), (th, th)), MapBounds(resolution))
    for key, e in excess.items():  # the derivation must hold on the log itself
        if e > p / 2:
            raise RuntimeError(f"{key}: the simulated log exceeds its derived bound by {e:.3g} (a bug)")
    head = (
        "# bounds of a simulated log (digslam.envs.sim.logs): the noise bounds plus the arc's geometry\n"
        f"# (source = {source}) plus {p:g} for floating point; see digslam.envs.sim.logs.bounds\n"
    )
    return head + b.to_toml()


__all__ = ["bounds_text", "check"]
