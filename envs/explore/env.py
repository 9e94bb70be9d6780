"""``digslam/Explore-v0``: a disc robot with exact sonar cones exploring an unknown world.

Action: normalised ``(v, omega)`` in ``[-1, 1]^2``: the commanded body-frame speed and yaw rate. Observation
(dict): range intervals ``ranges (n, 2)`` (``[r_max, top]`` where no echo), ``no_echo (n,)``,
``odometry (3, 2)`` (intervals of the forward speed, the leftward velocity and the yaw rate over the step
just ended) and ``heading (2,)`` (compass interval, shifted by a multiple of 2 pi into about ``[-pi, pi]``).
Reward: the newly and truly sensed free area (m^2; none with ``measure_coverage=False``). ``info`` holds the
:class:`~digslam.observer.record.mission.MissionRecord` under ``"record"`` and the
:class:`~digslam.envs.explore.truth.GroundTruth` under ``"truth"``.

Record convention (record ``j`` is the one returned at time ``t_j``; ``j = 0`` by ``reset``):

* ``heading[j]`` bounds the true heading at ``t_j`` and ``range[j]`` the exact distances from the pose at
  ``t_j``;
* ``speed[j]``, ``lateral[j]`` and ``yaw_rate[j]`` bound the true body-frame velocity ``(v_1, v_2)`` and yaw
  rate over the WHOLE step that just ended, ``[t_{j-1}, t_j]`` (the hull over all its physics substeps, see
  :mod:`digslam.envs.sim.robot`), not instantaneous values; record 0 carries the robot at rest, ``[0, 0]``
  widened by the noise bound. The unicycle cannot slip: its ``lateral`` is ``[0, 0]``, exactly;
* ``mean_velocity[j]`` (pymunk) bounds the odometry increment of that step, the velocity averaged over it in
  the body frame at ``t_{j-1}``: ``R(-psi_{j-1}) (x_j - x_{j-1}) / (t_j - t_{j-1})``, tight when the
  velocity changes within the step; the unicycle leaves it unmeasured (``[-inf, inf]``).

This is the data contract of :mod:`digslam.observer.record.mission`, which the observers (offline
``dig_slam``, the online filter of :mod:`digslam.envs.dig_coverage.wrapper`) read as it is. Every bound
contains the exact truth, floating point included. Under pymunk dynamics (``dynamics="pymunk"``, the default)
the truth is the piecewise-linear path through the substep states pymunk produced (``truth.states``,
``truth.taus``; exact by definition, ``pose_error = 0``) and the odometry hulls are rigorous bounds of its
body-frame velocity and yaw rate (:mod:`digslam.envs.sim.dynamics_jit`); under the unicycle it is the chain of
exact arcs of :mod:`digslam.envs.sim.arc_jit` (``truth.pieces``; the stored heading is exact, the stored
position within the proved ``truth.pose_error``), and the odometry hulls are the pieces' exact speeds and
outward-rounded yaw rates. Either way the robot's disc never overlaps an obstacle, and the ranges are rigorous
bounds around the true pose (:meth:`~digslam.envs.sim.sensors.SensorSuite.range_bounds`). Each step lasts
exactly the time between its two records."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from digslam.envs.config import ExploreConfig
from digslam.envs.explore.coverage import Coverage
from digslam.envs.explore.truth import GroundTruth
from digslam.envs.sim.arc_jit import exact_duration
from digslam.envs.sim.generators import Generator, WorldGenerator, make_generator
from digslam.envs.sim.noise_jit import obs_kernel
from digslam.envs.sim.robot import RobotSim
from digslam.envs.sim.sensors import SensorSuite, record_step
from digslam.envs.sim.world import World
from digslam.envs.splits import split_of
from digslam.observer.record.mission import MissionRecord

if TYPE_CHECKING:  # pygame is imported on use only
    from digslam.envs.sim.render import Renderer

#: The largest ``|a_i|`` of an action (normalised ``v``, ``omega``) accepted, then clipped to ``[-1, 1]``.
_ACTION_TOL = 1.0 + 1e-6


class ExploreEnv(gym.Env):
    """Exploration environment; see the module docstring.

    Args:
        config: An :class:`ExploreConfig`, a mapping, or None for the defaults.
        render_mode: ``"rgb_array"``, ``"human"`` or None.
        measure_coverage: Keep the ground-truth coverage (:attr:`coverage`) behind the reward, the
            termination and ``info["coverage"]`` (True). False keeps none: the reward is 0, no episode
            terminates and ``info`` has no ``"coverage"``; for a wrapper that measures the ground truth
            on an area of its own (e.g. the certified-coverage envs, which build their raw env so), one
            compiled coverage pass a step fewer.
        **overrides: Config fields overriding ``config`` (unknown keys raise ``ValueError``).

    Besides the Gymnasium API, :meth:`step_record` is the step without the observation, for a wrapper that
    replaces it.
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 10}

    def __init__(
        self,
        config: ExploreConfig | Mapping[str, Any] | None = None,
        render_mode: str | None = None,
        *,
        measure_coverage: bool = True,
        **overrides: Any,
    ) -> None:
        if isinstance(config, ExploreConfig):
            cfg = config.replace(**overrides) if overrides else config
        else:
            cfg = ExploreConfig.from_dict(config or {}, **overrides)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode: must be one of {self.metadata['render_modes']}, got {render_mode!r}"
            )
        self.config, self.render_mode = cfg, render_mode
        self.measure_coverage = bool(measure_coverage)
        self.suite = SensorSuite.from_config(cfg)
        self.generator: Generator = make_generator(cfg)
        n, nz = self.suite.n, cfg.noise
        self._top = float(self.suite.r_max.max() + 2 * nz.range + 1.0)
        s_top = 10 * cfg.max_speed + 2 * nz.speed + 1.0
        self._odo_top = np.array([[s_top], [s_top], [10 * cfg.max_yaw_rate + 2 * nz.yaw_rate + 1.0]])
        self.action_space = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
        hb = spaces.Box(-math.pi - 1.0 - 2 * nz.heading, math.pi + 1.0 + 2 * nz.heading, shape=(2,),
                        dtype=np.float64)  # fmt: skip
        self.observation_space = spaces.Dict(
            {
                "ranges": spaces.Box(0.0, self._top, shape=(n, 2), dtype=np.float64),
                "no_echo": spaces.MultiBinary(n),
                "odometry": spaces.Box(
                    -np.repeat(self._odo_top, 2, 1), np.repeat(self._odo_top, 2, 1), dtype=np.float64
                ),
                "heading": hb,
            }
        )
        self._odo_tops = (float(self._odo_top[0, 0]), float(self._odo_top[2, 0]))
        self._heading_box = (float(hb.low[0]), float(hb.high[0]))
        self.world: World | None = None
        self._world_seed: int | None = None
        self.sim: RobotSim | None = None
        self.coverage: Coverage | None = None
        self._renderer: Renderer | None = None

    # --- gymnasium API -------------------------------------------------------------------------------------
    def reset(
        self,
        *,
        seed: int | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        super().reset(seed=seed)
        cfg = self.config
        if cfg.map_seed is not None:  # one map for debugging
            if self.world is None or self._world_seed != cfg.map_seed:
                self.world, self._world_seed = self.generator.generate(cfg.map_seed), cfg.map_seed
        elif seed is not None or self.world is None or not cfg.fixed_world:
            self._world_seed = int(self.np_random.integers(2**31 - 1))
            gen = self.generator
            if isinstance(gen, WorldGenerator):  # the registry's take the split of the reset seed (an
                # unseeded reset draws a training level): a generator of real maps keeps each to one split
                split = split_of(seed) if seed is not None else "train"
                self.world = gen.generate(self._world_seed, split=split)
            else:  # any other Generator: one world per seed
                self.world = gen.generate(self._world_seed)
        skin = 1.5 * cfg.max_speed * cfg.dt / cfg.substeps
        if cfg.start is not None:
            pose = np.asarray(cfg.start, dtype=np.float64)
            self.world.check_start(pose, cfg.robot_radius + skin)
        elif cfg.start_rule == "origin":
            heading = float(self.np_random.uniform(-math.pi, math.pi))
            if self.world.clearance(np.zeros((1, 2)))[0] >= 1.5 * cfg.robot_radius + skin:
                pose = np.array([0.0, 0.0, heading])
            else:
                pose = self.world.sample_free_pose(self.np_random, 1.5 * cfg.robot_radius + skin)
        else:
            pose = self.world.sample_reachable_pose(self.np_random, 1.5 * cfg.robot_radius + skin)
        self.sim = RobotSim(self.world, cfg.robot_radius, pose, cfg.max_force, cfg.max_torque, skin,
                            cfg.dynamics, max_speed=cfg.max_speed, max_yaw_rate=cfg.max_yaw_rate)  # fmt: skip
        self.t, self.path = 0.0, [pose[:2].copy()]
        record, truth = self._sense(0)
        if self.measure_coverage:
            self.coverage = Coverage(self.world, cfg.coverage_resolution, float(self.suite.r_max.max()))
            self.coverage.update(truth.pose, self.suite, truth.ranges)
        self._last = record
        return self._obs(record), self._info(record, truth)

    def step(self, action: np.ndarray) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        """One step of ``dt`` under the normalised command ``action = (v, omega)`` in ``[-1, 1]²``: the
        Gymnasium ``(observation, reward, terminated, truncated, info)``, with the step's record and ground
        truth in ``info``."""
        reward, terminated, truncated, info = self.step_record(action)
        return self._obs(info["record"]), reward, terminated, truncated, info

    def step_record(self, action: np.ndarray) -> tuple[float, bool, bool, dict[str, Any]]:
        """:meth:`step` without building the observation: ``(reward, terminated, truncated, info)``, the
        step's :class:`~digslam.observer.record.mission.MissionRecord` in ``info["record"]`` (what the
        observation is made of). For a wrapper that replaces the observation with its own, such as
        :class:`~digslam.envs.dig_coverage.wrapper.GuaranteedObserver`; the env's state moves exactly as
        under :meth:`step`."""
        if self.sim is None:
            raise RuntimeError("step: call reset() before step()")
        v, w = self._check_action(action)
        cfg = self.config
        t1 = self.t + cfg.dt
        bumps = self.sim.step(v * cfg.max_speed, w * cfg.max_yaw_rate, exact_duration(self.t, t1),
                              cfg.substeps)  # fmt: skip
        self.t = t1
        record, truth = self._sense(bumps)
        self.path.append(truth.pose[:2].copy())
        self._last = record
        reward = self._reward(truth)
        if self.render_mode == "human":
            self.render()
        return reward, self._terminated(), False, self._info(record, truth)

    def render(self) -> np.ndarray | None:
        if self.render_mode is None:
            gym.logger.warn("render: no render_mode was given at construction")
            return None
        if self._renderer is None:
            from digslam.envs.sim.render import Renderer

            self._renderer = Renderer(self.render_mode, self.metadata["render_fps"])
        return self._renderer.draw(self, self._last)

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    # --- pieces of step ------------------------------------------------------------------------------------
    def _check_action(self, action: np.ndarray) -> tuple[float, float]:
        a = np.asarray(action)
        if a.shape != (2,):
            raise ValueError(f"action: expected shape (2,), got {a.shape}")
        v, w = a.tolist()
        v, w = float(v), float(w)
        if not (abs(v) <= _ACTION_TOL and abs(w) <= _ACTION_TOL):  # (false for NaN)
            if not (math.isfinite(v) and math.isfinite(w)):
                raise ValueError(f"action: must be finite, got {[v, w]}")
            raise ValueError(f"action: must lie in [-1, 1]^2 (normalised v, omega), got {[v, w]}")
        return min(max(v, -1.0), 1.0), min(max(w, -1.0), 1.0)

    def _sense(self, bumps: int) -> tuple[MissionRecord, GroundTruth]:
        assert self.sim is not None and self.world is not None
        sim, suite = self.sim, self.suite
        pose = sim.pose
        ranges, bounds = suite.sense(self.world, pose, sim.pose_error)  # true_ranges, range_bounds
        record = record_step(self.t, suite, bounds, sim.hulls, pose[2], sim.measured, self.config.noise,
                             self.np_random)  # fmt: skip
        states: np.ndarray | None
        taus: np.ndarray | None
        if sim.dynamics == "pymunk":
            states, taus = sim.states, sim.taus  # fresh arrays each step (the durations shared, read-only)
            if not len(taus):  # at reset: at rest, S + 1 copies of the start pose
                n = self.config.substeps
                states, taus = np.repeat(pose[None], n + 1, axis=0), np.zeros(n)
            pieces = sim.pieces  # NaN: shared, read-only
        else:
            states = taus = None
            pieces = sim.pieces.copy()  # the simulator rewrites its pieces each step
        truth = GroundTruth.of_step(self.t, pose, sim.speed, sim.yaw_rate, ranges, bumps, sim.bumps, pieces,
                                    sim.pose_error, sim.lateral, states, taus)  # fmt: skip
        return record, truth

    def _reward(self, truth: GroundTruth) -> float:
        if self.coverage is None:  # not measured (``measure_coverage=False``)
            return 0.0
        return self.coverage.update(truth.pose, self.suite, truth.ranges)

    def _terminated(self) -> bool:
        return self.coverage is not None and self.coverage.fraction >= 1.0

    def _info(self, record: MissionRecord, truth: GroundTruth) -> dict[str, Any]:
        if self.coverage is None:
            return {"record": record, "truth": truth, "bumps": int(truth.bumps_total)}
        return {
            "record": record,
            "truth": truth,
            "coverage": self.coverage.fraction,
            "bumps": int(truth.bumps_total),
        }

    def _obs(self, record: MissionRecord) -> dict[str, np.ndarray]:
        # lower range bounds are >= 0 by construction; the heading is shifted by a multiple of 2 pi
        lo, hi = self._heading_box
        n = self.suite.n
        ranges, no_echo, odo, heading = np.empty((n, 2)), np.empty(n, np.int8), np.empty((3, 2)), np.empty(2)
        obs_kernel(record.range, record.no_echo, record.speed, record.lateral, record.yaw_rate,
                   record.heading, self._top, self._odo_tops[0], self._odo_tops[1], lo, hi, ranges, no_echo,
                   odo, heading)  # fmt: skip
        return {"ranges": ranges, "no_echo": no_echo, "odometry": odo, "heading": heading}


__all__ = [
    "ExploreEnv",
]
