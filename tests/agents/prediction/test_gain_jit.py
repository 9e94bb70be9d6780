"""The predicted-gain kernel against a plain-Python oracle, and on cases whose answer is known."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.agents.prediction.gain_jit import visible_gain


def oracle(p, weight, unknown, rows, cols, radius, n_rays, step):
    """The module docstring's sum, written out sample by sample."""
    out = []
    for r0, c0 in zip(rows, cols, strict=True):
        total = 0.0
        for j in range(n_rays):
            th = j * (
                2.0 * math.pi / n_rays
            )  # the kernel's angles, bit for bit (samples fall on pixel edges)
            alive, last = 1.0, None
            for s in range(1, int(radius / step) + 1):
                r = s * step
                fr, fc = r0 + 0.5 - r * math.sin(th), c0 + 0.5 + r * math.cos(th)
                if not (0 <= fr < p.shape[0] and 0 <= fc < p.shape[1]):
                    break
                cell = (int(fr), int(fc))
                if unknown[cell]:
                    total += alive * weight[cell] * r * step * (2.0 * math.pi / n_rays)
                if cell != last:
                    alive *= p[cell]
                    last = cell
                if alive < 1e-3:
                    break
        out.append(total)
    return np.array(out)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(4, 20), st.integers(1, 24))
def test_matches_the_oracle(seed, m, n_rays):
    rng = np.random.default_rng(seed)
    p = rng.choice([0.0, 0.5, 1.0], size=(m, m))
    weight = rng.random((m, m))
    unknown = rng.random((m, m)) < 0.6
    rows, cols = rng.integers(0, m, 5), rng.integers(0, m, 5)
    got = visible_gain(p, weight, unknown, rows, cols, 0.4 * m, n_rays, 0.5)
    np.testing.assert_allclose(got, oracle(p, weight, unknown, rows, cols, 0.4 * m, n_rays, 0.5), rtol=1e-12)


def test_open_unknown_ground_gives_the_disc_area():
    """All free and unknown, far from the border: the sum approaches the disc's area, pi r^2."""
    m, r = 101, 20.0
    ones = np.ones((m, m))
    g = visible_gain(ones, ones, np.ones((m, m), bool), np.array([50]), np.array([50]), r, 720, 0.05)
    assert g[0] == pytest.approx(math.pi * r**2, rel=0.01)


def test_a_wall_hides_what_lies_behind_it():
    m = 41
    p, unknown = np.ones((m, m)), np.ones((m, m), bool)
    p[:, 25] = 0.0  # a wall column east of the candidate
    seen = visible_gain(p, p, unknown, np.array([20]), np.array([20]), 15.0, 64, 0.5)[0]
    beyond = np.ones((m, m), bool)
    beyond[:, 26:] = False  # what lies behind the wall no longer counts: the same total
    assert visible_gain(p, p, unknown & beyond, np.array([20]), np.array([20]), 15.0, 64, 0.5)[0] == seen
    open_p = np.ones((m, m))
    assert visible_gain(open_p, open_p, unknown, np.array([20]), np.array([20]), 15.0, 64, 0.5)[0] > seen
