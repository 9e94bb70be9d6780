"""The observation comes from the observer only: worlds with the same records give the same observations."""

from __future__ import annotations

import numpy as np

from digslam.envs.dig_coverage.env import DigCoverageEnv
from digslam.envs.dig_coverage.maps_jit import MapPlanes
from digslam.envs.dig_coverage.observe_jit import map_context, observe
from digslam.envs.sim.world import World
from digslam.observer.record.grid import Grid

#: The thesis room's wall (the room generator's world at jitter 0).
ROOM = np.array([(-9, -9), (-3, -8), (1, -9.2), (8.5, -8), (9, -2), (6, 1), (9.2, 5), (7, 9), (1, 8.5), (-1, 5),
                 (-4, 9), (-9, 8), (-8, 2), (-5, 0), (-9.3, -3)], np.float64)  # fmt: skip
#: A rock in the room's far corner, more than 8 m from the start: never within the 5 m sensors' reach here.
ROCK = np.array([(-7.5, -7.5), (-6.0, -7.5), (-6.0, -6.0), (-7.5, -6.0)], np.float64)


class _Fixed:
    """A generator that always returns ``world`` (the env asks it for a world at each seeded reset)."""

    def __init__(self, world: World) -> None:
        self.world, self.frame = world, world.frame

    def generate(self, seed: int | None = None) -> World:
        return self.world


def _episode(world: World, steps: int = 40) -> tuple[list, list, DigCoverageEnv]:
    """Observations and records of a slow spiral from the centre (the robot stays within 1.2 m of it); the
    start pose is given (drawn, it would depend on the world's reachable area)."""
    env = DigCoverageEnv(map_size=36, crop=4.0, start=(0.0, 0.0, 0.4))
    env.env.unwrapped.generator = _Fixed(world)
    obs, info = env.reset(seed=3)
    observations, records = [obs], [info["record"]]
    for k in range(steps):
        action = np.array([0.3, 0.6 if k % 10 < 7 else -0.4], np.float32)
        obs, _, terminated, truncated, info = env.step(action)
        observations.append(obs)
        records.append(info["record"])
        assert not (terminated or truncated)
    return observations, records, env


def test_two_worlds_with_the_same_records_give_the_same_observations() -> None:
    frame = (-10.0, -10.0, 10.0, 10.0)
    plain, rocky = World(frame, [ROOM], "room"), World(frame, [ROOM, ROCK], "room+rock")
    obs_a, rec_a, env_a = _episode(plain)
    obs_b, rec_b, env_b = _episode(rocky)
    assert len(rec_a) == len(rec_b) and all(a.same_as(b) for a, b in zip(rec_a, rec_b, strict=True))
    # the ground truth differs: the rock takes reachable free cells, so the certified coverage differs ...
    assert env_a.n_reachable > env_b.n_reachable
    assert env_a.unwrapped.world is plain and env_b.unwrapped.world is rocky
    # ... and no observation array does
    for a, b in zip(obs_a, obs_b, strict=True):
        assert a.keys() == b.keys()
        for key in a:
            assert np.array_equal(a[key], b[key]), key
    assert obs_a[-1]["state"][9] > obs_a[0]["state"][9] > 0.0  # the certified share grows as the robot moves


def test_the_certified_state_value_is_the_clear_share_of_the_grid() -> None:
    obs, records, env = _episode(World((-10.0, -10.0, 10.0, 10.0), [ROOM], "room"), steps=10)
    info_clear = env.filter.clear_mask()
    assert obs[-1]["state"][9] == np.float32(np.count_nonzero(info_clear) / info_clear.size)
    assert obs[-1]["state"][9] != np.float32(env.filter.clear_mask()[env.reachable].mean())


def test_no_observation_array_changes_when_only_the_reachable_area_changes() -> None:
    """The kernel that draws the observation, fed twice the same observer sets and two different
    ground-truth reachable planes: the image and the state agree; only the returned count (``info``) differs."""
    rng = np.random.default_rng(5)
    n, m = 48, 36
    g = Grid((-3.0, -3.0), (3.0, 3.0), (n, n))
    sure, maybe, free = (rng.random((n, n)) < p for p in (0.4, 0.6, 0.7))
    maybe |= sure
    lo, hi = np.array([-0.4, 0.1]), np.array([0.3, 0.5])
    out = []
    for reach in (rng.random((n, n)) < 0.8, np.ones((n, n), bool)):
        planes = np.zeros((4, n, n), np.uint8)
        planes[3] = reach
        maps = map_context((sure, maybe, free), MapPlanes(*planes), np.zeros((3, m, m), np.uint8), g.xs, -g.ys,
                           50.0)  # fmt: skip
        img, state = np.empty((4, m, m), np.uint8), np.empty(11, np.float32)
        snap = np.empty((3, n, n), np.uint8)
        count = observe(maps, lo, hi, (0.2, 0.4), (0, n, 0, n), 9, 0, img, state, snap)
        out.append((img, state, count, reach))
    (img_a, state_a, count_a, reach_a), (img_b, state_b, count_b, _) = out
    assert np.array_equal(img_a, img_b) and np.array_equal(state_a, state_b)
    clear = sure & free
    assert count_a == np.count_nonzero(clear & reach_a) < count_b == np.count_nonzero(clear)
    assert state_a[9] == np.float32(np.count_nonzero(clear) / clear.size)
