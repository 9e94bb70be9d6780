"""Bounded noise: every interval contains the truth under every model; outliers are flagged."""

from __future__ import annotations

import numpy as np
import pytest

from digslam.envs import ExploreConfig, NoiseConfig, SensorSuite
from digslam.envs.sim.noise import measure
from digslam.envs.sim.sensors import measure_step

MODELS = ["uniform", "adversarial", "biased"]


@pytest.mark.parametrize("model", MODELS)
def test_intervals_contain_the_truth(model: str) -> None:
    rng = np.random.default_rng(0)
    cfg = NoiseConfig(model=model, bias=-0.7)
    truth = np.concatenate(
        [rng.uniform(-1e3, 1e3, 20000), rng.uniform(-1e-3, 1e-3, 20000), [0.0, 1e-300, 1e16]]
    )
    for b in (0.0, 1e-12, 0.001, 0.01, 1.0):
        m, lo, hi = measure(truth, b, cfg, rng)
        assert np.all(lo <= truth) and np.all(truth <= hi)
        assert np.all(lo <= m) and np.all(m <= hi)
        assert np.all(hi - lo <= 2 * b + 1e-9 * np.maximum(np.abs(truth), 1))


def test_adversarial_puts_the_truth_exactly_on_a_bound() -> None:
    rng = np.random.default_rng(1)
    truth = rng.uniform(0, 10, 5000)
    _, lo, hi = measure(truth, 0.01, NoiseConfig(model="adversarial"), rng)
    on_lo, on_hi = lo == truth, hi == truth
    assert np.all(on_lo | on_hi)
    assert on_lo.any() and on_hi.any()  # both sides occur


def test_biased_errors_are_biased_and_bounded() -> None:
    rng = np.random.default_rng(2)
    truth = np.zeros(20000)
    m, _, _ = measure(truth, 1.0, NoiseConfig(model="biased", bias=0.5), rng)
    assert 0.45 < m.mean() < 0.55
    assert m.min() >= 0.0 - 1e-12 and m.max() <= 1.0 + 1e-12


@pytest.mark.parametrize("model", MODELS)
def test_step_record_contains_truth(model: str) -> None:
    rng = np.random.default_rng(3)
    suite = SensorSuite.from_config(ExploreConfig())
    noise = NoiseConfig(model=model, range=0.05, speed=0.01, yaw_rate=0.02, heading=0.03)
    for _ in range(300):
        ranges = np.where(rng.uniform(size=suite.n) < 0.3, np.inf, rng.uniform(0, 5, suite.n))
        speed, yaw, heading = rng.uniform(-1, 1, 3) * [1, 1, 50]
        rec = measure_step(1.0, suite, ranges, speed, yaw, heading, noise, rng)
        assert rec.speed[0] <= speed <= rec.speed[1]
        assert rec.yaw_rate[0] <= yaw <= rec.yaw_rate[1]
        assert rec.heading[0] <= heading <= rec.heading[1]
        assert np.all(rec.range[:, 0] <= ranges) and np.all(ranges <= rec.range[:, 1])
        assert np.array_equal(rec.no_echo, np.isinf(ranges))
        assert np.all(rec.range[rec.no_echo, 1] == np.inf) and np.all(rec.range[:, 0] >= 0)
        if model == "adversarial":
            finite = ~rec.no_echo & (ranges > 0.1)
            on = (rec.range[finite, 0] == ranges[finite]) | (rec.range[finite, 1] == ranges[finite])
            assert np.all(on)


def test_outliers_are_flagged_and_off_by_default() -> None:
    rng = np.random.default_rng(4)
    suite = SensorSuite.from_config(ExploreConfig())
    ranges = np.full(suite.n, 2.0)
    rec = measure_step(0.0, suite, ranges, 0.0, 0.0, 0.0, NoiseConfig(), rng)
    assert not rec.outlier.any()
    flagged = 0
    for _ in range(200):
        rec = measure_step(0.0, suite, ranges, 0.0, 0.0, 0.0, NoiseConfig(outlier_prob=0.3), rng)
        good = ~rec.outlier
        assert np.all(rec.range[good, 0] <= ranges[good]) and np.all(ranges[good] <= rec.range[good, 1])
        assert not np.any(rec.no_echo & rec.outlier)
        flagged += int(rec.outlier.sum())
    assert 0.2 < flagged / (200 * suite.n) < 0.4


def test_negative_noise_bounds_are_rejected() -> None:
    for key in ("speed", "yaw_rate", "heading", "range"):
        with pytest.raises(ValueError, match=f"noise.{key}"):
            NoiseConfig(**{key: -0.1})
    with pytest.raises(ValueError, match="noise.model"):
        NoiseConfig(model="gaussian")
    with pytest.raises(ValueError, match="noise.outlier_prob"):
        NoiseConfig(outlier_prob=2.0)
    with pytest.raises(ValueError, match="rnage"):
        NoiseConfig.from_dict({"rnage": 0.1})
    with pytest.raises(ValueError, match="modle"):
        ExploreConfig(noise={"modle": "uniform"})


def test_the_record_draws_are_those_of_uniform() -> None:
    """``record_step`` draws ``rng.random`` and its kernel reads each as ``-1 + 2 u``: bit for bit the values of
    ``rng.uniform(-1, 1)``, with the generator left in the same state (records stay reproducible)."""
    a, b = np.random.default_rng(11), np.random.default_rng(11)
    for k in (1, 12, 15, 1000, 100_000):
        want, got = a.uniform(-1.0, 1.0, k), -1.0 + 2.0 * b.random(k)
        assert np.array_equal(want.view(np.int64), got.view(np.int64))
    assert a.bit_generator.state == b.bit_generator.state
