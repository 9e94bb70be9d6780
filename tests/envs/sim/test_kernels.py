"""The simulator's compiled kernels against the numpy implementations they replaced (kept here as oracles).

Random configurations include thin obstacles (needles, 1 mm slivers), apexes on or touching an edge,
zero-length edges and cone axes far beyond the ±pi cut.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from digslam.envs import ExploreConfig, NoiseConfig, RockField, SensorSuite, World
from digslam.envs.explore.coverage import Coverage
from digslam.envs.sim import geometry as geo
from digslam.envs.sim.arc_jit import arc
from digslam.envs.sim.robot import FRACTIONS, SWEEP_POINTS, RobotSim
from digslam.envs.sim.sensors import measure_step
from digslam.observer.record.mission import MissionRecord


# --- numpy oracles (the previous implementations) ----------------------------------------------------------
def np_point_edge_distance(pts: np.ndarray, edges: np.ndarray) -> np.ndarray:
    if len(edges) == 0:
        return np.full(len(pts), np.inf)
    ax, ay = edges[None, :, 0] - pts[:, :1], edges[None, :, 1] - pts[:, 1:2]
    dx, dy = (edges[:, 2] - edges[:, 0])[None], (edges[:, 3] - edges[:, 1])[None]
    dd = dx * dx + dy * dy
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip(np.where(dd > 0, -(ax * dx + ay * dy) / dd, 0.0), 0.0, 1.0)
    return np.sqrt(np.min((ax + t * dx) ** 2 + (ay + t * dy) ** 2, axis=1))


def np_sector_distance(
    x: float, y: float, axis: np.ndarray, gamma: np.ndarray, edges: np.ndarray
) -> np.ndarray:
    S, E = len(axis), len(edges)
    if E == 0:
        return np.full(S, np.inf)
    ax, ay = edges[:, 0] - x, edges[:, 1] - y
    dx, dy = edges[:, 2] - edges[:, 0], edges[:, 3] - edges[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.minimum(np.maximum(-(ax * dx + ay * dy) / (dx * dx + dy * dy), 0.0), 1.0)
        px = np.concatenate([ax, ax + dx, ax + t * dx])
        py = np.concatenate([ay, ay + dy, ay + t * dy])
        norms = np.hypot(px, py)
        inside = np.cos(axis)[:, None] * px + np.sin(axis)[:, None] * py >= norms * np.cos(gamma)[:, None]
        best = np.where(inside, norms, np.inf).min(axis=1)
        for b in (axis - gamma, axis + gamma):
            wx, wy = np.cos(b)[:, None], np.sin(b)[:, None]
            den = wx * dy - wy * dx
            r = (ax * dy - ay * dx) / den
            sp = (wy * ax - wx * ay) / den
            best = np.minimum(best, np.where((r >= 0) & (sp >= 0) & (sp <= 1), r, np.inf).min(axis=1))
    return best


def np_robot_step(pose: np.ndarray, v: float, w: float, radius: float, edges: np.ndarray, dt: float = 0.1,
                  substeps: int = 4) -> tuple[int, float, np.ndarray]:  # fmt: skip
    def arcs(p: np.ndarray, vs: np.ndarray, tau: np.ndarray) -> np.ndarray:
        half = 0.5 * w * tau  # chord form: no cancellation for small w
        chord = vs[:, None] * tau * np.sinc(half / np.pi)
        mid = p[2] + half
        return np.stack([p[0] + chord * np.cos(mid), p[1] + chord * np.sin(mid)], -1)

    def sweep_ok(p: np.ndarray, vs: np.ndarray, tau: np.ndarray, piece: float) -> np.ndarray:
        d = np_point_edge_distance(arcs(p, vs, tau).reshape(-1, 2), edges).reshape(len(vs), len(tau))
        return d >= radius + np.abs(vs)[:, None] * (0.5 * piece)

    h, m = dt / substeps, SWEEP_POINTS
    first = substeps
    if (
        v != 0.0
        and not np_point_edge_distance(pose[None, :2], edges)[0] > radius + abs(v) * dt * (1 + 1e-9) + 1e-9
    ):
        ok = sweep_ok(pose, np.array([v]), (np.arange(substeps * m) + 0.5) * (h / m), h / m)[0]
        if not ok.all():
            first = int(np.argmin(ok)) // m
    if first:
        pose = arc(pose, v, w, first * h)
    rest, vi = substeps - first, v
    if rest:
        vs = v * np.array(FRACTIONS[1:])
        ok = sweep_ok(pose, vs, (np.arange(rest * m) + 0.5) * (h / m), h / m).all(axis=1)
        vi = float(vs[int(np.argmax(ok))]) if ok.any() else 0.0
        pose = arc(pose, vi, w, rest * h)
    return first, vi, pose


def np_cover(cov: Coverage, pose: np.ndarray, suite: SensorSuite, ranges: np.ndarray) -> np.ndarray:
    """Cells the previous numpy update marked (from an empty ``seen``)."""
    x, y, th = (float(c) for c in pose)
    X, Y = np.meshgrid(cov.xs, cov.ys)
    vx, vy = X - x, Y - y
    reach = np.where(np.isfinite(ranges), np.minimum(ranges, suite.r_max), suite.r_max)
    breaks, cover = cov._angular_cover(suite)
    radius = np.max(np.where(cover, reach[None, :], 0.0), axis=1)
    world = np.mod(breaks + th + np.pi, 2 * np.pi) - np.pi
    order = np.argsort(world, kind="stable")
    k = np.searchsorted(world[order], np.arctan2(vy, vx), side="right") - 1
    return (vx * vx + vy * vy < radius[order][k] ** 2) & cov.free


# --- random configurations ---------------------------------------------------------------------------------
def random_edges(rng: np.random.Generator, k_max: int = 8) -> np.ndarray:
    k = int(rng.integers(1, k_max))
    a = rng.uniform(-4, 4, (k, 2))
    length = rng.choice([0.0, 0.05, 0.5, 3.0], k, p=[0.05, 0.3, 0.35, 0.3]) * rng.uniform(0.2, 1.0, k)
    ang = rng.uniform(0, 2 * np.pi, k)
    e = np.hstack([a, a + length[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])])
    if rng.uniform() < 0.3:  # sliver: two parallel edges 1 mm apart
        e = np.vstack([e, e[:1] + [0, 1e-3, 0, 1e-3]])
    return e


def random_apex(rng: np.random.Generator, edges: np.ndarray) -> tuple[float, float]:
    u = rng.uniform()
    if u < 0.15:  # on an edge
        t = rng.uniform()
        return tuple(edges[0, :2] + t * (edges[0, 2:] - edges[0, :2]))  # type: ignore[return-value]
    if u < 0.2:  # on a vertex
        return float(edges[0, 0]), float(edges[0, 1])
    return tuple(rng.uniform(-3, 3, 2))  # type: ignore[return-value]


def test_sector_distance_matches_numpy_oracle() -> None:
    rng = np.random.default_rng(2026)
    for _ in range(3000):
        edges = random_edges(rng)
        x, y = random_apex(rng, edges)
        S = int(rng.integers(1, 6))
        axis = rng.uniform(-10, 10, S) + rng.choice([0.0, math.pi], S)  # far beyond ±pi, and at the cut
        gamma = rng.choice([1e-9, 0.05, 0.26, 1.0, 2.5, math.pi], S)
        d, wit = geo.sector_distance(x, y, axis, gamma, edges, return_witness=True)
        ref = np_sector_distance(x, y, axis, gamma, edges)
        omni = gamma >= math.pi
        assert np.array_equal(np.isinf(d), np.isinf(ref))
        fin = np.isfinite(d)
        np.testing.assert_allclose(d[fin & ~omni], ref[fin & ~omni], rtol=1e-12, atol=1e-15)
        # the compiled omni cone is the whole plane: the exact clearance, never farther than the oracle's
        clear = np_point_edge_distance(np.array([[x, y]]), edges)[0]
        assert np.all(np.abs(d[omni] - clear) <= 1e-12 * max(clear, 1.0)) and np.all(
            d[omni] <= ref[omni] + 1e-15
        )
        # the witness is an edge point at the reported distance
        if fin.any():
            np.testing.assert_allclose(
                np.hypot(wit[fin, 0] - x, wit[fin, 1] - y), d[fin], rtol=1e-12, atol=1e-15
            )
            assert np.all(np_point_edge_distance(wit[fin], edges) <= 1e-12)
        assert np.all(np.isnan(wit[~fin]))


def test_true_ranges_prefilter_matches_full_oracle() -> None:
    world = RockField(n=30).generate(5)
    suite = SensorSuite.from_config(ExploreConfig(n_sonars=8))
    rng = np.random.default_rng(1)
    for _ in range(300):
        pose = world.sample_free_pose(rng, 0.2)
        pose[2] = rng.uniform(-20, 20)
        ref = np_sector_distance(pose[0], pose[1], pose[2] + suite.alpha, suite.gamma, world.edges)
        ref = np.where(ref <= suite.r_max, ref, np.inf)
        got = suite.true_ranges(world, pose)
        assert np.array_equal(np.isinf(got), np.isinf(ref))
        np.testing.assert_allclose(got[np.isfinite(got)], ref[np.isfinite(ref)], rtol=1e-12)


def test_point_edge_distance_matches_numpy_oracle() -> None:
    rng = np.random.default_rng(3)
    for _ in range(500):
        edges = random_edges(rng)
        pts = rng.uniform(-5, 5, (20, 2))
        pts[0] = edges[0, :2]  # on a vertex: distance 0
        np.testing.assert_allclose(geo.point_edge_distance(pts, edges), np_point_edge_distance(pts, edges),
                                   rtol=1e-12, atol=1e-15)  # fmt: skip
        assert geo.point_edge_distance(pts, edges)[0] == 0.0
    assert np.all(np.isinf(geo.point_edge_distance(np.zeros((3, 2)), np.zeros((0, 4)))))


@pytest.mark.parametrize("seed", [0, 1])
def test_robot_step_matches_numpy_oracle(seed: int) -> None:
    rng = np.random.default_rng(seed)
    frame = np.array([(-5.0, -5.0), (5.0, -5.0), (5.0, 5.0), (-5.0, 5.0)])
    sliver = np.array([(1.0, -3.0), (1.001, -3.0), (1.001, 3.0), (1.0, 3.0)])  # a 1 mm wall
    world = World((-5, -5, 5, 5), [frame, sliver] + RockField(n=6, size=5.0).generate(seed).rings[1:])
    radius, blocked = 0.2, 0
    sim = RobotSim(world, radius, world.sample_free_pose(rng, 0.5), dynamics="unicycle")
    for k in range(1000):
        v = float(rng.choice([2.0, -2.0, 1.0, 0.0])) * rng.uniform(0.5, 1.0)
        w = float(rng.choice([0.0, 1e-13, rng.uniform(-2, 2)]))
        before = sim.pose
        first, vi, ref = np_robot_step(before, v, w, radius, world.edges)
        sim.step(v, w, 0.1, 4)
        assert (sim.speed_hull[0], sim.speed_hull[1]) == ((min(v, vi), max(v, vi)) if 0 < first < 4 else
                                                          ((v, v) if first == 4 else (vi, vi))), k  # fmt: skip
        np.testing.assert_allclose(sim.pose, ref, rtol=0, atol=1e-12)
        assert world.clearance(sim.pose[None, :2])[0] >= radius - 1e-9  # the nominal disc stays off the walls
        blocked += first < 4
    assert blocked > 50  # the walls were really hit


def test_coverage_matches_numpy_oracle() -> None:
    world = RockField(n=25).generate(4)
    rng = np.random.default_rng(0)
    mismatches, total = 0, 0
    for gamma, omni, n in ((math.pi / 12, True, 8), (0.5, False, 3), (math.pi, False, 1), (0.1, True, 13)):
        suite = SensorSuite.from_config(ExploreConfig(sonar_gamma=gamma, omni=omni, n_sonars=n))
        for _ in range(15):
            pose = world.sample_free_pose(rng, 0.3)
            pose[2] = rng.uniform(-20, 20)
            ranges = suite.true_ranges(world, pose)
            cov = Coverage(world, 0.1, float(suite.r_max.max()))
            area = cov.update(pose, suite, ranges)
            ref = np_cover(cov, pose, suite, ranges)
            assert area == pytest.approx(np.count_nonzero(cov.seen) * cov.cell_area)
            assert cov.n_seen == np.count_nonzero(cov.seen) and not np.any(cov.seen & ~cov.free)
            mismatches += int(np.count_nonzero(cov.seen ^ ref))
            total += int(np.count_nonzero(ref))
            assert cov.update(pose, suite, ranges) == 0.0
    assert total > 5000 and mismatches <= 1e-4 * total  # only centres within rounding of a cone edge


def np_measure(truth: np.ndarray, b: np.ndarray, cfg: NoiseConfig, u: np.ndarray) -> tuple[np.ndarray, ...]:
    def widen(lo: np.ndarray, hi: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return lo - 4.0 * np.spacing(s), hi + 4.0 * np.spacing(s)

    if cfg.model == "adversarial":
        side = np.where(u >= 0, 1.0, -1.0)
        far = truth + side * 2.0 * b
        plo, phi = widen(np.where(side > 0, truth, far), np.where(side > 0, far, truth),
                         np.maximum(np.abs(truth), 2.0 * b))  # fmt: skip
        return truth + side * b, np.where(side > 0, truth, plo), np.where(side > 0, phi, truth)
    e = (cfg.bias + (1.0 - abs(cfg.bias)) * u) * b if cfg.model == "biased" else u * b
    lo, hi = widen(truth + e - b, truth + e + b, np.maximum(np.abs(truth + e), b))
    return truth + e, lo, hi


@pytest.mark.parametrize("model", ["uniform", "adversarial", "biased"])
def test_noise_and_record_match_numpy_oracle(model: str) -> None:
    from digslam.envs.sim.noise import measure

    cfg = NoiseConfig(model=model, bias=-0.3, range=0.05, outlier_prob=0.2 if model == "biased" else 0.0)
    suite = SensorSuite.from_config(ExploreConfig())
    rng = np.random.default_rng(9)
    truth = rng.uniform(-100, 100, 2000) * rng.choice([1e-6, 1.0], 2000)
    b = rng.choice([0.0, 1e-3, 2.0], 2000)
    got = measure(truth, b, cfg, np.random.default_rng(1))
    ref = np_measure(truth, b, cfg, np.random.default_rng(1).uniform(-1.0, 1.0, 2000))
    for g, r in zip(got, ref, strict=True):
        assert np.array_equal(g, r)
    for _ in range(300):
        ranges = np.where(rng.uniform(size=suite.n) < 0.3, np.inf, rng.uniform(0, 5, suite.n))
        s, w, h = rng.uniform(-1, 1, 3) * [1, 1, 50]
        rec = measure_step(1.5, suite, ranges, (s, s + 0.1), w, h, cfg, rng, tol=1e-12)
        again = MissionRecord(**rec.as_dict())  # the record's own conversions and checks accept it as it is
        assert again.same_as(rec) and rec.range.flags.c_contiguous
        good = ~rec.outlier
        assert np.all(rec.range[good, 0] <= ranges[good]) and np.all(ranges[good] <= rec.range[good, 1])
        assert rec.speed[0] <= s and s + 0.1 <= rec.speed[1] and rec.heading[0] <= h <= rec.heading[1]
    with pytest.raises(ValueError, match="heading"):
        measure_step(0.0, suite, np.ones(suite.n), 0.0, 0.0, math.nan, cfg, rng)


@pytest.mark.parametrize(
    "name", ["sim.arc_jit", "sim.geometry_jit", "sim.robot_jit", "explore.coverage_jit", "sim.noise_jit"]
)
def test_kernel_module_doctests(name: str) -> None:
    import doctest
    import importlib

    res = doctest.testmod(importlib.import_module(f"digslam.envs.{name}"), optionflags=doctest.ELLIPSIS)
    assert res.attempted > 0 and res.failed == 0


@pytest.mark.parametrize("dynamics", ["pymunk", "unicycle"])
def test_observation_matches_numpy_oracle(dynamics: str) -> None:
    from digslam.envs import ExploreEnv

    env = ExploreEnv(world="rocks", noise={"range": 0.05}, dynamics=dynamics)
    env.reset(seed=3)
    rng = np.random.default_rng(5)
    top, odo_top, hb = env._top, env._odo_top, env.observation_space["heading"]
    for k in range(200):
        obs, _, _, _, info = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
        rec = info["record"]
        if k % 3 == 0:  # headings far from [-pi, pi], odometry beyond the clip
            rec.heading[:] += 2 * np.pi * rng.integers(-5, 6) + [0.0, 1e-3]
            rec.speed[:] *= rng.choice([1.0, 1e3])
            spread = np.array([-1.0, 1.0]) * rng.choice([0.0, 50.0])
            rec.lateral[:] = rec.lateral * rng.choice([1.0, 1e3]) + spread
            obs = env._obs(rec)
        h = rec.heading
        kk = np.round(0.5 * (h[0] + h[1]) / (2 * math.pi)) * 2 * math.pi
        ref = {
            "ranges": np.minimum(rec.range, top),
            "no_echo": rec.no_echo.astype(np.int8),
            "odometry": np.minimum(
                np.maximum(np.array([rec.speed, rec.lateral, rec.yaw_rate]), -odo_top), odo_top
            ),
            "heading": np.minimum(np.maximum(h - kk, hb.low), hb.high),
        }
        for key, val in ref.items():
            assert obs[key].dtype == val.dtype and np.array_equal(obs[key], val), key
        assert env.observation_space.contains(obs)


@pytest.mark.parametrize("dynamics", ["unicycle", "pymunk"])
def test_ground_truth_of_step_is_the_plain_constructor(dynamics: str) -> None:
    from digslam.envs.explore.episode import GroundTruth

    args: tuple = (
        1.5,
        np.array([0.1, -0.2, 7.0]),
        0.25,
        -0.5,
        np.array([1.0, np.inf]),
        1,
        4,
        np.array([[0.25, 0.05, 6.9], [0.0, 0.05, 7.0]]),
        1e-15,
    )
    if dynamics == "pymunk":  # the lateral velocity and the substep path
        args = (*args[:7], np.full((2, 3), np.nan), 0.0, 0.125, np.array([[0.0, 0.0, 6.9], [0.1, -0.2, 7.0]]),
                np.array([0.1]))  # fmt: skip
    fast, plain = GroundTruth.of_step(*args), GroundTruth(*args)
    assert fast == plain
    for a, b in zip(fast.as_dict().values(), plain.as_dict().values(), strict=True):
        assert type(a) is type(b) is np.ndarray and a.shape == b.shape and a.dtype == b.dtype
