"""Smoothing at loop closures (``OnlineConfig(loop_smoothing=...)``, :mod:`digslam.observer.online.history`).

* The independent auditor (:mod:`auditor`: exact poses and ranges, no observer code) checks every step of
  long hostile episodes with it on, a small ``history`` so that steps get frozen: the truth stays in every
  box, no dug or clear cell meets an obstacle, and no dark cell was sensed, also after the possibly sensed
  zone shrank (a cell that turns dark again is checked against every earlier step).
* A pass shrinks past boxes, grows the clear zone and makes some possibly sensed cells dark.
* The history never holds more than ``history`` steps.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from auditor import audit_episode, random_actions

import digslam.envs  # noqa: F401  (registers the environments)
from digslam.envs.sim.generators import ThesisRoom
from digslam.envs.sim.missions import loop_mission
from digslam.observer.online.observer import OnlineConfig, OnlineDigSlam
from digslam.observer.record.grid import Grid


@pytest.mark.parametrize(("world", "seed"), [("rooms", 961000), ("rocks", 961001), ("caves", 961002)])
def test_audit_with_loop_smoothing(world: str, seed: int) -> None:
    env = gym.make("digslam/DigCoverage-v0", world=world, online={"loop_smoothing": 0.1, "history": 64})
    try:
        aud = audit_episode(env, seed, random_actions(np.random.default_rng(seed), 220))
        f = _filter(env)
        assert aud.k >= 100 and aud.free_ok.any() and aud.seen_ok.any()
        assert f.history is not None and f.history.n <= 64
    finally:
        env.close()


@pytest.mark.expensive
@pytest.mark.parametrize("world", ["room", "rocks", "caves", "rooms"])
def test_audit_with_loop_smoothing_long(world: str) -> None:
    """1200 hostile steps with frequent passes (threshold 5 %) and a history of 200 steps."""
    env = gym.make("digslam/DigCoverage-v0", world=world, target=1.0,
                   online={"loop_smoothing": 0.05, "history": 200})  # fmt: skip
    try:
        seed = 961100 + len(world)
        aud = audit_episode(env, seed, random_actions(np.random.default_rng(seed), 1200))
        assert aud.k >= 600 and _filter(env).history.n <= 200
    finally:
        env.close()


def _filter(env: gym.Env) -> OnlineDigSlam:
    e = env
    while not hasattr(e, "filter"):
        e = e.env
    return e.filter


def _run(records, grid: Grid, lo: np.ndarray, hi: np.ndarray, config: OnlineConfig):  # type: ignore[no-untyped-def]
    f = OnlineDigSlam(grid, config)
    f.reset(lo, hi, records[0])
    dark_lost = 0
    for k in range(1, len(records)):
        before = f.sensed_maybe.copy()
        f.update(records[k])
        dark_lost += int(np.count_nonzero(before & ~f.sensed_maybe))
    return f, dark_lost


def test_a_pass_sharpens_the_past_and_grows_dark() -> None:
    """The thesis's loop (§6.4.2 room, 150 s): a pass at the loop closure shrinks the boxes, digs more and
    makes possibly sensed cells dark; the possibly sensed zone stays inside the plain filter's."""
    rec, truth = loop_mission(ThesisRoom().generate(0), duration=150.0, seed=3)
    grid = Grid.from_cell_size((-10.0, -10.0), (10.0, 10.0), 0.1)
    x0 = truth[0, :2]
    plain, _ = _run(rec, grid, x0, x0, OnlineConfig())
    loop, dark_lost = _run(rec, grid, x0, x0, OnlineConfig(loop_smoothing=0.05, history=2000))
    assert plain.consistent and loop.consistent and loop.history.passes > 0
    assert np.all(plain.pose_lo <= loop.pose_lo) and np.all(loop.pose_hi <= plain.pose_hi)
    assert not np.any(plain.dig.free & ~loop.dig.free) and not np.any(plain.sensed_sure & ~loop.sensed_sure)
    assert (loop.sensed_sure & loop.dig.free).sum() > (plain.sensed_sure & plain.dig.free).sum()
    assert not np.any(loop.sensed_maybe & ~plain.sensed_maybe)  # the possibly sensed zone only shrinks
    assert dark_lost > 0, "no pass ever made a possibly sensed cell dark"
    assert np.all(truth[-1, :2] >= loop.pose_lo) and np.all(truth[-1, :2] <= loop.pose_hi)


def test_bad_settings_get_one_line() -> None:
    with pytest.raises(ValueError, match="loop_smoothing"):
        OnlineConfig(loop_smoothing=1.0)
    with pytest.raises(ValueError, match="loop_smoothing"):
        OnlineConfig(loop_smoothing=True)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="history"):
        OnlineConfig(loop_smoothing=0.2, history=1)
