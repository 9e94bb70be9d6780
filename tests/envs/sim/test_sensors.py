"""Exactness of the sonar-cone distance against an independent brute-force geometric reference."""

from __future__ import annotations

import math

import numpy as np
import pytest

from digslam.envs import ExploreConfig, SensorSuite, World
from digslam.envs.sim import geometry as geo

N_SAMPLES = 4001


def _in_sector_ref(qx: np.ndarray, qy: np.ndarray, axis: float, gamma: float) -> np.ndarray:
    """Reference sector test with atan2 and explicit wrapping across the ±pi cut."""
    diff = np.mod(np.arctan2(qy, qx) - axis + math.pi, 2 * math.pi) - math.pi
    return (np.abs(diff) <= gamma) | ((qx == 0) & (qy == 0))


def reference(x: float, y: float, axis: float, gamma: float, edges: np.ndarray) -> float:
    """Dense sampling of every edge inside the sector, plus the exact crossings with the boundary rays."""
    best = math.inf
    t = np.linspace(0.0, 1.0, N_SAMPLES)
    for x1, y1, x2, y2 in edges:
        qx = x1 - x + t * (x2 - x1)
        qy = y1 - y + t * (y2 - y1)
        ok = _in_sector_ref(qx, qy, axis, gamma)
        if ok.any():
            best = min(best, float(np.min(np.hypot(qx[ok], qy[ok]))))
        for b in (axis - gamma, axis + gamma):  # r*(cos b, sin b) = P1 + s*(P2 - P1)
            m = np.array([[math.cos(b), -(x2 - x1)], [math.sin(b), -(y2 - y1)]])
            if abs(np.linalg.det(m)) < 1e-14:
                continue
            r, s = np.linalg.solve(m, [x1 - x, y1 - y])
            if r >= 0 and 0 <= s <= 1:
                best = min(best, float(r))
    return best


def _random_edges(rng: np.random.Generator) -> np.ndarray:
    """A few random segments, some short needles, some thin slivers (two close parallel edges)."""
    k = int(rng.integers(1, 7))
    a = rng.uniform(-4, 4, (k, 2))
    length = rng.choice([0.05, 0.5, 3.0], k) * rng.uniform(0.2, 1.0, k)
    ang = rng.uniform(0, 2 * np.pi, k)
    b = a + length[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])
    e = np.hstack([a, b])
    if rng.uniform() < 0.3:  # sliver: a thin obstacle made of two parallel edges 1 mm apart
        e = np.vstack([e, e[:1] + [0, 1e-3, 0, 1e-3]])
    return e


def _check(x: float, y: float, axis: float, gamma: float, edges: np.ndarray) -> None:
    d, w = geo.sector_distance(x, y, np.array([axis]), np.array([gamma]), edges, return_witness=True)
    ref = reference(x, y, axis, gamma, edges)
    if math.isinf(ref):
        assert math.isinf(d[0])
        return
    spacing = float(np.max(np.hypot(edges[:, 2] - edges[:, 0], edges[:, 3] - edges[:, 1]))) / (N_SAMPLES - 1)
    assert d[0] <= ref + 1e-9
    assert d[0] >= ref - spacing - 1e-9
    # The witness is a genuine obstacle point in the sector at the reported distance.
    assert math.hypot(w[0, 0] - x, w[0, 1] - y) == pytest.approx(d[0], abs=1e-9)
    assert geo.point_edge_distance(w, edges)[0] <= 1e-9
    vx, vy = w[0, 0] - x, w[0, 1] - y
    if math.hypot(vx, vy) > 1e-9:
        cosang = (vx * math.cos(axis) + vy * math.sin(axis)) / math.hypot(vx, vy)
        assert cosang >= math.cos(gamma) - 1e-9


def test_sector_distance_matches_brute_force_on_random_configurations() -> None:
    rng = np.random.default_rng(12345)
    for _ in range(2000):
        edges = _random_edges(rng)
        x, y = rng.uniform(-3, 3, 2)
        axis = float(rng.uniform(-10, 10))  # any real direction, far beyond ±pi
        gamma = float(rng.choice([rng.uniform(0.01, 0.5), rng.uniform(0.5, math.pi), math.pi]))
        _check(float(x), float(y), axis, gamma, edges)


def test_cones_across_the_pi_cut() -> None:
    rng = np.random.default_rng(7)
    for _ in range(500):
        edges = _random_edges(rng)
        axis = math.pi + float(rng.uniform(-0.3, 0.3)) + 2 * math.pi * int(rng.integers(-3, 4))
        _check(0.0, 0.0, axis, float(rng.uniform(0.05, 0.6)), edges)
    # An obstacle straight behind (direction exactly pi) is seen by a cone centred on -pi + 0.1.
    edges = np.array([[-2.0, -0.01, -2.0, 0.01]])
    d = geo.sector_distance(0.0, 0.0, np.array([-math.pi + 0.1, math.pi - 0.1, 0.0]), np.full(3, 0.2), edges)
    assert d[0] == pytest.approx(2.0) and d[1] == pytest.approx(2.0) and math.isinf(d[2])


