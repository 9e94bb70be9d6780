"""Behaviour-cloning warm start of a goal-level learner (``warm_start`` in
:class:`~.train_config.TrainConfig`).

Before PPO's first update, :func:`warm_start` plays a teacher (:mod:`digslam.agents.goals.teacher`:
``"frontier"``, the frontier agent's pick, ``"rollout"``, a one-step look-ahead over copies of the
simulator, or ``"rollout_fresh_noise"``, the same with noise of each copy's own) on ``warm_start_levels``
training levels of the run's goal env, then fits the policy to the teacher's picks by cross-entropy over
the valid candidates (:func:`clone`). The levels are the train split's
seeds from :data:`DEMO_SEED` on (never the validation or test split). Each level's decisions are saved as
``<out_dir>/demonstrations/level_<seed>.npz`` the moment they are recorded, and a level already there is
not played again: an interrupted warm start resumes where it stopped. The levels are played by ``n_envs``
worker processes.

With ``warm_start_rounds`` > 1 the rounds after the first are DAgger's: the policy fitted so far drives
new levels while the teacher labels its decisions, and the fit goes on over everything.

The learner only ever sees the goal observation (from the observer); the rollout teacher's look at the
simulator goes into its labels, not into any input.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from digslam.agents.learning.checkpoints import save_model
from digslam.agents.learning.train_config import TrainConfig
from digslam.envs.splits import check_not_test

if TYPE_CHECKING:  # stable-baselines3 is imported on use only
    import torch
    from sb3_contrib.common.maskable.policies import MaskableActorCriticPolicy
    from stable_baselines3.common.base_class import BaseAlgorithm

#: First training seed of the demonstration levels (level ``i`` is ``DEMO_SEED + i``, in the train split).
DEMO_SEED = 900_000


def level_seeds(n: int) -> list[int]:
    """The seeds of ``n`` demonstration levels (train split)."""
    seeds = list(range(DEMO_SEED, DEMO_SEED + n))
    check_not_test("warm_start_levels", seeds)
    return seeds


def _play(job: tuple[str, Mapping[str, Any], str, Mapping[str, Any], int, str, str | None]) -> str:
    """Worker: play one level, the teacher labelling every decision (the learner saved at ``actor``
    acting, if given), and save its decisions (returns the log line)."""
    env_id, env_kwargs, name, teacher_kwargs, seed, path, actor = job
    import gymnasium as gym
    import torch

    import digslam.agents.goals  # noqa: F401  (registers the goal-selection ids)
    from digslam.agents.goals.teacher import demonstrations, teacher

    torch.set_num_threads(1)
    env = gym.make(env_id, **dict(env_kwargs))
    act = None
    if actor is not None:
        from sb3_contrib import MaskablePPO

        model = MaskablePPO.load(actor, device="cpu")

        def act(obs: dict[str, np.ndarray]) -> int:
            return int(model.predict(obs, action_masks=np.asarray(obs["mask"]) > 0, deterministic=True)[0])

    lines: list[str] = []
    choose = teacher(name, **{"seed": seed, **teacher_kwargs})  # fresh noise: each level's streams its own
    data: dict[str, Any] = demonstrations(env, choose, [seed], log=lines.append, act=act)
    env.close()
    tmp = Path(path).with_suffix(".part.npz")
    np.savez_compressed(tmp, **data)
    tmp.replace(path)
    return f"{'learner' if actor else 'teacher'} acting, {lines[0]}"


def collect(env_id: str, env_kwargs: Mapping[str, Any], name: str, levels: int, out: str | Path,
            workers: int = 1, teacher_kwargs: Mapping[str, Any] | None = None,
            log: Callable[[str], None] | None = None, first: int = 0,
            actor: str | Path | None = None) -> dict[str, np.ndarray]:  # fmt: skip
    """The teacher ``name``'s decisions on ``levels`` demonstration levels of ``env_id`` (``env_kwargs``),
    the ``first``-th on, one file a level under ``<out>/demonstrations`` (levels already there are read,
    not played), concatenated (:func:`~digslam.agents.goals.teacher.demonstrations`'s arrays). With
    ``actor`` (a saved ``MaskablePPO``) that learner drives and the teacher labels its decisions."""
    folder = Path(out) / "demonstrations"
    folder.mkdir(parents=True, exist_ok=True)
    meta = {"env_id": env_id, "env_kwargs": dict(env_kwargs), "teacher": name,
            "teacher_kwargs": dict(teacher_kwargs or {})}  # fmt: skip
    stamp = folder / "teacher.json"
    if stamp.is_file() and json.loads(stamp.read_text()) != meta:
        raise ValueError(f"warm_start: {folder} holds another teacher's or env's decisions; "
                         "delete it or use another out_dir")  # fmt: skip
    stamp.write_text(json.dumps(meta, indent=2))
    seeds = level_seeds(first + levels)[first:]
    paths = {s: folder / f"level_{s}.npz" for s in seeds}
    who = None if actor is None else str(actor)
    jobs = [(env_id, dict(env_kwargs), name, dict(teacher_kwargs or {}), s, str(p), who)
            for s, p in paths.items() if not p.is_file()]  # fmt: skip
    if jobs:
        if workers > 1 and len(jobs) > 1:
            import multiprocessing as mp

            with mp.get_context("spawn").Pool(min(workers, len(jobs))) as pool:
                for line in pool.imap_unordered(_play, jobs):
                    if log is not None:
                        log(line)
        else:
            for job in jobs:
                line = _play(job)
                if log is not None:
                    log(line)
    parts = [dict(np.load(p)) for p in paths.values()]
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def warm_start(cfg: TrainConfig, model: BaseAlgorithm, out: Path) -> None:
    """Fit ``model`` to ``cfg.warm_start``'s picks: the teacher drives the first ``warm_start_levels``
    levels; in each further round (``warm_start_rounds``) the policy fitted so far drives ``dagger_levels``
    new levels (default as many) while the teacher labels its decisions (DAgger), and the fit goes on over
    everything. Saves ``warm_start_model.zip`` and ``warm_start.json`` (decisions, the teacher's share of
    non-first picks, accuracy per epoch, per round) in ``out``."""
    say = print if cfg.verbose else None
    n, more = cfg.warm_start_levels, cfg.dagger_levels or cfg.warm_start_levels
    rounds: list[dict[str, Any]] = []
    parts: list[dict[str, np.ndarray]] = []
    for r in range(cfg.warm_start_rounds):
        actor = None
        if r:
            actor = out / f"warm_start_round{r}.zip"
            save_model(model, actor, cfg)
        first, size = (0, n) if r == 0 else (n + (r - 1) * more, more)
        parts.append(collect(cfg.env_id, cfg.env_kwargs, cfg.warm_start, size, out, workers=cfg.n_envs,
                             log=say, first=first, actor=actor))  # fmt: skip
        data = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
        acc = clone(model, data, epochs=cfg.bc_epochs, seed=cfg.seed + r)
        picks = data["action"]
        rounds.append({"decisions": int(len(picks)), "not_first": float(np.mean(picks != 0)),
                       "accuracy": acc})  # fmt: skip
        if say is not None:
            say(f"warm start round {r}: {rounds[-1]['decisions']} decisions, accuracy {acc[-1]:.3f}")
    report = {"teacher": cfg.warm_start, "levels": n + more * (cfg.warm_start_rounds - 1), "rounds": rounds}
    (out / "warm_start.json").write_text(json.dumps(report, indent=2))
    save_model(model, out / "warm_start_model.zip", cfg)


def clone(model: BaseAlgorithm, data: Mapping[str, np.ndarray], epochs: int = 20, batch_size: int = 256,
          lr: float = 1e-3, seed: int = 0) -> list[float]:  # fmt: skip
    """Fit ``model``'s policy (a ``MaskablePPO``) to the picks ``data["action"]`` of the observations
    ``data["obs_<key>"]`` by cross-entropy over the valid candidates ``data["mask"]`` (Adam, ``lr``);
    returns the share of picks the policy's most likely candidate matches, after each epoch."""
    import torch
    from gymnasium import spaces
    from sb3_contrib.common.maskable.policies import MaskableActorCriticPolicy

    policy = model.policy
    if not isinstance(policy, MaskableActorCriticPolicy):
        raise ValueError(f"model: a MaskablePPO (a masked actor-critic policy), got {type(policy).__name__}")
    space = policy.observation_space
    keys = list(space.spaces) if isinstance(space, spaces.Dict) else []
    missing = [k for k in keys if f"obs_{k}" not in data]
    if missing or "action" not in data or "mask" not in data:
        raise ValueError(f"data: demonstrations lack {missing or ['action', 'mask']} for this policy")
    n = len(data["action"])
    actions = torch.as_tensor(np.asarray(data["action"], np.int64))
    masks = np.asarray(data["mask"], bool)
    opt = torch.optim.Adam(policy.parameters(), lr=lr)
    rng = np.random.default_rng(seed)
    policy.set_training_mode(True)
    acc: list[float] = []
    for _ in range(epochs):
        perm = rng.permutation(n)
        for b in range(0, n, batch_size):
            idx = perm[b : b + batch_size]
            obs, _ = policy.obs_to_tensor({k: np.asarray(data[f"obs_{k}"])[idx] for k in keys})
            dist = policy.get_distribution(obs, action_masks=masks[idx])
            loss = -dist.log_prob(actions[idx]).mean()
            opt.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_norm_(policy.parameters(), 0.5)
            opt.step()
        acc.append(_accuracy(policy, data, keys, masks, actions))
    policy.set_training_mode(False)
    return acc


def _accuracy(policy: MaskableActorCriticPolicy, data: Mapping[str, np.ndarray], keys: list[str],
              masks: np.ndarray, actions: torch.Tensor) -> float:  # fmt: skip
    import torch

    with torch.no_grad():
        obs, _ = policy.obs_to_tensor({k: np.asarray(data[f"obs_{k}"]) for k in keys})
        dist = policy.get_distribution(obs, action_masks=masks)
        pick = dist.mode()  # the most likely valid candidate
    return float((pick == actions).float().mean())


__all__ = [
    "DEMO_SEED",
    "clone",
    "collect",
    "level_seeds",
    "warm_start",
]
