"""The simulated robot and its sensors: from actions to a bounded mission record.

Lives here: :mod:`.arc_jit` (the exact arc of one piece of motion and its proved error bound),
:mod:`.robot` (``RobotSim``) and :mod:`.robot_jit`, :mod:`.sensors` (``SensorSuite``: sonars, omnidirectional
range, odometry, compass), :mod:`.noise` and :mod:`.noise_jit` (bounded noise models, outliers),
:mod:`.coverage` and :mod:`.coverage_jit` (ground-truth coverage) and :mod:`.missions` (the thesis's missions
as records).

May import: :mod:`digslam.observer.core`, :mod:`digslam.observer.slam` (the record),
:mod:`digslam.envs.world`, :mod:`digslam.envs.config`; numpy, pymunk.
"""

from .arc_jit import (
    advance,
    arc,
    arc_bounded,
    arc_move,
    exact_duration,
    yaw_rate_bounds,
)
from .coverage import (
    Coverage,
)
from .coverage_jit import (
    NB,
    cover_kernel,
    cover_update,
    pseudo_angle,
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
    MODEL_CODES,
    noise_kernel,
    obs_kernel,
    record_kernel,
)
from .robot import (
    FRACTIONS,
    ROBOT_TYPE,
    SWEEP_POINTS,
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
)

__all__ = [
    "Coverage",
    "FRACTIONS",
    "Hull",
    "MODEL_CODES",
    "NB",
    "ROBOT_TYPE",
    "RobotSim",
    "SWEEP_POINTS",
    "SensorSuite",
    "THESIS_LOOP",
    "WALL_TYPE",
    "advance",
    "arc",
    "arc_bounded",
    "arc_move",
    "cover_kernel",
    "cover_update",
    "exact_duration",
    "loop_mission",
    "measure",
    "measure_step",
    "noise_kernel",
    "obs_kernel",
    "outliers",
    "pseudo_angle",
    "record_kernel",
    "robot_step_kernel",
    "yaw_rate_bounds",
]
