"""The certified-coverage Gymnasium family ``digslam/DigCoverage-*``: the raw env under the guaranteed
observer.

Lives here: :mod:`.config` (``ObserverConfig``, ``DigCoverageConfig``), :mod:`.wrapper`
(``GuaranteedObserver``: runs the online observer and builds observations from its sets only),
:mod:`.maps_jit` (the observation maps' kernels), :mod:`.monitor` (``GuaranteeMonitor``, checks every claim
against the truth) and :mod:`.env` (``DigCoverageEnv``, reward and ``RGB`` palette).

The ids are registered by :mod:`digslam.envs` with :class:`DigCoverageEnv` as their entry point: the env an
id makes holds the id's spec (``env.spec``) and renders ``rgb_array``
only; ``env.unwrapped`` is the raw :class:`~digslam.envs.explore.env.ExploreEnv` underneath, whose spec is
its own (``digslam/Explore-v0`` with its config) and which passes ``gymnasium``'s ``check_env`` by itself.

Training with stable-baselines3 on a small machine: use one torch thread per process
(``torch.set_num_threads(1)``, and ``OMP_NUM_THREADS=1`` for the workers of a ``SubprocVecEnv``): the
policy's tensors are small, and more threads than cores only contend with the env processes (``digslam
train`` pins one thread already).

May import: all of :mod:`digslam.observer`, :mod:`digslam.envs.explore` and below; gymnasium, numpy.
"""

from .config import (
    NATURE_CNN_MIN,
    DigCoverageConfig,
    ObserverConfig,
)
from .env import (
    OBSTACLE_RGB,
    RENDER_SIZE,
    RGB,
    DigCoverageEnv,
)
from .maps_jit import (
    MapContext,
    MapPlanes,
    PixelBlocks,
    all_blocks,
    block_starts,
    crop_window,
    fill_map,
    map_context,
    observe,
    observer_sets,
    pixel_blocks,
    pixel_range,
    sets_and_map,
    three_state,
)
from .monitor import (
    SENSED_SAMPLES,
    GuaranteeMonitor,
    GuaranteeViolation,
)
from .wrapper import (
    N_STATE,
    GuaranteedObserver,
    make_grid,
    reachable_free,
)

__all__ = [
    "DigCoverageConfig",
    "DigCoverageEnv",
    "GuaranteeMonitor",
    "GuaranteeViolation",
    "GuaranteedObserver",
    "MapContext",
    "MapPlanes",
    "NATURE_CNN_MIN",
    "N_STATE",
    "OBSTACLE_RGB",
    "ObserverConfig",
    "PixelBlocks",
    "RENDER_SIZE",
    "RGB",
    "SENSED_SAMPLES",
    "all_blocks",
    "block_starts",
    "crop_window",
    "fill_map",
    "make_grid",
    "map_context",
    "observe",
    "observer_sets",
    "pixel_blocks",
    "pixel_range",
    "reachable_free",
    "sets_and_map",
    "three_state",
]
