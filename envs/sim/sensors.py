"""Exact sensors (sonar cones, omnidirectional range, odometry, compass) and the step's measurement record.

Range truth is geometric (the exact sector distance of :mod:`.geometry` over the edges pre-filtered by
bounding boxes), never a ray fan. The omnidirectional sensor is a cone of half-aperture ``pi``.

Odometry may be given as a hull ``(lo, hi)`` of the true values over a time slice (the env passes the hull
over the substeps or pieces of the step that just ended); the reported interval then contains the whole
hull. Odometry is the body-frame velocity ``(v_1, v_2)`` (forward, leftward: a Doppler velocity log whose
two components share the noise bound ``NoiseConfig.speed``) and the yaw rate; a robot that cannot slip
(the unicycle) records ``v_2 = [0, 0]``, the known constraint, unmeasured. Ranges
may likewise be given as rigorous bounds ``(n, 2)`` of the true distances: :meth:`SensorSuite.range_bounds`
computes them from the simulator's pose and its proved pose error (:mod:`.arc_jit`), so the record contains
the exact truth, floating point included, with no tolerance chosen by hand. ``tol`` is an optional extra
widening (``tol * max(1, |bound|)``) for callers whose truths are plain floats. Ranges, noise and widening
run compiled (:mod:`.geometry_jit`, :mod:`.noise_jit`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from digslam.envs.config import ExploreConfig, NoiseConfig
from digslam.envs.sim import geometry_jit as gjit
from digslam.envs.sim.noise import outliers
from digslam.envs.sim.noise_jit import MEASURE_LATERAL, MEASURE_MEAN, MODEL_CODES, RecordModel, record_kernel
from digslam.envs.sim.world import World
from digslam.observer.record.mission import MissionRecord

Hull = float | tuple[float, float]
_ROWS = ("speed", "yaw_rate", "heading")
_TAIL = ("lateral", "mean_velocity[0]", "mean_velocity[1]")
_UNMEASURED = ((-math.inf, math.inf), (-math.inf, math.inf))


def _hull(v: Hull) -> tuple[float, float]:
    if isinstance(v, tuple):
        return float(v[0]), float(v[1])
    return float(v), float(v)


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

    if TYPE_CHECKING:  # set by __post_init__ (the suite is frozen); not dataclass fields at run time
        _reach: float = field(init=False)
        _wit: np.ndarray = field(init=False)
        _k_alpha: np.ndarray = field(init=False)
        _k_gamma: np.ndarray = field(init=False)
        _k_r_max: np.ndarray = field(init=False)
        _k_cones: np.ndarray = field(init=False)
        _centred: np.ndarray = field(init=False)
        _model: tuple[Any, ...] = field(init=False)

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
        object.__setattr__(self, "_reach", float(self.r_max.max()) if self.n else 0.0)
        object.__setattr__(self, "_wit", np.empty((self.n, 2)))  # scratch of true_ranges (witnesses unused)
        # writeable copies for the compiled kernels: numba types read-only arrays apart, and one signature per
        # kernel keeps the first (uncached) compilation short
        for name in ("alpha", "gamma", "r_max"):
            object.__setattr__(self, "_k_" + name, getattr(self, name).copy())
        object.__setattr__(self, "_k_cones", np.stack([self.alpha, self.gamma, self.r_max]))  # sense()
        centred = np.zeros((self.n, 2))  # every record's mount and slack: cones at the centre, read at t
        centred.flags.writeable = False
        object.__setattr__(self, "_centred", centred)
        # record_step's cache per noise configuration: (noise, tol, r_max, the RecordModel's scalars, whether
        # outliers are drawn)
        object.__setattr__(self, "_model", (None, None, None, None, False))

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
        """Exact distance to the nearest obstacle point in each sector; ``inf`` beyond ``r_max`` (no echo).

        One compiled pass over the world's edges (:func:`.geometry_jit.sector_kernel`), pre-filtered by their
        bounding boxes against the largest range.
        """
        d = np.empty(self.n)
        gjit.sector_kernel(float(pose[0]), float(pose[1]), float(pose[2]), self._k_alpha, self._k_gamma,
                           self._k_r_max, world.edges, world.bbox, self._reach, d, self._wit)  # fmt: skip
        return d

    def range_bounds(self, world: World, pose: np.ndarray, pose_error: float) -> np.ndarray:
        """Rigorous bounds ``(n, 2)`` of the true distances from the true pose, whose heading is ``pose[2]``
        exactly and whose position lies within ``pose_error`` of ``pose[:2]`` per coordinate
        (:func:`.geometry_jit.sector_bounds_kernel`; ``inf`` upper bounds where no obstacle point is proved
        inside a cone, lower bounds above ``r_max`` where nothing lies within it)."""
        out = np.empty((self.n, 2))
        gjit.sector_bounds_kernel(float(pose[0]), float(pose[1]), float(pose[2]), self._k_alpha,
                                  self._k_gamma, world.edges, world.bbox, self._reach * (1.0 + 1e-9) + 1e-9,
                                  float(pose_error), out)  # fmt: skip
        return out

    def sense(self, world: World, pose: np.ndarray, pose_error: float) -> tuple[np.ndarray, np.ndarray]:
        """``(true_ranges(world, pose), range_bounds(world, pose, pose_error))``, bit for bit, in one compiled
        pass over the edges (:func:`.geometry_jit.sense_kernel`): what the env computes each step."""
        p = pose
        if not (type(p) is np.ndarray and p.dtype == np.float64 and p.shape == (3,)):
            p = np.array([float(pose[0]), float(pose[1]), float(pose[2])])
        d, out = np.empty(self.n), np.empty((self.n, 2))
        gjit.sense_kernel(p, self._k_cones, world.edges, world.bbox, self._reach, float(pose_error), d, out)
        return d, out


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
    lateral: Hull | None = None,
    mean: tuple[Hull, Hull] | None = None,
) -> MissionRecord:
    """Noisy record of one step from the true values.

    ``ranges`` holds the true distances ``(n,)`` (:meth:`SensorSuite.true_ranges`, ``inf`` for no echo) or
    rigorous bounds ``(n, 2)`` of them (:meth:`SensorSuite.range_bounds`). ``speed`` and ``yaw_rate`` are
    true values or hulls ``(lo, hi)`` of true values; the interval reported for a hull is the noisy interval
    of its midpoint widened by its half-width, so it contains the whole hull (under ``adversarial`` noise
    the hull touches a bound). ``lateral`` is the leftward velocity (value or hull), measured like the speed
    (same noise bound ``noise.speed``, one more draw); None (a unicycle) records ``[0, 0]`` exactly with no
    draw. ``mean`` is the body-frame velocity ``(v̄_1, v̄_2)`` averaged over the step (values or hulls; an
    integrating DVL, same noise bound, two more draws); None records ``[-inf, inf]`` twice (not measured).
    The random generator is advanced by the same amount whatever the values, so runs stay reproducible.
    """
    (s_lo, s_hi), (w_lo, w_hi) = _hull(speed), _hull(yaw_rate)
    l_lo, l_hi = _hull(lateral) if lateral is not None else (0.0, 0.0)
    (a_lo, a_hi), (b_lo, b_hi) = (_hull(mean[0]), _hull(mean[1])) if mean is not None else _UNMEASURED
    hulls = np.array([[s_lo, s_hi], [l_lo, l_hi], [w_lo, w_hi], [a_lo, a_hi], [b_lo, b_hi]])
    measured = (MEASURE_LATERAL if lateral is not None else 0) | (MEASURE_MEAN if mean is not None else 0)
    return record_step(t, suite, ranges, hulls, heading, measured, noise, rng, tol)


def record_step(t: float, suite: SensorSuite, ranges: np.ndarray, hulls: np.ndarray, heading: float,
                measured: int, noise: NoiseConfig, rng: np.random.Generator, tol: float = 0.0
                ) -> MissionRecord:  # fmt: skip
    """:func:`measure_step` with the odometry as one float64 array ``hulls (5, 2)`` (rows: forward speed,
    leftward velocity, yaw rate, then the odometry increment's two components; the order of
    :func:`.dynamics_jit.step_bounds`, whose output the env passes as it is) and ``measured`` the bits
    :data:`~.noise_jit.MEASURE_LATERAL` and :data:`~.noise_jit.MEASURE_MEAN` (unmeasured: the lateral row
    is recorded as it is, the increment as ``[-inf, inf]``); the env's per-step path."""
    n = suite.n
    r = ranges
    if not (type(r) is np.ndarray and r.dtype == np.float64 and r.shape == (n, 2) and r.flags.c_contiguous):
        r = np.asarray(ranges, dtype=np.float64)
        if r.shape == (n,):
            r = np.repeat(r[:, None], 2, axis=1)  # a known truth: [r, r]
        elif r.shape != (n, 2):
            raise ValueError(f"ranges: expected shape ({n},) or ({n}, 2), got {r.shape}")
        r = np.ascontiguousarray(r)
    model = suite._model  # what the kernel reads of the noise, built once per noise configuration
    if model[0] is not noise or model[1] != tol:
        rm = _record_model(suite, noise, tol)
        model = (noise, tol, rm.r_max, rm.scalars(), noise.outlier_prob > 0)
        object.__setattr__(suite, "_model", model)
    _, _, r_max, scalars, draw_outliers = model
    # n + 3 draws, one more for the lateral velocity, two more for the increment (MEASURE_MEAN == 2); the
    # kernel reads each as -1 + 2 u, the value of rng.uniform(-1.0, 1.0) (record_kernel)
    u = rng.random(n + 3 + (measured & MEASURE_LATERAL) + (measured & MEASURE_MEAN))
    if draw_outliers:
        flag, o_lo, o_hi = outliers(n, noise.outlier_prob, suite.r_max, noise.range, rng, noise.max_outliers)
    else:
        flag, o_lo, o_hi = np.zeros(n, dtype=bool), r_max, r_max
    out, no_echo = np.empty((n + 6, 2)), np.empty(n, dtype=bool)
    bad = record_kernel(r, hulls, float(heading), measured, r_max, scalars, u, flag, o_lo, o_hi, out, no_echo)
    if bad >= 0:
        name = _ROWS[bad] if bad < 3 else f"range[{bad - 3}]" if bad < n + 3 else _TAIL[bad - n - 3]
        raise ValueError(f"{name}: interval is not [lo <= hi]: {out[bad].tolist()}")
    t = float(t)
    if not math.isfinite(t):
        raise ValueError("t: times must be finite")
    return _record(t, out, suite, no_echo, flag)


