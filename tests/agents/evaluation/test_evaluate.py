"""Evaluation: same maps for every agent, padded curves, table, JSON, figure, GIF, SB3 compatibility."""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np
import pytest

import digslam.agents
from digslam.agents.baselines.registry import make_baseline
from digslam.agents.evaluation.evaluate import EvalResult, coverage_figure, evaluate
from digslam.agents.evaluation.pictures import record_episode_gif

SMALL = {"map_size": 36}


class _Forward:
    """A minimal non-baseline policy (SB3's predict signature): always straight ahead."""

    def predict(self, obs, state=None, episode_start=None, deterministic=True):  # type: ignore[no-untyped-def]
        return np.array([1.0, 0.0], np.float32), state


@pytest.fixture(scope="module")
def result() -> EvalResult:
    import gymnasium as gym

    import digslam.envs  # noqa: F401

    env = gym.make("digslam/DigCoverage-v0", **SMALL)
    policies = {"frontier": make_baseline("frontier", env, seed=0), "forward": _Forward()}
    return evaluate(policies, n_maps=2, seed=5, steps=40, env_kwargs=SMALL)


def test_curves_are_on_the_same_maps_and_sound(result: EvalResult) -> None:
    assert set(result.curves) == {"frontier", "forward"} and result.n_steps == 40
    for a in result.curves:
        c, t = result.curves[a], result.true_curves[a]
        assert c.shape == t.shape == (2, 41) and np.all((0 <= c) & (c <= 1)) and np.all((0 <= t) & (t <= 1))
        assert np.all(np.diff(c, axis=1) >= 0)  # certified coverage never drops (no inconsistency here)
        assert result.collisions[a].shape == (2,) and np.all(result.final_tube_width[a] >= 0)
        np.testing.assert_array_equal(result.lengths[a], [40, 40])
    # step 0 is the reset of the same map and seed for every agent
    np.testing.assert_array_equal(result.curves["frontier"][:, 0], result.curves["forward"][:, 0])
    assert result.env_id == "digslam/DigCoverage-v0" and result.seed == 5 and result.n_maps == 2


def test_table_json_and_figure(result: EvalResult, tmp_path) -> None:  # type: ignore[no-untyped-def]
    table = result.table(at=(20, 40, 1000))
    lines = table.splitlines()
    assert lines[0].startswith("| agent | certified @ 20 | certified @ 40 | true @ 40 |") and len(lines) == 4
    mean = result.curves["frontier"][:, 40].mean()
    assert f"{mean:.3f} ±" in lines[2] and lines[2].startswith("| frontier |")
    assert "certified @ 40" in result.table()  # default steps beyond the curves: the last step
    back = EvalResult.from_json(result.to_json(tmp_path / "r.json"))
    for f in ("curves", "true_curves", "collisions", "final_tube_width", "lengths"):
        for a, v in getattr(result, f).items():
            np.testing.assert_array_equal(getattr(back, f)[a], v)
    assert back.table() == result.table()
    png = coverage_figure(result, tmp_path / "fig" / "coverage.png")
    img = iio.imread(png)
    assert png.exists() and img.ndim == 3 and img.shape[0] > 200
    with pytest.raises(ValueError, match="path"):
        (tmp_path / "bad.json").write_text("{}")
        EvalResult.from_json(tmp_path / "bad.json")


def test_termination_pads_with_the_last_value_and_runs_are_deterministic() -> None:
    kw = {**SMALL, "target": 0.3}
    pol = {"forward": _Forward()}
    r1 = evaluate(pol, n_maps=2, seed=0, steps=60, env_kwargs=kw)
    r2 = evaluate(pol, n_maps=2, seed=0, steps=60, env_kwargs=kw)
    c = r1.curves["forward"]
    n = r1.lengths["forward"].astype(int)
    assert np.all(n < 60)  # reached the 0.3 target early
    for i in range(2):
        assert c[i, n[i]] >= 0.3 and np.all(c[i, n[i] :] == c[i, n[i]])
    np.testing.assert_array_equal(c, r2.curves["forward"])


def test_record_episode_gif_uses_the_pictures_palette(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from digslam.agents.evaluation.pictures import MAP_SIZE, PALETTE, PANEL_WIDTH

    path = record_episode_gif(
        _Forward(), path=tmp_path / "ep.gif", steps=12, seed=1, env_kwargs=SMALL, stride=3, scale=2
    )
    frames = iio.imread(path, index=None)
    assert frames.shape[0] == 5 and frames.shape[1:] == (MAP_SIZE // 2, (MAP_SIZE + PANEL_WIDTH) // 2, 3)
    colours = {tuple(int(v) for v in c) for c in frames[-1].reshape(-1, 3)}
    assert {PALETTE["clear"], PALETTE["dark"]} <= colours  # proved free is sky blue
    assert (0xE4, 0x1A, 0x1C) not in colours  # never the old red


def test_bad_input() -> None:
    with pytest.raises(ValueError, match="policies"):
        evaluate({})
    with pytest.raises(ValueError, match="'x' has no predict"):
        evaluate({"x": object()})
    with pytest.raises(ValueError, match="n_maps"):
        evaluate({"f": _Forward()}, n_maps=0)
    with pytest.raises(ValueError, match="steps"):
        record_episode_gif(_Forward(), steps=0)


def test_package_exports_without_torch() -> None:
    import subprocess
    import sys

    code = ("import sys, digslam.agents as A; A.make_baseline; A.evaluate_agents; A.EvalResult; "
            "assert 'torch' not in sys.modules and 'stable_baselines3' not in sys.modules")  # fmt: skip
    subprocess.run([sys.executable, "-c", code], check=True)
    assert digslam.agents.evaluate_agents is evaluate and "make_baseline" in digslam.agents.__all__


@pytest.mark.filterwarnings("ignore:Evaluation environment is not wrapped")
def test_sb3_evaluate_policy_accepts_a_baseline_on_a_vec_env() -> None:
    pytest.importorskip("stable_baselines3")
    import gymnasium as gym
    from stable_baselines3.common.evaluation import evaluate_policy
    from stable_baselines3.common.vec_env import DummyVecEnv

    import digslam.envs  # noqa: F401

    def make() -> gym.Env:
        return gym.make("digslam/DigCoverage-v0", max_episode_steps=25, **SMALL)

    venv = DummyVecEnv([make, make])
    agent = make_baseline("frontier", make())
    mean, _ = evaluate_policy(agent, venv, n_eval_episodes=2, deterministic=True)  # type: ignore[arg-type]
    assert mean > 0
    venv.close()


@pytest.mark.expensive
def test_an_untrained_ppo_model_is_evaluated_like_a_baseline(tmp_path) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("stable_baselines3")
    import gymnasium as gym
    from stable_baselines3 import PPO

    import digslam.envs  # noqa: F401

    env = gym.make("digslam/DigCoverage-v0", **SMALL)
    model = PPO("MultiInputPolicy", env, n_steps=64, batch_size=32, seed=0, verbose=0)
    model.save(tmp_path / "m.zip")
    res = evaluate({"ppo": PPO.load(tmp_path / "m.zip")}, n_maps=1, steps=20, env_kwargs=SMALL)
    assert res.curves["ppo"].shape == (1, 21)
