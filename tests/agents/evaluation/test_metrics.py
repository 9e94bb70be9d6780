"""Benchmark metrics on hand-made curves, the paired bootstrap, and their wiring into the evaluator."""

from __future__ import annotations

import math

import numpy as np
import pytest

from digslam.agents.baselines.registry import make_baseline
from digslam.agents.evaluation.evaluate import EvalResult, evaluate, make_env
from digslam.agents.evaluation.metrics import (
    auc,
    episode_metrics,
    metrics_table,
    paired_bootstrap_geomean,
    paired_bootstrap_ratio,
    path_length,
    summarize,
    time_to,
)


def test_times_to_levels_on_a_hand_made_curve() -> None:
    curve = np.array([0.1, 0.3, 0.79999, 0.8, 0.85, 0.9, 0.93, 0.949, 0.95, 0.96])
    m = episode_metrics(curve, budget=3000)
    assert (m["T80"], m["T90"], m["T95"]) == (3.0, 5.0, 8.0)
    assert (m["S80"], m["S90"], m["S95"]) == (1.0, 1.0, 1.0)
    assert time_to(curve, 0.97, budget=3000) == (3000, False)
    assert time_to(curve, 0.97) == (9, False)  # the curve's own steps by default
    assert time_to(np.array([0.95]), 0.9) == (0, True)  # already there at reset
    short = episode_metrics(np.array([0.0, 0.5, 0.82]), budget=100)
    assert (short["T80"], short["T90"], short["S90"], short["S80"]) == (2.0, 100.0, 0.0, 1.0)


def test_auc_is_the_mean_over_the_first_1000_steps_holding_the_last_value() -> None:
    ramp = np.concatenate([[0.0], np.arange(1, 3001) / 3000])  # coverage k / 3000 after step k
    assert auc(ramp) == pytest.approx(np.arange(1, 1001).mean() / 3000, rel=1e-12)
    # an episode that ended after 4 steps at 0.8: steps 5 to 1000 hold 0.8
    ended = np.array([0.0, 0.2, 0.4, 0.6, 0.8])
    assert auc(ended) == pytest.approx((0.2 + 0.4 + 0.6 + 0.8 * 997) / 1000, rel=1e-12)
    assert auc(ended, steps=2) == pytest.approx(0.3)
    assert episode_metrics(ended)["AUC"] == auc(ended)
    with pytest.raises(ValueError, match="curve"):
        auc(np.array([]))


def test_path_length_and_per_episode_values() -> None:
    assert path_length(np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 5.0]])) == pytest.approx(6.0)
    assert path_length(np.zeros((1, 2))) == 0.0
    m = episode_metrics(np.array([0.0, 1.0]), path=2.5, collisions=3, final_tube=0.1)
    assert (m["path_length"], m["collisions"], m["final_tube"]) == (2.5, 3.0, 0.1)
    assert math.isnan(episode_metrics(np.array([0.0, 1.0]))["path_length"])


def test_summaries_and_the_table() -> None:
    s = summarize({"T90": np.array([10.0, 20.0, 60.0]), "S90": np.array([1.0, 1.0, 0.0])})
    assert s["T90"] == {"mean": 30.0, "median": 20.0, "n": 3.0}
    assert s["S90"]["mean"] == pytest.approx(2 / 3)
    curves = np.array([[0.0, 0.85, 0.92, 0.96], [0.0, 0.5, 0.7, 0.81]])
    res = EvalResult({"a": curves}, {"a": curves}, {"a": np.array([0.0, 2.0])}, {"a": np.array([0.1, 0.3])})
    per = res.metrics()["a"]
    assert per["T80"].tolist() == [1.0, 3.0] and per["T95"].tolist() == [3.0, 3.0]
    assert per["S95"].tolist() == [1.0, 0.0] and per["collisions"].tolist() == [0.0, 2.0]
    row = metrics_table(res.metrics()).splitlines()[2]
    assert (
        row.startswith("| a | 2 / 2 (100%) | 2 / 2 (50%) | 2 / 2 (50%) | 3 / 3 (50%) |") and "n/a" in row
    )  # T80, T85, T90, T95


def test_the_paired_bootstrap_interval_holds_the_true_ratio_and_is_deterministic() -> None:
    rng = np.random.default_rng(0)
    difficulty = rng.uniform(500, 3000, 30)  # the maps: a large spread that both agents share
    a = difficulty * 0.8 * rng.lognormal(0.0, 0.05, 30)
    b = difficulty * rng.lognormal(0.0, 0.05, 30)
    ratio, lo, hi = paired_bootstrap_ratio(a, b, seed=7)
    assert lo < 0.8 < hi and lo <= ratio <= hi and ratio == pytest.approx(a.mean() / b.mean())
    assert hi - lo < 0.1  # paired: the shared map spread cancels
    assert paired_bootstrap_ratio(a, b, seed=7) == (ratio, lo, hi)  # same seed, same interval
    # unpaired (b's maps shuffled) the interval is much wider: the pairing is what makes it tight
    _, lo_u, hi_u = paired_bootstrap_ratio(a, rng.permutation(b), seed=7)
    assert hi_u - lo_u > 2 * (hi - lo)
    # pairs with a missing value are dropped
    assert paired_bootstrap_ratio(np.append(a, np.nan), np.append(b, 1.0), seed=7) == (ratio, lo, hi)
    with pytest.raises(ValueError, match="pair"):
        paired_bootstrap_ratio(a, b[:-1])


def test_the_evaluator_measures_the_true_path_and_gives_the_metrics() -> None:
    env = make_env("digslam/DigCoverage-v0", 40, {"map_size": 36})
    agent = make_baseline("frontier", env, seed=0)
    env.close()
    res = evaluate({"frontier": agent}, n_maps=1, seed=3, steps=40, env_kwargs={"map_size": 36})
    travelled = float(res.path_lengths["frontier"][0])
    assert 0.5 < travelled <= 40 * 1.0 * 0.1 + 1e-6  # moved, at most max_speed * dt per step
    m = res.metrics()["frontier"]
    assert m["path_length"][0] == travelled and m["T95"][0] == 40.0 and m["S95"][0] == 0.0


def test_paired_bootstrap_geomean_is_the_geometric_mean_of_the_per_map_ratios() -> None:
    rng = np.random.default_rng(3)
    b = rng.uniform(500, 3000, 40)
    a = b * np.exp(rng.normal(np.log(1.2), 0.1, 40))  # about 1.2x slower than b on every map
    r, lo, hi = paired_bootstrap_geomean(a, b, seed=1)
    assert r == pytest.approx(float(np.exp(np.mean(np.log(a / b)))))
    assert lo < r < hi and 1.1 < lo and hi < 1.3
    assert paired_bootstrap_geomean(a, b, seed=1) == (r, lo, hi)
    assert paired_bootstrap_geomean(np.array([2.0, np.nan, 0.0]), np.array([1.0, 1.0, 1.0]))[0] == 2.0
    with pytest.raises(ValueError, match="pair"):
        paired_bootstrap_geomean(np.array([1.0]), np.array([1.0, 2.0]))
