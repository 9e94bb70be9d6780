"""digslam.envs: simulator, Gymnasium environments and the observer wrapper.

Importing this package registers ``digslam/Explore-v0`` (the thesis room of Fig. 6.10) and its variants
(:data:`ENV_IDS`). In worker processes that have not imported it (e.g. SB3's ``SubprocVecEnv`` with
forkserver), use the ``"digslam.envs:digslam/Explore-v0"`` form, which imports the module first.
"""

from __future__ import annotations

import gymnasium as gym

from .config import ExploreConfig, NoiseConfig
from .episode import Episode, GroundTruth, record_episode, replay
from .explore_env import ExploreEnv
from .generators import Caves, FileMap, RockField, RoomsCorridors, ThesisRoom, WorldGenerator
from .sensors import SensorSuite
from .world import World

MAX_EPISODE_STEPS = 1000

#: Registered ids and their keyword arguments (all share ``ExploreEnv`` and ``MAX_EPISODE_STEPS``).
ENV_IDS: dict[str, dict[str, object]] = {
    "digslam/Explore-v0": {},
    "digslam/ExploreRocks-v0": {"world": "rocks"},
    "digslam/ExploreCaves-v0": {"world": "caves"},
    "digslam/ExploreRooms-v0": {"world": "rooms"},
    "digslam/ExploreAdversarial-v0": {"noise": {"model": "adversarial"}},
    "digslam/ExploreOutliers-v0": {"world": "rocks", "noise": {"outlier_prob": 0.05}},
}

for _id, _kw in ENV_IDS.items():
    if _id not in gym.registry:
        gym.register(
            id=_id,
            entry_point="digslam.envs.explore_env:ExploreEnv",
            kwargs=dict(_kw),
            max_episode_steps=MAX_EPISODE_STEPS,
        )

__all__ = [
    "ENV_IDS",
    "Caves",
    "Episode",
    "ExploreConfig",
    "ExploreEnv",
    "FileMap",
    "GroundTruth",
    "NoiseConfig",
    "RockField",
    "RoomsCorridors",
    "SensorSuite",
    "ThesisRoom",
    "World",
    "WorldGenerator",
    "record_episode",
    "replay",
]
