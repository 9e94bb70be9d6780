"""Frozen, validated configuration of the exploration environment.

Every config is a frozen dataclass on the project's config base (:mod:`digslam.observer.core.config`).
:meth:`~digslam.observer.core.config.Config.from_dict` builds one from a mapping and rejects unknown
keys with a ``ValueError`` naming them; the constructors validate values and name the offending field.
Noise bounds default to the thesis's orders of magnitude (§6.4.2: 0.001 m/s, 0.001 rad/s, 0.01 m).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import field

from digslam.observer.core.config import (
    Config,
    check,
    check_choice,
    check_finite_nonneg,
    check_finite_pos,
    check_in,
    config_dataclass,
    is_int,
)

NOISE_MODELS = ("uniform", "adversarial", "biased")
WORLDS = ("room", "rocks", "caves", "rooms", "file", "mixed", "floorplan")
#: How the robot moves (:mod:`digslam.envs.sim.robot`): pymunk rigid-body dynamics or exact unicycle arcs.
DYNAMICS = ("pymunk", "unicycle")
#: How a reset picks the start pose when ``start`` is None.
START_RULES = ("reachable", "origin")


@config_dataclass
class NoiseConfig(Config):
    """Bounded measurement noise.

    Attributes:
        speed: Half-width of the odometry velocity error (m/s): the forward speed and, under pymunk dynamics,
            the leftward velocity (a Doppler velocity log measures both body-frame components).
        yaw_rate: Half-width of the odometry yaw-rate error (rad/s).
        heading: Half-width of the compass error (rad).
        range: Half-width of the range error (m).
        model: ``uniform`` (error uniform in the bounds), ``adversarial`` (truth exactly on a bound) or
            ``biased`` (error ``bias * bound`` plus uniform jitter, always inside the bounds).
        bias: Bias as a fraction of the bound, in [-1, 1] (``biased`` model only).
        outlier_prob: Probability that a range reading is an outlier (flagged in the record).
        max_outliers: At most this many outliers per step (an integer >= 0; None: no cap). With
            ``max_outliers = q`` the premise of the observer's q-relaxed mode (``q`` outliers per step at
            most, :class:`~digslam.observer.online.observer.OnlineConfig`) holds exactly.
    """

    speed: float = 0.001
    yaw_rate: float = 0.001
    heading: float = 0.001
    range: float = 0.01
    model: str = "uniform"
    bias: float = 0.5
    outlier_prob: float = 0.0
    max_outliers: int | None = None

    def __post_init__(self) -> None:
        for name in ("speed", "yaw_rate", "heading", "range"):
            check_finite_nonneg(f"noise.{name}", getattr(self, name))
        check_choice("noise.model", self.model, NOISE_MODELS)
        check_in("noise.bias", self.bias, -1.0, 1.0)
        check_in("noise.outlier_prob", self.outlier_prob, 0.0, 1.0)
        m = self.max_outliers
        check(
            m is None or (is_int(m) and m >= 0),
            "noise.max_outliers",
            f"must be None or an integer >= 0, got {m!r}",
        )


@config_dataclass
class ExploreConfig(Config):
    """Configuration of ``digslam/Explore-v0``.

    Attributes:
        world: Generator name, one of ``room`` (thesis Fig. 6.10), ``rocks``, ``caves``, ``rooms``, ``file``
            (one map stretched over the frame), ``mixed`` (each level from one of the first four, drawn from
            its seed: training across them) or ``floorplan`` (windows of real floor plans at metric scale:
            the shipped KTH plans, split by plan, or the maps of ``floorplans``).
        world_size: Half-width of the square frame (m); the frame is ``[-s, s]^2``.
        n_obstacles: Number of rocks (``world='rocks'``).
        map_path: Polygon (``.json``/``.npz``) or image file for ``world="file"``.
        floorplans: Maps for ``world="floorplan"``: ROS map YAML files or ``.npz`` plans (None: the shipped
            plans). With the user's maps every seed is a level and no split applies.
        fixed_world: Keep the world of the first reset until a reset passes a seed (True), or draw a new one
            at every reset (False, the default: every episode is a new level, Procgen style;
            ``reset(seed=s)`` always builds the world of level ``s``).
        room_jitter: Displacement bound (m) of each vertex of the thesis room (``world='room'``), drawn per
            world: a new room every level (0: the room of Fig. 6.10 exactly).
        map_seed: When set, every reset uses the world generated from this seed (for debugging one map);
            the start pose still comes from the reset's seed.
        robot_radius: Robot disc radius (m); the dynamics (:mod:`digslam.envs.sim.robot`) keep this disc off
            every wall. Start poses keep ``1.5 * robot_radius`` plus a skin of ``1.5 * max_speed * dt /
            substeps``, which also pads pymunk's collision disc.
        max_speed: Speed for a normalised action of 1 (m/s).
        max_yaw_rate: Yaw rate for a normalised action of 1 (rad/s).
        dt: Step duration (s).
        substeps: Physics substeps per step (pymunk steps of exact durations summing to ``dt``; unicycle:
            exact arcs, possibly slowed or stopped by a wall).
        dynamics: ``pymunk`` (rigid-body dynamics with inertia, wall contacts and sliding; the default) or
            ``unicycle`` (exact arcs, blocked by walls; the thesis's missions).
        max_force: Force limit of the drive joint (N; pymunk dynamics; for the unicycle, the benchmarks'
            reference loop only). Every finite positive value is physical: beyond saturation (the force that
            reaches any command within a substep, ``2 max_speed * substeps / dt`` for a 1 kg robot with
            ``robot_radius * max_yaw_rate <= max_speed``) the joints get force and torque scaled by one factor
            and the force capped by the skin (:func:`digslam.envs.sim.robot.drive_limits`), so a stiff drive
            rams walls without the premise guard's hard stops.
        max_torque: Torque limit of its steering joint (N m; every finite positive value, as ``max_force``).
        n_sonars: Number of sonar cones, evenly spread around the heading.
        sonar_gamma: Half-aperture of each cone (rad), in (0, pi].
        sonar_range: Maximum sonar range (m).
        omni: Add the omnidirectional range sensor (half-aperture pi).
        omni_range: Maximum omni range (m).
        noise: Noise configuration (a :class:`NoiseConfig` or a mapping).
        coverage_resolution: Cell size of the ground-truth coverage grid behind the reward (m).
        start: Start pose ``(x, y, theta)``; None draws one from the reset's seed, uniformly in the reachable
            free space (:meth:`~digslam.envs.sim.world.World.sample_reachable_pose`: the largest region
            where the robot keeps its start clearance, so no start lies in a pocket), heading uniform.
        start_rule: ``reachable`` (above) or ``origin``: the origin with a uniform heading when it is free
            enough, else any free pose (the rule before procedural maps; older episode files replay with it).
    """

    world: str = "room"
    world_size: float = 10.0
    n_obstacles: int = 30
    map_path: str | None = None
    floorplans: tuple[str, ...] | None = None
    fixed_world: bool = False
    room_jitter: float = 0.3
    map_seed: int | None = None
    robot_radius: float = 0.2
    max_speed: float = 1.0
    max_yaw_rate: float = 1.0
    dt: float = 0.1
    substeps: int = 4
    dynamics: str = "pymunk"
    max_force: float = 50.0
    max_torque: float = 50.0
    n_sonars: int = 8
    sonar_gamma: float = math.pi / 12
    sonar_range: float = 5.0
    omni: bool = True
    omni_range: float = 5.0
    noise: NoiseConfig = field(default_factory=NoiseConfig)
    coverage_resolution: float = 0.1
    start: tuple[float, float, float] | None = None
    start_rule: str = "reachable"

    def __post_init__(self) -> None:
        if isinstance(self.noise, Mapping):
            object.__setattr__(self, "noise", NoiseConfig.from_dict(self.noise))
        check(isinstance(self.noise, NoiseConfig), "noise", "must be a NoiseConfig or a mapping")
        check_choice("world", self.world, WORLDS)
        check_choice("dynamics", self.dynamics, DYNAMICS)
        check_choice("start_rule", self.start_rule, START_RULES)
        check(self.world != "file" or bool(self.map_path), "map_path", "is required when world='file'")
        if self.floorplans is not None:
            paths = self.floorplans
            if isinstance(paths, (str, bytes, os.PathLike)) or not all(
                isinstance(f, (str, os.PathLike)) and os.fspath(f) for f in paths
            ):
                raise ValueError(
                    f"floorplans: must be a list of map paths (ROS map .yaml, .npz), got {paths!r}"
                )
            object.__setattr__(self, "floorplans", tuple(os.fspath(f) for f in paths))
        for name in (
            "world_size",
            "robot_radius",
            "max_speed",
            "max_yaw_rate",
            "dt",
            "max_force",
            "max_torque",
            "sonar_range",
            "omni_range",
            "coverage_resolution",
        ):
            check_finite_pos(name, getattr(self, name))
        for name in ("substeps", "n_sonars", "n_obstacles"):
            v = getattr(self, name)
            check(isinstance(v, int) and v >= (1 if name == "substeps" else 0), name, f"invalid count {v!r}")
        check(self.n_sonars + int(self.omni) > 0, "n_sonars", "need at least one range sensor (or omni=True)")
        check(
            0.0 < self.sonar_gamma <= math.pi,
            "sonar_gamma",
            f"aperture must be in (0, pi], got {self.sonar_gamma!r}",
        )
        check(
            math.isfinite(self.room_jitter) and 0.0 <= self.room_jitter <= 0.1 * self.world_size,
            "room_jitter",
            f"must be in [0, world_size / 10], got {self.room_jitter!r}",
        )
        if self.map_seed is not None:
            check(
                isinstance(self.map_seed, int) and not isinstance(self.map_seed, bool) and self.map_seed >= 0,
                "map_seed",
                f"must be a non-negative integer or None, got {self.map_seed!r}",
            )
        if self.start is not None:
            check(
                len(self.start) == 3 and all(math.isfinite(float(s)) for s in self.start),
                "start",
                f"must be a finite (x, y, theta), got {self.start!r}",
            )


__all__ = [
    "DYNAMICS",
    "ExploreConfig",
    "NOISE_MODELS",
    "NoiseConfig",
    "START_RULES",
    "WORLDS",
]
