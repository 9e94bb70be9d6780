"""Exact sensors (sonar cones, omnidirectional range, odometry, compass) and the step's measurement record.

Range truth is geometric (:func:`geometry.sector_distance` over the edges pre-filtered by bounding boxes),
never a ray fan. The omnidirectional sensor is a cone of half-aperture ``pi``.

Odometry may be given as a hull ``(lo, hi)`` of the true values over a time slice (the env passes the hull
over every physics substep of the step that just ended); the reported interval then contains the whole hull.
``tol`` widens every finite bound by ``tol * max(1, |bound|)`` to cover the simulator's own float64 rounding
(:data:`SIM_TOL`, the same widening as :data:`digslam.envs.missions.SIM_TOL`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from digslam.observer.record import MissionRecord

from . import geometry as geo
from .config import ExploreConfig, NoiseConfig
from .noise import measure, outliers
from .world import World

#: Relative (absolute below magnitude 1) widening of the env's records for the simulator's float rounding.
SIM_TOL = 1e-12

Hull = float | tuple[float, float]


def _hull(v: Hull) -> tuple[float, float]:
    if isinstance(v, tuple):
        return float(v[0]), float(v[1])
    return float(v), float(v)


def _pad(v: np.ndarray, tol: float, up: bool) -> np.ndarray:
    pad = tol * np.maximum(1.0, np.abs(np.where(np.isfinite(v), v, 0.0)))
    return v + pad if up else v - pad


@dataclass(frozen=True, eq=False)
class SensorSuite:
    """Range sensors in the robot frame.

    Attributes:
        alpha: Directions relative to the heading (rad), shape ``(n,)``.
        gamma: Half-apertures in ``(0, pi]``, shape ``(n,)``.
        r_max: Maximum ranges (m), shape ``(n,)``.
    """

    alpha: np.ndarray
    gamma: np.ndarray
    r_max: np.ndarray

    def __post_init__(self) -> None:
        for name in ("alpha", "gamma", "r_max"):
            arr = np.array(getattr(self, name), dtype=np.float64).reshape(-1)
            arr.flags.writeable = False  # shared by every record of the suite
            object.__setattr__(self, name, arr)
        if not (self.alpha.shape == self.gamma.shape == self.r_max.shape):
            raise ValueError("alpha: alpha, gamma and r_max must have the same length")
        if np.any(~(self.gamma > 0) | (self.gamma > math.pi)):
            raise ValueError(f"gamma: cone apertures must be in (0, pi], got {self.gamma.tolist()}")
        if np.any(~(self.r_max > 0)) or not np.all(np.isfinite(self.r_max)):
            raise ValueError(f"r_max: maximum ranges must be finite and > 0, got {self.r_max.tolist()}")

    @classmethod
    def from_config(cls, cfg: ExploreConfig) -> SensorSuite:
        """``n_sonars`` cones evenly spread from the heading, then the omni sensor if enabled."""
        n = cfg.n_sonars
        alpha = [2 * math.pi * k / n for k in range(n)]
        alpha = [a - 2 * math.pi if a > math.pi else a for a in alpha]
        gamma, r_max = [cfg.sonar_gamma] * n, [cfg.sonar_range] * n
        if cfg.omni:
            alpha, gamma, r_max = alpha + [0.0], gamma + [math.pi], r_max + [cfg.omni_range]
        return cls(np.array(alpha), np.array(gamma), np.array(r_max))

    @property
    def n(self) -> int:
        """Number of range sensors."""
        return len(self.alpha)

    def true_ranges(self, world: World, pose: np.ndarray) -> np.ndarray:
        """Exact distance to the nearest obstacle point in each sector; ``inf`` beyond ``r_max`` (no echo)."""
        x, y, th = float(pose[0]), float(pose[1]), float(pose[2])
        edges = geo.edges_near(world.edges, world.bbox, x, y, float(self.r_max.max()))
        d = geo.sector_distance(x, y, th + self.alpha, self.gamma, edges)
        return np.where(d <= self.r_max, d, np.inf)


def measure_step(
    t: float,
    suite: SensorSuite,
    ranges: np.ndarray,
    speed: Hull,
    yaw_rate: Hull,
    heading: float,
    noise: NoiseConfig,
    rng: np.random.Generator,
    tol: float = 0.0,
) -> MissionRecord:
    """Noisy record of one step from the true values (``ranges`` from :meth:`SensorSuite.true_ranges`).

    ``speed`` and ``yaw_rate`` are true values or hulls ``(lo, hi)`` of true values; the interval reported
    for a hull is the noisy interval of its midpoint widened by its half-width, so it contains the whole hull
    (under ``adversarial`` noise the hull touches a bound). The random generator is advanced by the same
    amount whatever the values, so runs stay reproducible.
    """
    (s_lo, s_hi), (w_lo, w_hi) = _hull(speed), _hull(yaw_rate)
    half = np.array([0.5 * (s_hi - s_lo), 0.5 * (w_hi - w_lo)])
    speed, yaw_rate = 0.5 * (s_lo + s_hi), 0.5 * (w_lo + w_hi)
    no_echo = ~np.isfinite(ranges)
    n = suite.n
    truth = np.empty(n + 3)
    truth[:3] = speed, yaw_rate, heading
    truth[3:] = np.where(no_echo, 0.0, ranges)
    bounds = np.empty(n + 3)
    bounds[:3] = noise.speed, noise.yaw_rate, noise.heading
    bounds[3:] = noise.range
    _, lo, hi = measure(truth, bounds, noise, rng)
    out = np.empty((n + 3, 2))  # rows: speed, yaw rate, heading, then the ranges
    out[:, 0], out[:, 1] = lo, hi
    out[:2, 0] -= half
    out[:2, 1] += half
    out[:2, 0] = np.minimum(out[:2, 0], [s_lo, w_lo])  # exact containment despite the rounding of +-half
    out[:2, 1] = np.maximum(out[:2, 1], [s_hi, w_hi])
    rng_out = out[3:]
    rng_out[:, 0] = np.where(no_echo, suite.r_max, np.maximum(lo[3:], 0.0))
    rng_out[no_echo, 1] = np.inf
    if noise.outlier_prob > 0:
        flag, o_lo, o_hi = outliers(n, noise.outlier_prob, suite.r_max, noise.range, rng)
        rng_out[flag, 0], rng_out[flag, 1] = o_lo[flag], o_hi[flag]
    else:
        flag = np.zeros(n, dtype=bool)
    if tol > 0:
        out[:, 0], out[:, 1] = _pad(out[:, 0], tol, False), _pad(out[:, 1], tol, True)
    return MissionRecord(
        t=np.float64(t),
        speed=out[0],
        yaw_rate=out[1],
        heading=out[2],
        alpha=suite.alpha,
        gamma=suite.gamma,
        r_max=suite.r_max,
        range=rng_out,
        no_echo=no_echo & ~flag,
        outlier=flag,
    )
