"""Mounted sensors and readings taken off the record's instant: where a cone's apex lies, from the pose box.

A range sensor sits at ``mount = (m_1, m_2)`` in the body frame, and a reading may be taken at an instant
whose pose is within ``slack = (s_p, s_ψ)`` of the record's (:mod:`digslam.observer.record.mission`). Its
cone's apex is ``a = x' + R(ψ') m`` and its direction ``ψ' + α``, with ``x' ∈ [x] ± s_p`` (each axis) and
``ψ' ∈ [ψ] ± s_ψ``. So every claim of a reading holds from the apex box

    ``[a] = [x] + R([ψ] ± s_ψ)·m ± s_p``

with the heading interval ``[ψ] ± s_ψ`` (:func:`apex`, outward rounded with :func:`.pose_jit.rotate`): the
dig (Eq. 6.21) and the explored zone (Eq. B.5) from the apex box are those of a centred cone at ``[a]``.
The impact contractor (Eq. 6.22) and its cones contract the apex box; the position then obeys
``x ∈ [a] - R([ψ] ± s_ψ)·m ∓ s_p`` (:func:`centre_of`), a sound backward step of the same relation.

:func:`mount_kind` sorts a step: 0, every reading centred (the centred kernels run unchanged, to the bit);
1, every reading shares one mount and slack (one apex box for the step); 2, mixed: each reading its own
apex box for digging and marking, and the impact radius of each reading widened to the position,
``y⁺ + |m| + √2·s_p`` (:func:`centre_ranges`: ``|x - a| <= |m| + √2·s_p``), without the cones.
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.scalar_jit import add_dn, add_up, mul_up, njit, sqrt_up, sub_dn, sub_up
from digslam.observer.online.dig_types import PoseBox
from digslam.observer.online.pose_jit import cos_sin, rotate

__all__ = ["apex", "centre_of", "centre_ranges", "mount_kind", "offset"]

#: ``√2`` rounded up.
_SQRT2_UP = math.nextafter(math.sqrt(2.0), math.inf)


@njit
def mount_kind(mount: np.ndarray, slack: np.ndarray) -> int:
    """0: every reading centred (``mount`` and ``slack`` zero, or no rows); 1: all rows equal; 2: mixed."""
    n = mount.shape[0]
    if n == 0:
        return 0
    same, zero = True, True
    for k in range(n):
        for c in range(2):
            if mount[k, c] != mount[0, c] or slack[k, c] != slack[0, c]:
                same = False
            if mount[k, c] != 0.0 or slack[k, c] != 0.0:
                zero = False
    if zero:
        return 0
    return 1 if same else 2


@njit
def offset(psi_lo: float, psi_hi: float, m1: float, m2: float) -> tuple[float, float, float, float]:
    """Enclosure ``(u_1⁻, u_1⁺, u_2⁻, u_2⁺)`` of ``R(ψ)·m`` over ``ψ ∈ [psi_lo, psi_hi]`` (outward rounded,
    :func:`.pose_jit.rotate`; ``[0, 0]`` twice for ``m = 0``)."""
    if m1 == 0.0 and m2 == 0.0:
        return 0.0, 0.0, 0.0, 0.0
    cl, ch, sl, sh = cos_sin(psi_lo, psi_hi)
    return rotate(m1, m1, m2, m2, cl, ch, sl, sh)


@njit
def apex(box: PoseBox, m1: float, m2: float, sp: float, spsi: float) -> PoseBox:
    """The apex box and the heading interval of a reading from the sensor at ``(m1, m2)`` with slack
    ``(sp, spsi)``: ``[x] + R([ψ] ± s_ψ)·m ± s_p`` and ``[ψ] ± s_ψ`` (outward rounded)."""
    pl, ph = box.psi_lo, box.psi_hi
    if spsi != 0.0:
        pl, ph = sub_dn(pl, spsi), add_up(ph, spsi)
    u0l, u0h, u1l, u1h = offset(pl, ph, m1, m2)
    x0, y0 = add_dn(box.x_lo, u0l), add_dn(box.y_lo, u1l)
    x1, y1 = add_up(box.x_hi, u0h), add_up(box.y_hi, u1h)
    if sp != 0.0:
        x0, y0, x1, y1 = sub_dn(x0, sp), sub_dn(y0, sp), add_up(x1, sp), add_up(y1, sp)
    return PoseBox(x0, y0, x1, y1, pl, ph)


@njit
def centre_of(x0: float, y0: float, x1: float, y1: float, a: PoseBox, m1: float, m2: float, sp: float
              ) -> tuple[float, float, float, float]:  # fmt: skip
    """The position box ``[x0, x1] × [y0, y1]`` intersected with ``[a] - R([ψ_a])·m ∓ s_p``, where ``a`` is a
    contracted apex box from :func:`apex` (its heading interval already widened by the slack)."""
    u0l, u0h, u1l, u1h = offset(a.psi_lo, a.psi_hi, m1, m2)
    nx0, ny0 = sub_dn(sub_dn(a.x_lo, u0h), sp), sub_dn(sub_dn(a.y_lo, u1h), sp)
    nx1, ny1 = add_up(sub_up(a.x_hi, u0l), sp), add_up(sub_up(a.y_hi, u1l), sp)
    return max(x0, nx0), max(y0, ny0), min(x1, nx1), min(y1, ny1)


@njit
def centre_ranges(ranges: np.ndarray, mount: np.ndarray, slack: np.ndarray) -> np.ndarray:
    """The range intervals ``(n, 2)`` with each upper bound widened to bound the distance from the
    position: ``y⁺ + |m| + √2·s_p`` (rounded up; the lower bounds as they are)."""
    out = ranges.copy()
    for k in range(ranges.shape[0]):
        m2 = add_up(mul_up(mount[k, 0], mount[k, 0]), mul_up(mount[k, 1], mount[k, 1]))
        out[k, 1] = add_up(add_up(ranges[k, 1], sqrt_up(m2)), mul_up(_SQRT2_UP, slack[k, 0]))
    return out
