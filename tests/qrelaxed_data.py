"""Synthetic episodes for the q-relaxed tests: a unicycle in the square room ``[-4, 4]²``, exact ranges.

No simulator: every record is built here from closed forms, so the data (and the digests of the filter's
results on them) do not move when the simulator does. Each range interval contains the truth: the lower
bound is the distance to the nearest wall minus the noise bound, the upper bound the distance along the
cone's axis plus it (the axis point is a point of the cone on a wall).
"""

from __future__ import annotations

import hashlib
import math

import numpy as np

from digslam.observer.online.observer import OnlineConfig, OnlineDigSlam
from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord

HALF = 4.0  # the room is [-HALF, HALF]²
GRID = Grid((-5.0, -5.0), (5.0, 5.0), (80, 80))
ALPHA = np.array([2 * math.pi * k / 8 - (2 * math.pi if k > 4 else 0.0) for k in range(8)] + [0.0])
GAMMA = np.array([math.pi / 12] * 8 + [math.pi])
R_MAX = np.full(9, 12.0)


def _ray(x: float, y: float, phi: float) -> float:
    """Distance from ``(x, y)`` (inside the room) to its wall along the direction ``phi``."""
    c, s = math.cos(phi), math.sin(phi)
    tx = (HALF - math.copysign(1.0, c) * x) / abs(c) if abs(c) > 1e-12 else math.inf
    ty = (HALF - math.copysign(1.0, s) * y) / abs(s) if abs(s) > 1e-12 else math.inf
    return min(tx, ty)


def square_room_records(seed: int, n: int, b: float = 0.01) -> tuple[list[MissionRecord], np.ndarray]:
    """``n`` single-step records and the true poses ``(n, 3)`` of a drive in the square room."""
    rng = np.random.default_rng(seed)
    x, y, th, dt = 0.0, 0.0, 0.0, 0.1
    recs, poses = [], []
    v = w = 0.0
    for k in range(n):
        if k:
            v = float(rng.uniform(0.3, 0.6))
            w = float(rng.uniform(-1.0, 1.0))
            if max(abs(x), abs(y)) > HALF - 1.2:  # turn towards the centre
                err = math.remainder(math.atan2(-y, -x) - th, 2 * math.pi)
                w = max(-1.0, min(1.0, 3.0 * err))
            d = v * dt * (math.sin(0.5 * w * dt) / (0.5 * w * dt) if w else 1.0)  # exact arc: the chord
            x, y, th = x + d * math.cos(th + 0.5 * w * dt), y + d * math.sin(th + 0.5 * w * dt), th + w * dt
        near = HALF - max(abs(x), abs(y))
        rg = np.empty((9, 2))
        for s in range(9):
            up = near if s == 8 else _ray(x, y, th + ALPHA[s])
            rg[s] = max(near - b, 0.0), up + b
        recs.append(MissionRecord(t=dt * k, speed=[v - b, v + b], yaw_rate=[w - b, w + b],
                                  heading=[th - b, th + b], alpha=ALPHA, gamma=GAMMA, r_max=R_MAX, range=rg,
                                  no_echo=np.zeros(9, bool), outlier=np.zeros(9, bool)))  # fmt: skip
        poses.append((x, y, th))
    return recs, np.array(poses)


def run(recs: list[MissionRecord], config: OnlineConfig | None = None) -> OnlineDigSlam:
    """The online filter over ``recs`` from the exact start."""
    f = OnlineDigSlam(GRID, config)
    f.reset([0.0, 0.0], [0.0, 0.0], recs[0])
    for r in recs[1:]:
        f.update(r)
    return f


def digest(f: OnlineDigSlam) -> str:
    """SHA-256 of the filter's sets, pose box and heading (bit for bit)."""
    h = hashlib.sha256()
    for a in (f.dig.free, f.sensed_sure, f.sensed_maybe, f.pose_lo, f.pose_hi,
              np.array([f.heading_lo, f.heading_hi, f.steps, f.consistent])):  # fmt: skip
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()
