"""Assembling a log's decoded messages into :class:`~digslam.observer.record.mission.MissionRecord` steps.

The reader (:mod:`.bag`) hands in plain arrays (the odometry's stamps, poses and twists, the compass's yaws,
each range topic's :class:`~digslam.observer.record.bag_messages.RangeMsg` list); :func:`assemble` returns the
records, each interval rounded outward so that it holds every value the bounds file's claims allow:

- **Records**: one per odometry message that has a reading attached, plus the first odometry message. A range
  message is attached to the last odometry message at or before its stamp; one before the first or after the
  last odometry message is dropped (``dropped["outside_odometry"]``). When several messages of one topic
  attach to one odometry message, the record holds them all (that topic's slots repeat, padded with "no
  reading" slots ``[0, inf]``), and ``q`` counts per message: ``Log.q = sum(q · most messages per record)``,
  twice for a scan kept with its merged readings (an outlier beam spoils its slot and its group's).
- **Odometry.** Odometry message ``i`` claims its interval over its own slice ``[t_{i-1}, t_i]``; a record's
  ``speed``, ``lateral`` and ``yaw_rate`` are the hull over the slices it spans (sound: each holds the truth
  on its part). ``source = "pose"``: the values are the pose increment, ``R(-psi_mid) (p_i - p_{i-1}) / dt``
  (``psi_mid`` the mean of the two yaws, the chord's direction on an arc) and ``(psi_i - psi_{i-1}) / dt``;
  ``mean_velocity`` is ``R(-psi_{i-1}) (p_i - p_{i-1}) / dt`` with the ``increment`` bound on both rows
  (without one: the speed and lateral bounds) when the record spans exactly one message,
  :data:`~digslam.observer.record.mission.UNMEASURED` otherwise.
  ``source = "twist"``: the values are the message's body-frame twist, and ``mean_velocity`` is unmeasured.
  ``lateral`` omitted: ``[-max_speed, max_speed]`` (the premise); ``unicycle``: ``[0, 0]`` (without
  ``increment``, the increment's leftward row is then ``[-max_speed, max_speed]``: a turning unicycle's
  increment is not).
  Record 0's odometry bounds nothing the observers use: it is the premise's ``[-max, max]``.
- **Readings** (REP 117): NaN dropped (``dropped["nan_beams"]``), ``-inf`` (too close) and values below
  ``range_min`` give no reading; ``+inf`` proves the cone free up to ``r_max`` (``min(max_range,
  range_max)``: never further than the sensor's own range); a finite ``v >= r_max`` proves it free up to
  ``min(r_max, lo(v))``; any other ``v`` is an echo. A float32 value ``v`` stands for a float64 in
  ``[v⁻, v⁺]`` (its neighbouring float32s), so the interval is ``[v⁻ - b, v⁺ + b]``, ``b = abs + rel·|v⁺|``.
  ``slack`` is ``(gap·max_speed, gap·max_yaw_rate)``, ``gap`` between the beam's instant (``stamp +
  i·time_increment``) and the record's, rounded up. With ``beams`` below a scan's count, the kept beams are
  evenly spread; when the scan's beams were taken at one instant and tile its field of view, the scan's
  free space between them is kept too, as ``merge`` merged readings (default ``beams``; :mod:`.scan_merge`).
- **Heading.** With a compass: each record takes the nearest compass message (either side), ``yaw ±
  (bound + max_yaw_rate·gap)``. Yaw is unwrapped across messages (unique while ``max_yaw_rate·dt + 2·bound <
  pi`` between neighbours, else an error), on the branch nearest the ``[start]`` heading's centre when given.
  Without a compass: ``heading[0]`` is the start heading, ``heading[k] = [-inf, inf]`` for ``k >= 1``.
- **Start box**: ``[start]`` where given; else the first odometry pose exactly (``source = "pose"``) or
  the origin (``"twist"``), and the compass's interval at record 0 for the heading when there is a compass.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .bag_messages import RangeMsg
from .bounds import Bound, Bounds, RangeBounds
from .mission import UNMEASURED, MissionRecord
from .scan_merge import can_merge, merge_beams

_EPS = np.finfo(np.float64).eps


class Sensor(NamedTuple):
    """One range topic: its bounds, its messages in stamp order and its mount ``(forward, leftward, yaw)``."""

    spec: RangeBounds
    msgs: list[RangeMsg]
    mount: tuple[float, float, float]


class Assembled(NamedTuple):
    """What :func:`assemble` returns (the fields of :class:`~digslam.observer.record.bag.Log` it fills)."""

    records: MissionRecord
    stamps_ns: np.ndarray
    x0_lo: np.ndarray
    x0_hi: np.ndarray
    q: int
    max_range: float
    dropped: dict[str, int]
    slot_topics: tuple[str, ...]


def bound_of(b: Bound, v: np.ndarray) -> np.ndarray:
    """:meth:`Bound.of` on an array: ``abs + rel·|v|`` rounded upward."""
    if b.rel == 0.0:
        return np.full(np.shape(v), b.abs)
    return np.nextafter(b.abs + np.nextafter(b.rel * np.abs(v), np.inf), np.inf)


def widen(v: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``[v - w, v + w]`` rounded outward, shape ``v.shape + (2,)``."""
    return np.stack([np.nextafter(v - w, -np.inf), np.nextafter(v + w, np.inf)], axis=-1)


