"""Ground truth of a step, kept apart from the measurements: what really happened, never observed."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

_EMPTY_STATES, _EMPTY_TAUS = np.zeros((0, 3)), np.zeros(0)
_EMPTY_STATES.flags.writeable = _EMPTY_TAUS.flags.writeable = False


@dataclass(eq=False)
class GroundTruth:
    """What really happened at a step; never part of the observation.

    Attributes:
        t: Time (s).
        pose: True pose ``(x, y, theta)``, continuous heading.
        speed: True forward body-frame velocity ``v_1`` at the step's end (m/s).
        yaw_rate: True yaw rate (rad/s).
        ranges: True range per sensor (m), ``inf`` where no echo.
        bumps: New wall contacts during the step.
        bumps_total: Wall contacts since reset.
        pieces: The step's motion under the unicycle ``(2, 3)``, rows ``(v, tau, theta_end)``
            (:mod:`digslam.envs.sim.arc_jit`): over each piece the speed is ``v`` and the heading moves
            linearly to ``theta_end`` from the previous piece's (or the previous step's); the taus sum
            exactly to the time since the previous record. At reset the robot is at rest (taus 0). NaN under
            pymunk dynamics (and in episodes saved before pieces were recorded).
        pose_error: Proved bound on ``max(|x - x_true|, |y - y_true|)`` of ``pose``, where the true
            position is the exact chain of arcs of ``pieces`` from the reset pose; ``pose[2]`` is exact.
            0 under pymunk (the stored states are the truth).
        lateral: True leftward body-frame velocity ``v_2`` at the step's end (m/s; 0 for the unicycle and in
            episodes saved before it was recorded, all unicycle).
        states: The step's motion under pymunk ``(S + 1, 3)``: ``(x, y, angle)`` before the step and after
            each of its ``S`` substeps; the truth is the piecewise-linear path through them
            (:mod:`digslam.envs.sim.dynamics_jit`), ``states[-1]`` is ``pose``. At reset, ``S + 1`` copies
            of the start pose. Empty ``(0, 3)`` under the unicycle (and in older episodes).
        taus: The substep durations ``(S,)``, exact floats summing exactly to the time since the previous
            record (0 at reset); empty ``(0,)`` under the unicycle.
    """

    t: np.ndarray
    pose: np.ndarray
    speed: np.ndarray
    yaw_rate: np.ndarray
    ranges: np.ndarray
    bumps: np.ndarray
    bumps_total: np.ndarray
    pieces: np.ndarray | None = None
    pose_error: np.ndarray | None = None
    lateral: np.ndarray | None = None
    states: np.ndarray | None = None
    taus: np.ndarray | None = None

    def __post_init__(self) -> None:
        d = self.__dict__
        lead = np.shape(d["t"])
        if d["pieces"] is None:  # an episode saved before pieces were recorded: unknown motion
            d["pieces"] = np.full(lead + (2, 3), np.nan)
        if d["pose_error"] is None:
            d["pose_error"] = np.full(lead, np.nan)
        if d["lateral"] is None:  # saved before pymunk dynamics: a unicycle, which never slips
            d["lateral"] = np.zeros(lead)
        if d["states"] is None:
            d["states"] = np.zeros(lead + (0, 3))
        if d["taus"] is None:
            d["taus"] = np.zeros(lead + (0,))
        for name in ("t", "pose", "speed", "yaw_rate", "ranges", "pieces", "pose_error", "lateral", "states",
                     "taus"):  # fmt: skip
            d[name] = np.asarray(d[name], dtype=np.float64)
        d["bumps"] = np.asarray(d["bumps"], dtype=np.int64)
        d["bumps_total"] = np.asarray(d["bumps_total"], dtype=np.int64)

    @classmethod
    def of_step(cls, t: float, pose: np.ndarray, speed: float, yaw_rate: float, ranges: np.ndarray,
                bumps: int, bumps_total: int, pieces: np.ndarray, pose_error: float, lateral: float = 0.0,
                states: np.ndarray | None = None, taus: np.ndarray | None = None) -> GroundTruth:  # fmt: skip
        """The same object as ``GroundTruth(...)`` for a float64 ``pose (3,)``, ``ranges (n,)``,
        ``pieces (2, 3)``, ``states (S + 1, 3)`` and ``taus (S,)`` the caller hands over (and never writes
        again; None: empty), with the scalars as 0-d views of two small arrays: the env's per-step
        constructor."""
        f = np.array([t, speed, yaw_rate, pose_error, lateral], dtype=np.float64)
        i = np.array([bumps, bumps_total], dtype=np.int64)
        g = cls.__new__(cls)
        g.__dict__ = {"t": f[..., 0], "pose": pose, "speed": f[..., 1], "yaw_rate": f[..., 2],
                      "ranges": ranges, "bumps": i[..., 0], "bumps_total": i[..., 1], "pieces": pieces,
                      "pose_error": f[..., 3], "lateral": f[..., 4],
                      "states": _EMPTY_STATES if states is None else states,
                      "taus": _EMPTY_TAUS if taus is None else taus}  # fmt: skip
        return g

    def as_dict(self) -> dict[str, np.ndarray]:
        """Field name to array."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def __eq__(self, other: object) -> bool:
        return isinstance(other, GroundTruth) and all(
            np.array_equal(a, b, equal_nan=True)
            for a, b in zip(self.as_dict().values(), other.as_dict().values(), strict=True)
        )

    __hash__ = None  # type: ignore[assignment]  # unhashable (arrays, compared by value): object declares it

    @staticmethod
    def stack(items: list[GroundTruth]) -> GroundTruth:
        """Stack along a new leading time axis."""
        return GroundTruth(
            **{f.name: np.stack([getattr(g, f.name) for g in items]) for f in fields(GroundTruth)}
        )


__all__ = ["GroundTruth"]
