"""Compiled kernels of the bounded noise (:mod:`.noise`) and of the step's record (:mod:`.sensors`).

The random draws stay in numpy (``rng.uniform``, or ``rng.random`` mapped to the same values, in a fixed
order, so runs are reproducible);
the kernels turn them into measured values and intervals. Every interval contains the truth exactly:

* ``uniform`` / ``biased``: ``[m - b, m + b]`` widened by 4 ulps of ``max(|m|, b)``;
* ``adversarial``: the truth is one bound, the other is ``truth ± 2 b`` widened by 4 ulps of
  ``max(|truth|, 2 b)``.

``4 * np.spacing(s)`` for ``s >= 0`` is computed as ``4 * (nextafter(s, inf) - s)``, the same value.

Example (adversarial noise: the truth is a bound):
    >>> import numpy as np
    >>> m, lo, hi = np.empty(2), np.empty(2), np.empty(2)
    >>> noise_kernel(np.array([1.0, 2.0]), np.array([0.1, 0.1]), np.array([0.5, -0.5]), ADVERSARIAL, 0.0,
    ...              m, lo, hi)
    >>> bool(lo[0] == 1.0 and hi[1] == 2.0 and hi[0] > 1.2 and lo[1] < 1.8)
    True
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from digslam.observer.core.scalar_jit import njit

UNIFORM, ADVERSARIAL, BIASED = 0, 1, 2
#: Noise model name to kernel code.
MODEL_CODES = {"uniform": UNIFORM, "adversarial": ADVERSARIAL, "biased": BIASED}


@njit(forceinline=True)
def _pad4(s: float) -> float:
    """``4 * np.spacing(s)`` for ``s >= 0``."""
    return 4.0 * (np.nextafter(s, math.inf) - s)


@njit(forceinline=True)
def _one(t: float, b: float, u: float, model: int, bias: float) -> tuple[float, float, float]:
    """``(measured, lo, hi)`` of one truth ``t`` with bound ``b`` from the uniform draw ``u in [-1, 1)``."""
    if model == ADVERSARIAL:
        side = 1.0 if u >= 0 else -1.0
        far = t + side * 2.0 * b
        pad = _pad4(max(abs(t), 2.0 * b))
        if side > 0:
            return t + side * b, t, far + pad
        return t + side * b, far - pad, t
    e = (bias + (1.0 - abs(bias)) * u) * b if model == BIASED else u * b
    m = t + e
    pad = _pad4(max(abs(m), b))
    return m, (m - b) - pad, (m + b) + pad


@njit
def noise_kernel(truth: np.ndarray, bound: np.ndarray, u: np.ndarray, model: int, bias: float,
                 m: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> None:  # fmt: skip
    """Measured values and intervals of flat arrays, written into ``m``, ``lo``, ``hi``."""
    for i in range(truth.shape[0]):
        m[i], lo[i], hi[i] = _one(truth[i], bound[i], u[i], model, bias)


@njit(forceinline=True)
def _pad(v: float, tol: float, sign: float) -> float:
    """``v + sign * tol * max(1, |v|)`` (``|v|`` taken as 0 when infinite), the simulator's widening."""
    a = abs(v) if math.isfinite(v) else 0.0
    return v + sign * (tol * max(1.0, a))


#: Rows of the hull array :func:`record_kernel` reads (the order of :func:`.dynamics_jit.step_bounds`).
SPEED, LATERAL, YAW, MEAN1, MEAN2 = 0, 1, 2, 3, 4
#: Bits of ``measured``: the lateral velocity, the odometry increment (the mean velocity, two components).
MEASURE_LATERAL, MEASURE_MEAN = 1, 2


