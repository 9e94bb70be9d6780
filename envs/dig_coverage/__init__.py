"""The certified-coverage Gymnasium family ``digslam/DigCoverage-*``: the raw env under the guaranteed
observer.

Lives here: :mod:`.config` (``ObserverConfig``, ``DigCoverageConfig``), :mod:`.wrapper`
(``GuaranteedObserver``: runs the online observer and builds observations from its sets only),
:mod:`.maps_jit` (the conservative downsampling of cell sets into map pixels), :mod:`.observe_jit` (the
observation of a step in one compiled call, laid out as :mod:`digslam.envs.observation` says),
:mod:`.monitor` (``GuaranteeMonitor``, checks every claim against the truth) and :mod:`.env`
(``DigCoverageEnv``, reward and ``RGB`` palette).

The ids are registered by :mod:`digslam.envs` with :class:`DigCoverageEnv` as their entry point, as
Gymnasium builds any env: ``gym.make`` writes the id's spec onto ``env.unwrapped``, the raw
:class:`~digslam.envs.explore.env.ExploreEnv` underneath, and ``env.spec`` reads it there (no additional
wrapper). The raw env knows nothing of the layers above it and passes ``gymnasium``'s ``check_env`` by itself;
the wrappers use its public API and ``info`` only.

Training with stable-baselines3 on a small machine: use one torch thread per process
(``torch.set_num_threads(1)``, and ``OMP_NUM_THREADS=1`` for the workers of a ``SubprocVecEnv``): the
policy's tensors are small, and more threads than cores only contend with the env processes (``digslam
train`` pins one thread already).

May import: all of :mod:`digslam.observer`, :mod:`digslam.envs.explore` and below; gymnasium, numpy.
"""

from digslam.envs.observation import N_STATE  # the observation's length (declared there)

from .config import DigCoverageConfig, ObserverConfig
from .env import DigCoverageEnv
from .monitor import GuaranteeMonitor, GuaranteeViolation
from .wrapper import GuaranteedObserver, reachable_free

__all__ = [
    "N_STATE",
    "DigCoverageConfig",
    "DigCoverageEnv",
    "GuaranteeMonitor",
    "GuaranteeViolation",
    "GuaranteedObserver",
    "ObserverConfig",
    "reachable_free",
]
