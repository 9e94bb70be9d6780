"""The raw Gymnasium family ``digslam/Explore-*``: the simulator as an environment, with ground truth.

Lives here: :mod:`.env` (``ExploreEnv``), :mod:`.coverage` and :mod:`.coverage_jit` (the ground-truth
coverage: which cells the sensors truly swept), :mod:`.truth` (``GroundTruth``) and :mod:`.episode`
(``Episode``, recording and replaying an episode).

May import: :mod:`digslam.observer.core`, :mod:`digslam.observer.record.mission`, :mod:`digslam.envs.sim`,
:mod:`digslam.envs.config`; gymnasium, numpy.
"""

from .coverage import Coverage
from .env import ExploreEnv
from .episode import Episode, record_episode, replay
from .truth import GroundTruth

__all__ = [
    "Coverage",
    "Episode",
    "ExploreEnv",
    "GroundTruth",
    "record_episode",
    "replay",
]