class RecordModel(NamedTuple):
    """How a record is made from the truth (:func:`record_kernel`): the sensors' ranges and the noise,
    fixed for a sensor suite and a noise configuration (built once, :func:`.sensors.measure_step`).

    Attributes:
        r_max: ``(n,)`` the sensors' maximum ranges.
        model: ``UNIFORM``, ``ADVERSARIAL`` or ``BIASED`` (:data:`MODEL_CODES`); bias: the ``biased`` share.
        speed, yaw_rate, heading, range: the noise bounds of each kind of reading (``speed`` bounds both
            body-frame velocity components).
        tol: widens every finite bound by ``tol * max(1, |bound|)`` (0 when the truths are rigorous).
    """

    r_max: np.ndarray
    model: int
    bias: float
    speed: float
    yaw_rate: float
    heading: float
    range: float
    tol: float

    def scalars(self) -> np.ndarray:
        """The fields after ``r_max`` as one float64 array ``(7,)``, in order: what :func:`record_kernel`
        reads (one array argument costs numba's dispatch far less than the tuple)."""
        fields = (self.model, self.bias, self.speed, self.yaw_rate, self.heading, self.range, self.tol)
        return np.array(fields, dtype=np.float64)


@njit
def record_kernel(r_b: np.ndarray, hulls: np.ndarray, heading: float, measured: int, r_max: np.ndarray,
                  noise: np.ndarray, u: np.ndarray, outlier: np.ndarray, outlier_lo: np.ndarray,
                  outlier_hi: np.ndarray, out: np.ndarray, no_echo: np.ndarray) -> int:  # fmt: skip
    """Intervals of one step into ``out (n + 6, 2)`` (speed, yaw rate, heading, the ``n`` ranges, then the
    lateral velocity and the two components of the odometry increment); ``no_echo``.

    The truth: ``r_b (n, 2)`` bounds of each true sector distance (``[r, r]`` where it is known exactly;
    ``inf`` where nothing lies in the sector), ``hulls (5, 2)`` the hulls over the step of the true forward
    velocity, leftward velocity and yaw rate and the bounds of the odometry increment's two components (rows
    :data:`SPEED`, :data:`LATERAL`, :data:`YAW`, :data:`MEAN1`, :data:`MEAN2`, as
    :func:`.dynamics_jit.step_bounds` writes them), the true ``heading``, and ``measured``, the bits
    :data:`MEASURE_LATERAL` (a Doppler velocity log, with the speed's noise bound; unmeasured, the lateral row
    is known to be the hull, ``[0, 0]`` for a unicycle, and is recorded as it is) and :data:`MEASURE_MEAN`
    (unmeasured: ``[-inf, inf]`` twice). ``r_max`` holds the maximum ranges, ``noise`` the noise model and its
    bounds (:meth:`RecordModel.scalars` of the :class:`RecordModel`); ``u`` the step's draws of
    ``Generator.random`` in ``[0, 1)``, each read as ``-1 + 2 u`` in ``[-1, 1)`` (bit for bit what
    ``Generator.uniform(-1, 1)`` returns for the same state: ``2 u`` is exact, so both round the same real sum
    once): ``n + 3`` (speed, yaw rate, heading, then the ranges), plus one for the lateral velocity when it is
    measured (so a unicycle draws exactly what it drew before the lateral velocity existed), plus two for the
    increment when it is measured; ``outlier`` (bool) the range readings replaced by an outlier, whose
    intervals are ``[outlier_lo, outlier_hi]``. A hull ``[lo, hi]`` is reported as the noisy interval of its
    midpoint widened by its half-width, so it contains the whole hull (under ``adversarial`` noise the hull
    touches a bound). A reading is ``no_echo`` (``[r_max, inf]``) only when the lower bound exceeds ``r_max``;
    one whose upper bound is not finite reads ``[min(lo, r_max), inf]``. Every finite bound is widened by the
    model's ``tol``. Returns the first row whose interval has a NaN or ``lo > hi`` (the checks of
    :class:`~digslam.observer.record.mission.MissionRecord`), -1 if none.
    """
    model, bias, b_speed, b_yaw, b_heading, b_range, tol = (int(noise[0]), noise[1], noise[2], noise[3],
                                                            noise[4], noise[5], noise[6])  # fmt: skip
    flag, o_lo, o_hi = outlier, outlier_lo, outlier_hi
    n = r_b.shape[0]
    lat = n + 3
    lateral, mean = (measured & MEASURE_LATERAL) != 0, (measured & MEASURE_MEAN) != 0
    for k in range(5):
        if k == 0:
            src, b, row, draw = SPEED, b_speed, 0, 0
        elif k == 1:
            src, b, row, draw = YAW, b_yaw, 1, 1
        elif k == 2:
            src, b, row, draw = LATERAL, b_speed, lat, lat
            if not lateral:
                out[lat, 0], out[lat, 1] = hulls[LATERAL, 0], hulls[LATERAL, 1]
                continue
        else:
            row = lat + k - 2
            src, b, draw = MEAN1 + k - 3, b_speed, row if lateral else row - 1
            if not mean:
                out[row, 0], out[row, 1] = -math.inf, math.inf
                continue
        h_lo, h_hi = hulls[src, 0], hulls[src, 1]
        half = 0.5 * (h_hi - h_lo)
        _, lo, hi = _one(0.5 * (h_lo + h_hi), b, -1.0 + 2.0 * u[draw], model, bias)
        out[row, 0], out[row, 1] = min(lo - half, h_lo), max(hi + half, h_hi)  # exact containment of the hull
    _, out[2, 0], out[2, 1] = _one(heading, b_heading, -1.0 + 2.0 * u[2], model, bias)
    for s in range(n):
        a, z = r_b[s, 0], r_b[s, 1]
        no_echo[s] = not a <= r_max[s]
        if no_echo[s] or not math.isfinite(z):
            _, lo, hi = _one(0.0 if no_echo[s] else a, b_range, -1.0 + 2.0 * u[3 + s], model, bias)
            lo, hi = min(lo, r_max[s]), math.inf
        else:
            half = 0.5 * (z - a)
            _, lo, hi = _one(0.5 * (a + z), b_range, -1.0 + 2.0 * u[3 + s], model, bias)
            lo, hi = min(lo - half, a), max(hi + half, z)
        if flag[s]:
            out[3 + s, 0], out[3 + s, 1] = o_lo[s], o_hi[s]
            no_echo[s] = False
        elif no_echo[s]:
            out[3 + s, 0], out[3 + s, 1] = r_max[s], math.inf
        else:
            out[3 + s, 0], out[3 + s, 1] = max(lo, 0.0), hi
    bad = -1
    for k in range(n + 6):
        if tol > 0 and (k < lat or (k == lat and lateral) or (k > lat and mean)):
            out[k, 0], out[k, 1] = _pad(out[k, 0], tol, -1.0), _pad(out[k, 1], tol, 1.0)
        if bad < 0 and not out[k, 0] <= out[k, 1]:
            bad = k
    return bad


