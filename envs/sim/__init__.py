"""The simulator: unstructured 2-D worlds, the robot that moves in them, and its bounded sensors.

Lives here, in data-flow order: :mod:`.world` (``World``: polygonal obstacles and a raster), :mod:`.tracing`
(marching squares), :mod:`.raster`, :mod:`.occupancy` (maps at metric scale: ROS map files, floor plans,
images with a resolution), :mod:`.generators` (the registry: ``ThesisRoom``, ``RockField``, ``Caves``,
``RoomsCorridors``, ``FileMap``, ``Mixed``, ``Floorplan``), :mod:`.geometry` and :mod:`.geometry_jit`
(rigorous point-edge and sector distances), :mod:`.arc_jit` (the exact arc of one piece of motion and its
proved error bound), :mod:`.robot` and :mod:`.robot_jit` (``RobotSim``: pymunk dynamics or exact unicycle
arcs), :mod:`.dynamics_jit` (the pymunk robot's premise guard, substep durations and velocity bounds),
:mod:`.sensors` (``SensorSuite``: sonars, omnidirectional range, odometry, compass), :mod:`.noise` and
:mod:`.noise_jit` (bounded noise, outliers), :mod:`.missions` (the thesis's missions as records) and
:mod:`.render` (pictures).

May import: :mod:`digslam.observer.core`, :mod:`digslam.observer.record.mission`, :mod:`digslam.envs.config`;
numpy, scipy, pymunk, pygame (on use). No gymnasium.
"""

from .generators import (
    BENCHMARK,
    GENERATORS,
    THESIS_ROOM,
    Caves,
    FileMap,
    Floorplan,
    Generator,
    Mixed,
    RockField,
    RoomsCorridors,
    ThesisRoom,
    WorldGenerator,
    make_generator,
)
from .missions import THESIS_LOOP, loop_mission
from .occupancy import OccupancyMap, load_map
from .robot import RobotSim
from .sensors import SensorSuite
from .world import World

__all__ = [
    "BENCHMARK",
    "Caves",
    "FileMap",
    "Floorplan",
    "GENERATORS",
    "Generator",
    "Mixed",
    "RobotSim",
    "RockField",
    "RoomsCorridors",
    "SensorSuite",
    "THESIS_LOOP",
    "THESIS_ROOM",
    "ThesisRoom",
    "OccupancyMap",
    "World",
    "WorldGenerator",
    "load_map",
    "loop_mission",
    "make_generator",
]
