"""The distance-advantage frontier agent: the paper's ordering and no ground truth (its full episodes on every
generator: ``test_frontier.py``)."""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium import spaces

import digslam.envs  # noqa: F401  (registers the ids)
from digslam.agents.baselines import DistanceAdvantageAgent, FrontierAgent, isolation, make_baseline
from digslam.envs.dig_coverage.env import DigCoverageEnv
from digslam.envs.observation import N_STATE, Channel, State
from digslam.envs.sim.world import World

M = 36


def _corridor() -> dict[str, np.ndarray]:
    """A corridor 9 px high across the map, the robot at its middle (pixel 18, 18), open to dark ground at
    its left end (15 px away) and, 7 px to the right of the robot, through a gap in each wall: three
    frontiers, the two gaps 4 px apart, the left end 22 px from the nearest gap."""
    clear, pen = np.zeros((M, M), bool), np.zeros((M, M), bool)
    clear[14:23, 1:35] = True
    pen[8:14, :] = True
    pen[23:29, :] = True
    pen[14:23, 35] = True
    pen[8:14, 28:31] = pen[23:29, 28:31] = False
    dark = ~(clear | pen)
    img = np.zeros((4, M, M), np.uint8)
    img[Channel.CLEAR][clear], img[Channel.PENUMBRA][pen], img[Channel.DARK][dark] = 255, 255, 255
    state = np.zeros(N_STATE, np.float32)
    # heading +x, consistent; the pose box at the centre, zero width
    state[[State.COS, State.CONSISTENT]] = 1.0
    return {"map": img, "state": state}


def test_isolation_is_the_distance_to_the_nearest_other_candidate() -> None:
    cols = (0, 1, 3)
    masks = [np.zeros((4, 4), bool) for _ in cols]
    for m, c in zip(masks, cols, strict=True):
        m[:, c] = True
    lengths = np.array([np.abs(np.arange(4) - c)[None, :].repeat(4, 0) for c in cols], dtype=float)
    assert isolation(lengths, masks).tolist() == [1.0, 1.0, 2.0]
    assert isolation(lengths[:1], masks[:1]).tolist() == [0.0]  # a lone candidate: no advantage
    unreachable = lengths.copy()
    unreachable[2] = np.inf
    assert isolation(unreachable, masks)[2] == 0.0


def test_the_isolated_frontier_comes_before_the_nearer_pair_as_in_the_paper() -> None:
    """Distance advantage ``A(s) = min_{s'} d(s', s) - d(x, s)``: the left end (about 22 - 15 = 7) beats
    each gap (about 4 - 7 = -3), though the gaps are nearer; the nearest-frontier agent takes a gap."""
    space = spaces.Box(-1, 1, (2,))
    plain = FrontierAgent(space, turn_weight=0.0, gain_weight=0.0)
    plain.predict(_corridor())
    assert plain._mem[0].goal[1] > 20  # a gap, 7 px away
    da = DistanceAdvantageAgent(space, turn_weight=0.0, gain_weight=0.0)
    da.predict(_corridor())
    assert da._mem[0].goal[1] < 8  # the left end, 15 px away
    zero = DistanceAdvantageAgent(space, turn_weight=0.0, gain_weight=0.0, advantage_weight=0.0)
    zero.predict(_corridor())
    assert zero._mem[0].goal == plain._mem[0].goal  # weight 0: the frontier agent's choice


class _Fixed:
    """A generator that always returns ``world``."""

    def __init__(self, world: World) -> None:
        self.world, self.frame = world, world.frame

    def generate(self, seed: int | None = None) -> World:
        return self.world


def _drive(world: World, steps: int = 30) -> tuple[list, list]:
    env = DigCoverageEnv(map_size=36, start=(0.0, 0.0, 0.4))
    env.env.unwrapped.generator = _Fixed(world)
    agent = make_baseline("distance_advantage", env, seed=0)
    obs, info = env.reset(seed=3)
    actions, records = [], [info["record"]]
    for _ in range(steps):
        a, _ = agent.predict(obs)
        actions.append(np.array(a))
        obs, _, _, _, info = env.step(a)
        records.append(info["record"])
    return actions, records


def test_two_worlds_with_the_same_records_give_the_same_actions() -> None:
    """A rock more than 8 m from the start, out of the sensors' reach in 30 steps (3 m at most): the
    records agree, so the actions must (the agent reads the observation only)."""
    room = np.array([(-9, -9), (9, -9), (9, 9), (-9, 9)], np.float64)
    rock = np.array([(-7.5, -7.5), (-6.0, -7.5), (-6.0, -6.0), (-7.5, -6.0)], np.float64)
    frame = (-10.0, -10.0, 10.0, 10.0)
    act_a, rec_a = _drive(World(frame, [room], "room"))
    act_b, rec_b = _drive(World(frame, [room, rock], "room+rock"))
    assert all(a.same_as(b) for a, b in zip(rec_a, rec_b, strict=True))
    assert all(np.array_equal(a, b) for a, b in zip(act_a, act_b, strict=True))
    assert any(np.abs(a).max() > 0 for a in act_a)  # it does drive


@pytest.mark.parametrize("kw", [{"advantage_weight": -1.0}, {"advantage_weight": float("nan")}])
def test_bad_settings_are_one_line(kw: dict) -> None:
    with pytest.raises(ValueError, match="advantage_weight"):
        DistanceAdvantageAgent(spaces.Box(-1, 1, (2,)), **kw)
