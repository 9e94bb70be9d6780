"""``predictive_frontier``: observation only at run time, the frontier agent at zero predicted weight, the
oracle diagnosis."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import digslam.envs  # noqa: F401
from digslam.agents.baselines.registry import make_baseline
from digslam.agents.prediction import make_predictive
from digslam.agents.prediction.agent import TrueMap
from digslam.agents.prediction.gate import Gate
from digslam.agents.prediction.oracle import ORACLE, oracle_suite
from digslam.envs.dig_coverage.env import DigCoverageEnv
from digslam.envs.sim.world import World

torch = pytest.importorskip("torch")

from digslam.agents.prediction.model import MapUNet, Predictor  # noqa: E402

ROOM = np.array([(-9, -9), (-3, -8), (1, -9.2), (8.5, -8), (9, -2), (6, 1), (9.2, 5), (7, 9), (1, 8.5), (-1, 5),
                 (-4, 9), (-9, 8), (-8, 2), (-5, 0), (-9.3, -3)], np.float64)  # fmt: skip
ROCK = np.array([(-7.5, -7.5), (-6.0, -7.5), (-6.0, -6.0), (-7.5, -6.0)], np.float64)


class _Fixed:
    def __init__(self, world: World) -> None:
        self.world, self.frame = world, world.frame

    def generate(self, seed: int | None = None) -> World:
        return self.world


class _Recording:
    """A map source that records what it was asked (the inputs a predictor sees) and answers with a net."""

    def __init__(self) -> None:
        torch.manual_seed(0)
        self.net, self.seen = Predictor(MapUNet()), []

    def free(self, image):
        self.seen.append(np.array(image))
        return self.net.free(image)


def _run(world: World, steps: int = 30):
    env = DigCoverageEnv(map_size=36, start=(0.0, 0.0, 0.4))
    env.env.unwrapped.generator = _Fixed(world)
    source = _Recording()
    agent = make_predictive(env, predictor=source, predict_every=5)
    obs, info = env.reset(seed=3)
    actions, records = [], [info["record"]]
    for _ in range(steps):  # at most 3 m from the start: the rock stays beyond the 5 m sensors
        a, _ = agent.predict(obs)
        actions.append(a)
        obs, _, _, _, info = env.step(a)
        records.append(info["record"])
    env.close()
    return np.array(actions), source.seen, records


def test_same_records_same_predictions_and_actions():
    """A rock beyond the sensors' reach changes the world and not the records: the agent cannot tell."""
    frame = (-10.0, -10.0, 10.0, 10.0)
    room, rocky = World(frame, [ROOM], "room"), World(frame, [ROOM, ROCK], "room+rock")
    a1, seen1, rec1 = _run(room)
    a2, seen2, rec2 = _run(rocky)
    assert all(x.same_as(y) for x, y in zip(rec1, rec2, strict=True))
    np.testing.assert_array_equal(a1, a2)
    assert len(seen1) == len(seen2) > 1
    for x, y in zip(seen1, seen2, strict=True):
        np.testing.assert_array_equal(x, y)


def test_zero_predicted_weight_is_the_frontier_agent():
    env = gym.make("digslam/DigCoverage-v0", world="rocks", fixed_world=False)
    base = make_baseline("frontier", env)
    torch.manual_seed(0)
    agent = make_predictive(env, predictor=Predictor(MapUNet()), predicted_weight=0.0, gain_weight=40.0)
    obs, _ = env.reset(seed=1_000_000)
    for _ in range(150):
        a, _ = agent.predict(obs)
        np.testing.assert_array_equal(a, base.predict(obs)[0])
        obs, *_ = env.step(a)
    env.close()


def test_bad_settings_say_what_is_wrong():
    env = gym.make("digslam/DigCoverage-v0")
    with pytest.raises(ValueError, match="uncertainty"):
        make_predictive(env, predictor=Predictor(MapUNet()), uncertainty=-1.0)
    with pytest.raises(ValueError, match="free\\(image\\)"):
        make_predictive(env, predictor=object())
    with pytest.raises(ValueError, match="TrueMap needs a DigCoverage env"):
        TrueMap(object())
    env.close()


def test_the_oracle_reads_the_true_map_and_runs_as_a_suite_row():
    env = gym.make("digslam/DigCoverage-v0", world="rooms", fixed_world=False)
    env.reset(seed=1_000_001)
    p, var = TrueMap(env).free(np.zeros((4, 64, 64), np.uint8))
    assert p.shape == (64, 64) and np.all(var == 0) and 0 < p.mean() < 1
    env.close()
    res = oracle_suite(n_maps=1, steps=40, split="validation", generators=["room"])
    assert res.agents == [ORACLE] and res.results["room"].curves[ORACLE].shape == (1, 41)


class _Uniform:
    """A map source that predicts every pixel free with probability ``p``."""

    def __init__(self, p: float) -> None:
        self.p = p

    def free(self, image):
        m = np.asarray(image).shape[-1]
        return np.full((m, m), self.p), np.zeros((m, m))


def _costs(agent, obs):
    """The frontier costs and predictive costs of ``agent`` at its first plan on ``obs``."""
    from digslam.agents.baselines import planning as pl
    from digslam.agents.baselines.frontier import FrontierAgent
    from digslam.agents.baselines.policy import Memory, parse

    view = parse(obs["map"], obs["state"])
    mem = Memory(view.clear.shape[0])
    free, weight = agent.planner_graph(view, mem, view.clear)  # the soft planner's graph
    dist, _ = pl.shortest_paths(free, view.cell, weight)
    reach = np.isfinite(dist) & view.clear
    base = FrontierAgent.frontier_costs(agent, view, mem, reach, dist)
    return (
        base,
        agent.frontier_costs(view, mem, reach, dist),
        agent.predicted_gain(view, mem, np.isfinite(base)),
    )


def test_the_ratio_score_is_path_per_predicted_gain():
    """``score="ratio"``: ``(max(c, 0) + offset) (scale + floor) / (g + floor)`` on the candidates, ``inf``
    elsewhere; ``"difference"``: ``c - w g / px``. Both rank by the same predicted gain ``g`` (no gate:
    ``test_gate.py`` checks what it does with these costs)."""
    env = gym.make("digslam/DigCoverage-v0", world="caves", fixed_world=False)
    obs, _ = env.reset(seed=1_000_002)
    for _ in range(20):
        obs, *_ = env.step(np.array([0.5, 0.3], np.float32))
    ratio = make_predictive(env, predictor=_Uniform(0.7), gate=Gate("off"))
    base, cost, gain = _costs(ratio, obs)
    cand = np.isfinite(base)
    px = ratio.px(base.shape[0])
    assert cand.any() and np.array_equal(np.isfinite(cost), cand) and gain[cand].max() > 0
    want = (np.maximum(base[cand], 0) + 3.125 / px) * (0.1 + 0.01) / (gain[cand] + 0.01)
    np.testing.assert_allclose(cost[cand], want)
    diff = make_predictive(env, predictor=_Uniform(0.7), score="difference", predicted_weight=80.0,
                           gate=Gate("off"))  # fmt: skip
    base, cost, gain = _costs(diff, obs)
    np.testing.assert_allclose(cost[cand], base[cand] - 80.0 * gain[cand] / px)
    with pytest.raises(ValueError, match="score: must be 'ratio' or 'difference'"):
        make_predictive(env, predictor=_Uniform(0.7), score="product")
    with pytest.raises(ValueError, match="gain_floor: must be finite and > 0"):
        make_predictive(env, predictor=_Uniform(0.7), gain_floor=0.0)
    env.close()
