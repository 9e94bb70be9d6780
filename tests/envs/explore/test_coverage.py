"""Ground-truth coverage (the reward): sensed cells against a per-sensor brute-force reference."""

from __future__ import annotations

import math

import numpy as np
import pytest
from coverage_oracle import cover_update

from digslam.envs import ExploreConfig, RockField, SensorSuite, World
from digslam.envs.explore.coverage import Coverage
from digslam.envs.explore.coverage_jit import todo_blocks
from digslam.envs.sim.generators import Caves, RoomsCorridors, ThesisRoom


def _reference_hits(cov: Coverage, pose: np.ndarray, suite: SensorSuite, ranges: np.ndarray) -> np.ndarray:
    """Cells whose centre is in some closed sector and closer than its reach (every free cell, seen or not)."""
    X, Y = np.meshgrid(cov.xs, cov.ys)
    vx, vy = X - pose[0], Y - pose[1]
    dist = np.hypot(vx, vy)
    reach = np.where(np.isfinite(ranges), np.minimum(ranges, suite.r_max), suite.r_max)
    hit = np.zeros(X.shape, dtype=bool)
    for a, g, r in zip(suite.alpha, suite.gamma, reach, strict=True):
        off = np.mod(np.arctan2(vy, vx) - pose[2] - a + math.pi, 2 * math.pi) - math.pi
        hit |= (np.abs(off) <= g) & (dist < r)
    return hit & cov.free


@pytest.mark.parametrize("gamma,omni", [(math.pi / 12, True), (0.5, False), (math.pi, False)])
def test_coverage_matches_brute_force(gamma: float, omni: bool) -> None:
    world = RockField(n=25).generate(4)
    suite = SensorSuite.from_config(ExploreConfig(sonar_gamma=gamma, omni=omni, n_sonars=7))
    rng = np.random.default_rng(0)
    pts = rng.uniform(-9, 9, (300, 2))
    pts = pts[world.clearance(pts) > 0.3][:40]
    mismatches, total = 0, 0
    for x, y in pts:
        pose = np.array([x, y, rng.uniform(-20, 20)])
        ranges = suite.true_ranges(world, pose)
        cov = Coverage(world, 0.1, float(suite.r_max.max()))
        area = cov.update(pose, suite, ranges)
        ref = _reference_hits(cov, pose, suite, ranges)
        assert area == pytest.approx(np.count_nonzero(cov.seen) * cov.cell_area)
        assert not np.any(cov.seen & ~cov.free)
        mismatches += int(np.count_nonzero(cov.seen ^ ref))
        total += int(np.count_nonzero(ref))
        assert cov.update(pose, suite, ranges) == 0.0  # nothing new from the same pose
    assert total > 1000
    assert mismatches <= 1e-3 * total  # only cell centres exactly on a cone edge may differ (rounding)


# --- the block-skipping update against the kernel it replaced ----------------------------------------------
CONFIGS = ((math.pi / 12, True, 8), (0.5, False, 3), (math.pi, False, 1), (0.1, True, 13), (1.4, True, 0))
SUITES = [SensorSuite.from_config(ExploreConfig(sonar_gamma=g, omni=o, n_sonars=n)) for g, o, n in CONFIGS]
SUITES.append(
    SensorSuite(np.array([0.3, -2.0, 7.0]), np.array([math.pi, 1e-3, 3.0]), np.array([0.5, 8.0, 2.0]))
)


def _walk(cov: Coverage, ref: Coverage, world: World, suite: SensorSuite, rng: np.random.Generator,
          steps: int) -> int:  # fmt: skip
    """Step ``cov`` (:meth:`Coverage.update`) and ``ref`` (the oracle kernel, ``coverage_oracle.cover_update``) along a
    random walk of free poses and check they mark the same cells each step; return the cells marked."""
    breaks, cover = ref._angular_cover(suite)
    pose = world.sample_free_pose(rng, 0.2)
    for k in range(steps):
        if k % 10 == 9:  # a jump
            pose = world.sample_free_pose(rng, 0.2)
        else:
            step = pose[:2] + rng.normal(0.0, 0.3, 2)
            if world.clearance(step[None])[0] > 0.05:
                pose = np.array([step[0], step[1], pose[2]])
        pose[2] = pose[2] + rng.normal(0.0, 1.0) + (rng.choice([0.0, 60.0]) if k % 17 == 0 else 0.0)
        ranges = suite.true_ranges(world, pose)
        if k % 7 == 3:  # readings other than the truth, larger ones included
            ranges = ranges * rng.uniform(0.3, 1.5, ranges.shape)
        area = cov.update(pose, suite, ranges)
        want = cover_update(ref.free, ref.seen, ref.xs, ref.ys, ref._win, pose, breaks, cover, ranges,
                            suite._k_r_max)  # fmt: skip
        assert area == want * cov.cell_area and np.array_equal(cov.seen, ref.seen), (k, pose.tolist())
    assert cov.n_seen == np.count_nonzero(cov.seen)
    assert np.array_equal(cov._todo, cov.free & ~cov.seen)
    assert np.array_equal(cov._blocks, todo_blocks(cov._todo))
    return cov.n_seen


@pytest.mark.parametrize("gen", [ThesisRoom(), RockField(n=30), Caves(size=12.0), RoomsCorridors()],
                         ids=["room", "rocks", "caves", "rooms"])  # fmt: skip
def test_update_marks_the_cells_of_the_previous_kernel(gen: object) -> None:
    rng = np.random.default_rng(3)
    world = gen.generate(5)  # type: ignore[attr-defined]
    marked = 0
    for suite in SUITES:
        reach = float(suite.r_max.max())
        marked += _walk(Coverage(world, 0.1, reach), Coverage(world, 0.1, reach), world, suite, rng, 60)
    assert marked > 20000


def test_update_on_cells_marks_the_cells_of_the_previous_kernel() -> None:
    """Non-square cells, a grid smaller than the world, a reach below the sensors' (the window clips)."""
    rng = np.random.default_rng(4)
    world = RockField(n=20).generate(6)
    for shape, cell, reach in (((90, 130), (0.13, 0.09), 5.0), ((41, 37), (0.25, 0.3), 2.0),
                               ((200, 1), (0.1, 0.1), 5.0)):  # fmt: skip
        free = rng.uniform(size=shape) < 0.9
        origin = (-6.0, -4.5)
        for suite in SUITES[:3]:
            cov = Coverage.on_cells(free, origin, cell, reach)
            ref = Coverage.on_cells(free, origin, cell, reach)
            _walk(cov, ref, world, suite, rng, 40)
