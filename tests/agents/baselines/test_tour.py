"""The tour frontier agent: the Held-Karp kernel against brute force, the regret, and the agent itself."""

from __future__ import annotations

import itertools

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces
from hypothesis import given, settings
from hypothesis import strategies as st
from planner_obs import planner_obs

import digslam.envs  # noqa: F401  (registers the env ids)
from digslam.agents.baselines import planning as pl
from digslam.agents.baselines.frontier import FrontierAgent
from digslam.agents.baselines.policy import parse
from digslam.agents.baselines.registry import BASELINES, make_baseline
from digslam.agents.baselines.tour import TourFrontierAgent, tour_regret
from digslam.agents.baselines.tour_jit import MAX_STOPS, open_tours

BOX = spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)


def brute_open_tours(d: np.ndarray) -> np.ndarray:
    """The oracle: every order of the other stops, for each start."""
    k = len(d)
    out = np.full(k, np.inf)
    for i in range(k):
        rest = [j for j in range(k) if j != i]
        for order in itertools.permutations(rest):
            path = (i, *order)
            out[i] = min(out[i], sum(d[a, b] for a, b in itertools.pairwise(path)))
    return out if k > 1 else np.zeros(k)


@settings(max_examples=60, deadline=None)
@given(k=st.integers(1, 7), seed=st.integers(0, 2**32 - 1), symmetric=st.booleans())
def test_open_tours_match_brute_force(k: int, seed: int, symmetric: bool) -> None:
    rng = np.random.default_rng(seed)
    d = rng.uniform(0.0, 50.0, (k, k))
    if symmetric:
        d = 0.5 * (d + d.T)
    np.fill_diagonal(d, 0.0)
    assert np.allclose(open_tours(d), brute_open_tours(d))


def test_an_unreachable_stop_makes_every_tour_infinite_and_the_regret_zero() -> None:
    d = np.array([[0.0, 1.0, np.inf], [1.0, 0.0, np.inf], [np.inf, np.inf, 0.0]])
    assert np.isinf(open_tours(d)).all()
    assert tour_regret(d).tolist() == [0.0, 0.0, 0.0]


def test_regret_is_zero_at_the_best_start_and_the_detour_elsewhere() -> None:
    # three stops on a line at 0, 10 and 30: starting at the middle one costs the way back to 0 (10 more)
    x = np.array([0.0, 10.0, 30.0])
    d = np.abs(x[:, None] - x[None, :])
    assert tour_regret(d).tolist() == [0.0, 10.0, 0.0]


def test_path_lengths_agree_with_shortest_paths() -> None:
    rng = np.random.default_rng(1)
    free = rng.random((20, 20)) > 0.25
    weight = rng.uniform(1.0, 3.0, free.shape)
    starts = np.array([[0, 0], [5, 7], [19, 19]])
    free[starts[:, 0], starts[:, 1]] = True
    many = pl.path_lengths(free, starts, weight)
    for s, row in zip(starts, many, strict=True):
        one, _ = pl.shortest_paths(free, (int(s[0]), int(s[1])), weight)
        assert np.array_equal(np.isfinite(one), np.isfinite(row))
        assert np.allclose(one[np.isfinite(one)], row[np.isfinite(row)])


def corridor_with_three_openings() -> tuple[np.ndarray, np.ndarray]:
    """A corridor along rows 16-20, columns 2-33, with dark ground beyond both ends and beyond an opening
    in its upper wall at columns 11-14. Every other pixel is a sensed obstacle (penumbra)."""
    clear = np.zeros((36, 36), bool)
    clear[16:21, 2:34] = True
    clear[14:16, 11:15] = True
    dark = np.zeros_like(clear)
    dark[16:21, :2] = dark[16:21, 34:] = dark[12:14, 11:15] = True
    return clear, dark


def test_each_cluster_costs_its_tour_regret_more_and_the_rest_is_unchanged() -> None:
    """Three frontier clusters along a corridor: both ends and an opening near the left end. A tour that
    starts at either end passes the opening on its way; one that starts at the opening leaves the left end
    behind and pays its way back to it (about 8 px here). The regret enters the cost map
    exactly as ``tour_weight * R`` on each cluster's pixels, and nowhere else."""
    clear, dark = corridor_with_three_openings()
    agent = TourFrontierAgent(BOX, span=36.0, gain_weight=0.0, turn_weight=0.0, tour_weight=2.0)
    obs = planner_obs(clear, (18.5, 20.5), dark)
    agent.predict(obs)
    view, mem = parse(obs["map"], obs["state"]), agent._mem[0]
    reach = np.isfinite(pl.shortest_paths(clear, view.cell)[0]) & view.clear
    base = agent.frontier_costs(view, mem, reach, np.zeros(clear.shape))
    pix, masks = agent.stops(view, mem, reach, base)
    assert len(masks) == 3
    eroded = agent.traversable(view)
    weight = agent.weights(view, eroded)
    trav = np.isfinite(weight)
    d = pl.path_lengths(trav, pix, np.where(trav, weight, 1.0))[:, pix[:, 0], pix[:, 1]]
    regret = tour_regret(d)
    ends = [int(np.argmin(pix[:, 1])), int(np.argmax(pix[:, 1]))]
    middle = ({0, 1, 2} - set(ends)).pop()
    assert 11 <= pix[middle, 1] <= 14
    assert regret[ends].tolist() == [0.0, 0.0] and regret[middle] > 5.0
    cost = base.copy()
    agent.add_regret(view, mem, reach, cost)
    for mask, r in zip(masks, regret, strict=True):
        assert np.allclose(cost[mask], base[mask] + 2.0 * r)
    rest = ~np.logical_or.reduce(masks)
    assert np.array_equal(cost[rest], base[rest])


def test_zero_tour_weight_is_the_frontier_agent() -> None:
    env = gym.make("digslam/DigCoverage-v0", world="rooms", map_size=36, max_episode_steps=200)
    tour = make_baseline("tour_frontier", env)
    tour.tour_weight = 0.0
    flat = make_baseline("frontier", env)
    assert "tour_frontier" in BASELINES and isinstance(tour, FrontierAgent)
    obs, _ = env.reset(seed=1_000_004)
    for _ in range(200):
        a, b = tour.predict(obs)[0], flat.predict(obs)[0]
        assert np.array_equal(a, b)
        obs, _, terminated, truncated, _ = env.step(a)
        if terminated or truncated:
            break
    env.close()


@pytest.mark.parametrize(
    ("kw", "word"),
    [({"tour_weight": -1.0}, "tour_weight"), ({"tour_weight": float("nan")}, "tour_weight"),
     ({"max_clusters": 1}, "max_clusters"), ({"max_clusters": MAX_STOPS + 1}, "max_clusters"),
     ({"min_cluster": 0}, "min_cluster")],
)  # fmt: skip
def test_bad_settings_are_one_line_naming_the_setting(kw: dict, word: str) -> None:
    with pytest.raises(ValueError, match=word):
        TourFrontierAgent(BOX, **kw)
