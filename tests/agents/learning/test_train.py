"""PPO training recipe: TrainConfig validation, the features extractor, spawn-safe env factories, training."""

from __future__ import annotations

import json
import pickle
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")
torch = pytest.importorskip("torch")

import gymnasium as gym  # noqa: E402
from gymnasium import spaces  # noqa: E402

from digslam.agents.learning.extractor import MapStateExtractor, conv_plan  # noqa: E402
from digslam.agents.learning.models import TRAINING_ONLY, model_env_kwargs  # noqa: E402
from digslam.agents.learning.train_config import DEFAULT_CONFIG, TrainConfig  # noqa: E402
from digslam.agents.learning.vec_env import EnvFactory  # noqa: E402
from digslam.observer.core.config import parse_value  # noqa: E402


def _space(c: int, m: int) -> spaces.Dict:
    return spaces.Dict(
        {"map": spaces.Box(0, 255, (c, m, m), np.uint8), "state": spaces.Box(-1, 1, (11,), np.float32)}
    )


def test_default_file_is_the_default_config_and_overrides_are_typed() -> None:
    assert DEFAULT_CONFIG.is_file() and TrainConfig.from_file() == TrainConfig()
    cfg = TrainConfig.from_file(None, ["n_envs=1", "learning_rate=1e-4", "env_kwargs.map_size=48",
                                       'out_dir="x"', "progress_bar=false", "gamma=1"])  # fmt: skip
    assert (cfg.n_envs, cfg.learning_rate, cfg.out_dir, cfg.progress_bar) == (1, 1e-4, "x", False)
    assert cfg.env_kwargs == {**TrainConfig().env_kwargs, "map_size": 48} and isinstance(cfg.gamma, float)
    assert cfg.override(["out_dir=plain"]).out_dir == "plain"  # an unquoted string stays a string
    assert parse_value("{map_size = 40, crop = 4.0}") == {"map_size": 40, "crop": 4.0}
    assert TrainConfig().eval_seeds() == (1_000_000, 1_000_001, 1_000_002)  # the validation split
    assert TrainConfig().train_seeds() == (0, 1)


def test_config_files_toml_and_json(tmp_path) -> None:  # type: ignore[no-untyped-def]
    j = tmp_path / "c.json"
    j.write_text(json.dumps({"n_envs": 3, "env_kwargs": {"map_size": 40}}))
    assert TrainConfig.from_file(j).n_envs == 3
    t = tmp_path / "c.toml"
    t.write_text("n_envs = 1\ntotal_timez = 5\n[env_kwargs]\nmap_size = 36\n")
    with pytest.raises(ValueError, match="total_timez"):
        TrainConfig.from_file(t)
    with pytest.raises(ValueError, match="path"):
        TrainConfig.from_file(tmp_path / "missing.toml")
    y = tmp_path / "c.yaml"
    y.write_text("n_envs: 1")
    with pytest.raises(ValueError, match="path"):
        TrainConfig.from_file(y)


@pytest.mark.parametrize(
    ("override", "key"),
    [
        ("n_env=2", "n_env"),
        ("n_envs=two", "n_envs"),
        ("n_envs=2.5", "n_envs"),
        ("learning_rate=fast", "learning_rate"),
        ("progress_bar=1", "progress_bar"),
        ("env_kwargs=3", "env_kwargs"),
        ("n_steps=0", "n_steps"),
        ("gamma=1.5", "gamma"),
        ("eval_seed=1", "eval_seed"),  # held-out seeds meet the training seeds 0, 1
        ("eval_seed=2000000", "eval_seed"),  # the test split: never for training or tuning
        ("seed=1999999", "seed"),  # the training envs' seeds 1999999, 2000000 reach the test split
        ("seed.x=1", "seed.x"),
        ("noequals", "overrides"),
    ],
)
def test_bad_keys_and_types_raise_value_error_naming_the_key(override: str, key: str) -> None:
    with pytest.raises(ValueError, match=key.replace(".", r"\.")):
        TrainConfig().override([override])


