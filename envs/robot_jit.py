"""Compiled step of the disc robot's blocked unicycle kinematics (the motion model of :mod:`.robot`).

:func:`robot_step_kernel` runs one step of :meth:`.robot.RobotSim.step` in machine code: the substeps
before the first blocked one run at the commanded speed, the rest of the step as one arc at the largest
fraction of it whose sweep is clear (or 0). A sweep is checked at the midpoints of ``m`` equal pieces of
each substep's arc: the disc there must keep ``radius`` plus half a piece's travel off every edge (every
point of the arc lies within that of a midpoint), so the nominal disc never overlaps an obstacle and never
tunnels. The edges checked are those whose bounding box lies within ``|v| dt + radius`` of the step's start:
every arc point of the step lies within ``|v| dt`` of it (an arc is never shorter than its chord), so no
edge that could block is left out. If the start's clearance exceeds ``radius + |v| dt`` the whole step is
clear without checking the arc.

Example (1 m/s for 4 substeps of 0.025 s at a wall 0.25 m ahead of a disc of radius 0.2: two substeps
run, then the disc touches the wall and stops):
    >>> import numpy as np
    >>> from digslam.envs.geometry_jit import edge_boxes
    >>> edges, pose, fractions = np.array([[0.25, -1.0, 0.25, 1.0]]), np.zeros(3), np.array([0.5, 0.25])
    >>> robot_step_kernel(pose, 1.0, 0.0, 0.1, 4, 4, 0.2, edges, edge_boxes(edges), fractions)
    (2, 0.0)
    >>> pose.tolist()
    [0.05, 0.0, 0.0]
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.jit import njit

from .geometry_jit import _near, _seg_dist


@njit(inline="always")
def _arc(x: float, y: float, th: float, v: float, w: float, tau: float) -> tuple[float, float, float]:
    """Exact unicycle pose after ``tau`` s of constant ``(v, w)`` (the formulas of :func:`.robot.arc`)."""
    th2 = th + w * tau
    if abs(w) < 1e-12:
        return x + v * tau * math.cos(th), y + v * tau * math.sin(th), th2
    k = v / w
    return x + k * (math.sin(th2) - math.sin(th)), y - k * (math.cos(th2) - math.cos(th)), th2


@njit(inline="always")
def _clear(x: float, y: float, edges: np.ndarray, idx: np.ndarray, n: int, need: float) -> bool:
    """Whether ``(x, y)`` lies at least ``need`` from each of the edges ``idx[:n]``."""
    for q in range(n):
        k = idx[q]
        ax, ay = edges[k, 0] - x, edges[k, 1] - y
        if _seg_dist(ax, ay, edges[k, 2] - edges[k, 0], edges[k, 3] - edges[k, 1]) < need:
            return False
    return True


@njit(inline="always")
def _sweep(x: float, y: float, th: float, v: float, w: float, pieces: int, piece: float, radius: float,
           edges: np.ndarray, idx: np.ndarray, n: int) -> int:  # fmt: skip
    """Index of the first blocked piece midpoint of the arc (``pieces`` if none is)."""
    need = radius + abs(v) * (0.5 * piece)
    for j in range(pieces):
        px, py, _ = _arc(x, y, th, v, w, (j + 0.5) * piece)
        if not _clear(px, py, edges, idx, n, need):
            return j
    return pieces


@njit
def robot_step_kernel(pose: np.ndarray, v: float, w: float, dt: float, substeps: int, m: int,
                      radius: float, edges: np.ndarray, bbox: np.ndarray,
                      fractions: np.ndarray) -> tuple[int, float]:  # fmt: skip
    """Advance ``pose`` (updated in place) by ``dt`` under command ``(v, w)``.

    Args:
        pose: ``(x, y, theta)``.
        v, w: Commanded speed and yaw rate.
        dt, substeps: Step duration and its number of substeps.
        m: Sweep check points per substep.
        radius: Disc radius.
        edges, bbox: The world's edges ``(E, 4)`` and their bounding boxes.
        fractions: Fractions of ``v`` tried, in order, once a substep is blocked.

    Returns:
        ``(first, vi)``: the substeps run at ``v``, and the speed of the remaining ``substeps - first``.
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
        if _near(bbox, k, x, y, reach2):
            idx[n] = k
            n += 1
            dmin = min(dmin, _seg_dist(edges[k, 0] - x, edges[k, 1] - y, edges[k, 2] - edges[k, 0],
                                       edges[k, 3] - edges[k, 1]))  # fmt: skip
    first = substeps
    if v != 0.0 and not dmin > radius + abs(v) * dt * (1.0 + 1e-9) + 1e-9:
        first = _sweep(x, y, th, v, w, substeps * m, piece, radius, edges, idx, n) // m
    if first:
        x, y, th = _arc(x, y, th, v, w, first * h)
    rest = substeps - first
    vi = v
    if rest:
        vi = 0.0
        for f in fractions:
            if _sweep(x, y, th, v * f, w, rest * m, piece, radius, edges, idx, n) == rest * m:
                vi = v * f
                break
        x, y, th = _arc(x, y, th, vi, w, rest * h)
    pose[0], pose[1], pose[2] = x, y, th
    return first, vi
