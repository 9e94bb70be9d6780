"""The raw Gymnasium family ``digslam/Explore-*``: the simulator as an environment.

Lives here: :mod:`.env` (``ExploreEnv``) and :mod:`.episode` (``Episode``, ``GroundTruth``, recording and
replaying an episode).

May import: :mod:`digslam.observer.core`, :mod:`digslam.observer.slam`, :mod:`digslam.envs.world`,
:mod:`digslam.envs.sim`, :mod:`digslam.envs.config`; gymnasium, numpy.
"""

from .env import (
    ExploreEnv,
)
from .episode import (
    Episode,
    GroundTruth,
    record_episode,
    replay,
)

__all__ = [
    "Episode",
    "ExploreEnv",
    "GroundTruth",
    "record_episode",
    "replay",
]
