"""The observer's data contract: what a simulator or a robot hands the observers, and the grid they map on.

Lives here: :mod:`.mission` (:class:`MissionRecord`: every measurement as an interval that contains the
truth, one step or a whole mission, and the data contract the observers rely on) and :mod:`.grid`
(:class:`Grid`: the regular grid of exact cell boxes that the observer's sets live on, §2.4.3). Both the
simulator (:mod:`digslam.envs.sim`) and the observers (:mod:`digslam.observer.slam`,
:mod:`digslam.observer.online`) read them from here.

May import: numpy only (no other folder of :mod:`digslam.observer`), so a reader of robot logs needs
nothing else.
"""

from .grid import Grid
from .mission import UNMEASURED, MissionRecord

__all__ = ["UNMEASURED", "Grid", "MissionRecord"]
