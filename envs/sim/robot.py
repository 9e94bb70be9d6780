"""A disc robot in a world of walls, moved by pymunk (default) or by exact unicycle kinematics.

Both dynamics share one interface (:class:`RobotSim`): :meth:`~RobotSim.step` advances one step and leaves
behind rigorous hulls of the true forward velocity (:attr:`~RobotSim.speed_hull`), leftward velocity
(:attr:`~RobotSim.lateral_hull`) and yaw rate (:attr:`~RobotSim.yaw_hull`) over the whole step, the true
pose and a proved bound on its position error (:attr:`~RobotSim.pose_error`). Each is the data contract of
the guaranteed observer (:mod:`digslam.observer.record.mission`): ``x' = R(psi) v`` with ``v = (v_1, v_2)``
inside the hulls at every instant.

**pymunk** (``dynamics="pymunk"``, the default). The robot is a pymunk body (a disc of mass 1 and the moment
of a uniform disc of radius ``radius``) driven the way pymunk's own top-down examples drive one: a kinematic
control body pulls it through a ``PivotJoint`` (``max_bias = 0``: a pure velocity constraint; ``max_force``:
the drive's force limit, so the body has inertia and lags the command) and a ``GearJoint`` (``max_bias = 0``,
``max_force = max_torque``). Each substep the control body's velocity is set from the command ``(v, omega)``
in the body frame: ``v`` along the body's current heading, ``omega`` its angular velocity. Walls are static
``pymunk.Segment`` shapes with friction (:data:`WALL_FRICTION`) and no elasticity, so the robot skids along
them and friction turns it; contacts are pymunk's. The body's velocity may lag its heading and slide along
walls: the record's lateral velocity and the rigorous hulls below bound that motion. The collision circle
has radius ``radius + skin``. A step of ``dt`` seconds runs ``substeps`` pymunk steps whose durations are
exact floats summing exactly to ``dt`` (:func:`.dynamics_jit.substep_times`);
while the space has no queued work they call chipmunk's step and body accessors directly (``Space.step``'s
C call without its Python bookkeeping: the same states, bit for bit).
The truth is the piecewise-linear path through the states read back after each substep (:mod:`.dynamics_jit`:
exact by definition, so ``pose_error = 0``); its body-frame velocity and yaw rate are bounded rigorously over
the step (:func:`.dynamics_jit.step_bounds`), and so is the odometry increment (:attr:`~RobotSim.mean_hull`:
the velocity averaged over the step in the body frame at its start, tight when inertia or a contact changes
the velocity within the step, where the hulls are as wide as the change); the heading over the step lies in
the hull of the substep headings and moves linearly between them, at a rate inside the yaw-rate hull. **The
premise by construction**: after every substep the disc of radius ``radius`` centred anywhere on the segment
from the previous state must be proved off every wall (:func:`.dynamics_jit.substep_clear`, rigorous float
geometry that also catches tunnelling through thin walls; away from walls the cheaper
:func:`.dynamics_jit.free_radius` proves it for the whole step). If it is not, the substep is undone: the body
goes back to the previous state with zero velocity and angular velocity (a hard stop) and
:attr:`~RobotSim.stops` counts it. The skin keeps pymunk's contacts off the disc, so hard stops are rare
(``tests/envs/sim/test_dynamics.py``). A bump is a contact that begins while the robot touched no wall
(pymunk's collision ``begin``).

**The drive's limits in the solver** (:func:`drive_limits`, when the robot is given its speed limits ``V =
max_speed``, ``Ω = max_yaw_rate``). pymunk solves the contacts before the joints in each of its ``n``
iterations; against a wall the two trade impulse, about ``m v_n`` an iteration (``v_n`` the speed into the
wall), until the pivot reaches its limit ``F τ``, and until then the joint's velocity wins: the disc closes in
by about ``F τ² / (n m)`` before the contact holds, and a stiff drive (``F = 10⁴ N``) pushes it through the
skin into the guard's hard stops. A limit beyond saturation, the impulse that takes the body from any velocity
up to ``max(V, r Ω)`` (yaw rate ``max(Ω, V / r)``) to any command within a substep, ``F_sat = m (V + max(V,
r Ω)) / τ`` and ``T_sat = I (Ω + max(Ω, V / r)) / τ``, moves the body in free motion as ``F_sat`` does; at a
wall, whose rigid contact takes whatever the drive pushes and whose Coulomb friction scales with it, the
motion depends on the two limits mostly through their ratio. So the joints get ``(k F, k T)``, ``k = min(1,
max(F_sat / F, T_sat / T))``, the least common scale that keeps both saturated, and the force is then capped
at ``max(F_sat, n m skin / (4 τ²))``, an overlap of a quarter of the skin. The default drive (``F = T = 50``
at ``dt = 0.1 s``, 4 substeps: ``F_sat = 80``) keeps its limits. Measured: no hard stop under full-speed
ramming on every generator for limits from ``5e-324`` to ``1e300``; against pymunk run to convergence (6000
iterations, ``F = 10⁴``, limits unscaled) within 3 mm (``T = 10⁴``), 2.5 cm and 0.05 rad (``T = 50``, where
friction's torque beats the steering and turns the robot to face the wall) over 4 s of ramming and sliding
(``tests/envs/sim/test_stiff_drive.py``). The guard still proves every substep.

**unicycle** (``dynamics="unicycle"``, the thesis's missions' model). Exact unicycle kinematics, blocked
(never sliding) by the world's walls: the robot follows the exact arcs of :mod:`.arc_jit` at constant speed
``v_i`` with ``psi`` linear over each piece, so ``x' = v (cos psi, sin psi)`` holds at every instant and
``v_2 = 0``. The heading the simulator stores is the true heading; the position it stores is within
:attr:`RobotSim.pose_error` (a proved, accumulated bound) of the true one. ``v_i`` is the commanded speed up
to the first substep whose sweep is blocked; the rest of the step runs, as one arc, at that speed scaled by
the largest fraction in ``(1/2, 1/4, 1/8, 0)`` whose sweep is clear. A sweep is checked at the midpoints of
``m`` equal pieces of the arc with a margin of half a piece's travel (every point of the arc lies within that
of a midpoint), so the nominal disc never overlaps an obstacle and never tunnels. Rotation in place is always
allowed (the disc does not move). A bump is a step that gets blocked after an unblocked one. Each step runs
compiled (:mod:`.robot_jit`). The pymunk space is still built and kept in sync, for reference ray casting
(``benchmarks/bench_env.py``).
"""