def test_unknown_key_in_constructor_and_from_dict() -> None:
    with pytest.raises(ValueError, match="batchsize"):
        TrainConfig.from_dict({"batchsize": 64})
    with pytest.raises(ValueError, match="features_dim"):
        TrainConfig(features_dim=0)


@pytest.mark.parametrize(("c", "m"), [(4, 36), (7, 36), (4, 64), (7, 64), (7, 40), (4, 48), (4, 100)])
def test_extractor_sizes_itself_from_the_space(c: int, m: int) -> None:
    ext = MapStateExtractor(_space(c, m), features_dim=32)
    x = {"map": torch.rand(3, c, m, m), "state": torch.rand(3, 11) * 2 - 1}
    y = ext(x)
    assert y.shape == (3, 32) and torch.all(y >= 0)
    assert ext.cnn[0].in_channels == c and len(conv_plan(m)) >= 2


def test_extractor_bad_input() -> None:
    with pytest.raises(ValueError, match="observation_space"):
        MapStateExtractor(spaces.Box(0, 1, (4, 36, 36)))
    with pytest.raises(ValueError, match="observation_space"):
        MapStateExtractor(
            spaces.Dict({"map": spaces.Box(0, 255, (4, 36, 40), np.uint8), "state": spaces.Box(-1, 1, (11,))})
        )
    with pytest.raises(ValueError, match="features_dim"):
        MapStateExtractor(_space(4, 36), features_dim=0)
    with pytest.raises(ValueError, match="side"):
        conv_plan(2)


def test_env_factory_is_picklable_and_cycles_held_out_seeds() -> None:
    fac = EnvFactory("digslam/DigCoverage-v0", {"map_size": 36, "crop": 4.0}, 1, (500, 501))
    fac2 = pickle.loads(pickle.dumps(fac))
    assert fac2 == fac
    env = fac2()
    o1, _ = env.reset()
    o2, _ = env.reset()
    o3, _ = env.reset()
    ref = gym.make("digslam/DigCoverage-v0", map_size=36, crop=4.0)
    r1, _ = ref.reset(seed=500)
    r2, _ = ref.reset(seed=501)
    assert o1["map"].shape == (7, 36, 36)
    assert all(np.array_equal(o1[k], r1[k]) and np.array_equal(o2[k], r2[k]) for k in o1)
    assert all(np.array_equal(o3[k], r1[k]) for k in o1)  # back to the first held-out map
    env.close()
    ref.close()


def test_ppo_with_the_extractor_predicts_on_the_env() -> None:
    from digslam.agents.learning.algos import build_model
    from digslam.agents.learning.vec_env import make_vec_env

    cfg = TrainConfig(n_envs=1, n_steps=16, batch_size=16, features_dim=16)
    vec = make_vec_env(EnvFactory(cfg.env_id, cfg.env_kwargs, 1), 1, 0)
    model = build_model(cfg, vec)
    obs = vec.reset()
    action, _ = model.predict(obs, deterministic=True)
    assert action.shape == (1, 2) and np.all(np.abs(action) <= 1)
    vec.close()


