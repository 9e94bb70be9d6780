"""Compiled step of the disc robot's blocked unicycle kinematics (the motion model of :mod:`.robot`).

:func:`robot_step_kernel` runs one step of :meth:`.robot.RobotSim.step` in machine code: the substeps before
the first blocked one run at the commanded speed, the rest of the step as one arc at the largest fraction of
it whose sweep is clear (or 0). Both pieces are arcs of :mod:`.arc_jit`: the heading stored is the true
heading, and the position error each step adds is bounded there. A sweep is checked at the midpoints of
``m`` equal pieces of each substep's arc: the disc there must keep ``radius`` plus half a piece's travel off
every edge (every point of the arc lies within that of a midpoint), so the nominal disc never overlaps an
obstacle and never tunnels. The edges checked are those whose bounding box lies within ``|v| dt + radius``
of the step's start: every arc point of the step lies within ``|v| dt`` of it (an arc is never shorter than
its chord), so no edge that could block is left out. If the start's clearance exceeds ``radius + |v| dt``
the whole step is clear without checking the arc.

Example (1 m/s for 4 substeps of 0.025 s at a wall 0.25 m ahead of a disc of radius 0.2: two substeps
run, then the disc touches the wall and stops)::

    >>> import numpy as np
    >>> from digslam.envs.sim.geometry_jit import edge_boxes
    >>> edges, pose, fractions = np.array([[0.25, -1.0, 0.25, 1.0]]), np.zeros(3), np.array([0.5, 0.25])
    >>> pieces = np.empty((2, 3))
    >>> first, vi, err, w_lo, w_hi = robot_step_kernel(pose, 1.0, 0.0, 0.1, 4, 4, 0.2, edges,
    ...                                                edge_boxes(edges), fractions, pieces)
    >>> (first, vi), pose.tolist(), pieces.tolist(), (w_lo, w_hi), err < 1e-15
    ((2, 0.0), [0.05, 0.0, 0.0], [[1.0, 0.05, 0.0], [0.0, 0.05, 0.0]], (0.0, 0.0), True)
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from digslam.envs.sim.arc_jit import advance, yaw_rate_bounds
from digslam.envs.sim.geometry_jit import edge_near, segment_distance
from digslam.observer.core.scalar_jit import add_up, njit


class _NearEdges(NamedTuple):
    """The edges a step may meet: ``edges[idx[:n]]`` of the world's ``(E, 4)`` edge array."""

    edges: np.ndarray
    idx: np.ndarray
    n: int


@njit(inline="always")
def _clear(x: float, y: float, near: _NearEdges, need: float) -> bool:
    """Whether ``(x, y)`` lies at least ``need`` from each of the edges ``near``."""
    edges, idx = near.edges, near.idx
    for q in range(near.n):
        k = idx[q]
        ax, ay = edges[k, 0] - x, edges[k, 1] - y
        if segment_distance(ax, ay, edges[k, 2] - edges[k, 0], edges[k, 3] - edges[k, 1]) < need:
            return False
    return True


@njit(inline="always")
def _sweep(x: float, y: float, th: float, v: float, w: float, pieces: int, piece: float, radius: float,
           near: _NearEdges) -> int:  # fmt: skip
    """Index of the first blocked piece midpoint of the arc (``pieces`` if none is)."""
    need = radius + abs(v) * (0.5 * piece)
    for j in range(pieces):
        px, py, _, _ = advance(x, y, th, v, w, (j + 0.5) * piece)
        if not _clear(px, py, near, need):
            return j
    return pieces


@njit
def robot_step_kernel(pose: np.ndarray, v: float, w: float, dt: float, substeps: int, m: int,
                      radius: float, edges: np.ndarray, bbox: np.ndarray, fractions: np.ndarray,
                      pieces: np.ndarray) -> tuple[int, float, float, float, float]:  # fmt: skip
    """Advance ``pose`` (updated in place) by ``dt`` under command ``(v, w)``.

    Args:
        pose: ``(x, y, theta)``.
        v, w: Commanded speed and yaw rate.
        dt, substeps: Step duration (the exact time between the step's records) and its number of substeps.
        m: Sweep check points per substep.
        radius: Disc radius.
        edges, bbox: The world's edges ``(E, 4)`` and their bounding boxes.
        fractions: Fractions of ``v`` tried, in order, once a substep is blocked.
        pieces: Output ``(2, 3)``: the step's two pieces ``(v, tau, theta_end)`` of :mod:`.arc_jit`, whose
            ``tau`` sum to ``dt`` exactly (a piece may last 0 s).

    Returns:
        ``(first, vi, err, w_lo, w_hi)``: the substeps run at ``v``, the speed of the remaining
        ``substeps - first``, the bound on the position error this step adds (:func:`.arc_jit.arc_move`), and
        outward bounds of the true yaw rates of the pieces that last more than 0 s.
    """
    x, y, th = pose[0], pose[1], pose[2]
    h = dt / substeps
    piece = h / m
    reach = abs(v) * dt + radius + 1e-9
    reach2 = reach * reach
    idx = np.empty(edges.shape[0], dtype=np.int64)
    n = 0
    dmin = math.inf
    for k in range(edges.shape[0]):
        if edge_near(bbox, k, x, y, reach2):
            idx[n] = k
            n += 1
            dmin = min(dmin, segment_distance(edges[k, 0] - x, edges[k, 1] - y, edges[k, 2] - edges[k, 0],
                                       edges[k, 3] - edges[k, 1]))  # fmt: skip
    near = _NearEdges(edges, idx, n)
    first = substeps
    if v != 0.0 and not dmin > radius + abs(v) * dt * (1.0 + 1e-9) + 1e-9:
        first = _sweep(x, y, th, v, w, substeps * m, piece, radius, near) // m
    rest = substeps - first
    vi = v
    # durations that sum to dt exactly: t2 = dt - t1 is exact when t1 >= dt / 2 (Sterbenz), else t1 is
    # recomputed as dt - t2, exact since t2 > dt / 2
    t1, t2 = dt, 0.0
    if rest == substeps:
        t1, t2 = 0.0, dt
    elif rest:
        t1 = dt * first / substeps
        t2 = dt - t1
        if t1 < 0.5 * dt:
            t1 = dt - t2
    err, w_lo, w_hi = 0.0, math.inf, -math.inf
    th0 = th
    if t1 > 0.0:
        x, y, th, err = advance(x, y, th, v, w, t1)
        w_lo, w_hi = yaw_rate_bounds(th0, th, t1)
    pieces[0, 0], pieces[0, 1], pieces[0, 2] = v, t1, th
    if rest:
        vi = 0.0
        for f in fractions:
            if _sweep(x, y, th, v * f, w, rest * m, piece, radius, near) == rest * m:
                vi = v * f
                break
        th0 = th
        x, y, th, e2 = advance(x, y, th, vi, w, t2)
        err = add_up(err, e2)
        lo, hi = yaw_rate_bounds(th0, th, t2)
        w_lo, w_hi = min(w_lo, lo), max(w_hi, hi)
    pieces[1, 0], pieces[1, 1], pieces[1, 2] = vi, t2, th
    pose[0], pose[1], pose[2] = x, y, th
    return first, vi, err, w_lo, w_hi


__all__ = [
    "robot_step_kernel",
]
