"""The compiled disc (:func:`digslam.agents.baselines.policy_jit.disk`) against its numpy oracle."""

import math

import numpy as np

from digslam.agents.baselines import policy_jit as pj


def oracle_disk(m, centre, radius_px):
    out = np.zeros((m, m), dtype=bool)
    rr = np.arange(m)[:, None]
    cc = np.arange(m)[None, :]
    out[:] = (rr + 0.5 - centre[0]) ** 2 + (cc + 0.5 - centre[1]) ** 2 <= radius_px**2
    return out


def test_disk_matches_the_oracle_on_and_off_the_map() -> None:
    rng = np.random.default_rng(0)
    for _ in range(400):
        m = int(rng.integers(4, 40))
        centre = rng.uniform(-3, m + 3, 2)
        radius = float(rng.choice([0.75, 1.0, 2.4, rng.uniform(0.1, 8.0)]))
        got = pj.disk(m, float(centre[0]), float(centre[1]), radius, radius**2)
        assert np.array_equal(got, oracle_disk(m, centre, radius))


def test_disk_on_exact_pixel_boundaries() -> None:
    # a centre on a pixel corner and a radius reaching pixel centres exactly: the boundary counts as in
    got = pj.disk(6, 3.0, 3.0, math.sqrt(0.5), 0.5)
    assert got.sum() == 4 and got[2:4, 2:4].all()
