"""Online Dig-SLAM: the observer that runs step by step beside a simulator or a robot.

Lives here: :mod:`.observer` (``OnlineDigSlam``, ``OnlineConfig``), :mod:`.window` (the dig map kept in a
sliding window) and its kernels: :mod:`.dig_jit` (digging, the cone windows and the named tuples the
kernels take: ``GridFrame``, ``CellSets``, ``PoseBox``, ``StepRecord``...), :mod:`.mark_jit`
(marking the explored zone), :mod:`.pose_jit` (pose prediction and contraction), :mod:`.cones_jit` (the
directional impact contractor: each echo's cone meets ``comp M⁻``), :mod:`.step_jit` (one whole filter
step, q-relaxed, Sec. 6.3), :mod:`.smooth_jit` (the filter over a whole record and the smoothing sweeps over
stored steps) and :mod:`.smoother` (``dig_slam``: offline Dig-SLAM, Alg. 6.3, the fixpoint of the filter's
contractors over a record).

May import: :mod:`digslam.observer.core`, :mod:`digslam.observer.slam` (records, grid, dig map, the tube
pieces of Dig-SLAM), :mod:`digslam.observer.thick` (the thick-set codes), :mod:`digslam.observer.tube`
(``C_d/dt`` of the offline tube); numpy, numba.
"""

from .cones_jit import (
    ANGLE_PAD,
    MIN_SLICE,
    box_feasible,
    box_in_cone,
    cone_cell_ok,
    contract_cones,
)
from .dig_jit import (
    CellAxes,
    CellSets,
    GridFrame,
    PoseBox,
    SectorBatch,
    StepRecord,
    box_ok,
    cell_size,
    cone_window,
    dig_batch,
    dig_cells,
    dig_reading,
    edge_direction,
    in_frame,
    prod_hi,
    prod_lo,
    reach_axes,
    union,
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
    rotate,
)
from .smooth_jit import (
    RecordArrays,
    filter_record,
    mark_record,
    record_arrays,
    smooth_pass,
    step_at,
)
from .smoother import dig_slam
from .step_jit import (
    filter_step,
    filter_step_flat,
    filter_step_q,
)
from .window import (
    MARGIN,
    WindowDigMap,
    grid_frame,
    mark_possibly_sensed,
)

__all__ = [
    "ANGLE_PAD",
    "MIN_SLICE",
    "CellAxes",
    "CellSets",
    "GridFrame",
    "MARGIN",
    "OnlineConfig",
    "OnlineDigSlam",
    "PoseBox",
    "RecordArrays",
    "SectorBatch",
    "StepRecord",
    "WindowDigMap",
    "box_feasible",
    "box_in_cone",
    "box_ok",
    "cell_size",
    "clearance_cells",
    "cone_window",
    "cone_cell_ok",
    "contract",
    "contract_cones",
    "cos_sin",
    "dig_and_mark",
    "dig_and_mark_q",
    "dig_batch",
    "dig_cells",
    "dig_slam",
    "dig_reading",
    "edge_direction",
    "filter_record",
    "filter_step",
    "filter_step_flat",
    "filter_step_q",
    "grid_frame",
    "impact_bound",
    "impact_bound_q",
    "in_frame",
    "mark_batch",
    "mark_cells",
    "mark_possibly_sensed",
    "mark_record",
    "predict",
    "prod_hi",
    "prod_lo",
    "reach_axes",
    "record_arrays",
    "rotate",
    "smooth_pass",
    "step_at",
    "union",
]
