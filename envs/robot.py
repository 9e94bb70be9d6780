"""Pymunk physics: static walls from the world's edges and a disc robot driven by a unicycle command.

The robot is a dynamic circle pulled by a kinematic control body through a pivot joint (drive) and a gear
joint (steering), both with ``max_bias = 0`` and a finite force. The control body takes the commanded
velocities; the robot follows only as far as the walls allow, so it never tunnels (setting the robot's
velocity directly would). Pymunk detects contacts only once shapes overlap, by up to one substep's travel;
the collision disc is therefore the robot's radius plus a ``skin`` of that travel, so the nominal disc never
overlaps an obstacle. Bumps (new contacts with a wall) are counted.
"""

from __future__ import annotations

import math

import numpy as np
import pymunk

from .world import World

ROBOT_TYPE, WALL_TYPE = 1, 2


class RobotSim:
    """A pymunk space holding the world's walls and the robot.

    Args:
        world: Ground-truth world; each edge becomes a static ``pymunk.Segment``.
        radius: Robot radius (m).
        pose: Start pose ``(x, y, theta)``.
        max_force: Drive force limit (N).
        max_torque: Steering torque limit (N m).
        skin: Extra collision radius (m); at least the largest travel in one substep.
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
        self._touching = 0

    def _on_bump(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        self.bumps += 1

    def step(self, v: float, omega: float, dt: float, substeps: int) -> int:
        """Advance ``dt`` seconds under command ``(v, omega)``; return the bumps that occurred."""
        before = self.bumps
        h = dt / substeps
        self.control.angular_velocity = omega
        for _ in range(substeps):
            a = self.body.angle
            self.control.velocity = (v * math.cos(a), v * math.sin(a))
            self.space.step(h)
        return self.bumps - before

    @property
    def pose(self) -> np.ndarray:
        """True pose ``(x, y, theta)`` with a continuous (unwrapped) heading."""
        p = self.body.position
        return np.array([p.x, p.y, self.body.angle])

    @property
    def speed(self) -> float:
        """True forward speed (velocity projected on the heading, m/s)."""
        a = self.body.angle
        vel = self.body.velocity
        return vel.x * math.cos(a) + vel.y * math.sin(a)

    @property
    def yaw_rate(self) -> float:
        """True yaw rate (rad/s)."""
        return float(self.body.angular_velocity)
