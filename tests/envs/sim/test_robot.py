"""Robot physics: no tunnelling at full speed, bumps counted, concave obstacles kept exact."""

from __future__ import annotations

import math

import numpy as np
import pytest

from digslam.envs import ExploreEnv, World
from digslam.envs.sim.robot import RobotSim

PENETRATION_TOL = 1e-3  # m: the collision skin keeps the nominal disc off the walls


@pytest.mark.parametrize("world", ["room", "rocks", "caves", "rooms"])
def test_never_inside_an_obstacle_at_full_speed(world: str) -> None:
    env = ExploreEnv(world=world, max_speed=2.0)
    env.reset(seed=11)
    rng = np.random.default_rng(0)
    r = env.config.robot_radius
    for k in range(400):
        turn = 0.0 if k % 50 < 35 else float(rng.uniform(-1, 1))
        _, _, _, _, info = env.step(np.array([1.0, turn], dtype=np.float32))
        pose = info["truth"].pose
        assert env.world.clearance(pose[None, :2])[0] >= r - PENETRATION_TOL, (world, k, pose)
    assert info["bumps"] > 0


def test_head_on_into_a_wall_and_a_thin_sliver() -> None:
    frame = np.array([(-5.0, -5.0), (5.0, -5.0), (5.0, 5.0), (-5.0, 5.0)])
    sliver = np.array([(2.0, -3.0), (2.001, -3.0), (2.001, 3.0), (2.0, 3.0)])  # 1 mm thick wall
    world = World((-5, -5, 5, 5), [frame, sliver])
    sim = RobotSim(world, 0.2, np.array([0.0, 0.0, 0.0]), max_force=200.0, skin=5.0 * 0.1 / 4 * 1.5)
    for _ in range(100):
        bumps = sim.step(5.0, 0.0, 0.1, 4)  # 5 m/s, much faster than the env allows
        x = sim.pose[0]
        assert x <= 2.0 - 0.2 + PENETRATION_TOL
    assert sim.bumps >= 1 and bumps == 0  # one bump, then a resting contact
    assert 1.8 - 0.2 < sim.pose[0] <= 1.8


def test_concave_room_is_not_its_convex_hull() -> None:
    # A U-shaped obstacle: pymunk.Poly would take its hull and block the notch; edges keep it exact.
    frame = np.array([(-6.0, -6.0), (6.0, -6.0), (6.0, 6.0), (-6.0, 6.0)])
    u = np.array(
        [(1.0, -2.0), (4.0, -2.0), (4.0, 2.0), (1.0, 2.0), (1.0, 1.0), (3.0, 1.0), (3.0, -1.0), (1.0, -1.0)]
    )
    world = World((-6, -6, 6, 6), [frame, u])
    assert world.is_free([[2.0, 0.0]])[0]
    sim = RobotSim(world, 0.2, np.array([-1.0, 0.0, 0.0]))
    for _ in range(40):
        sim.step(1.0, 0.0, 0.1, 4)
    assert 3.0 - 0.2 - 0.03 <= sim.pose[0] <= 3.0 - 0.2  # drove into the notch to its end
    assert abs(sim.pose[1]) < 1e-6


def test_turning_follows_the_command() -> None:
    world = World((-20, -20, 20, 20), [np.array([(-20, -20), (20, -20), (20, 20), (-20, 20)])])
    sim = RobotSim(world, 0.2, np.array([0.0, 0.0, 0.0]))
    for _ in range(10):
        sim.step(1.0, 0.5, 0.1, 4)
    assert sim.pose[2] == pytest.approx(0.5, abs=0.02)
    assert sim.speed == pytest.approx(1.0, abs=0.02) and sim.yaw_rate == pytest.approx(0.5, abs=0.02)
    assert math.hypot(*sim.pose[:2]) == pytest.approx(2 * math.sin(0.25) / 0.5, abs=0.03)


@pytest.mark.expensive
@pytest.mark.parametrize("world", ["room", "rocks", "caves", "rooms"])
@pytest.mark.parametrize("model", ["uniform", "adversarial", "biased"])
def test_long_rollouts_stay_free_and_contained(world: str, model: str) -> None:
    env = ExploreEnv(world=world, max_speed=2.0, noise={"model": model}, fixed_world=False)
    rng = np.random.default_rng(1)
    for episode in range(3):
        env.reset(seed=episode)
        for _ in range(2000):
            _, _, _, _, info = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
            rec, truth = info["record"], info["truth"]
            assert env.world.clearance(truth.pose[None, :2])[0] >= env.config.robot_radius - PENETRATION_TOL
            assert np.all(rec.range[:, 0] <= truth.ranges) and np.all(truth.ranges <= rec.range[:, 1])
            assert rec.speed[0] <= truth.speed <= rec.speed[1]
            assert rec.heading[0] <= truth.pose[2] <= rec.heading[1]