from __future__ import annotations

import math

import numpy as np
import pymunk

from digslam.envs.config import DYNAMICS
from digslam.envs.sim import geometry_jit as gjit
from digslam.envs.sim.dynamics_jit import free_radius, step_bounds_free, substep_clear, substep_times
from digslam.envs.sim.noise_jit import MEASURE_LATERAL, MEASURE_MEAN
from digslam.envs.sim.robot_jit import robot_step_kernel
from digslam.envs.sim.world import World

ROBOT_TYPE, WALL_TYPE = 1, 2
#: Fractions of the commanded speed tried, in order, when a substep's sweep is blocked (unicycle).
FRACTIONS = (1.0, 0.5, 0.25, 0.125)
#: Sweep check points per substep (unicycle).
SWEEP_POINTS = 4
#: Friction coefficients of the walls and of the robot (pymunk multiplies them: 0.5 at a contact).
WALL_FRICTION, ROBOT_FRICTION = 0.5, 1.0
_FRACTIONS = np.array(FRACTIONS[1:])
_NAN_PIECES = np.full((2, 3), np.nan)
_NAN_PIECES.flags.writeable = False
#: How far (m) the guard's fast path looks around a step's start; ``_GROW`` covers an L1 norm's rounding.
_FREE_REACH, _GROW = 1.0, 1.0 + 2.0**-50
# chipmunk's calls behind pymunk's ``Space.step`` and body accessors, made directly in the substep loop (the
# same C calls on the same values, without pymunk's Python wrappers; see ``RobotSim._step_pymunk``). They are
# pymunk internals: a pymunk without them (or without the space's queue attributes) takes the public path.
try:
    from pymunk._chipmunk import lib as _cp

    _CP_STEP, _CP_SET_V, _CP_SET_W = _cp.cpSpaceStep, _cp.cpBodySetVelocity, _cp.cpBodySetAngularVelocity
    _CP_GET_P, _CP_GET_A = _cp.cpBodyGetPosition, _cp.cpBodyGetAngle
    _DIRECT = True
