"""The simulator: unstructured 2-D worlds, the robot that moves in them, and its bounded sensors.

Lives here, in data-flow order: :mod:`.world` (``World``: polygonal obstacles and a raster), :mod:`.tracing`
(marching squares), :mod:`.raster`, :mod:`.generators` (``ThesisRoom``, ``RockField``, ``Caves``,
``RoomsCorridors``, ``FileMap``, ``Mixed``), :mod:`.geometry` and :mod:`.geometry_jit` (rigorous point-edge
and sector distances), :mod:`.arc_jit` (the exact arc of one piece of motion and its proved error bound),
:mod:`.robot` and :mod:`.robot_jit` (``RobotSim``: pymunk dynamics or exact unicycle arcs),
:mod:`.dynamics_jit` (the pymunk robot's premise guard, substep durations and velocity bounds),
:mod:`.sensors` (``SensorSuite``: sonars, omnidirectional range, odometry, compass), :mod:`.noise` and
:mod:`.noise_jit` (bounded noise, outliers), :mod:`.missions` (the thesis's missions as records) and
:mod:`.render` (pictures).

May import: :mod:`digslam.observer.core`, :mod:`digslam.observer.record.mission`, :mod:`digslam.envs.config`;
numpy, scipy, pymunk, pygame (on use). No gymnasium.
"""

from .arc_jit import (
    advance,
    arc,
    arc_bounded,
    arc_move,
    exact_duration,
    yaw_rate_bounds,
)
from .dynamics_jit import (
    step_bounds,
    substep_clear,
    substep_times,
)
from .generators import (
    GENERATORS,
    THESIS_ROOM,
    Caves,
    FileMap,
    Mixed,
    RockField,
    RoomsCorridors,
    ThesisRoom,
    WorldGenerator,
)
from .geometry import (
    Edges,
    edge_bboxes,
    point_edge_distance,
    point_free,
    rings_to_edges,
    sector_distance,
)
from .geometry_jit import (
    edge_boxes,
    edge_near,
    points_edges_kernel,
    sector_bounds_kernel,
    sector_kernel,
    segment_distance,
)
from .missions import (
    THESIS_LOOP,
    loop_mission,
)
from .noise import (
    measure,
    outliers,
)
from .noise_jit import (
    MEASURE_LATERAL,
    MEASURE_MEAN,
    MODEL_CODES,
    RecordModel,
    noise_kernel,
    obs_kernel,
    record_kernel,
)
from .raster import (
    cell_centres,
    grid_shape,
    rasterize,
)
from .render import (
    FREE,
    MIXED,
    Renderer,
)
from .robot import (
    FRACTIONS,
    ROBOT_FRICTION,
    ROBOT_TYPE,
    SWEEP_POINTS,
    WALL_FRICTION,
    WALL_TYPE,
    RobotSim,
)
from .robot_jit import (
    robot_step_kernel,
)
from .sensors import (
    Hull,
    SensorSuite,
    measure_step,
    record_step,
)
from .tracing import (
    chain_rings,
    marching_squares,
    mask_edges,
    smooth_noise,
)
from .world import (
    World,
)

__all__ = [
    "Caves",
    "Edges",
    "FRACTIONS",
    "FREE",
    "FileMap",
    "Mixed",
    "GENERATORS",
    "Hull",
    "MIXED",
    "MEASURE_LATERAL",
    "MEASURE_MEAN",
    "MODEL_CODES",
    "ROBOT_TYPE",
    "ROBOT_FRICTION",
    "RecordModel",
    "Renderer",
    "RobotSim",
    "RockField",
    "RoomsCorridors",
    "SWEEP_POINTS",
    "SensorSuite",
    "THESIS_LOOP",
    "THESIS_ROOM",
    "ThesisRoom",
    "WALL_FRICTION",
    "WALL_TYPE",
    "World",
    "WorldGenerator",
    "advance",
    "arc",
    "arc_bounded",
    "arc_move",
    "cell_centres",
    "chain_rings",
    "edge_bboxes",
    "edge_boxes",
    "edge_near",
    "exact_duration",
    "grid_shape",
    "loop_mission",
    "marching_squares",
    "mask_edges",
    "measure",
    "measure_step",
    "record_step",
    "noise_kernel",
    "obs_kernel",
    "outliers",
    "point_edge_distance",
    "point_free",
    "points_edges_kernel",
    "rasterize",
    "record_kernel",
    "rings_to_edges",
    "robot_step_kernel",
    "sector_bounds_kernel",
    "sector_distance",
    "sector_kernel",
    "segment_distance",
    "smooth_noise",
    "step_bounds",
    "substep_clear",
    "substep_times",
    "yaw_rate_bounds",
]