def test_train_end_to_end_gives_a_loadable_model(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from stable_baselines3 import PPO

    from digslam.agents.learning.train import train

    cfg = TrainConfig.from_file(None, [
        "n_envs=2", "total_timesteps=256", "n_steps=64", "batch_size=64", "n_epochs=1", "features_dim=32",
        "eval_freq=128", "eval_maps=1", "checkpoint_freq=128", "progress_bar=false",
        "env_kwargs.max_episode_steps=50", f'out_dir="{tmp_path.as_posix()}"',
    ])  # fmt: skip
    path = train(cfg)
    assert path.is_file() and (tmp_path / "best_model.zip").is_file()
    assert any((tmp_path / "checkpoints").glob("*.zip")) and any((tmp_path / "tb").iterdir())
    assert json.loads((tmp_path / "config.json").read_text())["total_timesteps"] == 256
    model = PPO.load(path, device="cpu")
    env = gym.make("digslam/DigCoverage-v0", **TrainConfig().env_kwargs)
    obs, _ = env.reset(seed=1)
    action, _ = model.predict(obs, deterministic=True)
    assert env.action_space.contains(action)
    assert model.num_timesteps >= 256
    # the model goes through every command with the environment it was trained on (its sidecar)
    side = json.loads(path.with_suffix(".json").read_text())
    assert side["env_kwargs"] == dict(cfg.env_kwargs) and side["env_id"] == cfg.env_id
    from digslam.agents.cli import main as cli

    out = tmp_path / "cli"
    assert cli.main(["demo", "--model", str(path), "--steps", "5", "--out", str(out / "demo")]) == 0
    assert cli.main(["evaluate", "--model", str(path), "--agents", "ppo", "--maps", "1", "--steps", "5",
                     "--out", str(out / "evaluate")]) == 0  # fmt: skip
    assert cli.main(["record", "--agent", "ppo", "--model", str(path), "--steps", "5",
                     "--out", str(out / "ep.npz")]) == 0  # fmt: skip
    # a checkpoint has no sidecar: the run's config.json, one folder up, gives its keywords
    ckpt = next((tmp_path / "checkpoints").glob("*.zip"))
    assert model_env_kwargs(ckpt) == {k: v for k, v in cfg.env_kwargs.items() if k not in TRAINING_ONLY}


def test_turn_go_actions_and_tube_penalty() -> None:
    from digslam.agents.learning.wrappers import TURN_GO, TubePenalty, TurnGoActions, wrap_training_env

    base = gym.make("digslam/DigCoverage-v0", map_size=36)
    env = TurnGoActions(base)
    assert env.action_space == spaces.Discrete(len(TURN_GO))
    assert all(base.action_space.contains(a) for a in TURN_GO)
    for a in TURN_GO:  # drive straight or turn in place, never both
        assert a[0] == 0.0 or a[1] == 0.0
    with pytest.raises(ValueError, match="action"):
        env.action(len(TURN_GO))
    with pytest.raises(ValueError, match="actions"):
        wrap_training_env(base, "arcs")
    with pytest.raises(ValueError, match="tube_penalty"):
        TrainConfig(tube_penalty=-1.0)
    # the penalty is the growth of the widest side of the pose box, times the weight
    plain, pen = (
        gym.make("digslam/DigCoverage-v0", map_size=36),
        TubePenalty(gym.make("digslam/DigCoverage-v0", map_size=36), weight=100.0),
    )
    plain.reset(seed=4)
    pen.reset(seed=4)
    tube0, total = 0.0, 0.0
    for _ in range(30):
        _, r0, *_, info = plain.step(TURN_GO[2])
        _, r1, *_ = pen.step(TURN_GO[2])
        box = np.asarray(info["pose_box"])
        tube = float(np.max(box[1] - box[0]))
        assert r1 == pytest.approx(r0 - 100.0 * max(tube - tube0, 0.0)) or tube0 == 0.0
        total += r0 - r1
        tube0 = tube
    assert total > 0  # turning in place grows the box (odometry noise): penalised


def test_turn_go_model_acts_in_the_continuous_env(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A model trained on turn-or-go actions loads as a continuous-action policy (``TurnGoPolicy``)."""
    from digslam.agents.learning.algos import build_model
    from digslam.agents.learning.models import load_ppo
    from digslam.agents.learning.vec_env import EnvFactory, make_vec_env
    from digslam.agents.learning.wrappers import TURN_GO, TurnGoPolicy

    cfg = TrainConfig(n_envs=1, n_steps=32, batch_size=32, features_dim=16, actions="turn_go",
                      env_kwargs={"map_size": 36, "max_episode_steps": 40})  # fmt: skip
    vec = make_vec_env(EnvFactory(cfg.env_id, cfg.env_kwargs, actions="turn_go"), 1, 0)
    model = build_model(cfg, vec)
    model.learn(32)
    path = tmp_path / "m.zip"
    model.save(path)
    vec.close()
    env = gym.make("digslam/DigCoverage-v0", map_size=36)
    policy = load_ppo(path, env)
    assert isinstance(policy, TurnGoPolicy)
    obs, _ = env.reset(seed=2)
    action, _ = policy.predict(obs, deterministic=True)
    assert env.action_space.contains(action) and any(np.array_equal(action, a) for a in TURN_GO)


def test_maskable_ppo_trains_on_the_goal_env_from_the_heuristic_prior(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """``algo = "maskable_ppo"`` on the goal-selection env: it trains end to end at tiny size, its logits
    start from the heuristic's ranking (candidate 0 first), and its model comes with its sidecar."""
    import torch

    from digslam.agents.learning.algos import build_maskable
    from digslam.agents.learning.train import train
    from digslam.agents.learning.vec_env import env_module, make_vec_env

    assert env_module("digslam/DigCoverageGoalsRooms-v0") == "digslam.agents.goals"
    cfg = TrainConfig.from_file(
        Path(__file__).parents[3] / "agents" / "configs" / "goals_maskable.toml",
        ["n_envs=1", "total_timesteps=32", "n_steps=16", "batch_size=16", "n_epochs=1", "eval_freq=0",
         "checkpoint_freq=16", "progress_bar=false", "env_kwargs.max_steps=200", "env_kwargs.step_cap=20",
         f'out_dir="{tmp_path.as_posix()}"'],
    )  # fmt: skip
    vec = make_vec_env(EnvFactory(cfg.env_id, cfg.env_kwargs), 1, 0)
    model = build_maskable(cfg, vec)
    bias = model.policy.action_net.bias.detach()
    assert torch.all(bias[:-1] > bias[1:])  # the heuristic's ranking: candidate 0 first
    obs = vec.reset()
    masks = np.stack(vec.env_method("action_masks"))
    action, _ = model.predict(obs, action_masks=masks, deterministic=True)
    assert int(action[0]) == 0  # untrained: the heuristic's pick
    vec.close()
    path = train(cfg)
    assert path.is_file() and json.loads(path.with_suffix(".json").read_text())["env_id"] == cfg.env_id


def test_train_resumes_from_the_latest_checkpoint(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """``resume=true`` continues the run in ``out_dir`` from the saved model with the most timesteps (a
    checkpoint or ``interrupted_model.zip``) up to ``total_timesteps``; without one it starts afresh."""
    from stable_baselines3 import PPO

    from digslam.agents.learning.checkpoints import latest_checkpoint
    from digslam.agents.learning.train import train

    base = ["n_envs=1", "n_steps=32", "batch_size=32", "n_epochs=1", "features_dim=16", "eval_freq=0",
            "checkpoint_freq=32", "progress_bar=false", "env_kwargs.max_episode_steps=40",
            f'out_dir="{tmp_path.as_posix()}"']  # fmt: skip
    assert latest_checkpoint(tmp_path) is None
    first = train(TrainConfig.from_file(None, [*base, "total_timesteps=64", "resume=true"]))  # nothing yet
    assert PPO.load(first, device="cpu").num_timesteps == 64
    path, steps = latest_checkpoint(tmp_path)
    assert steps == 64 and path.parent.name == "checkpoints"
    (tmp_path / "interrupted_model.zip").write_bytes(b"not a model")  # a damaged file is skipped
    assert latest_checkpoint(tmp_path) == (path, 64)
    final = train(TrainConfig.from_file(None, [*base, "total_timesteps=128", "resume=true"]))
    assert PPO.load(final, device="cpu").num_timesteps == 128  # 64 more, not 128 more
    assert latest_checkpoint(tmp_path)[1] == 128


@pytest.mark.parametrize("name", ["PRETRAINED", "CHOOSER", "LOWLEVEL"])
def test_every_shipped_model_loads_and_acts(name: str) -> None:
    """A saved model names its classes by module path (the extractor, the attention policy): every shipped
    model loads at today's paths and acts in the env of its sidecar."""
    import digslam.envs  # noqa: F401  (registers the ids)
    from digslam.agents.learning import models

    path = getattr(models, name)
    env = gym.make(models.DEFAULT_ENV, **models.model_env_kwargs(path))
    try:
        policy = models.load_ppo(path, env)
        obs, _ = env.reset(seed=0)
        action, _ = policy.predict(obs, deterministic=True)
        assert env.action_space.contains(np.asarray(action, np.float32).reshape(env.action_space.shape))
    finally:
        env.close()
