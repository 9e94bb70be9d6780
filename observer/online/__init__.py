"""Online Dig-SLAM: the observer that runs step by step beside a simulator or a robot.

Lives here: :mod:`.observer` (``OnlineDigSlam``, ``OnlineConfig``), :mod:`.window` (the dig map kept in a
sliding window), :mod:`.history` (the stored steps of loop smoothing), :mod:`.smoother` (``dig_slam``:
offline Dig-SLAM, Alg. 6.3, the fixpoint of the filter's contractors over a record), :mod:`.dig_types` (the
named tuples the kernels take: ``GridFrame``, ``CellSets``, ``PoseBox``, ``StepRecord``...) and the
kernels: :mod:`.dig_jit` (digging and the cone windows), :mod:`.mark_jit` (marking the explored zone),
:mod:`.pose_jit` (pose prediction and contraction), :mod:`.cones_jit` (the directional impact contractor:
each echo's cone meets ``comp M⁻``), :mod:`.step_jit` (one whole filter step, q-relaxed, Sec. 6.3) and
:mod:`.smooth_jit` (the filter over a whole record and the smoothing sweeps over stored steps).

May import: :mod:`digslam.observer.core`, :mod:`digslam.observer.record` (records, grid),
:mod:`digslam.observer.slam` (the dig map, the tube pieces of Dig-SLAM), :mod:`digslam.observer.thick` (the
cell codes), :mod:`digslam.observer.tube` (``C_d/dt`` of the offline tube); numpy, numba.
"""

from .observer import OnlineConfig, OnlineDigSlam
from .smoother import dig_slam
from .window import WindowDigMap, mark_possibly_sensed

__all__ = ["OnlineConfig", "OnlineDigSlam", "WindowDigMap", "dig_slam", "mark_possibly_sensed"]
