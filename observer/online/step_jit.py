"""One step of the online Dig-SLAM filter (thesis §6.4, Algorithm 6.3, Eq. 6.21–6.23) in one compiled call.

:func:`filter_step` chains the kernels :meth:`.online.OnlineDigSlam.update` used to call one by one from
Python, with the same arguments and the same results:

1. :func:`.online_jit_pose.predict`: the tube step (Eq. 6.23, heading fused with the compass);
2. with ``impacts``, :func:`.online_jit_pose.impact_bound` then :func:`.online_jit_pose.contract` (Eq. 6.22),
   skipped (box unchanged) when the box leaves the grid's frame or no sensor echoed, as
   :meth:`.online_explored.WindowDigMap.contract_box` does;
3. :func:`.online_jit_mark.dig_and_mark`: digs ``M⁻`` (Eq. 6.21) and grows the explored zone (Eq. B.5).

:func:`filter_step_q` takes ``q``, the number of outliers allowed among the step's range readings (thesis
§2.6.2): step 2 then uses the q-relaxed impact radius and step 3 digs a cell only where ``q + 1`` readings
prove it free; :func:`filter_step` is ``q = 0``.

The new state is written into one ``float64`` array ``st`` of 10 values: the pose box ``x⁻, y⁻, x⁺, y⁺``,
the heading ``ψ⁻, ψ⁺`` and the displacement box ``d_x⁻, d_y⁻, d_x⁺, d_y⁺``.
Nothing is rounded here: every bound comes from those kernels (outward rounded with :mod:`.jit`).

>>> from digslam.observer.slam.grid import Grid
>>> g = Grid((-3.0, -3.0), (3.0, 3.0), (60, 60))
>>> free, sure, maybe = (np.zeros(g.shape, bool) for _ in range(3))
>>> st, frame = np.zeros(10), np.array([-3.0, -3.0, 3.0, 3.0, 0.1, 0.1, 1.0, 0.0])
>>> code, *win = filter_step(free, sure, maybe, g.xs, g.ys, -g.ys, frame, np.zeros(2), np.zeros(2), -1e-3,
...     1e-3, st, 0.1, np.array([-0.01, 0.01]),
...     np.array([-1e-3, 1e-3]), np.array([0.99, 1.01]), np.zeros(1), np.array([np.pi]), np.array([5.0]),
...     np.array([[1.9, 2.0]]), np.zeros(1, bool), False)
>>> code, bool(st[0] <= 0.1 <= st[2]), bool(free[30, 30]), bool(free[30, 55])  # dug near, not at the wall
(0, True, True, False)
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.scalar_jit import njit
from digslam.observer.online.mark_jit import dig_and_mark_q
from digslam.observer.online.pose_jit import contract, impact_bound_q, predict

__all__ = ["filter_step", "filter_step_q"]


@njit
def filter_step_q(free: np.ndarray, sure: np.ndarray, maybe: np.ndarray, xs: np.ndarray, ys: np.ndarray,
                nys: np.ndarray, frame: np.ndarray, lo: np.ndarray, hi: np.ndarray, h_lo: float, h_hi: float,
                st: np.ndarray, dt: float, yaw: np.ndarray,
                comp: np.ndarray, speed: np.ndarray, alpha: np.ndarray, gamma: np.ndarray, r_max: np.ndarray,
                rng: np.ndarray, no_echo: np.ndarray, impacts: bool, q: int, cnt: np.ndarray, lst: np.ndarray
                ) -> tuple[int, int, int, int, int]:  # fmt: skip
    """Predict, contract and measure one step (see the module docstring), robust to ``q`` outliers.

    Args:
        free, sure, maybe: ``(ny, nx)`` bool ``M⁻``, certainly and possibly sensed cells (updated in place).
        xs, ys, nys: exact cell bounds of the grid (``nys = -ys``).
        frame: ``(gx⁻, gy⁻, gx⁺, gy⁺, dx, dy, keep, off)``: the grid's frame, cell size and the clearance
            bound's constants (:func:`.online_explored._slack`).
        lo, hi, h_lo, h_hi: the pose box ``(2,)`` and the heading interval at the previous step.
        st: ``(10,)`` output: the state (module docstring).
        dt: the step's duration; yaw, comp, speed: ``(2,)`` yaw-rate, compass and speed intervals.
        alpha, gamma, r_max, rng, no_echo: the step's readings (``rng`` ``(n, 2)``).
        impacts: apply Eq. 6.22.
        q: at most ``q`` of this step's range readings are outliers (0: none): the impact radius is the
            q-relaxed :func:`.online_jit_pose.impact_bound_q` and a cell is dug where ``q + 1`` readings
            prove it free (:func:`.online_jit_mark.dig_and_mark_q`).
        cnt, lst: ``(2, ny, nx)`` and ``(ny·nx + 1,)`` int32 zeros, the per-cell counts and the list of the
            counted cells of the q-relaxed mode (``q = 0``: unused).

    Returns:
        ``(code, r0, r1, c0, c1)``: ``code`` 0 and the window holding every changed cell, or ``code`` 1
        when the data contradict their bounds (empty heading or box; nothing dug).
    """
    ok, hl, hh, x0, y0, x1, y1, d0l, d1l, d0h, d1h = predict(lo[0], lo[1], hi[0], hi[1], h_lo, h_hi, dt,
                                                             yaw[0], yaw[1], comp[0], comp[1], speed[0],
                                                             speed[1])  # fmt: skip
    if not ok:
        return 1, 0, 0, 0, 0
    if impacts:
        r_hi = impact_bound_q(no_echo, rng, q)
        if math.isfinite(r_hi) and frame[0] <= x0 <= x1 <= frame[2] and frame[1] <= y0 <= y1 <= frame[3]:
            x0, y0, x1, y1 = contract(free, xs, ys, nys, x0, y0, x1, y1, r_hi, frame[4], frame[5], frame[6],
                                      frame[7])  # fmt: skip
    if not (x0 <= x1 and y0 <= y1):
        return 1, 0, 0, 0, 0
    st[0], st[1], st[2], st[3], st[4], st[5] = x0, y0, x1, y1, hl, hh
    st[6], st[7], st[8], st[9] = d0l, d1l, d0h, d1h
    r0, r1, c0, c1 = dig_and_mark_q(free, sure, maybe, cnt, lst, xs, ys, nys, x0, y0, x1, y1, hl, hh, alpha,
                                    gamma, r_max, rng, True, q)  # fmt: skip
    return 0, r0, r1, c0, c1


@njit
def filter_step(free: np.ndarray, sure: np.ndarray, maybe: np.ndarray, xs: np.ndarray, ys: np.ndarray,
                nys: np.ndarray, frame: np.ndarray, lo: np.ndarray, hi: np.ndarray, h_lo: float, h_hi: float,
                st: np.ndarray, dt: float, yaw: np.ndarray,
                comp: np.ndarray, speed: np.ndarray, alpha: np.ndarray, gamma: np.ndarray, r_max: np.ndarray,
                rng: np.ndarray, no_echo: np.ndarray, impacts: bool
                ) -> tuple[int, int, int, int, int]:  # fmt: skip
    """:func:`filter_step_q` with ``q = 0`` (no outlier: every reading's interval contains the truth)."""
    return filter_step_q(free, sure, maybe, xs, ys, nys, frame, lo, hi, h_lo, h_hi, st, dt, yaw, comp, speed,
                         alpha, gamma, r_max, rng, no_echo, impacts, 0, np.zeros((2, 1, 1), np.int32),
                         np.zeros(1, np.int32))  # fmt: skip
