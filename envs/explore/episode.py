"""Ground truth (kept apart from the measurements) and episode recording, saving and replay."""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from digslam.envs.config import ExploreConfig
from digslam.observer.slam.record import MissionRecord


@dataclass(eq=False)
class GroundTruth:
    """What really happened at a step; never part of the observation.

    Attributes:
        t: Time (s).
        pose: True pose ``(x, y, theta)``, continuous heading.
        speed: True forward speed (m/s).
        yaw_rate: True yaw rate (rad/s).
        ranges: True range per sensor (m), ``inf`` where no echo.
        bumps: New wall contacts during the step.
        bumps_total: Wall contacts since reset.
        pieces: The step's motion ``(2, 3)``, rows ``(v, tau, theta_end)`` (:mod:`.arc`): over each piece
            the speed is ``v`` and the heading moves linearly to ``theta_end`` from the previous piece's
            (or the previous step's); the taus sum exactly to the time since the previous record. At reset
            the robot is at rest (taus 0).
        pose_error: Proved bound on ``max(|x - x_true|, |y - y_true|)`` of ``pose``, where the true
            position is the exact chain of arcs of ``pieces`` from the reset pose; ``pose[2]`` is exact.
    """

    t: np.ndarray
    pose: np.ndarray
    speed: np.ndarray
    yaw_rate: np.ndarray
    ranges: np.ndarray
    bumps: np.ndarray
    bumps_total: np.ndarray
    pieces: np.ndarray | None = None
    pose_error: np.ndarray | None = None

    def __post_init__(self) -> None:
        d = self.__dict__
        lead = np.shape(d["t"])
        if d["pieces"] is None:  # an episode saved before pieces were recorded: unknown motion
            d["pieces"] = np.full(lead + (2, 3), np.nan)
        if d["pose_error"] is None:
            d["pose_error"] = np.full(lead, np.nan)
        for name in ("t", "pose", "speed", "yaw_rate", "ranges", "pieces", "pose_error"):
            d[name] = np.asarray(d[name], dtype=np.float64)
        d["bumps"] = np.asarray(d["bumps"], dtype=np.int64)
        d["bumps_total"] = np.asarray(d["bumps_total"], dtype=np.int64)

    @classmethod
    def of_step(cls, t: float, pose: np.ndarray, speed: float, yaw_rate: float, ranges: np.ndarray,
                bumps: int, bumps_total: int, pieces: np.ndarray,
                pose_error: float) -> GroundTruth:  # fmt: skip
        """The same object as ``GroundTruth(...)`` for a float64 ``pose (3,)``, ``ranges (n,)`` and
        ``pieces (2, 3)`` the caller hands over, with the scalars as 0-d views of two small arrays: the env's
        per-step constructor."""
        f = np.array([t, speed, yaw_rate, pose_error], dtype=np.float64)
        i = np.array([bumps, bumps_total], dtype=np.int64)
        g = cls.__new__(cls)
        g.__dict__.update(t=f[..., 0], pose=pose, speed=f[..., 1], yaw_rate=f[..., 2], ranges=ranges,
                          bumps=i[..., 0], bumps_total=i[..., 1], pieces=pieces,
                          pose_error=f[..., 3])  # fmt: skip
        return g

    def as_dict(self) -> dict[str, np.ndarray]:
        """Field name to array."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def __eq__(self, other: object) -> bool:
        return isinstance(other, GroundTruth) and all(
            np.array_equal(a, b, equal_nan=True)
            for a, b in zip(self.as_dict().values(), other.as_dict().values(), strict=True)
        )

    __hash__ = None  # type: ignore[assignment]

    @staticmethod
    def stack(items: list[GroundTruth]) -> GroundTruth:
        """Stack along a new leading time axis."""
        return GroundTruth(
            **{f.name: np.stack([getattr(g, f.name) for g in items]) for f in fields(GroundTruth)}
        )


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
        np.savez(
            path,
            config=np.array(json.dumps(asdict(self.config))),
            seed=np.array(self.seed),
            actions=self.actions,
            **self.records.to_arrays(),
            **{"truth_" + k: v for k, v in self.truth.as_dict().items()},
        )

    @staticmethod
    def load(path: str | Path) -> Episode:
        """Load an episode saved by :meth:`save`."""
        with np.load(path) as z:
            data = dict(z)
        cfg: dict[str, Any] = json.loads(str(data["config"]))
        if cfg.get("start") is not None:
            cfg["start"] = tuple(cfg["start"])
        truth = GroundTruth(**{f.name: data.get("truth_" + f.name) for f in fields(GroundTruth)})
        return Episode(
            ExploreConfig.from_dict(cfg),
            int(data["seed"]),
            data["actions"],
            MissionRecord.from_arrays(data),
            truth,
        )


def record_episode(env: Any, seed: int, actions: np.ndarray) -> Episode:
    """Run ``env`` (an ``ExploreEnv``, possibly wrapped) from ``reset(seed)`` through ``actions``."""
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
        env.unwrapped.config,
        int(seed),
        actions[: len(recs) - 1],
        MissionRecord.stack(recs),
        GroundTruth.stack(truths),
    )


def replay(episode: Episode) -> Episode:
    """Re-run a recorded episode in a fresh environment with the same config, seed and actions."""
    from digslam.envs.explore.env import ExploreEnv

    env = ExploreEnv(config=episode.config)
    try:
        return record_episode(env, episode.seed, episode.actions)
    finally:
        env.close()


__all__ = [
    "Episode",
    "GroundTruth",
    "record_episode",
    "replay",
]
