"""Offline Dig-SLAM (:func:`digslam.observer.online.smoother.dig_slam`) against the online filter on the same
record: never less sharp, never wrong.

On hostile episodes (the auditor's random actions: tiny, subnormal and huge yaws, spins, full-speed runs into
walls; adversarial noise) of every generator and both robots, with the filter's settings:

* every offline box lies inside the filter's box of the same step (exactly: the offline observer starts
  from the filter's boxes and only intersects), and holds the true position;
* the offline ``M⁻`` and clear cells contain the filter's, and its dark cells contain the filter's;
* every offline free cell is free in the exact world (:func:`ground_truth.assert_free`, no observer code).
"""

from __future__ import annotations

import numpy as np
import pytest
from auditor import random_actions
from ground_truth import assert_free
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from digslam.envs import ExploreEnv, record_episode
from digslam.observer.online.observer import OnlineConfig, OnlineDigSlam
from digslam.observer.online.smoother import dig_slam
from digslam.observer.record.grid import Grid
from digslam.observer.slam.digslam import DigSlamConfig
from digslam.observer.thick.cells import CLEAR, DARK

CELL = 0.125


def online_run(grid: Grid, records, lo, hi, config: OnlineConfig):  # type: ignore[no-untyped-def]
    """The filter step by step: its boxes ``(T + 1, 2)`` twice, and the filter."""
    f = OnlineDigSlam(grid, config)
    f.reset(lo, hi, records[0])
    los, his = [f.pose_lo.copy()], [f.pose_hi.copy()]
    for k in range(1, len(records)):
        f.update(records[k])
        los.append(f.pose_lo.copy())
        his.append(f.pose_hi.copy())
    return np.array(los), np.array(his), f


def check_offline_inside_online(world: str, dynamics: str, seed: int, steps: int, q: int = 0,
                                cones: bool = True) -> None:  # fmt: skip
    env = ExploreEnv(world=world, dynamics=dynamics, noise={"model": "adversarial"})
    ep = record_episode(env, seed, random_actions(np.random.default_rng(seed), steps))
    s = float(ep.config.world_size)
    n = int(round(2 * s / CELL))
    grid = Grid((-s, -s), (s, s), (n, n))
    p = ep.truth.pose[0, :2]
    lo, hi = np.maximum(p - 0.1, -s), np.minimum(p + 0.1, s)
    on = OnlineConfig(q=q, cones=cones)
    o_lo, o_hi, f = online_run(grid, ep.records, lo, hi, on)
    res = dig_slam(ep.records, grid, lo, hi, DigSlamConfig(q=q, cones=cones, cone_every=on.cone_every))
    assert f.consistent and res.consistent, (world, dynamics, seed)
    g_lo, g_hi = res.tube.gate_lo, res.tube.gate_hi
    assert np.all((o_lo <= g_lo) & (g_hi <= o_hi)), "an offline box leaves the filter's"
    assert np.all(res.tube.contains(ep.records.t, ep.truth.pose[:, :2])), "the truth left the offline tube"
    assert not np.any(f.dig.free & ~res.dig.free), "the filter proved a cell free that the offline did not"
    assert not np.any(f.sensed_sure & (res.explored != CLEAR)), "a filter-clear cell is not offline-clear"
    assert not np.any(~f.sensed_maybe & (res.explored != DARK)), "a filter-dark cell is not offline-dark"
    assert_free(res.dig.free, env.world, grid, np.random.default_rng(seed), n=500)
    env.close()


@pytest.mark.parametrize("world", ["room", "rocks", "caves", "rooms"])
@pytest.mark.parametrize("dynamics", ["pymunk", "unicycle"])
def test_offline_inside_online_on_hostile_episodes(world: str, dynamics: str) -> None:
    check_offline_inside_online(world, dynamics, seed=11, steps=160)


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(world=st.sampled_from(["room", "rocks", "caves", "rooms"]), dynamics=st.sampled_from(["pymunk", "unicycle"]),
       seed=st.integers(0, 2**20), q=st.sampled_from([0, 1]), cones=st.booleans())  # fmt: skip
def test_offline_inside_online_property(world: str, dynamics: str, seed: int, q: int, cones: bool) -> None:
    check_offline_inside_online(world, dynamics, seed, steps=90, q=q, cones=cones)


def test_offline_is_sharper_somewhere_on_a_long_episode() -> None:
    """On a 600-step episode of the rooms generator the offline tube is strictly narrower than the filter's
    at some step (the future's readings and ``M⁻`` contract the past), so the property above is not vacuous."""
    env = ExploreEnv(world="rooms", noise={"model": "uniform"})
    ep = record_episode(env, 3, random_actions(np.random.default_rng(3), 600))
    s = float(ep.config.world_size)
    grid = Grid((-s, -s), (s, s), (int(round(2 * s / CELL)),) * 2)
    p = ep.truth.pose[0, :2]
    res = dig_slam(ep.records, grid, p - 0.1, p + 0.1)
    assert res.consistent and res.online_widths is not None
    w = res.tube.widths()
    assert np.all(w <= res.online_widths) and np.any(w < res.online_widths - 1e-3)
    env.close()


def test_bad_input_gets_one_line() -> None:
    env = ExploreEnv()
    ep = record_episode(env, 0, np.zeros((3, 2)))
    grid = Grid((-10.0, -10.0), (10.0, 10.0), (16, 16))
    with pytest.raises(ValueError, match="inside the grid"):
        dig_slam(ep.records, grid, [20.0, 0.0], [21.0, 0.0])
    with pytest.raises(ValueError, match="finite"):
        dig_slam(ep.records, grid, [np.inf, 0.0], [np.inf, 0.0])
    with pytest.raises(ValueError, match="grid"):
        dig_slam(ep.records, None, [0.0, 0.0], [0.0, 0.0])  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="q"):
        DigSlamConfig(q=-1)
    with pytest.raises(ValueError, match="explored"):
        dig_slam(ep.records, grid, [0.0, 0.0], [0.0, 0.0], DigSlamConfig(q=1, explored=True))
    env.close()
