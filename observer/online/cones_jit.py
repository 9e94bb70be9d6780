"""Compiled directional impact contractor of the online filter: each echo's cone must meet ``comp M⁻``.

An echo of the cone ``k`` (direction ``ψ + α_k``, half-aperture ``γ_k``, range ``y_k ∈ [y_k⁻, y_k⁺]``) says
that an obstacle point ``p`` lies in the sector of apex ``x``, radius ``y_k⁺`` and angles
``[ψ + α_k - γ_k, ψ + α_k + γ_k]``; no obstacle point lies in the proved-free ``M⁻``, so

    ``S_k(x, ψ) ∩ comp M⁻ ≠ ∅``  for some ``ψ ∈ [ψ]``,

the directional form of Eq. 6.22 (``dist(x, comp M⁻) <= y⁺`` is the omnidirectional case, ``γ = π``,
kept in :func:`.pose_jit.contract`). One cone bounds the position on the side away from the obstacle it
sees; cones that see walls on opposite sides bound it on both, which the nearest-echo form cannot.

:func:`contract_cones` shaves slices off the four sides of the position box while no position of a slice
may satisfy all but at most ``q`` of these constraints (the q-relaxed intersection, thesis §2.6.2). A box
``C`` (a slice, or the whole box) satisfies cone ``k`` when a not-free cell, or the outside of the grid's
frame, holds a point ``g`` with ``|g - c| <= y_k⁺`` and ``g - c`` in the cone's directions for some
``c ∈ C`` (:func:`box_in_cone`): the distance between the two boxes is bounded from below with downward
rounding, and the directions of the difference box ``G - C`` (outward rounded) are compared with the
cone's angle range, both ranges padded by ``ANGLE_PAD`` (far above the few ulps of ``atan2`` and the
additions); a difference box whose directions span about a half turn or more is accepted outright (near
``±π`` the corners' angles may wrap to the wrong side). A slice is dropped only when every candidate fails
one of these tests, so the true position is never dropped. Full-circle cones (``γ_k ≥ π``, or a heading
interval so wide that the range spans a turn) are left to :func:`.pose_jit.contract`.

A slice starts at a quarter of its side and halves while it may hold a feasible position, down to
:data:`MIN_SLICE`; a slice that fails is cut and the next one of the same width is tried. A whole box, or
the rest of one, that fails means that the data contradict their bounds: the empty box is returned.

>>> from digslam.observer.online.window import grid_frame
>>> from digslam.observer.record.grid import Grid
>>> g = grid_frame(Grid((0.0, 0.0), (4.0, 4.0), (40, 40)))
>>> free = np.ones((40, 40), bool); free[:, 30:] = False        # a wall from x = 3 on, dug up to it
>>> ranges = np.array([[0.99, 1.01], [np.inf, np.inf]])          # the cone along +x sees it at 1 m
>>> box = contract_cones(free, g, 1.0, 1.0, 2.5, 2.5, 0.0, 0.0, np.array([0.0, np.pi]),
...                      np.array([0.1, 0.1]), ranges, np.array([False, True]), 0)
>>> [round(v, 2) for v in box]        # x >= 3 - 1.01 (and the cone's spread): the far side is cut
[1.98, 1.0, 2.5, 2.5]
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.angles_jit import sector_box
from digslam.observer.core.grid_jit import window
from digslam.observer.core.scalar_jit import add_dn, dn, mul_dn, njit, sqrt_dn, up

__all__ = ["ANGLE_PAD", "MIN_SLICE", "box_feasible", "box_in_cone", "cone_cell_ok", "contract_cones"]

#: Padding (rad) of both angle ranges of :func:`box_in_cone`.
ANGLE_PAD = 1e-9
_TWO_PI = 2.0 * math.pi
#: Thinnest slice (m) that :func:`contract_cones` tries to shave off.
MIN_SLICE = 0.02


@njit(forceinline=True)
def _wrap(a: float) -> float:
    """``a`` in about ``[-π, π)`` (the rounding is covered by :data:`ANGLE_PAD`)."""
    return a - _TWO_PI * math.floor((a + math.pi) / _TWO_PI)


@njit
def box_in_cone(cx0: float, cy0: float, cx1: float, cy1: float, gx0: float, gy0: float, gx1: float,
                gy1: float, r: float, mid: float, half: float) -> bool:  # fmt: skip
    """Whether some ``g`` of the box ``G = [gx0, gx1] × [gy0, gy1]`` and some ``c`` of ``C`` may have
    ``|g - c| <= r`` and the direction of ``g - c`` within ``half`` of ``mid`` (rigorous: False only
    when no such pair exists)."""
    dx = max(0.0, gx0 - cx1, cx0 - gx1)
    dy = max(0.0, gy0 - cy1, cy0 - gy1)
    dx, dy = (dn(dx) if dx > 0.0 else 0.0), (dn(dy) if dy > 0.0 else 0.0)
    if sqrt_dn(add_dn(mul_dn(dx, dx), mul_dn(dy, dy))) > r:
        return False
    # directions of the difference box G - C (outward rounded)
    lx, hx, ly, hy = dn(gx0 - cx1), up(gx1 - cx0), dn(gy0 - cy1), up(gy1 - cy0)
    if lx <= 0.0 <= hx and ly <= 0.0 <= hy:
        return True  # the boxes touch: every direction
    centre = math.atan2(0.5 * ly + 0.5 * hy, 0.5 * lx + 0.5 * hx)
    lo, hi = 0.0, 0.0
    for k in range(4):
        a = _wrap(math.atan2(ly if k < 2 else hy, lx if k % 2 == 0 else hx) - centre)
        lo, hi = min(lo, a), max(hi, a)
    if hi - lo > math.pi - 1e-6:
        # nearly a half-plane of directions: a corner's relative angle near ±π may have wrapped to the
        # other side, which shows as a span of about π or more; say yes rather than trust the side
        return True
    gap = abs(_wrap(centre + 0.5 * (lo + hi) - mid))
    return gap <= half + 0.5 * (hi - lo) + 2.0 * ANGLE_PAD


@njit(forceinline=True)
def _outside(cx0: float, cy0: float, cx1: float, cy1: float, gx0: float, gy0: float, gx1: float, gy1: float,
             hp: np.ndarray) -> bool:  # fmt: skip
    """Whether the difference box ``G - C`` lies wholly on the outer side of one of the half-planes
    ``n·v >= 0`` (rows ``(n_x, n_y)`` of ``hp``, each holding the cone), by more than the rounding."""
    lx, hx, ly, hy = gx0 - cx1, gx1 - cx0, gy0 - cy1, gy1 - cy0
    tol = 1e-9 * (abs(lx) + abs(hx) + abs(ly) + abs(hy)) + 1e-300
    for k in range(hp.shape[0]):
        nx, ny = hp[k, 0], hp[k, 1]
        if max(nx * lx, nx * hx) + max(ny * ly, ny * hy) < -tol:
            return True
    return False


@njit
def cone_cell_ok(free: np.ndarray, xs: np.ndarray, ys: np.ndarray, nys: np.ndarray, cx0: float, cy0: float,
                 cx1: float, cy1: float, r: float, mid: float, half: float) -> bool:  # fmt: skip
    """Whether the cone ``(r, mid ± half)`` from some point of ``C`` may meet ``comp M⁻``: a not-free cell
    of ``free`` (grid bounds ``xs``, ``ys``, ``nys = -ys``) or the outside of the grid's frame."""
    e = r * (1.0 + 1e-9) + 1e-9
    # the cells that may meet the sector: C plus the sector's bounding box (padded for the rounding)
    a0, a1 = mid - half, mid + half
    sx0, sx1, sy0, sy1 = sector_box(e, a0, a1, math.cos(a0), math.sin(a0), math.cos(a1), math.sin(a1))
    pad = 1e-9 * e + 1e-9
    r0, r1, c0, c1 = window(xs, nys, cx0 + sx0 - pad, cy0 + sy0 - pad, cx1 + sx1 + pad, cy1 + sy1 + pad)
    # a quick filter before the exact test: three half-planes that hold the cone (its two edges, padded,
    # and the half-plane ahead), when it is narrower than a half turn
    cm, sm = math.cos(mid), math.sin(mid)
    hp = np.zeros((3 if half + 1e-6 < 0.5 * math.pi else 0, 2))
    if hp.shape[0]:
        b0, b1 = a0 - 1e-6, a1 + 1e-6
        hp[0, 0], hp[0, 1] = -math.sin(b0), math.cos(b0)
        hp[1, 0], hp[1, 1] = math.sin(b1), -math.cos(b1)
        hp[2, 0], hp[2, 1] = cm, sm
    # the echo lies near the sector's far end: scan from there (rows or columns, as the cone points)
    if abs(cm) >= abs(sm):
        for jj in range(c0, c1):
            j = c1 - 1 - (jj - c0) if cm > 0.0 else jj
            for i in range(r0, r1):
                if free[i, j] or _outside(cx0, cy0, cx1, cy1, xs[j], ys[i + 1], xs[j + 1], ys[i], hp):
                    continue
                if box_in_cone(cx0, cy0, cx1, cy1, xs[j], ys[i + 1], xs[j + 1], ys[i], r, mid, half):
                    return True
    else:
        for ii in range(r0, r1):
            i = ii if sm > 0.0 else r1 - 1 - (ii - r0)  # row 0 is the top (largest y)
            for j in range(c0, c1):
                if free[i, j] or _outside(cx0, cy0, cx1, cy1, xs[j], ys[i + 1], xs[j + 1], ys[i], hp):
                    continue
                if box_in_cone(cx0, cy0, cx1, cy1, xs[j], ys[i + 1], xs[j + 1], ys[i], r, mid, half):
                    return True
    # the outside of the frame, clipped to the disc's bounding box (a half-plane as a whole would let the
    # distance and the direction tests be met by two different points)
    fx0, fx1, fy0, fy1 = xs[0], xs[-1], ys[-1], ys[0]
    bx0, by0, bx1, by1 = cx0 - e, cy0 - e, cx1 + e, cy1 + e
    outside = (
        (bx0, by0, min(fx0, bx1), by1),
        (max(fx1, bx0), by0, bx1, by1),
        (bx0, by0, bx1, min(fy0, by1)),
        (bx0, max(fy1, by0), bx1, by1),
    )
    for o in outside:
        if o[0] <= o[2] and o[1] <= o[3] and box_in_cone(cx0, cy0, cx1, cy1, o[0], o[1], o[2], o[3], r, mid,
                                                         half):  # fmt: skip
            return True
    return False


