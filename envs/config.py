"""Frozen, validated configuration of the exploration environment.

Every config is a frozen dataclass. :meth:`_Config.from_dict` builds one from a mapping and rejects unknown
keys with a ``ValueError`` naming them; the constructors validate values and name the offending field.
Noise bounds default to the thesis's orders of magnitude (§6.4.2: 0.001 m/s, 0.001 rad/s, 0.01 m).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any, TypeVar

NOISE_MODELS = ("uniform", "adversarial", "biased")
WORLDS = ("room", "rocks", "caves", "rooms", "file")

C = TypeVar("C", bound="_Config")


def _reject_unknown(cls: type, keys: object) -> None:
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(keys) - known)  # type: ignore[call-overload]
    if unknown:
        raise ValueError(f"{cls.__name__}: unknown configuration key(s) {unknown}; known: {sorted(known)}")


def config_dataclass(cls: type[C]) -> type[C]:
    """``@dataclass(frozen=True)`` whose constructor raises ``ValueError`` (not ``TypeError``) on bad keys."""
    cls = dataclass(frozen=True)(cls)
    init: Callable[..., None] = cls.__init__  # type: ignore[misc]

    @functools.wraps(init)
    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        _reject_unknown(type(self), kwargs)
        init(self, *args, **kwargs)

    cls.__init__ = __init__  # type: ignore[misc]
    return cls


class _Config:
    """Mixin: construction from a mapping that rejects unknown keys."""

    @classmethod
    def from_dict(cls: type[C], data: Mapping[str, Any] | None = None, **kwargs: Any) -> C:
        """Build from ``data`` and keyword overrides; an unknown key raises ``ValueError`` naming it."""
        merged = {**(data or {}), **kwargs}
        _reject_unknown(cls, merged)
        return cls(**merged)

    def replace(self: C, **kwargs: Any) -> C:
        """Copy with some fields changed (unknown keys rejected)."""
        _reject_unknown(type(self), kwargs)
        return replace(self, **kwargs)  # type: ignore[type-var]


def _check(cond: bool, name: str, msg: str) -> None:
    if not cond:
        raise ValueError(f"{name}: {msg}")


def _finite_nonneg(name: str, v: float) -> None:
    _check(
        isinstance(v, (int, float)) and math.isfinite(v) and v >= 0,
        name,
        f"must be finite and >= 0, got {v!r}",
    )


@config_dataclass
class NoiseConfig(_Config):
    """Bounded measurement noise.

    Attributes:
        speed: Half-width of the odometry speed error (m/s).
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
            _finite_nonneg(f"noise.{name}", getattr(self, name))
        _check(
            self.model in NOISE_MODELS, "noise.model", f"must be one of {NOISE_MODELS}, got {self.model!r}"
        )
        _check(-1.0 <= self.bias <= 1.0, "noise.bias", f"must be in [-1, 1], got {self.bias!r}")
        _check(
            0.0 <= self.outlier_prob <= 1.0,
            "noise.outlier_prob",
            f"must be in [0, 1], got {self.outlier_prob!r}",
        )
        m = self.max_outliers
        _check(
            m is None or (isinstance(m, int) and not isinstance(m, bool) and m >= 0),
            "noise.max_outliers",
            f"must be None or an integer >= 0, got {m!r}",
        )


@config_dataclass
class ExploreConfig(_Config):
    """Configuration of ``digslam/Explore-v0``.

    Attributes:
        world: Generator name, one of ``room`` (thesis Fig. 6.10), ``rocks``, ``caves``, ``rooms``, ``file``.
        world_size: Half-width of the square frame (m); the frame is ``[-s, s]^2``.
        n_obstacles: Number of rocks (``world='rocks'``).
        map_path: Polygon (``.json``/``.npz``) or image file for ``world="file"``.
        fixed_world: Keep the world of the first reset (True) or draw a new one at each reset.
        robot_radius: Robot disc radius (m); the kinematics (:mod:`.robot`) keep this disc off every wall.
            Start poses keep ``1.5 * robot_radius`` plus a skin of ``1.5 * max_speed * dt / substeps``.
        max_speed: Speed for a normalised action of 1 (m/s).
        max_yaw_rate: Yaw rate for a normalised action of 1 (rad/s).
        dt: Step duration (s).
        substeps: Physics substeps per step (each one exact arc, possibly slowed or stopped by a wall).
        max_force: Force limit of the drive joint of the pymunk reference loop (N; benchmarks only).
        max_torque: Torque limit of its steering joint (N m).
        n_sonars: Number of sonar cones, evenly spread around the heading.
        sonar_gamma: Half-aperture of each cone (rad), in (0, pi].
        sonar_range: Maximum sonar range (m).
        omni: Add the omnidirectional range sensor (half-aperture pi).
        omni_range: Maximum omni range (m).
        noise: Noise configuration (a :class:`NoiseConfig` or a mapping).
        coverage_resolution: Cell size of the ground-truth coverage grid behind the reward (m).
        start: Start pose ``(x, y, theta)``; None draws a free pose.
    """

    world: str = "room"
    world_size: float = 10.0
    n_obstacles: int = 30
    map_path: str | None = None
    fixed_world: bool = True
    robot_radius: float = 0.2
    max_speed: float = 1.0
    max_yaw_rate: float = 1.0
    dt: float = 0.1
    substeps: int = 4
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

    def __post_init__(self) -> None:
        if isinstance(self.noise, Mapping):
            object.__setattr__(self, "noise", NoiseConfig.from_dict(self.noise))
        _check(isinstance(self.noise, NoiseConfig), "noise", "must be a NoiseConfig or a mapping")
        _check(self.world in WORLDS, "world", f"must be one of {WORLDS}, got {self.world!r}")
        _check(self.world != "file" or bool(self.map_path), "map_path", "is required when world='file'")
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
            v = getattr(self, name)
            _check(
                isinstance(v, (int, float)) and math.isfinite(v) and v > 0,
                name,
                f"must be finite and > 0, got {v!r}",
            )
        for name in ("substeps", "n_sonars", "n_obstacles"):
            v = getattr(self, name)
            _check(isinstance(v, int) and v >= (1 if name == "substeps" else 0), name, f"invalid count {v!r}")
        _check(
            self.n_sonars + int(self.omni) > 0, "n_sonars", "need at least one range sensor (or omni=True)"
        )
        _check(
            0.0 < self.sonar_gamma <= math.pi,
            "sonar_gamma",
            f"aperture must be in (0, pi], got {self.sonar_gamma!r}",
        )
        if self.start is not None:
            _check(
                len(self.start) == 3 and all(math.isfinite(float(s)) for s in self.start),
                "start",
                f"must be a finite (x, y, theta), got {self.start!r}",
            )


__all__ = [
    "ExploreConfig",
    "NOISE_MODELS",
    "NoiseConfig",
    "WORLDS",
    "config_dataclass",
]
