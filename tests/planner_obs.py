"""Test helper: a hand-made observation of ``digslam/DigCoverage-v0`` for the planning agents' unit tests."""

from __future__ import annotations

import math

import numpy as np

from digslam.envs.observation import BASE_CHANNELS, N_STATE, Channel, State


def planner_obs(clear: np.ndarray, pos: tuple[float, float], dark: np.ndarray | None = None, heading: float = 0.0,
                tube: float = 0.0, elapsed: float = 0.1) -> dict[str, np.ndarray]:  # fmt: skip
    """An observation with the ``clear`` and ``dark`` masks (None: every pixel not clear is dark; the rest is
    penumbra), the robot at pixel ``pos`` (row, column; a point pose box) with ``heading`` (rad), the tube
    width ``tube`` (m), the ``elapsed`` share and the consistency flag set."""
    m = clear.shape[0]
    dark = ~clear if dark is None else dark
    img = np.zeros((BASE_CHANNELS, m, m), np.uint8)
    img[Channel.CLEAR][clear] = 255
    img[Channel.DARK][dark & ~clear] = 255
    img[Channel.PENUMBRA][~clear & ~dark] = 255
    ux, uy = 2 * pos[1] / m - 1, 1 - 2 * pos[0] / m
    s = np.zeros(N_STATE, np.float32)
    s[[State.X_LO, State.Y_LO, State.X_HI, State.Y_HI]] = ux, uy, ux, uy
    s[State.COS], s[State.SIN] = math.cos(heading), math.sin(heading)
    s[State.TUBE], s[State.ELAPSED], s[State.CONSISTENT] = math.tanh(tube), elapsed, 1.0
    return {"map": img, "state": s}
