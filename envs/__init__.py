"""digslam.envs: simulator, Gymnasium environments and the observer wrapper.

Importing this package registers ``digslam/Explore-v0`` (the thesis room of Fig. 6.10) and its variants
(:data:`ENV_IDS`), and the certified-coverage ``digslam/DigCoverage-v0`` and its variants
(:data:`COVERAGE_IDS`: omni-only, sonar-only, large caves, adversarial noise, 10x odometry noise (stress),
and unflagged outliers, at most one per step, under the observer's q-relaxed mode with ``q = 1``;
``ExploreOutliers-v0`` caps its outliers at one per step too). The seed passed to ``reset`` picks a new world
and a new reachable start pose (a level), and :mod:`.splits` fixes the train, validation and test levels
(``ExploreConfig.map_seed`` pins one world for debugging). Most worlds are procedural; those of
``digslam/ExploreFloorplan-v0`` and ``digslam/DigCoverageFloorplan-v0`` are square windows of real building
floor plans (the KTH plans shipped with the package, or the user's ROS map files and plans with
``floorplans=``; :class:`~.sim.generators.floorplan.Floorplan`), :data:`FLOORPLAN_WORLD_SIZE` metres in
half-width (the benchmark's floorplan levels), and the reset seed's split chooses the plans they are cut from.
In worker processes that have not imported it (e.g. SB3's ``SubprocVecEnv`` with forkserver), use the
``"digslam.envs:digslam/Explore-v0"`` form, which imports the module first.

The certified-coverage observation is laid out once in :mod:`.observation` (:class:`Channel`,
:class:`State`); :func:`observer_of` finds the observer layer of a stack of wrappers (:mod:`.stack`); the
worlds are named in one registry, :data:`GENERATORS`.
"""

from __future__ import annotations

import gymnasium as gym

from digslam.envs.config import ExploreConfig, NoiseConfig
from digslam.envs.explore.env import ExploreEnv
from digslam.envs.explore.episode import Episode, record_episode, replay
from digslam.envs.explore.truth import GroundTruth
from digslam.envs.observation import N_STATE, Channel, State
from digslam.envs.sim.generators import (
    BENCHMARK,
    GENERATORS,
    PROCEDURAL,
    Caves,
    FileMap,
    Generator,
    Mixed,
    RockField,
    RoomsCorridors,
    ThesisRoom,
    WorldGenerator,
)
from digslam.envs.sim.sensors import SensorSuite
from digslam.envs.sim.world import World
from digslam.envs.stack import find_wrapper, observer_of
from digslam.observer.cache import origin as _origin  # a shadowing source folder is reported in one line

_origin.warn_if_shadowed(__name__)


MAX_EPISODE_STEPS = 1000
#: Half-width (m) of the floorplan ids' frame, and of the benchmark's floorplan levels: 20 m windows of the
#: plans (the largest on which the level rule vouches for a level: ``docs/benchmark.md``).
FLOORPLAN_WORLD_SIZE = 10.0

#: Registered ids and their keyword arguments (all share ``ExploreEnv`` and ``MAX_EPISODE_STEPS``).
ENV_IDS: dict[str, dict[str, object]] = {
    "digslam/Explore-v0": {},
    "digslam/ExploreRocks-v0": {"world": "rocks"},
    "digslam/ExploreCaves-v0": {"world": "caves"},
    "digslam/ExploreRooms-v0": {"world": "rooms"},
    "digslam/ExploreFloorplan-v0": {"world": "floorplan", "world_size": FLOORPLAN_WORLD_SIZE},
    "digslam/ExploreAdversarial-v0": {"noise": {"model": "adversarial"}},
    "digslam/ExploreOutliers-v0": {"world": "rocks", "noise": {"outlier_prob": 0.05, "max_outliers": 1}},
}

#: Certified-coverage ids (``DigCoverageEnv``: the raw env under the guaranteed observer) and their kwargs.
COVERAGE_IDS: dict[str, dict[str, object]] = {
    "digslam/DigCoverage-v0": {},
    "digslam/DigCoverageOmni-v0": {"n_sonars": 0},
    "digslam/DigCoverageSonar-v0": {"omni": False},
    "digslam/DigCoverageCaves-v0": {"world": "caves", "world_size": 20.0},
    "digslam/DigCoverageFloorplan-v0": {"world": "floorplan", "world_size": FLOORPLAN_WORLD_SIZE},
    "digslam/DigCoverageAdversarial-v0": {"noise": {"model": "adversarial"}},
    # the tube matters: odometry 10x noisier than the default, so an agent that never returns to known walls
    # loses its pose (the impacts on known walls are what narrows the pose box again)
    "digslam/DigCoverageStress-v0": {"noise": {"speed": 0.01, "yaw_rate": 0.01}},
    "digslam/DigCoverageOutliers-v0": {
        "world": "rocks",
        "noise": {"outlier_prob": 0.05, "max_outliers": 1},
        "q": 1,
    },  # fmt: skip
}

for _ids, _entry in (
    (ENV_IDS, "digslam.envs.explore.env:ExploreEnv"),
    (COVERAGE_IDS, "digslam.envs.dig_coverage.env:DigCoverageEnv"),
):
    for _id, _kw in _ids.items():
        if _id not in gym.registry:
            gym.register(id=_id, entry_point=_entry, kwargs=dict(_kw), max_episode_steps=MAX_EPISODE_STEPS)

#: Names of the observer side, imported on first use (they need ``digslam.observer.online.observer`` and
#: scipy).
_LAZY = {
    "DigCoverageEnv": "dig_coverage.env",
    "DigCoverageConfig": "dig_coverage.config",
    "ObserverConfig": "dig_coverage.config",
    "GuaranteedObserver": "dig_coverage.wrapper",
    "GuaranteeMonitor": "dig_coverage.monitor",
    "GuaranteeViolation": "dig_coverage.monitor",
}


def __getattr__(name: str) -> object:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "BENCHMARK",
    "PROCEDURAL",
    "COVERAGE_IDS",
    "Channel",
    "GENERATORS",
    "Generator",
    "N_STATE",
    "State",
    "find_wrapper",
    "observer_of",
    "DigCoverageConfig",
    "DigCoverageEnv",
    "GuaranteeMonitor",
    "GuaranteeViolation",
    "GuaranteedObserver",
    "ObserverConfig",
    "ENV_IDS",
    "FLOORPLAN_WORLD_SIZE",
    "Caves",
    "Episode",
    "ExploreConfig",
    "ExploreEnv",
    "FileMap",
    "Mixed",
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
