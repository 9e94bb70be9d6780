"""The fused sensing kernel (:meth:`SensorSuite.sense`, :func:`.geometry_jit.sense_kernel`) against the two
kernels it fuses: ``true_ranges`` and ``range_bounds``, bit for bit, on every generator's worlds and on
random edge soups (zero-length edges, apexes on edges, slivers), with and without pose error."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from digslam.envs import ExploreConfig, SensorSuite, World
from digslam.envs.sim.generators import Caves, RockField, RoomsCorridors, ThesisRoom
from digslam.envs.sim.geometry_jit import edge_boxes

CONFIGS = ((math.pi / 12, True, 8), (0.5, False, 3), (math.pi, False, 1), (0.1, True, 13), (1.4, True, 0))
SUITES = [SensorSuite.from_config(ExploreConfig(sonar_gamma=g, omni=o, n_sonars=n)) for g, o, n in CONFIGS]
SUITES.append(
    SensorSuite(np.array([0.3, -2.0, 7.0]), np.array([math.pi, 1e-3, 3.0]), np.array([0.5, 8.0, 2.0]))
)


def _same(suite: SensorSuite, world: World | SimpleNamespace, pose: np.ndarray, err: float) -> None:
    d, b = suite.sense(world, pose, err)  # type: ignore[arg-type]
    want_d, want_b = suite.true_ranges(world, pose), suite.range_bounds(world, pose, err)  # type: ignore[arg-type]
    assert d.shape == want_d.shape and b.shape == want_b.shape and b.flags.c_contiguous
    assert np.array_equal(d, want_d) and np.array_equal(b, want_b), (pose.tolist(), err)


@pytest.mark.parametrize("gen", [ThesisRoom(), RockField(n=30), Caves(size=12.0), RoomsCorridors()],
                         ids=["room", "rocks", "caves", "rooms"])  # fmt: skip
def test_sense_is_true_ranges_and_range_bounds_on_generated_worlds(gen: object) -> None:
    rng = np.random.default_rng(1)
    for seed in range(2):
        world = gen.generate(seed)  # type: ignore[attr-defined]
        x0, y0, x1, y1 = world.frame
        for k in range(40):
            if k % 4 == 0:  # anywhere, obstacles included
                pose = np.array([rng.uniform(x0, x1), rng.uniform(y0, y1), rng.uniform(-50, 50)])
            else:
                pose = world.sample_free_pose(rng, 0.2)
                pose[2] = rng.uniform(-50, 50)
            for suite in SUITES:
                _same(suite, world, pose, float(rng.choice([0.0, 1e-9, 1e-3, 0.05])))


def test_sense_is_true_ranges_and_range_bounds_on_edge_soups() -> None:
    rng = np.random.default_rng(2)
    for _ in range(300):
        k = int(rng.integers(1, 12))
        a = rng.uniform(-4, 4, (k, 2))
        length = rng.choice([0.0, 0.05, 0.5, 3.0], k) * rng.uniform(0.2, 1.0, k)
        ang = rng.uniform(0, 2 * np.pi, k)
        edges = np.hstack([a, a + length[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])])
        if rng.uniform() < 0.3:  # a sliver: two parallel edges 1 mm apart
            edges = np.vstack([edges, edges[:1] + [0, 1e-3, 0, 1e-3]])
        world = SimpleNamespace(edges=np.ascontiguousarray(edges), bbox=edge_boxes(edges))  # what sense reads
        u = rng.uniform()
        if u < 0.2:  # on an edge, or on a vertex
            t = 0.0 if u < 0.05 else rng.uniform()
            xy = edges[0, :2] + t * (edges[0, 2:] - edges[0, :2])
        else:
            xy = rng.uniform(-3, 3, 2)
        pose = np.array([xy[0], xy[1], rng.uniform(-30, 30)])
        for suite in SUITES:
            _same(suite, world, pose, float(rng.choice([0.0, 1e-6, 0.02])))
