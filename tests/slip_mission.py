"""A synthetic mission with lateral slip, for the tests of ``x' = R(psi) v`` (thesis Eq. 3.59, 6.12, B.20).

The robot turns at the constant yaw rate ``omega`` while it moves forward at ``v_1`` and slides to its left
at ``v_2`` (both constant, in the body frame): ``psi(t) = psi_0 + omega t`` and, integrating
``x' = (v_1 cos psi - v_2 sin psi, v_1 sin psi + v_2 cos psi)``,

    ``x(t) = x_0 + (v_1 (sin psi - sin psi_0) + v_2 (cos psi - cos psi_0)) / omega``,
    ``y(t) = y_0 + (v_2 (sin psi - sin psi_0) - v_1 (cos psi - cos psi_0)) / omega``.

The truth is that closed form evaluated with mpmath at 50 digits at the record's float times (the reals
``omega``, ``v_1``, ``v_2``, ``psi_0`` are the floats below, exactly), so it is independent of the observers'
float code; a float bound is compared with it as an mpmath number. Every interval of the record contains
the truth. The one sensor is omnidirectional and never echoes (no impact contraction): what bounds the
position is the odometry alone, so the tests see the prediction.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np

from digslam.observer.record.mission import MissionRecord

DT = 0.1
OMEGA, V1, V2, PSI0 = 0.4, 1.0, 0.3, 0.3
N = 51  # samples: 50 slices, 5 s, 1.5 m of sideways slip


def truth(t: float) -> tuple[mpmath.mpf, mpmath.mpf, mpmath.mpf]:
    """``(x, y, psi)`` at the real time ``t`` (a float, taken exactly), with ``x_0 = y_0 = 0``."""
    with mpmath.workdps(50):
        w, v1, v2, p0 = (mpmath.mpf(a) for a in (OMEGA, V1, V2, PSI0))
        p = p0 + w * mpmath.mpf(t)
        ds, dc = mpmath.sin(p) - mpmath.sin(p0), mpmath.cos(p) - mpmath.cos(p0)
        return (v1 * ds + v2 * dc) / w, (v2 * ds - v1 * dc) / w, p


def mission(lateral: bool = True) -> MissionRecord:
    """The stacked record (``lateral=False``: the same record with ``lateral = [0, 0]``, the unicycle model,
    whose velocity intervals then miss the truth)."""
    t = np.arange(N) * DT
    psi = [truth(float(tk))[2] for tk in t]
    heading = np.array([[float(p) - 2e-3, float(p) + 2e-3] for p in psi])
    assert all(mpmath.mpf(h[0]) <= p <= mpmath.mpf(h[1]) for h, p in zip(heading, psi, strict=True))
    tile = lambda a, b: np.tile([a, b], (N, 1))  # noqa: E731
    rec = MissionRecord(
        t=t, speed=tile(V1 - 0.01, V1 + 0.01), yaw_rate=tile(OMEGA - 0.01, OMEGA + 0.01), heading=heading,
        alpha=np.zeros((N, 1)), gamma=np.full((N, 1), math.pi), r_max=np.full((N, 1), 1.0),
        range=np.tile([1.0, math.inf], (N, 1, 1)), no_echo=np.ones((N, 1), bool), outlier=np.zeros((N, 1), bool),
        lateral=tile(V2 - 0.01, V2 + 0.01) if lateral else np.zeros((N, 2)),
    )  # fmt: skip
    return rec


def inside(lo: np.ndarray, hi: np.ndarray, t: float) -> bool:
    """Whether the box ``[lo, hi]`` (``(2,)`` floats) holds the true position at time ``t`` (exactly)."""
    x, y, _ = truth(t)
    return bool(mpmath.mpf(lo[0]) <= x <= mpmath.mpf(hi[0]) and mpmath.mpf(lo[1]) <= y <= mpmath.mpf(hi[1]))
