"""A stiff drive rams walls without hard stops (issue #35, item 5).

pymunk solves contacts before joints in each iteration, so a drive whose impulse limit per substep beats what
the contact takes in those iterations pushes the disc through the collision skin, and the premise guard
stops it dead. The simulator gives the joints limits sized from the speed limits
(:func:`digslam.envs.sim.robot.drive_limits`). These tests ram full speed into walls, straight and turning,
on every generator, at drive limits across what the config accepts, and count the guard's hard stops
(``RobotSim.stops``); they check that the scaled limits change nothing below saturation and that a stiff drive
moves as pymunk run to convergence moves it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from premise import PremiseChecker

from digslam.envs import ExploreEnv, World
from digslam.envs.sim.robot import RobotSim, drive_limits

WORLDS = ("room", "rocks", "caves", "rooms")
#: Drive limits ``(max_force, max_torque)`` across the accepted range (finite, positive): the default, the
#: issue's, either one stiff, both extreme, one extreme and the other negligible.
LIMITS = [(50.0, 50.0), (1e4, 1e4), (1e4, 50.0), (50.0, 1e4), (1e300, 1e300), (1e300, 1e-3), (1e-3, 1e300),
          (5e-324, 1e300), (1e3, 1.0)]  # fmt: skip


def _ram(env: ExploreEnv, seed: int, steps: int, turn: str) -> int:
    """Full speed ahead from the start of ``reset(seed)``: ``straight`` with a new heading now and then, or
    ``weave`` (always turning); returns the hard stops."""
    env.reset(seed=seed)
    for k in range(steps):
        if turn == "straight":
            w = 0.0 if k % 50 < 35 else (1.0 if seed % 2 else -1.0)
        else:
            w = 0.6 * math.sin(k / 5.0)
        env.step(np.array([1.0, w]))
    assert env.sim is not None
    return env.sim.stops


def test_the_issue_reproduction_stops_no_more() -> None:
    """The reproduction of issue #35: a 10⁴ N drive driven full speed into the room's wall (10 hard stops
    before, the first at step 11)."""
    env = ExploreEnv(max_force=1e4, max_torque=1e4, start=(7.5, -5.0, 0.0), room_jitter=0.0)
    env.reset(seed=930900)
    for _ in range(40):
        env.step(np.array([1.0, 0.0]))
    assert env.sim is not None
    assert env.sim.bumps >= 1 and env.sim.stops == 0
    assert env.sim.pose[0] > 8.4  # it reached the wall (x = 8.75 less the radius and the skin)


@pytest.mark.parametrize("limits", LIMITS, ids=[f"{f:g}-{t:g}" for f, t in LIMITS])
def test_no_hard_stop_at_any_drive_limit_on_every_generator(limits: tuple[float, float]) -> None:
    force, torque = limits
    for world in WORLDS:
        env = ExploreEnv(world=world, n_obstacles=12, max_force=force, max_torque=torque)
        for seed, turn in ((6, "weave"), (7, "straight")):
            assert _ram(env, seed, 150, turn) == 0, (world, seed, turn)
            assert env.sim is not None  # it did ram a wall (a drive under 1 N barely moves)
            assert env.sim.bumps >= (1 if force >= 1.0 else 0), (world, seed, turn)


@pytest.mark.expensive
@pytest.mark.parametrize("extra", [{"substeps": 1}, {"substeps": 16}, {"dt": 0.5}, {"dt": 0.02},
                                   {"max_speed": 3.0, "max_yaw_rate": 3.0}, {"robot_radius": 0.5},
                                   {"max_yaw_rate": 10.0}])  # fmt: skip
@pytest.mark.parametrize("limits", [(1e4, 1e4), (1e4, 50.0), (1e300, 1e300)])
def test_no_hard_stop_under_other_steps_and_speeds(extra: dict, limits: tuple[float, float]) -> None:
    force, torque = limits
    for world in WORLDS:
        env = ExploreEnv(world=world, n_obstacles=12, max_force=force, max_torque=torque, **extra)
        for seed, turn in ((5, "straight"), (6, "weave"), (7, "straight")):
            assert _ram(env, seed, 200, turn) == 0, (world, seed, extra, limits)


def test_limits_below_saturation_are_kept() -> None:
    """The default drive (and any with one limit below saturation and the force under the cap) keeps its
    limits; beyond saturation both scale by one factor, the force capped by the skin."""
    m, i, r, v, w, tau, skin = 1.0, 0.02, 0.2, 1.0, 1.0, 0.025, 0.0375
    assert drive_limits(50.0, 50.0, m, i, r, v, w, tau, skin, 20) == (50.0, 50.0)
    capped = drive_limits(1e4, 1.0, m, i, r, v, w, tau, skin, 20)  # the force capped at n m skin / (4 tau²)
    assert capped == pytest.approx((300.0, 1.0))
    f, t = drive_limits(1e4, 1e4, m, i, r, v, w, tau, skin, 20)
    assert f == pytest.approx(80.0) and t == pytest.approx(80.0)  # F_sat = m (v + v) / tau
    f, t = drive_limits(1e4, 50.0, m, i, r, v, w, tau, skin, 20)
    assert t == pytest.approx(4.8) and f == pytest.approx(300.0)  # T_sat = I (w + v / r) / tau; F capped
    assert drive_limits(math.inf, math.inf, m, i, r, v, w, tau, skin, 20) == pytest.approx((80.0, 4.8))
    assert drive_limits(1e4, 1e4, m, i, r, math.inf, math.inf, tau, skin, 20) == (1e4, 1e4)  # no speed limits
    env = ExploreEnv()
    env.reset(seed=0)
    env.step(np.array([1.0, 0.5]))
    assert env.sim is not None and env.sim.drive == (50.0, 50.0)
    assert {c.max_force for c in env.sim.space.constraints} == {50.0}


_FRAME = np.array([(-5.0, -5.0), (5.0, -5.0), (5.0, 5.0), (-5.0, 5.0)])


def _slide(force: float, torque: float, heading: float, turn: float, iterations: int | None) -> RobotSim:
    """Full speed at ``heading`` (degrees) into the wall x = 5, turning at ``turn``, then reversing the turn;
    ``iterations`` given: pymunk's solver with that many iterations and the limits as they are."""
    world = World((-5, -5, 5, 5), [_FRAME])
    speeds = {} if iterations else {"max_speed": 1.0, "max_yaw_rate": 1.0}
    sim = RobotSim(world, 0.2, np.array([3.5, 0.0, math.radians(heading)]), force, torque, 0.0375, **speeds)
    if iterations:
        sim.space.iterations = iterations
    return sim


