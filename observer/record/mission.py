"""Mission record: what the robot measured, as plain numpy arrays (no ground truth here).

A :class:`MissionRecord` holds one time step (scalar ``t``) or a whole mission (every field stacked along a
leading time axis). Every measured quantity is an interval ``[lo, hi]`` of float64 that contains the truth,
except readings flagged in ``outlier`` (injected on purpose to test relaxed intersections).

Range sensors are sonar cones in the robot frame: direction ``alpha`` (rad, relative to the heading),
half-aperture ``gamma`` in ``(0, pi]`` (``gamma = pi`` is the omnidirectional sensor) and maximum range
``r_max``. A cone with ``no_echo`` set saw nothing up to ``r_max``: its interval is ``[r_max, inf]``. An
echoing cone's interval contains the distance from the robot centre to the nearest obstacle point anywhere in
its sector.

Data contract (what the observers rely on): ``heading[k]`` bounds the true heading at ``t_k`` and
``range[k]`` the exact distances from the pose at ``t_k``; ``speed[k]``, ``lateral[k]`` and ``yaw_rate[k]``
bound the true body-frame velocity ``v = (v_1, v_2)`` (forward, leftward; a Doppler velocity log) and yaw
rate at every instant of the WHOLE slice ``[t_{k-1}, t_k]`` that ends at ``t_k`` (not an instantaneous
value); record 0's odometry bounds nothing the observers use. The position then obeys ``x' = R(psi) v``
(Eq. 3.59, 6.12, B.20). A unicycle record (a robot that cannot slip sideways) has ``lateral = [0, 0]``,
the default: records saved before the field existed load with it. ``mean_velocity[k]`` (optional, ``(2, 2)``:
rows forward, leftward) bounds the odometry increment: the velocity averaged over the slice in the body
frame at its start, ``v̄ = (1/dt) ∫ R(psi(t) - psi(t_{k-1})) v(t) dt = (1/dt) R(-psi(t_{k-1})) (x_k -
x_{k-1})`` (a DVL integrated with the gyro's relative rotation, as odometry reports pose increments); it
stays tight when the velocity changes within the slice (inertia, contact), where the hull
``speed x lateral`` cannot. Its default, ``[-inf, inf]`` twice, measures nothing (records saved before the
field existed load with it).

This module needs numpy only, so the observer can read missions without importing the simulator.

>>> rec = MissionRecord(t=0.0, speed=[0.9, 1.1], yaw_rate=[-0.01, 0.01], heading=[0.0, 0.002],
...                     alpha=[0.0], gamma=[np.pi / 12], r_max=[5.0], range=[[2.0, 2.02]],
...                     no_echo=[False], outlier=[False])
>>> mission = MissionRecord.stack([rec, rec])
>>> rec.n_sensors, len(mission), mission.range.shape, mission[1] == rec
(1, 2, (2, 1, 2), True)
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

_PREFIX = "record_"
_FLOAT_FIELDS = ("t", "speed", "yaw_rate", "heading", "alpha", "gamma", "r_max", "range", "lateral",
                 "mean_velocity", "mount", "slack")  # fmt: skip
#: Fields that default when absent (records saved before they existed).
_OPTIONAL = ("lateral", "mean_velocity", "mount", "slack")
#: ``mean_velocity`` of a record that does not measure it: the whole line for ``v_1`` and ``v_2``.
UNMEASURED = np.array([[-np.inf, np.inf], [-np.inf, np.inf]])
UNMEASURED.flags.writeable = False


@dataclass(eq=False)
class MissionRecord:
    """Measured data of one step, or of a mission with a leading time axis.

    Attributes:
        t: Time of the measurement (s).
        speed: Forward body-frame velocity ``v_1`` interval ``[lo, hi]`` (m/s), shape ``(..., 2)``.
        yaw_rate: Odometry yaw-rate interval (rad/s), shape ``(..., 2)``.
        heading: Compass heading interval (rad, continuous, not wrapped), shape ``(..., 2)``.
        alpha: Cone directions relative to the heading (rad), shape ``(..., n)``.
        gamma: Cone half-apertures in ``(0, pi]`` (rad), shape ``(..., n)``.
        r_max: Cone maximum ranges (m), shape ``(..., n)``.
        range: Range intervals (m), shape ``(..., n, 2)``; ``[r_max, inf]`` where ``no_echo``.
        no_echo: True where nothing lies in the cone up to ``r_max``, shape ``(..., n)``.
        outlier: True where the reading is an injected outlier (its interval may miss the truth).
        lateral: Leftward body-frame velocity ``v_2`` interval (m/s), shape ``(..., 2)``; default ``[0, 0]``
            (a unicycle).
        mean_velocity: The odometry increment: the velocity averaged over the slice that ends at the record,
            in the body frame at the slice's start (m/s), shape ``(..., 2, 2)`` (rows forward, leftward;
            columns ``lo``, ``hi``); default :data:`UNMEASURED`.
        mount: Where each range sensor sits on the robot, in the body frame (m), shape ``(..., n, 2)``
            (forward, leftward); default zeros (every cone's apex at the robot's centre). A reading's cone
            has its apex at ``x + R(psi) mount`` and its ranges are distances from that apex.
        slack: How far each reading's own instant may be from the record's, shape ``(..., n, 2)``: the
            pose when the reading was taken lies within ``slack[..., 0]`` (m, on each axis) of the
            record's position and ``slack[..., 1]`` (rad) of its heading; default zeros (the reading is
            taken at ``t``). A log's reader sets it from the gap between the reading's stamp and the
            record's, times the premise's speed and yaw-rate limits.
    """

    t: np.ndarray
    speed: np.ndarray
    yaw_rate: np.ndarray
    heading: np.ndarray
    alpha: np.ndarray
    gamma: np.ndarray
    r_max: np.ndarray
    range: np.ndarray
    no_echo: np.ndarray
    outlier: np.ndarray
    lateral: np.ndarray = None  # type: ignore[assignment]  # None: [0, 0] (set in __post_init__)
    mean_velocity: np.ndarray = None  # type: ignore[assignment]  # None: UNMEASURED (set in __post_init__)
    mount: np.ndarray = None  # type: ignore[assignment]  # None: zeros (set in __post_init__)
    slack: np.ndarray = None  # type: ignore[assignment]  # None: zeros (set in __post_init__)

    def __post_init__(self) -> None:
        d = self.__dict__
        if d["lateral"] is None:
            d["lateral"] = np.zeros(np.shape(d["speed"]))
        if d["mean_velocity"] is None:
            d["mean_velocity"] = np.broadcast_to(UNMEASURED, np.shape(d["t"]) + (2, 2)).copy()
        for name in ("mount", "slack"):
            if d[name] is None:
                d[name] = np.zeros(np.shape(d["alpha"]) + (2,))
        for name in _FLOAT_FIELDS:
            d[name] = np.asarray(d[name], dtype=np.float64)
        d["no_echo"] = np.asarray(d["no_echo"], dtype=bool)
        d["outlier"] = np.asarray(d["outlier"], dtype=bool)
        lead = self.t.shape
        n = self.alpha.shape[len(lead) :]
        if len(n) != 1:
            raise ValueError(f"alpha: expected shape {lead}+(n,), got {self.alpha.shape}")
        for name in ("speed", "yaw_rate", "heading", "lateral"):
            if getattr(self, name).shape != lead + (2,):
                raise ValueError(f"{name}: expected shape {lead + (2,)}, got {getattr(self, name).shape}")
        for name in ("gamma", "r_max", "no_echo", "outlier"):
            if getattr(self, name).shape != lead + n:
                raise ValueError(f"{name}: expected shape {lead + n}, got {getattr(self, name).shape}")
        if self.range.shape != lead + n + (2,):
            raise ValueError(f"range: expected shape {lead + n + (2,)}, got {self.range.shape}")
        if self.mean_velocity.shape != lead + (2, 2):
            raise ValueError(f"mean_velocity: expected shape {lead + (2, 2)}, got {self.mean_velocity.shape}")
        for name in ("mount", "slack"):
            if getattr(self, name).shape != lead + n + (2,):
                raise ValueError(f"{name}: expected shape {lead + n + (2,)}, got {getattr(self, name).shape}")
        self._check_bounds()

    def _check_bounds(self) -> None:
        """Reject intervals with a NaN or ``lo > hi``, non-finite times and bad cone geometry."""
        for name in ("speed", "yaw_rate", "heading", "range", "lateral", "mean_velocity"):
            v = getattr(self, name)
            bad = np.isnan(v).any(axis=-1) | (v[..., 0] > v[..., 1])
            if bad.any():
                k = tuple(int(i) for i in np.argwhere(bad)[0])
                raise ValueError(f"{name}: interval at index {k} is not [lo <= hi]: {v[k].tolist()}")
        if not np.all(np.isfinite(self.t)):
            raise ValueError("t: times must be finite")
        if np.any(~(self.gamma > 0) | (self.gamma > np.pi)):
            raise ValueError("gamma: cone half-apertures must be in (0, pi]")
        if np.any(~(self.r_max > 0) | ~np.isfinite(self.r_max)):
            raise ValueError("r_max: maximum ranges must be finite and > 0")
        if not np.all(np.isfinite(self.mount)):
            raise ValueError("mount: sensor positions must be finite")
        if np.any(~(self.slack >= 0) | ~np.isfinite(self.slack)):
            raise ValueError("slack: reading slacks must be finite and >= 0")

    @property
    def n_sensors(self) -> int:
        """Number of range sensors (cones, omni included)."""
        return int(self.alpha.shape[-1])

    @property
    def centred(self) -> bool:
        """Whether every reading is taken from the robot's centre at the record's instant (``mount`` and
        ``slack`` all zero): the observers then use their centred kernels unchanged."""
        return not (np.any(self.mount) or np.any(self.slack))

    def __len__(self) -> int:
        if self.t.ndim == 0:
            raise TypeError("t: a single-step record has no length")
        return int(self.t.shape[0])

    def __getitem__(self, k: int | slice) -> MissionRecord:
        """Step ``k`` (or a slice of steps) of a stacked mission."""
        if self.t.ndim == 0:
            raise TypeError("t: a single-step record cannot be indexed")
        return MissionRecord(**{f.name: getattr(self, f.name)[k] for f in fields(self)})

    def __eq__(self, other: object) -> bool:
        return isinstance(other, MissionRecord) and self.same_as(other)

    __hash__ = None  # type: ignore[assignment]  # compared by value (same_as), arrays inside: unhashable

    def as_dict(self) -> dict[str, np.ndarray]:
        """Field name to array."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def same_as(self, other: MissionRecord) -> bool:
        """Bitwise equality of every field (NaN equal to NaN)."""
        return all(
            a.shape == b.shape and a.dtype == b.dtype and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")
            for a, b in zip(self.as_dict().values(), other.as_dict().values(), strict=True)
        )

    @staticmethod
    def stack(records: list[MissionRecord]) -> MissionRecord:
        """Stack single-step records into a mission along a new leading time axis."""
        if not records:
            raise ValueError("records: cannot stack an empty list")
        return MissionRecord(
            **{f.name: np.stack([getattr(r, f.name) for r in records]) for f in fields(records[0])}
        )

    def to_arrays(self, prefix: str = _PREFIX) -> dict[str, np.ndarray]:
        """Arrays keyed ``prefix + field`` for ``np.savez``."""
        return {prefix + k: v for k, v in self.as_dict().items()}

    @staticmethod
    def from_arrays(
        arrays: dict[str, np.ndarray] | np.lib.npyio.NpzFile, prefix: str = _PREFIX
    ) -> MissionRecord:
        """Inverse of :meth:`to_arrays`; raises ``KeyError`` naming a missing field (``lateral``,
        ``mean_velocity``, ``mount`` and ``slack``, absent from records saved before they existed, default to
        ``[0, 0]``, :data:`UNMEASURED` and zeros)."""
        out = {}
        for f in fields(MissionRecord):
            key = prefix + f.name
            if key not in arrays and f.name in _OPTIONAL:
                continue
            if key not in arrays:
                raise KeyError(f"{key}: missing from the record arrays")
            out[f.name] = np.asarray(arrays[key])
        return MissionRecord(**out)

    def save_npz(self, path: str | Path) -> None:
        """Save to a ``.npz`` file."""
        np.savez(path, **self.to_arrays())  # type: ignore[arg-type]  # numpy's stub: **arrays could fill allow_pickle

    @staticmethod
    def load_npz(path: str | Path) -> MissionRecord:
        """Load a record saved by :meth:`save_npz`."""
        with np.load(path) as z:
            return MissionRecord.from_arrays(dict(z))


__all__ = [
    "UNMEASURED",
    "MissionRecord",
]
