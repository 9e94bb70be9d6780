"""Episode recording, saving and replay: the seed, the actions, the records and the ground truth."""

from __future__ import annotations

import json
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from digslam.envs.config import ExploreConfig
from digslam.envs.explore.env import ExploreEnv
from digslam.envs.explore.truth import GroundTruth
from digslam.observer.record.mission import MissionRecord


@dataclass(eq=False)
class Episode:
    """A recorded episode: the seed, the actions, the measurement records and the ground truth.

    ``records[0]`` and ``truth[0]`` come from ``reset``; step ``k`` (``actions[k]``) gives index ``k + 1``.
    """

    config: ExploreConfig
    seed: int
    actions: np.ndarray
    records: MissionRecord
    truth: GroundTruth

    def save(self, path: str | Path) -> None:
        """Save to ``.npz`` (the config as JSON, records and truth under prefixes)."""
        arrays: dict[str, Any] = {
            "config": np.array(json.dumps(self.config.to_dict())),
            "seed": np.array(self.seed),
            "actions": self.actions,
            **self.records.to_arrays(),
            **{"truth_" + k: v for k, v in self.truth.as_dict().items()},
        }
        np.savez(path, **arrays)

    @staticmethod
    def load(path: str | Path) -> Episode:
        """Load an episode saved by :meth:`save` (one saved before a field existed gets its old meaning:
        unicycle dynamics, no lateral velocity, no substep path, the exact thesis room and the origin start
        rule)."""
        with np.load(path) as z:
            data = dict(z)
        cfg: dict[str, Any] = json.loads(str(data["config"]))
        cfg.setdefault("dynamics", "unicycle")  # saved before pymunk dynamics: every robot was a unicycle
        if "room_jitter" not in cfg:  # saved before procedural maps: the exact room, the origin start rule
            cfg.update(room_jitter=0.0, start_rule="origin")
        if cfg.get("start") is not None:
            cfg["start"] = tuple(cfg["start"])
        saved: dict[str, Any] = {f.name: data.get("truth_" + f.name) for f in fields(GroundTruth)}
        truth = GroundTruth(**saved)
        return Episode(
            ExploreConfig.from_dict(cfg),
            int(data["seed"]),
            data["actions"],
            MissionRecord.from_arrays(data),
            truth,
        )


def record_episode(env: gym.Env, seed: int, actions: np.ndarray) -> Episode:
    """Run ``env`` (an ``ExploreEnv``, possibly wrapped) from ``reset(seed)`` through ``actions``."""
    raw = env.unwrapped
    if not isinstance(raw, ExploreEnv):
        raise TypeError(f"env: must be an ExploreEnv, possibly wrapped; got {type(raw).__name__} below")
    actions = np.asarray(actions, dtype=np.float32).reshape(-1, 2)
    _, info = env.reset(seed=seed)
    recs, truths = [info["record"]], [info["truth"]]
    for a in actions:
        _, _, terminated, truncated, info = env.step(a)
        recs.append(info["record"])
        truths.append(info["truth"])
        if terminated or truncated:
            break
    return Episode(
        raw.config,
        int(seed),
        actions[: len(recs) - 1],
        MissionRecord.stack(recs),
        GroundTruth.stack(truths),
    )


def replay(episode: Episode) -> Episode:
    """Re-run a recorded episode in a fresh environment with the same config, seed and actions."""

    env = ExploreEnv(config=episode.config)
    try:
        return record_episode(env, episode.seed, episode.actions)
    finally:
        env.close()


__all__ = [
    "Episode",
    "record_episode",
    "replay",
]
