"""Random polar boxes ``(x, y, rho, theta)`` for the polar contractor's tests (shared by numpy and kernel tests)."""

from __future__ import annotations

import numpy as np


def random_boxes(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    c, w = rng.uniform(-5, 5, (n, 2)), rng.uniform(0.05, 6, (n, 2))
    rl = np.where(rng.random(n) < 0.2, rng.uniform(-3, 5, n), rng.uniform(0, 5, n))
    rh = rl + rng.uniform(0.05, 4, n)
    tl = rng.uniform(-8, 8, n)
    tw = np.choose(
        rng.integers(0, 3, n), [rng.uniform(0.02, 1, n), rng.uniform(1, 4, n), rng.uniform(4, 15, n)]
    )
    return np.c_[c - w, rl, tl], np.c_[c + w, rh, tl + tw]
