"""Behaviour cloning: the fit learns a rule the features show, the demonstrations resume per level, and
``digslam train`` warm-starts an attention policy end to end."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("sb3_contrib")
torch = pytest.importorskip("torch")

import gymnasium as gym  # noqa: E402

import digslam.agents.goals  # noqa: E402, F401
from digslam.agents.learning.train import train  # noqa: E402
from digslam.agents.learning.train_config import TrainConfig  # noqa: E402
from digslam.agents.learning.warm_start import DEMO_SEED, clone, collect, level_seeds  # noqa: E402


def test_clone_learns_a_rule_of_the_features() -> None:
    """Labels: the valid candidate with the largest first feature. The attention policy fits them."""
    from sb3_contrib import MaskablePPO

    from digslam.agents.learning.attention import CandidateAttentionPolicy

    env = gym.make("digslam/DigCoverageGoals-v0", max_steps=100, step_cap=20)
    model = MaskablePPO(CandidateAttentionPolicy, env, seed=0, device="cpu",
                        policy_kwargs={"d": 32, "heuristic_prior": 3.0})  # fmt: skip
    rng = np.random.default_rng(0)
    n, k, f = 600, *env.observation_space["candidates"].shape
    cands = rng.uniform(-1, 1, (n, k, f)).astype(np.float32)
    mask = rng.uniform(size=(n, k)) < 0.5
    mask[:, 0] = True
    action = np.where(mask, cands[:, :, 0], -np.inf).argmax(axis=1)
    data = {"obs_candidates": cands, "obs_mask": mask.astype(np.int8),
            "obs_global": rng.uniform(-1, 1, (n, env.observation_space["global"].shape[0])).astype(np.float32),
            "mask": mask, "action": action}  # fmt: skip
    acc = clone(model, data, epochs=30, batch_size=64, lr=3e-3)
    assert acc[0] < acc[-1] and acc[-1] > 0.9
    with pytest.raises(ValueError, match="lack"):
        clone(model, {"action": action})


def test_collect_saves_each_level_and_resumes(tmp_path) -> None:  # type: ignore[no-untyped-def]
    kw = {"max_steps": 60, "step_cap": 20}
    first = collect("digslam/DigCoverageGoals-v0", kw, "frontier", 1, tmp_path)
    path = tmp_path / "demonstrations" / f"level_{DEMO_SEED}.npz"
    assert path.is_file() and len(first["action"]) > 0
    stamp = path.stat().st_mtime_ns
    again = collect("digslam/DigCoverageGoals-v0", kw, "frontier", 1, tmp_path)  # read, not played
    assert path.stat().st_mtime_ns == stamp and np.array_equal(first["action"], again["action"])
    with pytest.raises(ValueError, match="another teacher"):
        collect("digslam/DigCoverageGoals-v0", kw, "rollout", 1, tmp_path)
    assert level_seeds(2) == [DEMO_SEED, DEMO_SEED + 1]


def test_config_checks_and_train_warm_starts_an_attention_policy(tmp_path) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ValueError, match="warm_start: must be one of"):
        TrainConfig(algo="maskable_ppo", warm_start="oracle")
    with pytest.raises(ValueError, match="maskable_ppo"):
        TrainConfig(policy="attention")
    with pytest.raises(ValueError, match="maskable_ppo"):
        TrainConfig(warm_start="frontier")
    cfg = TrainConfig.from_dict({
        "env_id": "digslam/DigCoverageGoals-v0", "algo": "maskable_ppo", "policy": "attention",
        "warm_start": "frontier", "warm_start_levels": 1, "warm_start_rounds": 2, "bc_epochs": 2, "n_envs": 1, "total_timesteps": 16,
        "n_steps": 16, "batch_size": 8, "n_epochs": 1, "features_dim": 16, "eval_freq": 0, "checkpoint_freq": 0,
        "progress_bar": False, "heuristic_prior": 3.0, "out_dir": tmp_path.as_posix(),
        "env_kwargs": {"max_steps": 60, "step_cap": 20, "fixed_world": False},
    })  # fmt: skip
    final = train(cfg)
    report = json.loads((tmp_path / "warm_start.json").read_text())
    first, second = report["rounds"]
    assert report["teacher"] == "frontier" and report["levels"] == 2
    assert 0 < first["decisions"] < second["decisions"] and second["not_first"] == 0.0
    assert second["accuracy"][-1] == 1.0  # candidate 0 every time: learnt at once from the prior
    assert (tmp_path / "warm_start_round1.zip").is_file()  # the learner that drove round 1
    assert sorted(p.name for p in (tmp_path / "demonstrations").glob("level_*.npz")) == [
        f"level_{DEMO_SEED}.npz",
        f"level_{DEMO_SEED + 1}.npz",
    ]
    for name in ("warm_start_model", "final_model"):
        assert (tmp_path / f"{name}.zip").is_file() and (tmp_path / f"{name}.json").is_file()
    assert final == tmp_path / "final_model.zip"