def _up(x: np.ndarray) -> np.ndarray:
    """``x`` rounded up by one float, zeros kept exact."""
    return np.where(x > 0, np.nextafter(x, np.inf), 0.0)


def _unwrap(ns: np.ndarray, yaw: np.ndarray, rate: float, margin: float, what: str) -> np.ndarray:
    """``yaw`` unwrapped, each step the branch nearest the last; ``ValueError`` where a step could turn by
    pi or more (``rate·dt + margin >= pi``) and so the branch is ambiguous."""
    dt = np.diff(ns) * 1e-9
    bad = np.flatnonzero(rate * dt + margin >= math.pi)
    if bad.size:
        k = int(bad[0])
        raise ValueError(
            f"{what}: {dt[k]:.3f} s between stamps {ns[k] * 1e-9:.9f} and {ns[k + 1] * 1e-9:.9f}: "
            "at max_yaw_rate the yaw could turn by pi or more, so it cannot be unwrapped"
        )
    return np.unwrap(yaw)


def slice_odometry(b: Bounds, ns: np.ndarray, pose: np.ndarray, twist: np.ndarray) -> tuple[np.ndarray, ...]:
    """Per-slice intervals (row ``i`` for slice ``[t_{i-1}, t_i]``, row 0 unused): speed, lateral, yaw_rate
    and the increment ``mean_velocity`` (``(n, 2, 2)``; NaN rows for the twist source)."""
    o = b.odometry
    dt = np.diff(ns).astype(np.float64) * 1e-9
    n = len(ns)
    if o.source == "pose":
        psi = _unwrap(ns, pose[:, 2], o.max_yaw_rate, 0.0, f"{o.topic}: odometry yaw")
        dp = np.diff(pose[:, :2], axis=0)
        err = 8 * _EPS * (np.abs(pose[1:, :2]) + np.abs(pose[:-1, :2])).sum(axis=1) / dt  # float64 of dp / dt

        def body(angle: np.ndarray) -> np.ndarray:
            c, s = np.cos(angle), np.sin(angle)
            return np.stack([c * dp[:, 0] + s * dp[:, 1], -s * dp[:, 0] + c * dp[:, 1]], axis=1) / dt[:, None]

        m, d = body(0.5 * (psi[1:] + psi[:-1])), body(psi[:-1])
        v = np.column_stack([m, np.diff(psi) / dt])
        err3 = np.column_stack([err, err, 8 * _EPS * (np.abs(psi[1:]) + np.abs(psi[:-1])) / dt])
    else:
        v, err3 = twist[1:], np.zeros((n - 1, 3))
        d = np.full((n - 1, 2), np.nan)
    out = [np.zeros((n, 2)) for _ in range(3)]
    for j, bound in enumerate((o.speed, o.lateral, o.yaw_rate)):
        if bound is None:
            out[j][1:] = [0.0, 0.0] if o.unicycle else [-o.max_speed, o.max_speed]
        else:
            w = v[:, j]
            out[j][1:] = widen(w, np.nextafter(bound_of(bound, w) + err3[:, j], np.inf))
    mean = np.full((n, 2, 2), np.nan)
    if o.source == "pose":
        for j, bound in enumerate((o.speed, o.lateral) if o.increment is None else (o.increment,) * 2):
            if bound is not None:
                mean[1:, j] = widen(d[:, j], np.nextafter(bound_of(bound, d[:, j]) + err, np.inf))
            else:  # the increment turns with the robot: never [0, 0], even for a unicycle
                mean[1:, j] = [-o.max_speed, o.max_speed]
    return out[0], out[1], out[2], mean


