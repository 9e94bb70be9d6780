"""A disc robot with exact unicycle kinematics, blocked (never sliding) by the world's walls.

Motion model (the data contract of the guaranteed observer, see :mod:`.missions`): the robot follows exact
arcs of constant ``(v_i, ω)``, so ``ẋ = v (cos ψ, sin ψ)`` holds at every instant with ``ψ`` linear. ``v_i``
is the commanded speed up to the first substep whose sweep is blocked; the rest of the step runs, as one arc,
at that speed scaled by the largest fraction in ``(1/2, 1/4, 1/8, 0)`` whose sweep is clear. A sweep is
checked at the midpoints of ``m`` equal pieces of the arc with a margin of half a piece's travel (every
point of the arc lies within that of a midpoint), so the nominal disc never overlaps an obstacle and never
tunnels. Rotation in place is always allowed (the disc does not move). A bump is a step that gets blocked
after an unblocked one.

An earlier version drove the robot through pymunk joints: the body's velocity then lagged its heading (by up
to 0.5 rad on reversals) and slid along walls, motions that no unicycle with the recorded heading explains,
so the observer's tube could miss the truth. The pymunk space (walls, body, control body and joints) is
still built and kept in sync, for reference ray casting (``benchmarks/bench_env.py``).
"""

from __future__ import annotations

import math

import numpy as np
import pymunk

from . import geometry as geo
from .world import World

ROBOT_TYPE, WALL_TYPE = 1, 2
#: Fractions of the commanded speed tried, in order, when a substep's sweep is blocked.
FRACTIONS = (1.0, 0.5, 0.25, 0.125)
#: Sweep check points per substep.
SWEEP_POINTS = 4


def arcs(pose: np.ndarray, v: float | np.ndarray, w: float, tau: np.ndarray) -> np.ndarray:
    """Exact unicycle poses ``(..., len(tau), 3)`` after ``tau`` s of constant ``(v, ω)`` from ``pose``
    (``v`` a scalar or an array of speeds, broadcast against ``tau``)."""
    x, y, th = (float(c) for c in pose)
    v = np.asarray(v, dtype=np.float64)[..., None] if np.ndim(v) else float(v)
    th2 = th + w * tau
    if abs(w) < 1e-12:
        px, py = x + v * tau * math.cos(th), y + v * tau * math.sin(th)
    else:
        k = v / w
        px, py = x + k * (np.sin(th2) - math.sin(th)), y - k * (np.cos(th2) - math.cos(th))
    th2 = np.broadcast_to(th2, np.shape(px))
    return np.stack([px, py, th2], axis=-1)


def arc(pose: np.ndarray, v: float, w: float, tau: float) -> np.ndarray:
    """:func:`arcs` for one scalar ``tau`` (plain floats, same formulas)."""
    x, y, th = (float(c) for c in pose)
    th2 = th + w * tau
    if abs(w) < 1e-12:
        return np.array([x + v * tau * math.cos(th), y + v * tau * math.sin(th), th2])
    k = v / w
    return np.array([x + k * (math.sin(th2) - math.sin(th)), y - k * (math.cos(th2) - math.cos(th)), th2])


