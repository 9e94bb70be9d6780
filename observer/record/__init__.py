"""The observer's data contract: what a simulator or a robot hands the observers, and the grid they map on.

Lives here: :mod:`.mission` (:class:`MissionRecord`: every measurement as an interval that contains the
truth, one step or a whole mission, and the data contract the observers rely on), :mod:`.grid`
(:class:`Grid`: the regular grid of exact cell boxes that the observer's sets live on, §2.4.3), :mod:`.bounds`
(:class:`Bounds`: a robot log's error bounds and premises, read from a TOML bounds file) and :mod:`.bag`
(:func:`read_log`: a ROS 2 or ROS 1 bag and its bounds into records; per-message decoding in
:mod:`.bag_messages`, the records' assembly in :mod:`.bag_bridge`). Both the simulator
(:mod:`digslam.envs.sim`) and the observers (:mod:`digslam.observer.slam`, :mod:`digslam.observer.online`)
read them from here.

May import: numpy only (no other folder of :mod:`digslam.observer`), so a reader of robot logs needs
nothing else; the log reader imports ``rosbags`` (the ``[ros]`` extra) inside its functions only, so
importing this folder never needs it.
"""

from .bag import Log, LogError, log_topics, read_log
from .bounds import (
    Bound,
    Bounds,
    BoundsError,
    HeadingBounds,
    MapBounds,
    OdometryBounds,
    RangeBounds,
    StartBounds,
    parse_bounds,
    read_bounds,
)
from .grid import Grid
from .mission import UNMEASURED, MissionRecord

__all__ = [
    "UNMEASURED",
    "Bound",
    "Bounds",
    "BoundsError",
    "Grid",
    "HeadingBounds",
    "Log",
    "LogError",
    "MapBounds",
    "MissionRecord",
    "OdometryBounds",
    "RangeBounds",
    "StartBounds",
    "log_topics",
    "parse_bounds",
    "read_bounds",
    "read_log",
]
