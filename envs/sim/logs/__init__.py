"""Simulated robot logs: a simulated mission in the streams a robot records, with its exact truth and the
bounds file it satisfies, and an environment's episode as such streams.

Lives here: :mod:`.simulate` (:func:`simulate_log`: odometry, a mounted laser and a compass at their own rates
and phases on the exact arcs; :class:`SimLog`), :mod:`.path` (the scripted tour it drives), :mod:`.bounds`
(the bounds file a simulated log satisfies) and :mod:`.episode` (an environment's episode as streams, for
``digslam record --format``). The streams are :mod:`digslam.observer.record.streams`; writing them as a ROS
bag is :func:`digslam.observer.record.bag_write.write_log`.

May import: what :mod:`digslam.envs.sim` may (this is one of its concepts).
"""

from .simulate import LaserSpec, SimLog, SimNoise, simulate_log

__all__ = ["LaserSpec", "SimLog", "SimNoise", "simulate_log"]
