"""Ground-truth coverage (the reward): sensed cells against a per-sensor brute-force reference."""

from __future__ import annotations

import math

import numpy as np
import pytest

from digslam.envs import ExploreConfig, RockField, SensorSuite
from digslam.envs.explore.coverage import Coverage


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
