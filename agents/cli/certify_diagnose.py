"""Where and why a log contradicts its bounds: the first failing record and the sensor or premise that broke.

:func:`first_failure` is the first record ``k`` such that the records ``0..k`` are inconsistent with their
bounds under the offline observer (:func:`.certify_run.is_consistent`), by bisection: adding records adds
constraints, so a prefix that fails makes every longer one fail. The online filter's failing step, when it
failed, bounds the search (the offline observer starts from the filter's own sets).

:func:`culprit` then asks which single claim, made less sharp, restores consistency on the records
``0..k``: each candidate's intervals are widened about their centres by 2, 4, 8, ... 256 times (or its
readings dropped), in the order range topics, odometry, compass, reading slack (the ``max_speed`` and
``max_yaw_rate`` premises). A range topic whose removal restores consistency is named first (the smallest
widening factor among them); otherwise the candidate of the smallest factor; the runner-up (the smallest
factor among the others) is named too, since the data alone cannot tell a range bound that is too tight
from an odometry bound that is; the start box when nothing restores consistency. When the heading tube
alone empties, only the yaw rate and the compass are candidates, the factors are those that make the whole
log's heading tube consistent, and the yaw rate is named first (a gyro bound too tight drifts away from
the compass; the compass follows as the runner-up). Nothing
here claims which sensor lies (that needs the truth): it names the bound whose widening the data ask for
least.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from digslam.agents.cli.certify_run import heading_tube, is_consistent
from digslam.observer.record.mission import MissionRecord

#: The widening factors tried, smallest first; ``inf`` drops the readings (or the premise) altogether.
FACTORS = (2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 256.0, np.inf)


def first_failure(check: Callable[[int], bool], n: int, upper: int | None = None) -> int:
    """The smallest ``k`` in ``[1, upper]`` with ``check(k)`` False (records ``0..k`` inconsistent), given
    that ``check(upper)`` is False (``upper`` defaults to ``n - 1``)."""
    lo, hi = 0, n - 1 if upper is None else upper  # check(lo) is True (taken), check(hi) is False
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if check(mid):
            lo = mid
        else:
            hi = mid
    return hi


def widen(iv: np.ndarray, f: float, floor: float = -np.inf) -> np.ndarray:
    """Intervals ``[lo, hi]`` widened ``f`` times about their centres (``inf``: the whole line above
    ``floor``); unbounded ones are kept."""
    lo, hi = iv[..., 0], iv[..., 1]
    finite = np.isfinite(lo) & np.isfinite(hi)
    with np.errstate(invalid="ignore"):
        c, r = np.where(finite, 0.5 * (lo + hi), 0.0), np.where(finite, 0.5 * (hi - lo), 0.0)
        out = np.stack([np.maximum(c - f * r, floor), c + f * r], axis=-1) if np.isfinite(f) else None
    if out is None:
        out = np.stack([np.full_like(lo, floor), np.full_like(hi, np.inf)], axis=-1)
    return np.where(finite[..., None], out, iv)


@dataclass(frozen=True)
class Candidate:
    """A claim that may be too sharp: its name in words, the bounds-file key to widen, and how to widen it
    in a record (a copy, widened ``f`` times)."""

    name: str
    key: str
    apply: Callable[[MissionRecord, float], MissionRecord]


def _ranges(cols: np.ndarray) -> Callable[[MissionRecord, float], MissionRecord]:
    def apply(rec: MissionRecord, f: float) -> MissionRecord:
        out = copy.copy(rec)
        out.range = rec.range.copy()
        if np.isfinite(f):
            echo = ~rec.no_echo[:, cols]
            out.range[:, cols] = np.where(
                echo[..., None], widen(rec.range[:, cols], f, 0.0), rec.range[:, cols]
            )
        else:  # dropped: a "no reading" slot digs nothing and proves no impact
            out.range[:, cols] = (0.0, np.inf)
            out.no_echo = rec.no_echo.copy()
            out.no_echo[:, cols] = False
        return out

    return apply


def _fields(*names: str) -> Callable[[MissionRecord, float], MissionRecord]:
    def apply(rec: MissionRecord, f: float) -> MissionRecord:
        out = copy.copy(rec)
        for name in names:
            if name == "slack":
                out.slack = rec.slack * (f if np.isfinite(f) else 1e6)
            else:
                setattr(out, name, widen(getattr(rec, name), f))
        return out

    return apply


def candidates(rec: MissionRecord, columns: dict[str, np.ndarray], topics: dict[str, str],
               heading_only: bool) -> list[Candidate]:  # fmt: skip
    """The claims to widen, in the order they are named when several restore consistency."""
    odom, imu = topics.get("odometry", "the odometry"), topics.get("heading")
    has_compass = bool(np.isfinite(rec.heading[1:]).any())
    out: list[Candidate] = []
    if heading_only:
        out.append(Candidate(f"the yaw rate of {odom}", "[odometry] yaw_rate", _fields("yaw_rate")))
    else:
        for i, (topic, cols) in enumerate(columns.items()):
            key = f'[[ranges]] #{i + 1} (topic = "{topic}") bound or q'
            out.append(Candidate(f"the ranges of {topic}", key, _ranges(np.asarray(cols))))
        out.append(Candidate(f"the odometry {odom}", "[odometry] speed, lateral and yaw_rate",
                             _fields("speed", "lateral", "yaw_rate", "mean_velocity")))  # fmt: skip
    if has_compass:
        head = _fields("heading")

        def compass(r: MissionRecord, f: float) -> MissionRecord:  # record 0's heading is the start's
            out = head(r, f)
            out.heading[0] = r.heading[0]
            return out

        out.append(Candidate(f"the compass {imu or ''}".rstrip(), "[heading] bound", compass))
    if not heading_only and np.any(rec.slack):
        out.append(Candidate("the stamp bridging", "[odometry] max_speed and max_yaw_rate", _fields("slack")))
    return out


@dataclass(frozen=True)
class Culprit:
    """What broke: the candidate's words, its key, the widening factor that restores consistency (None when
    none does alone), and the runner-up ``(words, key, factor)`` when another candidate restores it too."""

    name: str
    key: str
    factor: float | None
    other: tuple[str, str, float] | None = None


def _factor(ok: Callable[[MissionRecord], bool], rec: MissionRecord, c: Candidate) -> float | None:
    """The smallest factor of :data:`FACTORS` whose widening of ``c`` restores consistency (None if none)."""
    return next((f for f in FACTORS if ok(c.apply(rec, f))), None)


def culprit(rec: MissionRecord, x0_lo: Any, x0_hi: Any, q: int, max_range: float, resolution: float,
            columns: dict[str, np.ndarray], topics: dict[str, str],
            whole: MissionRecord | None = None) -> Culprit:  # fmt: skip
    """The claim whose smallest widening restores consistency on ``rec`` (see the module docstring); when
    the heading tube empties, the factors are those of the ``whole`` log (cheap: the heading tube only)."""
    heading_only = heading_tube(rec).is_empty()
    if heading_only and whole is not None:
        rec = whole
    cands = candidates(rec, columns, topics, heading_only)

    def ok(r: MissionRecord) -> bool:
        if heading_only:
            return not heading_tube(r).is_empty()
        return is_consistent(r, x0_lo, x0_hi, q, max_range, resolution)

    dropped = [c for c in cands if not c.key.startswith("[[ranges]]") or ok(c.apply(rec, np.inf))]
    found = [(f, i, c) for i, c in enumerate(dropped) if (f := _factor(ok, rec, c)) is not None]
    if found:
        ranges = [v for v in found if v[2].key.startswith("[[ranges]]")]
        if heading_only:  # the yaw rate first
            first = found[0]
        else:  # a range topic whose widening (or dropping) restores consistency, else the smallest factor
            first = min(ranges or found, key=lambda v: (v[0], v[1]))
        rest = sorted((v for v in found if v is not first), key=lambda v: (v[0], v[1]))
        other = (rest[0][2].name, rest[0][2].key, rest[0][0]) if rest else None
        return Culprit(first[2].name, first[2].key, first[0], other)
    if not heading_only:
        grow = np.full(2, 1.0)
        lo, hi = np.array(x0_lo, dtype=np.float64), np.array(x0_hi, dtype=np.float64)
        lo[:2], hi[:2] = lo[:2] - grow, hi[:2] + grow
        if is_consistent(rec, lo, hi, q, max_range, resolution):
            return Culprit("the start box", "[start] x and y", None)
    return Culprit("no single sensor or premise (several contradict each other)", "the [odometry] and "
                   "[[ranges]] bounds", None)  # fmt: skip


def _times(f: float) -> str:
    return "dropping them" if not np.isfinite(f) else f"widening its bound {f:g}x"


def describe(c: Culprit) -> str:
    """``c`` in words: what broke and what to widen (and the runner-up, which restores consistency too)."""
    if c.factor is None:
        return f"{c.name} broke; widen {c.key}"
    text = f"{c.name} broke ({_times(c.factor)} restores consistency"
    if c.other is not None:
        text += f"; so does {_times(c.other[2])} on {c.other[0]}, {c.other[1]}"
    return f"{text}); widen {c.key}"


__all__ = ["FACTORS", "Candidate", "Culprit", "candidates", "culprit", "describe", "first_failure", "widen"]