except (ImportError, AttributeError):  # pragma: no cover - another pymunk
    _DIRECT = False
#: The queues ``Space.step`` works through after chipmunk's step (the direct path needs them empty).
_QUEUES = ("_bodies_to_check", "_add_later", "_remove_later", "_post_step_callbacks", "_removed_shapes")


def _quiet(space: pymunk.Space) -> bool | None:
    """Whether ``space`` has nothing queued for ``Space.step``'s Python bookkeeping (None: a pymunk whose
    internals differ, so the direct path is off)."""
    try:
        return not (space.threaded or any(getattr(space, q) for q in _QUEUES))
    except AttributeError:  # pragma: no cover - another pymunk
        return None


def drive_limits(max_force: float, max_torque: float, mass: float, moment: float, radius: float,
                 max_speed: float, max_yaw_rate: float, tau: float, skin: float, iterations: int
                 ) -> tuple[float, float]:  # fmt: skip
    """The limits ``(force, torque)`` the drive's joints get for substeps of ``tau`` seconds (see the module):
    ``(k F, k T)`` with ``k = min(1, max(F_sat / F, T_sat / T))``, the force then capped at ``max(F_sat, n m
    skin / (4 τ²))`` (``n = iterations``). Infinite speed limits give ``(F, T)`` unchanged.

    Example (the default drive at ``dt = 0.1 s``, 4 substeps: below saturation; a stiff one: scaled):
        >>> drive_limits(50.0, 50.0, 1.0, 0.02, 0.2, 1.0, 1.0, 0.025, 0.0375, 20)
        (50.0, 50.0)
        >>> [round(x, 6) for x in drive_limits(1e4, 1e4, 1.0, 0.02, 0.2, 1.0, 1.0, 0.025, 0.0375, 20)]
        [80.0, 80.0]
    """
    v, w = max_speed, max_yaw_rate
    f_sat = mass * (v + max(v, radius * w)) / tau
    t_sat = moment * (w + max(w, v / radius)) / tau
    k = max(f_sat / max_force, t_sat / max_torque)
    force, torque = max_force, max_torque
    if k < 1.0:  # both beyond saturation (k = 0: both infinite)
        force, torque = (max_force * k, max_torque * k) if k > 0.0 else (f_sat, t_sat)
    return min(force, max(f_sat, iterations * mass * skin / (4.0 * tau * tau))), torque


