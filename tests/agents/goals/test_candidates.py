"""The candidate goals on hand-made observations: the frontier agent's pick first, the turn, loop closures.

``digslam.agents.goals`` is imported inside the tests, not at collection: importing it registers the
``digslam/DigCoverageGoals*`` ids, and other test modules list the registered ``digslam/`` ids when they are
collected (``tests/envs/test_check_env.py``, the guarantee audit).
"""

from __future__ import annotations

import importlib
import math
from types import ModuleType

import numpy as np
import pytest
from gymnasium import spaces
from planner_obs import planner_obs

from digslam.agents.baselines import planning as pl
from digslam.agents.baselines.frontier import FrontierAgent
from digslam.agents.baselines.policy import parse

BOX = spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)


@pytest.fixture(scope="module")
def G() -> ModuleType:
    return importlib.import_module("digslam.agents.goals")


def _room() -> tuple[np.ndarray, np.ndarray]:
    """A clear room with unexplored (dark) ground beyond its left and right sides, penumbra above and
    below."""
    clear = np.zeros((36, 36), bool)
    clear[8:28, 6:30] = True
    dark = np.zeros_like(clear)
    dark[:, :4] = dark[:, 32:] = True
    return clear, dark


def test_clusters_keep_each_components_cheapest_pixel_sorted_by_cost(G: ModuleType) -> None:
    pixels = np.zeros((6, 8), bool)
    pixels[0, 0:3] = True  # one component
    pixels[4:6, 5:8] = True  # another
    cost = np.arange(48, dtype=float).reshape(6, 8)[::-1].copy()  # rows reversed: cheaper towards the bottom
    reps, costs, sizes = G.clusters(pixels, cost)
    assert reps.tolist() == [45, 0] and costs.tolist() == [5.0, 40.0] and sizes.tolist() == [6, 3]
    assert G.clusters(np.zeros((3, 3), bool), np.zeros((3, 3)))[0].size == 0


@pytest.mark.parametrize("heading", [0.0, math.pi])
def test_candidate_zero_is_the_frontier_agents_goal(G: ModuleType, heading: float) -> None:
    clear, dark = _room()
    obs = planner_obs(clear, (18.5, 12.5), dark, heading, tube=0.02)
    kw = {"span": 36.0, "unvisited_penalty": 100.0}  # the dark-ground frontiers first
    agent = FrontierAgent(BOX, **kw)
    agent.predict(obs)
    driver = G.GoalDriver(BOX, **kw)
    mem = driver.begin(36)
    c = G.candidates(driver, parse(obs["map"], obs["state"]), mem, n=16)
    assert tuple(c.goal[0]) == agent._mem[0].goal and c.kind[0] == G.FRONTIER
    sides = {
        int(g[1] < 18) for g, k, t in zip(c.goal, c.kind, c.features[:, 3]) if k == G.FRONTIER and t == 1
    }
    assert sides == {0, 1}  # a dark-ground frontier cluster on each side
    kinds = c.kind[c.mask].tolist()
    assert kinds == sorted(kinds, key=[G.FRONTIER, G.TURN, G.CLOSURE].index) and kinds.count(G.TURN) == 1
    assert c.mask.tolist() == sorted(c.mask.tolist(), reverse=True)  # the valid slots first
    f = c.features
    assert f.dtype == np.float32 and f.shape == (16, G.N_FEATURES) and np.all(np.abs(f) <= 1.0)
    assert not f[~c.mask].any() and np.all(f[c.mask, :3].sum(axis=1) == 1.0)
    fr = c.kind == G.FRONTIER
    assert np.all(np.diff(f[fr, 5]) >= 0)  # frontier clusters by heuristic cost
    assert np.all(f[fr & (f[:, 3] == 1.0), 9] > 0)  # gain: dark ground within sensor range of dark frontiers
    # the left frontier is nearer, the right one ahead at heading 0: the turn term of the frontier costs
    # decides
    assert (c.goal[0, 1] < 18) == (heading == math.pi)


def test_with_no_frontier_left_the_turn_comes_first(G: ModuleType) -> None:
    clear, dark = _room()
    obs = planner_obs(clear, (18.5, 12.5), dark, tube=0.02)
    driver = G.GoalDriver(BOX, span=36.0)
    mem = driver.begin(36)
    mem.visited[:] = True
    view = parse(obs["map"], obs["state"])
    c = G.candidates(driver, view, mem, n=8)
    assert c.kind[0] == G.TURN and tuple(c.goal[0]) == view.cell and c.n_frontier == 0
    assert c.features[0, 2] == 1.0 and c.features[0, 4] == 0.0


def test_loop_closure_candidates_are_pixels_passed_with_a_narrow_tube(G: ModuleType) -> None:
    clear, dark = _room()
    driver = G.GoalDriver(BOX, span=36.0)
    mem = driver.begin(36)
    for pos in [(9.5, 8.5), (9.5, 27.5)]:  # near the top-left and top-right walls, narrow tube
        view = parse(*planner_obs(clear, pos, dark, tube=0.05).values())
        G.candidates(driver, view, mem)
    view = parse(*planner_obs(clear, (20.5, 18.5), dark, tube=0.8).values())
    c = G.candidates(driver, view, mem, n=16)
    closure = np.flatnonzero(c.kind == G.CLOSURE)
    assert closure.size >= 1 and closure.min() > np.flatnonzero(c.kind == G.TURN)[0]
    for s in closure:
        assert c.features[s, 1] == 1.0 and c.features[s, 10] == pytest.approx(math.tanh(0.05), abs=1e-6)
        near = pl.dilate(view.penumbra, driver.erosion(view) + 1)  # next to sensed obstacles
        assert mem.best_tube[tuple(c.goal[s])] <= 0.4 and near[tuple(c.goal[s])]
    # with the tube as narrow as then, nothing calls for a loop closure
    view = parse(*planner_obs(clear, (20.5, 18.5), dark, tube=0.05).values())
    assert G.candidates(driver, view, mem, n=16).n_closure == 0


def test_few_slots_keep_the_cheapest_frontiers_the_turn_and_some_closures(G: ModuleType) -> None:
    clear, dark = _room()
    driver = G.GoalDriver(BOX, span=36.0)
    mem = driver.begin(36)
    G.candidates(driver, parse(*planner_obs(clear, (9.5, 8.5), dark, tube=0.05).values()), mem)
    view = parse(*planner_obs(clear, (20.5, 18.5), dark, tube=0.8).values())
    full = G.candidates(driver, view, mem, n=32)
    two = G.candidates(driver, view, mem, n=2)
    assert two.mask.all() and two.kind.tolist() == [G.FRONTIER, G.TURN]
    assert tuple(two.goal[0]) == tuple(full.goal[0])