def test_thin_obstacle_between_would_be_rays_is_seen() -> None:
    # A 5-ray fan over a cone of half-aperture 0.4 has rays at 0, ±0.2, ±0.4: put needles between them.
    for mid in (0.1, -0.3, 0.3):
        r = 2.0
        c = np.array([r * math.cos(mid), r * math.sin(mid)])
        t = 0.02 * np.array([-math.sin(mid), math.cos(mid)])  # 4 cm needle across the direction
        edges = np.array([[*(c - t), *(c + t)], [10, -10, 10, 10]])
        d = geo.sector_distance(0.0, 0.0, np.array([0.0]), np.array([0.4]), edges)
        assert d[0] == pytest.approx(math.hypot(r, 0.0), abs=1e-12)
        rays = np.linspace(-0.4, 0.4, 5)
        fan = geo.sector_distance(0.0, 0.0, rays, np.full(5, 1e-12), edges)  # degenerate cones = rays
        assert np.all(fan > 9.0)  # the ray fan misses the needle


def test_robot_touching_an_obstacle() -> None:
    world = World((-5, -5, 5, 5), [np.array([(-5, -5), (5, -5), (5, 5), (-5, 5)])])
    radius = 0.2
    suite = SensorSuite.from_config(ExploreConfig())
    pose = np.array([5.0 - radius, 0.0, 0.0])  # the robot disc touches the east wall
    d = suite.true_ranges(world, pose)
    assert d[0] == pytest.approx(radius, abs=1e-12)  # forward cone
    assert d[-1] == pytest.approx(radius, abs=1e-12)  # omni
    # Apex exactly on an edge: distance 0 in every sector facing it.
    d0 = geo.sector_distance(
        0.0, 0.0, np.array([0.0, 1.0, math.pi]), np.array([0.1, 0.1, 0.1]), np.array([[-1.0, 0.0, 1.0, 0.0]])
    )
    assert np.all(d0 == 0.0)


def test_omni_is_the_exact_clearance() -> None:
    rng = np.random.default_rng(3)
    for _ in range(300):
        edges = _random_edges(rng)
        p = rng.uniform(-3, 3, (1, 2))
        d = geo.sector_distance(
            float(p[0, 0]), float(p[0, 1]), np.array([rng.uniform(-9, 9)]), np.array([math.pi]), edges
        )
        assert d[0] == pytest.approx(geo.point_edge_distance(p, edges)[0], abs=1e-12)


def test_no_echo_beyond_max_range() -> None:
    world = World((-50, -50, 50, 50), [np.array([(-50, -50), (50, -50), (50, 50), (-50, 50)])])
    suite = SensorSuite.from_config(ExploreConfig())
    assert np.all(np.isinf(suite.true_ranges(world, np.array([0.0, 0.0, 0.3]))))


@pytest.mark.parametrize("seed", [0, 1])
def test_bounding_box_prefilter_drops_nothing(seed: int) -> None:
    from digslam.envs import Caves, RockField

    rng = np.random.default_rng(seed)
    suite = SensorSuite.from_config(ExploreConfig(n_sonars=12, sonar_gamma=0.3))
    for world in (RockField(n=40).generate(seed), Caves().generate(seed)):
        pts = rng.uniform(-10, 10, (600, 2))
        pts = pts[world.clearance(pts) > 0.05][:100]
        for x, y in pts:
            pose = np.array([x, y, rng.uniform(-np.pi, np.pi)])
            full = geo.sector_distance(pose[0], pose[1], pose[2] + suite.alpha, suite.gamma, world.edges)
            expected = np.where(full <= suite.r_max, full, np.inf)
            assert np.array_equal(suite.true_ranges(world, pose), expected)


def test_thesis_sonar_example_4_2_3() -> None:
    # Thesis §4.2.3: map x1 < 5 or x2 < 3, cone pi/4 ± pi/24 from (0, 0): published d in [6.2988, 6.3085].
    free = np.array([(-50.0, -50.0), (50.0, -50.0), (50.0, 3.0), (5.0, 3.0), (5.0, 50.0), (-50.0, 50.0)])
    world = World((-50, -50, 50, 50), [free])
    d = geo.sector_distance(0.0, 0.0, np.array([math.pi / 4]), np.array([math.pi / 24]), world.edges)
    assert d[0] == pytest.approx(5.0 / math.cos(math.pi / 4 - math.pi / 24), rel=1e-12)
    assert 6.2988 <= d[0] <= 6.3085


def test_sensor_suite_rejects_bad_aperture() -> None:
    for g in (0.0, -0.1, 3.2, math.nan):
        with pytest.raises(ValueError, match="gamma"):
            SensorSuite(np.array([0.0]), np.array([g]), np.array([5.0]))