@njit
def box_feasible(free: np.ndarray, xs: np.ndarray, ys: np.ndarray, nys: np.ndarray, cx0: float, cy0: float,
                 cx1: float, cy1: float, psi_lo: float, psi_hi: float, alpha: np.ndarray, gamma: np.ndarray,
                 ranges: np.ndarray, no_echo: np.ndarray, q: int) -> bool:  # fmt: skip
    """Whether some position of ``C = [cx0, cx1] × [cy0, cy1]`` may meet all but at most ``q`` cone
    constraints (False: none does)."""
    miss = 0
    for k in range(alpha.size):
        r = ranges[k, 1]
        if no_echo[k] or not math.isfinite(r):
            continue
        half = 0.5 * (psi_hi - psi_lo) + gamma[k] + ANGLE_PAD
        if not half < math.pi - 1e-6:
            continue  # a full circle: the nearest-echo contractor's business
        mid = 0.5 * (psi_lo + psi_hi) + alpha[k]
        if not cone_cell_ok(free, xs, ys, nys, cx0, cy0, cx1, cy1, r, mid, half):
            miss += 1
            if miss > q:
                return False
    return True


@njit
def contract_cones(free: np.ndarray, grid: tuple, x0: float, y0: float, x1: float, y1: float, psi_lo: float,
                   psi_hi: float, alpha: np.ndarray, gamma: np.ndarray, ranges: np.ndarray,
                   no_echo: np.ndarray, q: int) -> tuple[float, float, float, float]:  # fmt: skip
    """The position box ``[x0, x1] × [y0, y1]`` with slices shaved off its four sides while a slice holds no
    position that meets all but at most ``q`` cone constraints (:func:`box_feasible`); the slices start at
    a quarter of the side and halve down to :data:`MIN_SLICE`; ``(inf, inf, -inf, -inf)`` when the whole
    box fails. ``grid`` is a :class:`.dig_types.GridFrame` (or the tuple of its fields), ``alpha``,
    ``gamma``, ``ranges``, ``no_echo`` the step's cones (:class:`.dig_types.StepRecord`), ``[psi_lo,
    psi_hi]`` the heading interval."""
    xs, ys, nys = grid[0], grid[1], grid[2]
    if not box_feasible(free, xs, ys, nys, x0, y0, x1, y1, psi_lo, psi_hi, alpha, gamma, ranges, no_echo, q):
        return math.inf, math.inf, -math.inf, -math.inf
    for side in range(4):
        w = 0.25 * ((x1 - x0) if side < 2 else (y1 - y0))
        while w >= MIN_SLICE:
            if side == 0:
                s = min(x0 + w, x1)
                c = (x0, y0, s, y1)
            elif side == 1:
                s = max(x1 - w, x0)
                c = (s, y0, x1, y1)
            elif side == 2:
                s = min(y0 + w, y1)
                c = (x0, y0, x1, s)
            else:
                s = max(y1 - w, y0)
                c = (x0, s, x1, y1)
            if box_feasible(free, xs, ys, nys, c[0], c[1], c[2], c[3], psi_lo, psi_hi, alpha, gamma, ranges,
                            no_echo, q):  # fmt: skip
                w *= 0.5  # something may lie in the slice: try a thinner one
            elif s == (x1 if side == 0 else x0 if side == 1 else y1 if side == 2 else y0):
                # the slice was all that was left: no position meets the constraints
                return math.inf, math.inf, -math.inf, -math.inf
            elif side == 0:  # nothing in the slice: cut it (its far edge stays, closed)
                x0 = s
            elif side == 1:
                x1 = s
            elif side == 2:
                y0 = s
            else:
                y1 = s
    return x0, y0, x1, y1
