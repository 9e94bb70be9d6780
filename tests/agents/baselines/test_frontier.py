"""The navigating baselines' loop closure: how a closure ends, and full episodes on every world generator."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces
from planner_obs import planner_obs

import digslam.envs  # noqa: F401  (registers the env ids)
from digslam.agents.baselines.frontier import FrontierAgent
from digslam.agents.baselines.navigating import BACK_STEPS, STALL_STEPS
from digslam.agents.baselines.registry import BASELINES, UncertaintyAwareFrontier, make_baseline
from digslam.envs.observation import State
from digslam.envs.sim.generators import GENERATORS

BOX = spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)


def test_a_closure_with_no_target_left_ends_at_once_even_through_the_cautious_pass() -> None:
    """The crash of issue #18 on ``rooms``: a closure whose targets are all used up, on a map where no frontier
    is left over clear ground either, so that the cautious pass (across penumbra) plans a second time."""
    clear = np.zeros((36, 36), bool)
    clear[4:32, 4:32] = True
    pen = np.zeros_like(clear)
    pen[2:34, 2:34] = True
    dark = ~pen  # sensed obstacles (penumbra) all around the clear room, dark beyond
    agent = UncertaintyAwareFrontier(BOX, tube_high=0.5, span=36.0)
    agent.predict(planner_obs(clear, (18.5, 18.5), dark, tube=0.05))
    mem = agent._mem[0]
    mem.visited[:] = True  # nothing left to explore over clear ground: the cautious pass runs
    mem.extra.update(closing=0.8, t0=mem.t, done_at=[np.array([18.5, 18.5])], high=0.5, closures=1)
    mem.best_tube[:] = np.inf  # no obstacle was passed with a narrow tube: no loop-closure target anywhere
    mem.goal = mem.waypoint = None
    action, _ = agent.predict(planner_obs(clear, (18.5, 18.5), dark, tube=0.8))
    assert BOX.contains(action)
    assert mem.extra["closing"] is None  # the closure ended: it had nowhere to go
    assert mem.extra["high"] == pytest.approx(0.8 * agent.backoff)  # a failed one: the tube did not shrink
    assert all(p is not None for p in mem.extra["done_at"])


def test_a_closure_keeps_going_while_targets_remain() -> None:
    clear = np.zeros((36, 36), bool)
    clear[2:34, 2:34] = True
    dark = np.zeros_like(clear)
    dark[:, 34:] = True
    agent = UncertaintyAwareFrontier(BOX, tube_high=0.5, span=36.0, visits=3)
    agent.predict(planner_obs(clear, (4.5, 4.5), dark, tube=0.05))  # near the top-left walls, narrow tube
    agent.predict(planner_obs(clear, (4.5, 29.5), dark, tube=0.05))  # near the top-right ones, 25 m away
    agent.predict(planner_obs(clear, (20.5, 20.5), dark, tube=0.8))
    mem = agent._mem[0]
    assert mem.extra["closing"] == pytest.approx(0.8, abs=1e-6) and mem.extra["targets"]
    first = mem.goal
    agent.predict(
        planner_obs(clear, (first[0] + 0.5, first[1] + 0.5), dark, tube=0.8)
    )  # at the target: one visit
    assert len(mem.extra["done_at"]) == 1 and mem.extra["closing"] is not None  # the other corner is left
    assert mem.goal is not None and abs(mem.goal[1] - first[1]) > 15
    second = mem.goal
    agent.predict(planner_obs(clear, (second[0] + 0.5, second[1] + 0.5), dark, tube=0.8))
    assert len(mem.extra["done_at"]) == 2 and mem.extra["closing"] is None  # no target left: it ended
    assert mem.extra["high"] == pytest.approx(0.8 * agent.backoff)


@pytest.mark.parametrize("world", sorted(set(GENERATORS) - {"file"}))
@pytest.mark.parametrize("name", ["frontier", "uncertainty_frontier", "tour_frontier", "distance_advantage"])
def test_the_frontier_agents_run_a_full_short_episode_on_every_generator(world: str, name: str) -> None:
    env = gym.make("digslam/DigCoverage-v0", world=world, map_size=36, max_episode_steps=150)
    agent = make_baseline(name, env, seed=0)
    assert name in BASELINES
    obs, info = env.reset(seed=1)
    done, steps = False, 0
    while not done:
        action, _ = agent.predict(obs)
        assert env.action_space.contains(action)
        obs, _, terminated, truncated, info = env.step(action)
        done, steps = terminated or truncated, steps + 1
    assert steps <= 150 and info["consistent"] and info["certified_coverage"] > 0.0
    env.close()


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_uncertainty_aware_frontier_survives_the_rooms_episode_that_crashed(seed: int) -> None:
    """On ``rooms`` the closures run out of targets (``TypeError`` in ``_costs`` before the fix, after about
    2300 steps with the defaults); here within 500 steps: a low threshold starts closures early and a wide
    spread uses their targets up fast (the old code crashed on three of these four maps)."""
    env = gym.make("digslam/DigCoverage-v0", world="rooms", map_size=36, max_episode_steps=500)
    agent = make_baseline("uncertainty_frontier", env, seed=0)
    agent.tube_high, agent.closure_steps, agent.spread = 0.05, 100, 8.0
    obs, _ = env.reset(seed=seed)
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(agent.predict(obs)[0])
        done = terminated or truncated
    extra = agent._mem[0].extra
    assert extra.get("exhausted", 0) >= 1  # the path that crashed was taken
    assert info["consistent"]
    env.close()


def test_with_every_clear_pixel_visited_the_goal_is_the_far_end_of_a_penumbra_corridor() -> None:
    """A room seen in full and a corridor out of it seen only in penumbra (the cones, cut short by its walls,
    never cleared it), dark beyond: once the room is visited, the goal is the corridor's edge with the dark
    ground (``penumbra_frontier``), not the penumbra band along the room's walls; without it there is no goal at
    all (the stall on ``rooms``)."""
    clear = np.zeros((36, 36), bool)
    clear[10:26, 4:16] = True
    dark = np.ones_like(clear)
    dark[8:28, 2:18] = False  # the room and its walls' penumbra
    dark[16:20, 18:26] = False  # the corridor, penumbra, ending at dark column 26
    goals = {}
    for on in (True, False):
        agent = FrontierAgent(BOX, span=36.0, penumbra_frontier=on)
        agent.predict(planner_obs(clear, (18.5, 9.5), dark, tube=0.05))
        mem = agent._mem[0]
        mem.visited[clear] = True  # the whole room explored
        mem.goal = mem.waypoint = None
        agent.predict(planner_obs(clear, (18.5, 9.5), dark, tube=0.05))
        goals[on] = mem.goal
    assert goals[False] is None
    g = goals[True]
    assert g is not None and 16 <= g[0] < 20 and 18 < g[1] <= 25  # in the corridor, not the room's wall band


def test_a_robot_driving_without_moving_blocks_the_pixel_ahead_and_backs_off() -> None:
    """Pressed into an obstacle that the map shows as free (the observation stays the same while the agent
    drives): after ``STALL_STEPS`` driving steps the pixel ahead is blocked for the planner, the goal is
    dropped and the robot reverses for ``BACK_STEPS`` steps; with ``unstick=False`` it pushes on."""
    clear = np.zeros((36, 36), bool)
    clear[4:32, 4:32] = True
    dark = np.zeros_like(clear)
    dark[:, 33:] = True
    obs = planner_obs(
        clear, (18.5, 10.5), dark, tube=0.05
    )  # heading +x (State.COS = 1), frontier to the east
    for unstick in (True, False):
        agent = FrontierAgent(BOX, span=36.0, visit_radius=0.5, unstick=unstick)
        actions = [agent.predict(obs)[0] for _ in range(STALL_STEPS + 1 + BACK_STEPS)]
        mem = agent._mem[0]
        driving = [i for i, a in enumerate(actions) if a[0] > 0]
        assert driving, "the agent never drove towards the frontier"
        if unstick:
            first = driving[0]
            reverse = [i for i, a in enumerate(actions) if a[0] < 0]
            assert reverse and reverse[0] == first + STALL_STEPS + 1  # STALL_STEPS steps of driving seen
            assert all(actions[i][0] < 0 for i in range(reverse[0], reverse[0] + BACK_STEPS))
            assert mem.blocked[18, 11] and not mem.blocked[18, 10]  # the pixel ahead; never the robot's own
            assert mem.goal is None or not mem.blocked[mem.goal]
        else:
            assert not mem.blocked.any()
            assert all(a[0] >= 0 for a in actions)


def test_of_two_frontiers_the_one_facing_more_dark_ground_wins() -> None:
    """The expected gain (``gain_weight``): a clear strip with dark ground at both ends, the robot in the
    middle facing neither end; beyond the west end a large dark area, beyond the east end, a pixel closer, a
    thin dark band (then ground seen from elsewhere). Without the gain term the goal is the nearer east end;
    with it, the west end."""
    clear = np.zeros((36, 36), bool)
    clear[16:20, 10:26] = True  # the strip
    clear[:, 28:] = True  # already seen beyond the thin east band
    dark = np.zeros_like(clear)
    dark[:, :10] = True  # the large unexplored west
    dark[:, 26:28] = True  # a thin dark band to the east
    obs = planner_obs(clear, (18.0, 18.0), dark, tube=0.05)
    # heading north: both ends are a quarter turn away
    obs["state"][State.COS], obs["state"][State.SIN] = 0.0, 1.0
    goal = {}
    for w in (0.0, 40.0):
        agent = FrontierAgent(
            BOX,
            span=36.0,
            visit_radius=0.5,
            gain_weight=w,
            sensor_range=12.0,
            penumbra_penalty=100.0,
            unvisited_penalty=200.0,
        )  # dark-ground frontiers only
        agent.predict(obs)
        goal[w] = agent._mem[0].goal
    assert goal[0.0] is not None and goal[0.0][1] >= 20  # the nearer east end
    assert goal[40.0] is not None and goal[40.0][1] < 16  # the west end, facing the unexplored