class RobotSim:
    """The robot's exact kinematics, plus a pymunk space holding the world's walls and the robot.

    Args:
        world: Ground-truth world; each edge becomes a static ``pymunk.Segment``.
        radius: Robot radius (m).
        pose: Start pose ``(x, y, theta)``.
        skin: Extra radius of the pymunk collision disc (reference loop only; the kinematics use ``radius``).
        max_force, max_torque: Joint limits of the pymunk reference loop only.
    """

    def __init__(
        self,
        world: World,
        radius: float,
        pose: np.ndarray,
        max_force: float = 50.0,
        max_torque: float = 50.0,
        skin: float = 0.02,
    ) -> None:
        self.space = pymunk.Space()
        self.space.collision_slop = 1e-4
        self.space.iterations = 20
        walls = []
        for x1, y1, x2, y2 in world.edges.tolist():
            if x1 == x2 and y1 == y2:
                continue
            seg = pymunk.Segment(self.space.static_body, (x1, y1), (x2, y2), 0.0)
            seg.collision_type, seg.friction, seg.elasticity = WALL_TYPE, 0.0, 0.0
            walls.append(seg)
        self.space.add(*walls)
        mass = 1.0
        self.body = pymunk.Body(mass, pymunk.moment_for_circle(mass, 0, radius))
        self.body.position = (float(pose[0]), float(pose[1]))
        self.body.angle = float(pose[2])
        self.shape = pymunk.Circle(self.body, radius + skin)
        self.shape.collision_type, self.shape.friction, self.shape.elasticity = ROBOT_TYPE, 0.0, 0.0
        self.control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        self.control.position, self.control.angle = self.body.position, self.body.angle
        pivot = pymunk.PivotJoint(self.control, self.body, (0, 0), (0, 0))
        pivot.max_bias, pivot.max_force = 0.0, float(max_force)
        gear = pymunk.GearJoint(self.control, self.body, 0.0, 1.0)
        gear.max_bias, gear.max_force = 0.0, float(max_torque)
        self.space.add(self.body, self.shape, self.control, pivot, gear)
        self.bumps = 0
        self.space.on_collision(ROBOT_TYPE, WALL_TYPE, begin=self._on_bump)
        self.radius, self.edges, self.bbox = float(radius), world.edges, world.bbox
        self._pose = np.array([float(pose[0]), float(pose[1]), float(pose[2])])
        self._v, self._w, self._blocked = 0.0, 0.0, False
        self.speed_hull: tuple[float, float] = (0.0, 0.0)
        self.yaw_hull: tuple[float, float] = (0.0, 0.0)

    def _on_bump(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        pass  # contacts of the reference pymunk loop (benchmarks) are not the robot's bumps

    def _sweep_ok(self, pose: np.ndarray, vs: np.ndarray, w: float, tau: np.ndarray, piece: float,
                  edges: np.ndarray) -> np.ndarray:  # fmt: skip
        """``(len(vs), len(tau))``: whether the disc centred at the arc points ``tau`` (midpoints of pieces of
        duration ``piece``) keeps ``radius`` plus half a piece's travel off every edge."""
        mids = arcs(pose, vs, w, tau)
        d = geo.point_edge_distance(mids[..., :2].reshape(-1, 2), edges).reshape(len(vs), len(tau))
        return d >= self.radius + np.abs(vs)[:, None] * (0.5 * piece)

    def step(self, v: float, omega: float, dt: float, substeps: int) -> int:
        """Advance ``dt`` seconds under command ``(v, omega)``; return the bumps that occurred.

        The substeps before the first blocked one run at full speed; the rest of the step runs at the
        largest fraction of :data:`FRACTIONS` (or 0) whose sweep is clear, as one arc. Afterwards
        :attr:`speed_hull` and :attr:`yaw_hull` hold the hull of the true speed and yaw rate over the
        whole step.
        """
        before = self.bumps
        h = dt / substeps
        m = SWEEP_POINTS
        x, y = float(self._pose[0]), float(self._pose[1])
        edges = geo.edges_near(self.edges, self.bbox, x, y, abs(v) * dt + self.radius + 1e-9)
        first = substeps
        # fast path: every point of the step's arc lies within |v| dt of the start (a chord is never longer
        # than its arc), so a start clearance above radius + |v| dt clears the whole sweep
        clear = not len(edges) or float(geo.point_edge_distance(self._pose[None, :2], edges)[0]) > (
            self.radius + abs(v) * dt * (1.0 + 1e-9) + 1e-9
        )
        if v != 0.0 and not clear:
            tau = (np.arange(substeps * m) + 0.5) * (h / m)
            ok = self._sweep_ok(self._pose, np.array([v]), omega, tau, h / m, edges)[0]
            if not ok.all():
                first = int(np.argmin(ok)) // m
        used = [v] * first
        if first:
            self._pose = arc(self._pose, v, omega, first * h)
        rest = substeps - first
        if rest:
            vs = v * np.array(FRACTIONS[1:])
            tau = (np.arange(rest * m) + 0.5) * (h / m)
            ok = self._sweep_ok(self._pose, vs, omega, tau, h / m, edges).all(axis=1)
            vi = float(vs[int(np.argmax(ok))]) if ok.any() else 0.0
            self._pose = arc(self._pose, vi, omega, rest * h)
            used += [vi] * rest
            if not self._blocked:
                self.bumps += 1
        self._blocked = rest > 0
        self._v, self._w = used[-1], float(omega)
        self.speed_hull = (min(used), max(used))
        self.yaw_hull = (float(omega), float(omega))
        self.body.position = (float(self._pose[0]), float(self._pose[1]))
        self.body.angle = float(self._pose[2])
        return self.bumps - before

    @property
    def pose(self) -> np.ndarray:
        """True pose ``(x, y, theta)`` with a continuous (unwrapped) heading."""
        return self._pose.copy()

    @property
    def speed(self) -> float:
        """True forward speed (velocity projected on the heading, m/s)."""
        return self._v

    @property
    def yaw_rate(self) -> float:
        """True yaw rate (rad/s)."""
        return self._w
