"""A disc robot with exact unicycle kinematics, blocked (never sliding) by the world's walls.

Motion model (the data contract of the guaranteed observer, see :mod:`.missions`): the robot follows the exact
arcs of :mod:`.arc` at constant speed ``v_i`` with ``ψ`` linear over each piece, so ``ẋ = v (cos ψ, sin ψ)``
holds at every instant. The heading the simulator stores is the true heading; the position it stores is within
:attr:`RobotSim.pose_error` (a proved, accumulated bound) of the true one. ``v_i`` is the commanded speed up
to the first substep whose sweep is blocked; the rest of the step runs, as one arc, at that speed scaled by
the largest fraction in ``(1/2, 1/4, 1/8, 0)`` whose sweep is clear. A sweep is checked at the midpoints of
``m`` equal pieces of the arc with a margin of half a piece's travel (every point of the arc lies within that
of a midpoint), so the nominal disc never overlaps an obstacle and never tunnels. Rotation in place is always
allowed (the disc does not move). A bump is a step that gets blocked after an unblocked one. Each step runs
compiled (:mod:`.robot_jit`).

An earlier version drove the robot through pymunk joints: the body's velocity then lagged its heading (by up
to 0.5 rad on reversals) and slid along walls, motions that no unicycle with the recorded heading explains,
so the observer's tube could miss the truth. The pymunk space (walls, body, control body and joints) is
still built and kept in sync, for reference ray casting (``benchmarks/bench_env.py``).
"""

from __future__ import annotations

import math

import numpy as np
import pymunk

from digslam.envs.sim import geometry_jit as gjit
from digslam.envs.sim.robot_jit import robot_step_kernel
from digslam.envs.sim.world import World

ROBOT_TYPE, WALL_TYPE = 1, 2
#: Fractions of the commanded speed tried, in order, when a substep's sweep is blocked.
FRACTIONS = (1.0, 0.5, 0.25, 0.125)
#: Sweep check points per substep.
SWEEP_POINTS = 4
_FRACTIONS = np.array(FRACTIONS[1:])


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
        self.radius = float(radius)
        self.edges = np.ascontiguousarray(world.edges, dtype=np.float64)
        self.bbox = gjit.edge_boxes(self.edges)
        self._pose = np.array([float(pose[0]), float(pose[1]), float(pose[2])])
        self._v, self._w, self._blocked = 0.0, 0.0, False
        self.speed_hull: tuple[float, float] = (0.0, 0.0)
        self.yaw_hull: tuple[float, float] = (0.0, 0.0)
        #: The last step's pieces ``(v, tau, theta_end)`` (:mod:`.arc`); at reset, at rest.
        self.pieces = np.array([[0.0, 0.0, self._pose[2]], [0.0, 0.0, self._pose[2]]])
        #: Proved bound on ``max(|x - x_true|, |y - y_true|)`` of :attr:`pose` (the heading is exact).
        self.pose_error = 0.0

    def _on_bump(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        pass  # contacts of the reference pymunk loop (benchmarks) are not the robot's bumps

    def step(self, v: float, omega: float, dt: float, substeps: int) -> int:
        """Advance ``dt`` seconds under command ``(v, omega)``; return the bumps that occurred.

        ``dt`` must be the exact time between the step's two records (:func:`.arc.exact_duration`). The
        substeps before the first blocked one run at full speed; the rest of the step runs at the largest
        fraction of :data:`FRACTIONS` (or 0) whose sweep is clear, as one arc (compiled,
        :func:`.robot_jit.robot_step_kernel`). Afterwards :attr:`speed_hull` and :attr:`yaw_hull` bound the
        true speed and yaw rate over the whole step (the yaw rate outward-rounded), :attr:`pieces` holds the
        step's pieces ``(v, tau, theta_end)`` and :attr:`pose_error` the accumulated position-error bound.
        """
        v, omega = float(v), float(omega)
        first, vi, err, w_lo, w_hi = robot_step_kernel(
            self._pose,
            v,
            omega,
            float(dt),
            int(substeps),
            SWEEP_POINTS,
            self.radius,
            self.edges,
            self.bbox,
            _FRACTIONS,
            self.pieces,
        )
        if err > 0.0:  # rounded upward: the sum stays a bound
            self.pose_error = math.nextafter(self.pose_error + err, math.inf)
        rest = substeps - first
        bumped = rest > 0 and not self._blocked
        if bumped:
            self.bumps += 1
        self._blocked = rest > 0
        if rest and first:
            self.speed_hull = (min(v, vi), max(v, vi))
        else:
            self.speed_hull = (vi, vi) if rest else (v, v)
        self._v, self._w = (vi if rest else v), 0.5 * (w_lo + w_hi)
        self.yaw_hull = (w_lo, w_hi)
        self.body.position = (float(self._pose[0]), float(self._pose[1]))
        self.body.angle = float(self._pose[2])
        return int(bumped)

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
        """True yaw rate (rad/s), to within an ulp: the middle of :attr:`yaw_hull` (the exact rates are
        ``(theta_end - theta_start) / tau`` of :attr:`pieces`)."""
        return self._w


__all__ = ["FRACTIONS", "ROBOT_TYPE", "SWEEP_POINTS", "WALL_TYPE", "RobotSim"]
