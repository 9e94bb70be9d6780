"""Test helper: a hand-made observation of ``digslam/DigCoverage-v0`` for the planning agents' unit tests."""

from __future__ import annotations

import math

import numpy as np


def planner_obs(clear: np.ndarray, pos: tuple[float, float], dark: np.ndarray | None = None, heading: float = 0.0,
                tube: float = 0.0, elapsed: float = 0.1) -> dict[str, np.ndarray]:  # fmt: skip
    """An observation with the ``clear`` and ``dark`` masks (None: every pixel not clear is dark; the rest is
    penumbra), the robot at pixel ``pos`` (row, column; a point pose box) with ``heading`` (rad), the tube
    width ``tube`` (m), the ``elapsed`` share and the consistency flag set."""
    m = clear.shape[0]
    dark = ~clear if dark is None else dark
    img = np.zeros((4, m, m), np.uint8)
    img[0][clear], img[2][dark & ~clear], img[1][~clear & ~dark] = 255, 255, 255
    ux, uy = 2 * pos[1] / m - 1, 1 - 2 * pos[0] / m
    s = np.zeros(11, np.float32)
    s[:4] = ux, uy, ux, uy
    s[4:6] = math.cos(heading), math.sin(heading)
    s[7], s[8], s[10] = math.tanh(tube), elapsed, 1.0
    return {"map": img, "state": s}