class RobotSim:
    """The robot: pymunk dynamics with a premise guard, or exact unicycle kinematics (see the module).

    Args:
        world: Ground-truth world; each edge becomes a static ``pymunk.Segment``.
        radius: Robot radius (m): the disc the premise keeps off every wall.
        pose: Start pose ``(x, y, theta)``.
        max_force, max_torque: Force and torque limits of the drive (pymunk dynamics, through
            :func:`drive_limits`; for the unicycle, the joints' limits in the reference loop).
        skin: Extra radius of the pymunk collision disc.
        dynamics: ``"pymunk"`` (default) or ``"unicycle"``.
        max_speed, max_yaw_rate: Bounds of the commanded speed (m/s) and yaw rate (rad/s), which size the
            joints' limits (:func:`drive_limits`); infinite (the default): the joints get ``max_force`` and
            ``max_torque`` as they are.
    """

    def __init__(
        self,
        world: World,
        radius: float,
        pose: np.ndarray,
        max_force: float = 50.0,
        max_torque: float = 50.0,
        skin: float = 0.02,
        dynamics: str = "pymunk",
        max_speed: float = math.inf,
        max_yaw_rate: float = math.inf,
    ) -> None:
        if dynamics not in DYNAMICS:
            raise ValueError(f"dynamics: must be one of {DYNAMICS}, got {dynamics!r}")
        self.dynamics = dynamics
        self.space = pymunk.Space()
        self.space.collision_slop = 1e-4
        self.space.iterations = 20
        walls = []
        for x1, y1, x2, y2 in world.edges.tolist():
            if x1 == x2 and y1 == y2:
                continue
            seg = pymunk.Segment(self.space.static_body, (x1, y1), (x2, y2), 0.0)
            seg.collision_type, seg.friction, seg.elasticity = WALL_TYPE, WALL_FRICTION, 0.0
            walls.append(seg)
        self.space.add(*walls)
        mass = 1.0
        self.body = pymunk.Body(mass, pymunk.moment_for_circle(mass, 0, radius))
        self.body.position = (float(pose[0]), float(pose[1]))
        self.body.angle = float(pose[2])
        self.shape = shape = pymunk.Circle(self.body, radius + skin)
        shape.collision_type, shape.friction, shape.elasticity = ROBOT_TYPE, ROBOT_FRICTION, 0.0
        self.control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        self.control.position, self.control.angle = self.body.position, self.body.angle
        self._pivot = pivot = pymunk.PivotJoint(self.control, self.body, (0, 0), (0, 0))
        pivot.max_bias, pivot.max_force = 0.0, float(max_force)
        self._gear = gear = pymunk.GearJoint(self.control, self.body, 0.0, 1.0)
        gear.max_bias, gear.max_force = 0.0, float(max_torque)
        self.space.add(self.body, self.shape, self.control, pivot, gear)
        #: The drive's limits ``(force, torque)`` as given, and those its joints have now (pymunk: set at
        #: each step length from :func:`drive_limits`).
        self.max_force, self.max_torque = float(max_force), float(max_torque)
        self.drive = (self.max_force, self.max_torque)
        self._limits = (float(max_speed), float(max_yaw_rate), float(skin))
        #: Bumps since construction; hard stops of the premise guard (pymunk).
        self.bumps, self.stops = 0, 0
        self._touching = 0
        if dynamics == "pymunk":
            self.space.on_collision(ROBOT_TYPE, WALL_TYPE, begin=self._begin, separate=self._separate)
        self.radius = float(radius)
        self.edges = np.ascontiguousarray(world.edges, dtype=np.float64)
        self.bbox = gjit.edge_boxes(self.edges)
        self._pose = np.array([float(pose[0]), float(pose[1]), float(pose[2])])
        self._v, self._w, self._lat, self._blocked = 0.0, 0.0, 0.0, False
        #: The odometry over the last step, ``(5, 2)`` rows ``[lo, hi]``: the hulls of the forward velocity,
        #: the leftward velocity and the yaw rate, then the odometry increment's two components (pymunk,
        #: :func:`.dynamics_jit.step_bounds`; the unicycle's lateral row is ``[0, 0]`` and its increment is
        #: not measured, ``[-inf, inf]``). Overwritten each step: copy what you keep.
        self.hulls = np.zeros((5, 2))
        #: The bits of :data:`.noise_jit.MEASURE_LATERAL` and :data:`.noise_jit.MEASURE_MEAN` this robot's
        #: record measures (pymunk: both; the unicycle: neither).
        self.measured = MEASURE_LATERAL | MEASURE_MEAN if dynamics == "pymunk" else 0
        if dynamics != "pymunk":
            self.hulls[3:] = (-math.inf, math.inf)
        #: The last step's pieces ``(v, tau, theta_end)`` (:mod:`.arc_jit`; unicycle; NaN under pymunk); at
        #: reset, at rest.
        self.pieces = np.array([[0.0, 0.0, self._pose[2]], [0.0, 0.0, self._pose[2]]])
        if dynamics == "pymunk":
            self.pieces = _NAN_PIECES
        #: The last step's path (pymunk): the states ``(S + 1, 3)`` (``x, y, angle`` before the step and
        #: after each substep) and the substep durations ``(S,)``; empty before the first step and under the
        #: unicycle. Fresh arrays each step, never written afterwards.
        self.states = np.zeros((0, 3))
        self.taus = np.zeros(0)
        #: Proved bound on ``max(|x - x_true|, |y - y_true|)`` of :attr:`pose` (the heading is exact; 0 under
        #: pymunk, whose stored states are the truth).
        self.pose_error = 0.0
        self._times: dict[tuple[float, int], tuple[np.ndarray, list[float], tuple[float, float]]] = {}
        #: The guard's fast path around the current pose (pymunk: :func:`.dynamics_jit.free_radius`, then
        #: computed at the end of each step for the next, :func:`.dynamics_jit.step_bounds_free`).
        self._free = 0.0
        if dynamics == "pymunk":
            x, y = self._pose[0], self._pose[1]
            self._free = free_radius(x, y, self.radius, _FREE_REACH, self.edges, self.bbox)

    def _begin(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        if self._touching == 0:
            self.bumps += 1
        self._touching += 1

    def _separate(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        self._touching = max(self._touching - 1, 0)

    def step(self, v: float, omega: float, dt: float, substeps: int) -> int:
        """Advance ``dt`` seconds under command ``(v, omega)``; return the bumps that occurred.

        ``dt`` must be the exact time between the step's two records (:func:`.arc_jit.exact_duration`).
        Afterwards :attr:`speed_hull`, :attr:`lateral_hull` and :attr:`yaw_hull` bound the true body-frame
        velocity and yaw rate over the whole step (outward-rounded), :attr:`pose` is the true pose (within
        :attr:`pose_error`), and :attr:`states` / :attr:`taus` (pymunk) or :attr:`pieces` (unicycle) hold the
        step's exact motion.
        """
        if self.dynamics == "pymunk":
            return self._step_pymunk(float(v), float(omega), float(dt), int(substeps))
        return self._step_unicycle(float(v), float(omega), float(dt), int(substeps))

    def _step_pymunk(self, v: float, omega: float, dt: float, substeps: int) -> int:
        key = (dt, substeps)
        got = self._times.get(key)
        if got is None:  # the durations and drive limits of a step length, computed once (shared, read-only)
            taus = substep_times(dt, substeps)
            taus.flags.writeable = False
            if len(self._times) > 64:
                self._times.clear()
            v_max, w_max, skin = self._limits
            body = self.body
            drive = drive_limits(self.max_force, self.max_torque, body.mass, body.moment, self.radius, v_max,
                                 w_max, dt / substeps, skin, self.space.iterations)  # fmt: skip
            got = self._times[key] = (taus, taus.tolist(), drive)
        taus, tau_list, drive = got
        if drive != self.drive:
            self._pivot.max_force, self._gear.max_force = self.drive = drive
        x, y, a = self._pose.tolist()
        x0, y0, flat = x, y, [x, y, a]  # the states, row after row
        space, body, control = self.space, self.body, self.control
        # pymunk's Space.step is chipmunk's step plus Python bookkeeping that has nothing to do while the
        # space's queues are empty (no body added or changed, nothing deferred, no threads): then the substeps
        # call chipmunk directly, locking the space as Space.step does (the same C calls, the same results);
        # else they go through Space.step. (The robot's collision callbacks defer nothing.)
        direct = _DIRECT and bool(_quiet(space))
        if direct:
            cp_space, cp_body, cp_control = space._space, body._body, control._body
        radius, edges, bbox = self.radius, self.edges, self.bbox
        # the fast path of the guard: a substep whose ends lie within `free` of the start is clear
        free = self._free
        inside = free > 0.0
        bumps = self.bumps
        if direct:
            _CP_SET_W(cp_control, omega)
        else:
            control.angular_velocity = omega
        for tau in tau_list:
            if direct:
                _CP_SET_V(cp_control, (v * math.cos(a), v * math.sin(a)))
                space._locked = True
                try:
                    _CP_STEP(cp_space, tau)
                finally:
                    space._locked = False
                p = _CP_GET_P(cp_body)
                x1, y1, a1 = p.x, p.y, _CP_GET_A(cp_body)
            else:  # pymunk's public path
                control.velocity = (v * math.cos(a), v * math.sin(a))
                space.step(tau)
                (x1, y1), a1 = body.position, body.angle
            near = (abs(x1 - x0) + abs(y1 - y0)) * _GROW < free  # |p1 - p0| < free, rounding included
            ok = a1 - a1 == 0.0 and ((inside and near) or substep_clear(x, y, x1, y1, radius, edges, bbox))
            if not ok:  # (a NaN or infinite state is never ok) undo the substep: a hard stop
                self.stops += 1
                x1, y1, a1, near = x, y, a, inside
                body.position, body.angle = (x, y), a
                body.velocity, body.angular_velocity = (0.0, 0.0), 0.0
            x, y, a, inside = x1, y1, a1, near
            flat += x, y, a
        if direct and (space._add_later or space._remove_later or space._post_step_callbacks):
            raise RuntimeError("step: a collision callback deferred work on the robot's space")
        states = np.array(flat).reshape(-1, 3)
        self._pose[0], self._pose[1], self._pose[2] = x, y, a
        # the hulls, and the next step's fast path around the end pose
        self._free = step_bounds_free(states, taus, self.hulls, radius, _FREE_REACH, edges, bbox)
        # the true velocity at the step's end (floats): the last substep's, in the body frame at angle a_S
        tau, (xp, yp, ap) = tau_list[-1], flat[-6:-3]
        ux, uy = (x - xp) / tau, (y - yp) / tau
        c, s = math.cos(a), math.sin(a)
        self._v, self._lat, self._w = c * ux + s * uy, c * uy - s * ux, (a - ap) / tau
        self.states, self.taus = states, taus
        return self.bumps - bumps

    def _step_unicycle(self, v: float, omega: float, dt: float, substeps: int) -> int:
        first, vi, err, w_lo, w_hi = robot_step_kernel(
            self._pose,
            v,
            omega,
            dt,
            substeps,
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
        h = self.hulls
        if rest and first:
            h[0, 0], h[0, 1] = min(v, vi), max(v, vi)
        else:
            h[0, 0] = h[0, 1] = vi if rest else v
        self._v, self._w = (vi if rest else v), 0.5 * (w_lo + w_hi)
        h[2, 0], h[2, 1] = w_lo, w_hi
        self.body.position = (float(self._pose[0]), float(self._pose[1]))
        self.body.angle = float(self._pose[2])
        return int(bumped)

    @property
    def speed_hull(self) -> tuple[float, float]:
        """Hull of the true forward velocity over the last step (m/s)."""
        return float(self.hulls[0, 0]), float(self.hulls[0, 1])

    @property
    def lateral_hull(self) -> tuple[float, float]:
        """Hull of the true leftward velocity over the last step (m/s; ``(0, 0)`` for the unicycle)."""
        return float(self.hulls[1, 0]), float(self.hulls[1, 1])

    @property
    def yaw_hull(self) -> tuple[float, float]:
        """Hull of the true yaw rate over the last step (rad/s)."""
        return float(self.hulls[2, 0]), float(self.hulls[2, 1])

    @property
    def mean_hull(self) -> tuple[tuple[float, float], tuple[float, float]] | None:
        """Bounds ``((v̄_1⁻, v̄_1⁺), (v̄_2⁻, v̄_2⁺))`` of the velocity averaged over the last step in the body
        frame at its start (pymunk); None under the unicycle, which does not measure it."""
        if not self.measured & MEASURE_MEAN:
            return None
        h = self.hulls
        return (float(h[3, 0]), float(h[3, 1])), (float(h[4, 0]), float(h[4, 1]))

    @property
    def pose(self) -> np.ndarray:
        """True pose ``(x, y, theta)`` with a continuous (unwrapped) heading."""
        return self._pose.copy()

    @property
    def speed(self) -> float:
        """True forward velocity ``v_1`` at the step's end (m/s; unicycle: the speed of the last piece)."""
        return self._v

    @property
    def lateral(self) -> float:
        """True leftward velocity ``v_2`` at the step's end (m/s; 0 for the unicycle)."""
        return self._lat

    @property
    def yaw_rate(self) -> float:
        """True yaw rate at the step's end (rad/s): pymunk, the last substep's (to within float rounding);
        unicycle, the middle of :attr:`yaw_hull` (the exact rates are ``(theta_end - theta_start) / tau`` of
        :attr:`pieces`), to within an ulp."""
        return self._w


__all__ = [
    "FRACTIONS",
    "ROBOT_TYPE",
    "ROBOT_FRICTION",
    "SWEEP_POINTS",
    "WALL_FRICTION",
    "WALL_TYPE",
    "RobotSim",
    "drive_limits",
]