@pytest.mark.parametrize("limits", [(1e4, 1e4), (1e4, 50.0), (1e4, 1.0)])
def test_a_stiff_drive_moves_as_the_converged_solver_moves_it(limits: tuple[float, float]) -> None:
    """Against pymunk run to convergence (6000 iterations, no scaling, itself free of hard stops): the scaled
    drive keeps within 3 cm and 0.06 rad over 4 s of ramming and sliding along a wall, also when friction's
    torque beats the steering (``T = 50``: the robot is turned to face the wall); the disc keeps off the wall
    (exact check of every substep)."""
    chk = PremiseChecker(World((-5, -5, 5, 5), [_FRAME]).edges, radius=0.2, ranges=False)
    for heading, turn in ((30.0, 0.0), (60.0, 0.0), (20.0, 0.5)):
        sims = _slide(*limits, heading, turn, None), _slide(*limits, heading, turn, 6000)
        dev, dpsi = 0.0, 0.0
        for k in range(40):
            for sim in sims:
                sim.step(1.0, turn if k < 30 else -1.0, 0.1, 4)
            chk.check_path(sims[0].states, sims[0].taus)
            dev = max(dev, float(np.abs(sims[0].pose[:2] - sims[1].pose[:2]).max()))
            dpsi = max(dpsi, abs(sims[0].pose[2] - sims[1].pose[2]))
        assert sims[0].stops == sims[1].stops == 0 and sims[0].bumps >= 1
        assert dev < 0.03 and dpsi < 0.06, (limits, heading, dev, dpsi)
        assert sims[0].pose[0] > 4.7  # pressed against the wall (x = 5 less the radius and the skin)
