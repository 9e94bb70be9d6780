"""Scripted missions with exact ground truth, for the offline observer (thesis §6.4.2).

The robot follows a closed loop of waypoints with a pure-pursuit controller. Between two samples its
speed and yaw rate are constant over each slice, so the motion over ``[t_k, t_{k+1}]`` is an exact arc and
its heading moves linearly from ``ψ_k`` to ``ψ_{k+1}``. The records follow the data contract of
:mod:`digslam.observer.record.mission`, like the environments':

* ``speed[k]`` and ``yaw_rate[k]`` bound the true values over the slice ``[t_{k-1}, t_k]`` that ends at
  ``t_k`` (record 0: the robot at rest);
* ``heading[k]`` bounds the true heading at ``t_k`` (a compass);
* ``range[k]`` bounds the exact sonar / omnidirectional distances (:class:`~.sensors.SensorSuite`) at
  the true pose ``k``.

The truth is the chain of exact arcs of :mod:`.arc_jit` (one function for the whole project): each slice lasts
exactly ``t_{k+1} - t_k`` (consecutive float times), its heading ``fl(ψ_k + ω τ)`` is the true heading, and
the position carries the proved, accumulated error bound of :func:`.arc_jit.arc_move`. The records contain the
exact truth, floating point included: the speed is exact, the yaw rate is outward-rounded
(:func:`.arc_jit.yaw_rate_bounds`) and the ranges are rigorous bounds around the true pose
(:meth:`~.sensors.SensorSuite.range_bounds`); no tolerance is chosen by hand.

>>> rec, truth = loop_mission(duration=2.0, seed=0)
>>> len(rec), truth.shape, bool(np.all(rec.range[:, 0, 0] <= rec.range[:, 0, 1]))
(21, (21, 5), True)
"""

from __future__ import annotations

import math

import numpy as np

from digslam.envs.config import NoiseConfig
from digslam.envs.sim.arc_jit import arc_bounded, exact_duration, yaw_rate_bounds
from digslam.envs.sim.generators import ThesisRoom
from digslam.envs.sim.sensors import SensorSuite, measure_step
from digslam.envs.sim.world import World
from digslam.observer.record.mission import MissionRecord

#: A loop of waypoints inside the thesis room of Fig. 6.10 (at least 1.3 m from every wall).
THESIS_LOOP = np.array(
    [(0.0, 0.0), (3.0, -5.5), (6.5, -5.0), (5.0, -1.0), (4.0, 2.5), (6.5, 5.5), (4.0, 6.5), (0.5, 2.0),
     (-3.0, 5.5), (-6.5, 5.5), (-5.5, 2.5), (-2.5, 0.5), (-6.5, -3.5), (-6.0, -6.5), (-2.0, -5.0)]
)  # fmt: skip


def loop_mission(
    world: World | None = None,
    waypoints: np.ndarray | None = None,
    suite: SensorSuite | None = None,
    duration: float = 1200.0,
    dt: float = 0.1,
    speed: float = 0.5,
    max_yaw_rate: float = 0.6,
    noise: NoiseConfig | None = None,
    seed: int | None = 0,
) -> tuple[MissionRecord, np.ndarray]:
    """Simulate a loop mission and its bounded measurements.

    Args:
        world: the map (default: the thesis room of Fig. 6.10).
        waypoints: ``(k, 2)`` closed loop of waypoints, the first one being the start (default
            :data:`THESIS_LOOP`); the robot starts there heading to the second one.
        suite: range sensors (default: one omnidirectional sensor of range 10 m, as in §6.4.2).
        duration: mission length (s); ``round(duration / dt) + 1`` samples.
        dt: sampling period (s).
        speed: cruise speed (m/s).
        max_yaw_rate: yaw-rate saturation of the controller (rad/s).
        noise: error bounds and noise model (default: the thesis's 0.001 m/s, 0.001 rad, 0.01 m).
        seed: seed of the noise draws.

    Returns:
        ``(record, truth)``: the stacked :class:`MissionRecord` and the truth ``(T+1, 5)``: pose
        ``(x, y, ψ)`` at ``t_k`` and the constant ``(v, ω)`` over the slice that starts there.

    Raises:
        ValueError: on a non-positive ``dt``, ``duration`` or ``speed``, or too few waypoints.
    """
    if not (dt > 0 and duration > 0 and speed > 0 and max_yaw_rate > 0):
        raise ValueError(
            f"dt, duration, speed, max_yaw_rate: must be > 0, got {dt}, {duration}, {speed}, {max_yaw_rate}"
        )
    world = world if world is not None else ThesisRoom().generate(0)
    wp = np.asarray(THESIS_LOOP if waypoints is None else waypoints, dtype=np.float64)
    if wp.ndim != 2 or wp.shape[1] != 2 or len(wp) < 3:
        raise ValueError(f"waypoints: expected (k >= 3, 2) points, got shape {wp.shape}")
    suite = suite or SensorSuite(np.array([0.0]), np.array([math.pi]), np.array([10.0]))
    noise = noise or NoiseConfig()
    rng = np.random.default_rng(seed)
    n = int(round(duration / dt))
    d0 = wp[1] - wp[0]
    pose = np.array([wp[0, 0], wp[0, 1], math.atan2(d0[1], d0[0])])
    target, records, truth = 1, [], []
    odo: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))  # record 0: at rest
    pose_error = 0.0
    for k in range(n + 1):
        to = wp[target] - pose[:2]
        if np.hypot(*to) < 0.6:
            target = (target + 1) % len(wp)
            to = wp[target] - pose[:2]
        err = (math.atan2(to[1], to[0]) - pose[2] + math.pi) % (2 * math.pi) - math.pi
        w = float(np.clip(1.5 * err, -max_yaw_rate, max_yaw_rate))
        v = speed * max(0.2, math.cos(err))
        bounds = suite.range_bounds(world, pose, pose_error)
        records.append(measure_step(k * dt, suite, bounds, *odo, float(pose[2]), noise, rng))
        truth.append([*pose, v, w])
        nxt, err = arc_bounded(pose, v, w, exact_duration(k * dt, (k + 1) * dt))
        pose_error = math.nextafter(pose_error + err, math.inf)
        odo = ((v, v), yaw_rate_bounds(float(pose[2]), float(nxt[2]), (k + 1) * dt - k * dt))
        pose = nxt  # odo is bounded by the next record: the slice that ends there
    return MissionRecord.stack(records), np.array(truth)


__all__ = ["THESIS_LOOP", "loop_mission"]