def _record_model(suite: SensorSuite, noise: NoiseConfig, tol: float) -> RecordModel:
    """The :class:`.noise_jit.RecordModel` of ``suite`` under ``noise`` and the widening ``tol``."""
    nz = noise
    bounds = (float(nz.speed), float(nz.yaw_rate), float(nz.heading), float(nz.range))
    return RecordModel(suite._k_r_max, MODEL_CODES[nz.model], float(nz.bias), *bounds, float(tol))


def _record(
    t: float, out: np.ndarray, suite: SensorSuite, no_echo: np.ndarray, flag: np.ndarray
) -> MissionRecord:
    """A :class:`MissionRecord` built from arrays already of the right dtype and shape, whose intervals
    :func:`record_kernel` has checked: the same fields as ``MissionRecord(...)``, without re-running its
    per-field conversions and checks each step (``tests/envs/sim/test_kernels.py`` checks the two agree)."""
    rec = MissionRecord.__new__(MissionRecord)
    rec.__dict__ = {
        "t": np.array(t),  # a float: float64
        "speed": out[0],
        "yaw_rate": out[1],
        "heading": out[2],
        "alpha": suite.alpha,
        "gamma": suite.gamma,
        "r_max": suite.r_max,
        "range": out[3:-3],
        "no_echo": no_echo,
        "outlier": flag,
        "lateral": out[-3],
        "mean_velocity": out[-2:],
        "mount": suite._centred,
        "slack": suite._centred,
    }
    return rec


__all__ = [
    "Hull",
    "SensorSuite",
    "measure_step",
    "record_step",
]