def _kept(spec: RangeBounds, n: int) -> np.ndarray:
    """The beams of an ``n``-beam message kept as they are: ``beams`` of them evenly spread, or all."""
    if spec.beams is None or spec.beams >= n:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, spec.beams)).astype(np.int64))


def _groups(spec: RangeBounds, msg: RangeMsg) -> int:
    """How many merged readings a message gives (:mod:`.scan_merge`): ``merge`` (default ``beams`` when
    that is below the message's count, else none), and none when its beams cannot be merged
    (:func:`.scan_merge.can_merge`)."""
    n = len(msg.ranges)
    want = spec.merge if spec.merge is not None else (spec.beams if spec.beams is not None and spec.beams < n
                                                      else 0)  # fmt: skip
    gamma = spec.aperture if spec.aperture is not None else msg.gamma
    if not want or n < 2 or not can_merge(msg.angle_increment, gamma, msg.time_increment):
        return 0
    return min(want, n)


def _width(s: Sensor, msg: RangeMsg) -> int:
    """How many slots one message of ``s`` fills: the kept beams, then its merged readings."""
    return len(_kept(s.spec, len(msg.ranges))) + _groups(s.spec, msg)


def _slots(
    s: Sensor, msg: RangeMsg, t_rec: int, b: Bounds, dropped: dict[str, int]
) -> tuple[np.ndarray, ...]:
    """One message's kept beams: alpha, gamma, r_max, range (n, 2), no_echo, slack (n, 2)."""
    spec, n = s.spec, len(msg.ranges)
    gamma = spec.aperture if spec.aperture is not None else msg.gamma
    keep, groups = _kept(spec, n), _groups(spec, msg)
    idx = np.arange(n) if groups else keep  # merging reads every beam, then keeps some and merges all
    sensor_max = msg.range_max if math.isfinite(msg.range_max) and msg.range_max > 0 else math.inf
    eff = min(spec.max_range if spec.max_range is not None else math.inf, sensor_max)
    if not math.isfinite(eff):
        raise ValueError(f"{spec.topic}: the message's range_max is {msg.range_max}: set max_range")
    if not 0 < gamma <= math.pi:
        raise ValueError(f"{spec.topic}: a beam's half-aperture is {gamma}: set aperture in (0, pi]")
    v32 = msg.ranges[idx]
    v = v32.astype(np.float64)
    with np.errstate(invalid="ignore", over="ignore"):
        a = np.nextafter(v32, np.float32(-np.inf)).astype(np.float64)
        c = np.nextafter(v32, np.float32(np.inf)).astype(np.float64)
        bnd = bound_of(spec.bound, np.maximum(np.abs(a), np.abs(c)))
        lo = np.maximum(np.nextafter(a - bnd, -np.inf), 0.0)
        hi = np.nextafter(c + bnd, np.inf)
    finite = np.isfinite(v)
    below = finite & (v < msg.range_min)
    far = finite & ~below & (v >= eff)
    echo = finite & ~below & ~far
    free_to = np.where(far, np.minimum(eff, lo), eff)
    no_echo = (v == np.inf) | (far & (free_to > 0))
    dropped["nan_beams"] += int(np.isnan(v).sum())
    dropped["too_close"] += int((v == -np.inf).sum())
    dropped["below_range_min"] += int(below.sum())
    r_max = np.where(no_echo, free_to, eff)
    rng = np.where(
        echo[:, None], np.stack([lo, hi], axis=1), np.stack([r_max, np.full_like(v, np.inf)], axis=1)
    )
    rng[~(echo | no_echo)] = [0.0, np.inf]
    gap = np.abs((msg.ns - t_rec) * 1e-9 + idx * msg.time_increment) * (1 + 4 * _EPS)
    slack = np.stack([_up(gap * b.odometry.max_speed), _up(gap * b.odometry.max_yaw_rate)], axis=1)
    alpha = s.mount[2] + msg.angle_min + idx * msg.angle_increment
    if not groups:
        return alpha, np.full(len(idx), gamma), r_max, rng, no_echo, slack
    reading = echo | no_echo
    m_a, m_g, m_r, m_y, m_ne = merge_beams(alpha, gamma, rng, no_echo, r_max, reading, groups)
    return (
        np.concatenate([alpha[keep], m_a]),
        np.concatenate([np.full(len(keep), gamma), m_g]),
        np.concatenate([r_max[keep], m_r]),
        np.concatenate([rng[keep], m_y]),
        np.concatenate([no_echo[keep], m_ne]),
        np.concatenate([slack[keep], np.repeat(slack[:1], groups, axis=0)]),  # one instant: one slack
    )


