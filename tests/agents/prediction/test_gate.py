"""The do-no-harm gate of ``predictive_frontier``: its rule, thresholds from the settings file, a closed gate
is the frontier agent, its decisions read the records only, and in a single room the agent's path to the
level stays within 5 % of the frontier agent's."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import digslam.envs  # noqa: F401
from digslam.agents.baselines.registry import make_baseline
from digslam.agents.evaluation.levels import TARGET_LEVELS
from digslam.agents.prediction import make_predictive
from digslam.agents.prediction.gate import Gate
from digslam.agents.prediction.settings import SHIPPED_SETTINGS, PredictiveSettings, load_settings
from digslam.envs.dig_coverage.env import DigCoverageEnv
from digslam.envs.sim.world import World

torch = pytest.importorskip("torch")

from digslam.agents.prediction.model import MapUNet, Predictor  # noqa: E402

ROOM = np.array([(-9, -9), (-3, -8), (1, -9.2), (8.5, -8), (9, -2), (6, 1), (9.2, 5), (7, 9), (1, 8.5), (-1, 5),
                 (-4, 9), (-9, 8), (-8, 2), (-5, 0), (-9.3, -3)], np.float64)  # fmt: skip
ROCK = np.array([(-7.5, -7.5), (-6.0, -7.5), (-6.0, -6.0), (-7.5, -6.0)], np.float64)
FRAME = (-10.0, -10.0, 10.0, 10.0)


class _Fixed:
    def __init__(self, world: World) -> None:
        self.world, self.frame = world, world.frame

    def generate(self, seed: int | None = None) -> World:
        return self.world


def _net() -> Predictor:
    torch.manual_seed(0)
    return Predictor(MapUNet())


def test_the_rule():
    g = Gate("score_ratio", ratio=2.0, margin=0.5)
    assert g.keeps_prediction(10.0, 20.5) and not g.keeps_prediction(10.0, 20.4)
    assert Gate("off").keeps_prediction(1.0, 0.0)
    for kw, key in (({"mode": "sometimes"}, "gate"), ({"ratio": 0.9}, "gate_ratio"),
                    ({"margin": -1.0}, "gate_margin"), ({"ratio": float("nan")}, "gate_ratio")):  # fmt: skip
        with pytest.raises(ValueError, match=key):
            Gate(**kw)


def test_thresholds_come_from_the_settings_file(tmp_path: Path):
    env = gym.make("digslam/DigCoverage-v0")
    shipped = load_settings()
    assert make_predictive(env, predictor=_net()).gate == shipped.make_gate()
    assert PredictiveSettings.from_file(SHIPPED_SETTINGS) == shipped
    f = tmp_path / "mine.toml"
    f.write_text('kind = "predictive_frontier"\ngate = "score_ratio"\ngate_ratio = 3.0\ngate_margin = 0.02\n')
    agent = make_predictive(env, predictor=_net(), settings=f)
    assert agent.gate == Gate("score_ratio", 3.0, 0.02)
    f.write_text('kind = "predictive_frontier"\ngate_ratoi = 3.0\n')
    with pytest.raises(ValueError, match="gate_ratoi"):
        make_predictive(env, predictor=_net(), settings=f)
    f.write_text('kind = "predictive_frontier"\ngate = "score_ratio"\nscore = "difference"\n')
    with pytest.raises(ValueError, match="gate: compares path per gain"):
        make_predictive(env, predictor=_net(), settings=f)
    env.close()


def test_a_closed_gate_is_the_frontier_agent():
    """A ratio no prediction reaches: every plan takes the frontier agent's costs, hysteresis included."""
    env = gym.make("digslam/DigCoverage-v0", world="rocks", fixed_world=False)
    base = make_baseline("frontier", env)
    agent = make_predictive(env, predictor=_net(), gate=Gate("score_ratio", ratio=1e12, margin=1.0))
    obs, _ = env.reset(seed=1_000_000)
    for _ in range(200):
        a, _ = agent.predict(obs)
        np.testing.assert_array_equal(a, base.predict(obs)[0])
        obs, *_ = env.step(a)
    kept, closed = agent.memory(0).extra.get("gate_counts", [0, 0])
    assert kept == 0 and closed > 0  # the gate was asked, and said no
    env.close()


def _gated_run(world: World, steps: int = 40) -> tuple[np.ndarray, list]:
    env = DigCoverageEnv(map_size=36, start=(0.0, 0.0, 0.4))
    env.env.unwrapped.generator = _Fixed(world)
    agent = make_predictive(env, predictor=_net(), predict_every=5, gate=Gate("score_ratio", 1.1))
    obs, _ = env.reset(seed=3)
    actions, decisions = [], []
    for _ in range(steps):  # at most 4 m from the start: the rock stays beyond the 5 m sensors
        a, _ = agent.predict(obs)
        actions.append(a)
        x = agent.memory(0).extra
        decisions.append((x.get("gate"), tuple(x.get("gate_counts", ()))))
        obs, *_ = env.step(a)
    env.close()
    return np.array(actions), decisions


def test_the_gate_reads_the_records_only():
    """A rock beyond the sensors' reach changes the world and not the records: same decisions, same
    actions."""
    a1, d1 = _gated_run(World(FRAME, [ROOM], "room"))
    a2, d2 = _gated_run(World(FRAME, [ROOM, ROCK], "room+rock"))
    np.testing.assert_array_equal(a1, a2)
    assert d1 == d2


def _path_to_level(agent_of, level: float, steps: int = 3000) -> float:
    """Metres the true robot drives in the hand-made room until certified coverage reaches ``level``."""
    env = DigCoverageEnv(map_size=64, start=(-6.0, -6.0, 0.3), target=1.0)
    env.env.unwrapped.generator = _Fixed(World(FRAME, [ROOM], "room"))
    agent = agent_of(env)
    obs, info = env.reset(seed=7)
    pos, length = np.asarray(info["truth"].pose[:2], float), 0.0
    for _ in range(steps):
        obs, _, term, trunc, info = env.step(agent.predict(obs)[0])
        nxt = np.asarray(info["truth"].pose[:2], float)
        length, pos = length + float(np.hypot(*(nxt - pos))), nxt
        if info["certified_coverage"] >= level or term or trunc:
            break
    env.close()
    assert info["certified_coverage"] >= level, "the level was not reached"
    return length


def test_in_a_single_room_the_path_stays_within_5_percent_of_the_frontier_agents():
    """The shipped agent (shipped predictor and settings) in a hand-made room."""
    level = TARGET_LEVELS["room"]
    frontier = _path_to_level(lambda env: make_baseline("frontier", env), level)
    predictive = _path_to_level(lambda env: make_predictive(env), level)
    assert predictive <= 1.05 * frontier, (predictive, frontier)