@njit
def obs_kernel(rng: np.ndarray, no_echo: np.ndarray, speed: np.ndarray, lateral: np.ndarray, yaw: np.ndarray,
               heading: np.ndarray, top: float, s_top: float, w_top: float, h_lo: float, h_hi: float,
               r: np.ndarray, e: np.ndarray, odo: np.ndarray, h: np.ndarray) -> None:  # fmt: skip
    """The observation of a record, written into ``r (n, 2)``, ``e (n,)`` (int8), ``odo (3, 2)`` and
    ``h (2,)`` (new arrays the caller allocates: cheaper than boxing arrays the kernel allocates): ranges
    capped at ``top``, ``no_echo`` as int8, the odometry (speed, lateral velocity, yaw rate) clipped to
    ``±s_top``, ``±s_top`` and ``±w_top``, and the heading shifted by the multiple of ``2 pi`` nearest its
    midpoint (half to even, as ``np.round``), clipped to ``[h_lo, h_hi]``."""
    n = rng.shape[0]
    for s in range(n):
        r[s, 0], r[s, 1] = min(rng[s, 0], top), min(rng[s, 1], top)
        e[s] = 1 if no_echo[s] else 0
    for j in range(2):
        odo[0, j] = min(max(speed[j], -s_top), s_top)
        odo[1, j] = min(max(lateral[j], -s_top), s_top)
        odo[2, j] = min(max(yaw[j], -w_top), w_top)
    k = np.rint(0.5 * (heading[0] + heading[1]) / (2 * math.pi)) * 2 * math.pi
    for j in range(2):
        h[j] = min(max(heading[j] - k, h_lo), h_hi)


__all__ = [
    "LATERAL",
    "MEAN1",
    "MEAN2",
    "MEASURE_LATERAL",
    "MEASURE_MEAN",
    "MODEL_CODES",
    "SPEED",
    "YAW",
    "RecordModel",
    "noise_kernel",
    "obs_kernel",
    "record_kernel",
]