def _heading(b: Bounds, t: np.ndarray, compass: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """Each record's compass interval (the nearest message, widened by ``max_yaw_rate·gap``)."""
    assert b.heading is not None
    ns, yaw = compass
    rate, bound = b.odometry.max_yaw_rate, b.heading.bound
    u = _unwrap(ns, yaw, rate, 2 * bound.of(math.pi), f"{b.heading.topic}: heading")
    after = np.minimum(np.searchsorted(ns, t), len(ns) - 1)
    before = np.maximum(after - 1, 0)
    j = np.where(np.abs(t - ns[before]) <= np.abs(ns[after] - t), before, after)  # the nearest, either side
    if b.start.heading is not None:
        centre = 0.5 * (b.start.heading[0] + b.start.heading[1])
        u = u + 2 * math.pi * round((centre - u[j[0]]) / (2 * math.pi))
    gap = np.abs(t - ns[j]) * 1e-9 * (1 + 4 * _EPS)
    y = u[j]
    return widen(y, np.nextafter(bound_of(bound, y) + _up(gap * rate), np.inf))


def assemble(b: Bounds, ns: np.ndarray, pose: np.ndarray, twist: np.ndarray,
             compass: tuple[np.ndarray, np.ndarray] | None, sensors: list[Sensor]) -> Assembled:  # fmt: skip
    """The records of a log (see the module's docstring); ``ns`` the odometry's increasing stamps (int ns),
    ``pose`` its ``(x, y, yaw)`` rows, ``twist`` its ``(v1, v2, w)`` rows."""
    o, dropped = b.odometry, {"nan_beams": 0, "too_close": 0, "below_range_min": 0, "outside_odometry": 0}
    groups: list[dict[int, list[RangeMsg]]] = []
    for s in sensors:
        g: dict[int, list[RangeMsg]] = {}
        for msg in s.msgs:
            if msg.ns < ns[0] or msg.ns > ns[-1]:
                dropped["outside_odometry"] += 1
                continue
            g.setdefault(int(np.searchsorted(ns, msg.ns, side="right")) - 1, []).append(msg)
        groups.append(g)
    rec = np.array(sorted({0}.union(*[g.keys() for g in groups])), dtype=np.int64)
    K, t_rec = len(rec), ns[rec]
    # slots: sensor s has `per` messages of `width` beams per record
    widths = [max([_width(s, m) for m in s.msgs] or [1]) for s in sensors]
    pers = [max([len(v) for v in g.values()] or [1]) for g in groups]
    N = sum(w * p for w, p in zip(widths, pers))
    alpha, gamma, r_max = np.zeros((K, N)), np.full((K, N), math.pi), np.ones((K, N))
    rng, no_echo = np.tile([0.0, np.inf], (K, N, 1)), np.zeros((K, N), bool)
    mount, slack = np.zeros((K, N, 2)), np.zeros((K, N, 2))
    slot_topics: list[str] = []
    off = 0
    row = {int(i): k for k, i in enumerate(rec)}
    for s, g, w, p in zip(sensors, groups, widths, pers):
        mount[:, off : off + w * p] = s.mount[:2]
        slot_topics += [s.spec.topic] * (w * p)
        for i, msgs in g.items():
            k = row[i]
            for j, msg in enumerate(msgs):
                a, gm, rm, rg, ne, sl = _slots(s, msg, int(ns[i]), b, dropped)
                sl_ = slice(off + j * w, off + j * w + len(a))
                alpha[k, sl_], gamma[k, sl_], r_max[k, sl_], rng[k, sl_], no_echo[k, sl_], slack[k, sl_] = (
                    a, gm, rm, rg, ne, sl)  # fmt: skip
        off += w * p
    speed, lateral, yaw_rate, mean = slice_odometry(b, ns, pose, twist)
    prem = {0: o.max_speed, 1: o.max_speed, 2: o.max_yaw_rate}
    odo = []
    for j, arr in enumerate((speed, lateral, yaw_rate)):
        out = np.empty((K, 2))
        out[0] = [0.0, 0.0] if (j == 1 and o.unicycle) else [-prem[j], prem[j]]
        if K > 1:
            out[1:, 0] = np.minimum.reduceat(arr[: rec[-1] + 1, 0], rec[:-1] + 1)
            out[1:, 1] = np.maximum.reduceat(arr[: rec[-1] + 1, 1], rec[:-1] + 1)
        odo.append(out)
    mv = np.broadcast_to(UNMEASURED, (K, 2, 2)).copy()
    one = np.flatnonzero(np.diff(rec) == 1) + 1
    if o.source == "pose" and one.size:
        mv[one] = mean[rec[one]]
    x0 = [list(b.start.x or ((pose[0, 0],) * 2 if o.source == "pose" else (0.0, 0.0))),
          list(b.start.y or ((pose[0, 1],) * 2 if o.source == "pose" else (0.0, 0.0)))]  # fmt: skip
    heading = np.tile([-np.inf, np.inf], (K, 1))
    if compass is not None:
        heading = _heading(b, t_rec, compass)
        if b.start.heading is not None:
            lo, hi = max(heading[0, 0], b.start.heading[0]), min(heading[0, 1], b.start.heading[1])
            if lo > hi:
                raise ValueError(f"[start] heading {list(b.start.heading)} misses the compass's "
                                 f"{heading[0].tolist()} at the first record")  # fmt: skip
            heading[0] = [lo, hi]
    else:
        heading[0] = b.start.heading or ((pose[0, 2],) * 2 if o.source == "pose" else (0.0, 0.0))
    x0.append(list(heading[0]))
    box = np.array(x0, dtype=np.float64)
    records = MissionRecord(
        t=(t_rec - ns[0]) * 1e-9, speed=odo[0], lateral=odo[1], yaw_rate=odo[2], heading=heading,
        alpha=alpha, gamma=gamma, r_max=r_max, range=rng, no_echo=no_echo, outlier=np.zeros((K, N), bool),
        mean_velocity=mv, mount=mount, slack=slack,
    )  # fmt: skip
    reading = no_echo | np.isfinite(rng[..., 1])
    far = np.where(np.isfinite(rng[..., 1]), np.maximum(r_max, rng[..., 1]), r_max)
    reach = np.hypot(mount[..., 0], mount[..., 1]) + far + math.sqrt(2) * slack[..., 0]
    max_range = float(np.nextafter(reach[reading].max() if reading.any() else r_max.max(), np.inf))
    # an outlier beam spoils its own slot and its group's merged reading: q counts twice on merged scans
    q = sum(s.spec.q * p * (2 if any(_groups(s.spec, m) for m in s.msgs) else 1)
            for s, p in zip(sensors, pers))  # fmt: skip
    return Assembled(records, t_rec, box[:, 0].copy(), box[:, 1].copy(), q, max_range, dropped,
                     tuple(slot_topics))  # fmt: skip


__all__ = ["Assembled", "Sensor", "assemble", "bound_of", "slice_odometry", "widen"]
