"""Online Dig-SLAM: the observer that runs step by step beside a simulator or a robot.

Lives here: :mod:`.observer` (``OnlineDigSlam``, ``OnlineConfig``), :mod:`.window` (the dig map kept in a
sliding window) and its kernels: :mod:`.dig_jit` (digging and the cone windows), :mod:`.mark_jit`
(marking the explored zone), :mod:`.pose_jit` (pose prediction and contraction) and :mod:`.step_jit` (one
whole filter step, q-relaxed, Sec. 6.3).

May import: :mod:`digslam.observer.core`, :mod:`digslam.observer.slam` (records, grid, dig map),
:mod:`digslam.observer.thick` (the thick-set codes); numpy, numba.
"""

from .dig_jit import (
    dig_batch,
    dig_cells,
    window,
)
from .mark_jit import (
    dig_and_mark,
    dig_and_mark_q,
    mark_batch,
    mark_cells,
)
from .observer import (
    OnlineConfig,
    OnlineDigSlam,
)
from .pose_jit import (
    clearance_cells,
    contract,
    cos_sin,
    impact_bound,
    impact_bound_q,
    predict,
)
from .step_jit import (
    filter_step,
    filter_step_q,
)
from .window import (
    MARGIN,
    WindowDigMap,
    mark_possibly_sensed,
)

__all__ = [
    "MARGIN",
    "OnlineConfig",
    "OnlineDigSlam",
    "WindowDigMap",
    "clearance_cells",
    "contract",
    "cos_sin",
    "dig_and_mark",
    "dig_and_mark_q",
    "dig_batch",
    "dig_cells",
    "filter_step",
    "filter_step_q",
    "impact_bound",
    "impact_bound_q",
    "mark_batch",
    "mark_cells",
    "mark_possibly_sensed",
    "predict",
    "window",
]
