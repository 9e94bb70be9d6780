"""Bounded noise: every measurement comes with an interval that contains the truth.

Models (see :class:`~digslam.envs.config.NoiseConfig`): ``uniform`` error in ``[-b, b]``; ``adversarial``
error exactly ``±b`` so that the truth sits exactly on a bound of the reported interval; ``biased`` error
``bias*b`` plus jitter, still inside ``[-b, b]``. Intervals ``[m - b, m + b]`` are widened by a few ulps so
that floating-point rounding can never exclude the truth.
"""

from __future__ import annotations

import numpy as np

from digslam.envs.config import NoiseConfig
from digslam.envs.sim.noise_jit import MODEL_CODES, noise_kernel


def measure(
    truth: np.ndarray,
    bound: float | np.ndarray,
    cfg: NoiseConfig,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Noisy measurement of ``truth`` with error bound ``bound`` (compiled: :func:`.noise_jit.noise_kernel`).

    Args:
        truth: True values (finite).
        bound: Error half-width ``b >= 0`` (scalar or broadcastable to ``truth``).
        cfg: Noise model.
        rng: Random generator (always advanced by the same amount, whatever the values).

    Returns:
        ``(measured, lo, hi)`` with ``lo <= truth <= hi`` exactly.
    """
    truth = np.asarray(truth, dtype=np.float64)
    b = np.broadcast_to(np.asarray(bound, dtype=np.float64), truth.shape)
    u = rng.uniform(-1.0, 1.0, truth.shape)
    m, lo, hi = np.empty(truth.size), np.empty(truth.size), np.empty(truth.size)
    noise_kernel(np.ascontiguousarray(truth).reshape(-1), np.ascontiguousarray(b).reshape(-1),
                 u.reshape(-1), MODEL_CODES[cfg.model], float(cfg.bias), m, lo, hi)  # fmt: skip
    return m.reshape(truth.shape), lo.reshape(truth.shape), hi.reshape(truth.shape)


def outliers(
    n: int,
    prob: float,
    r_max: np.ndarray,
    bound: float,
    rng: np.random.Generator,
    max_count: int | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Outlier draws: ``(flag (n,), lo (n,), hi (n,))``, a spurious echo uniform in ``[0, r_max]``.

    Each reading is an outlier with probability ``prob``; with ``max_count``, at most that many per call (one
    step): when more are drawn, the ``max_count`` with the smallest draws are kept (each reading alike).
    The generator is advanced by ``2 n`` uniform draws whatever happens, so runs stay reproducible.

    >>> f, lo, hi = outliers(9, 1.0, np.full(9, 5.0), 0.01, np.random.default_rng(0), max_count=1)
    >>> int(f.sum()), bool(np.all(lo <= hi))
    (1, True)
    """
    if max_count is not None and not (isinstance(max_count, int | np.integer) and max_count >= 0):
        raise ValueError(f"max_count: must be None or an integer >= 0, got {max_count!r}")
    u = rng.uniform(0.0, 1.0, n)
    flag = u < prob
    m = rng.uniform(0.0, 1.0, n) * r_max
    if max_count is not None and int(flag.sum()) > max_count:
        keep = np.argsort(u, kind="stable")[:max_count]
        flag = np.zeros(n, dtype=bool)
        flag[keep] = True
    return flag, np.maximum(m - bound, 0.0), m + bound


__all__ = [
    "measure",
    "outliers",
]
