"""Bounded noise: every measurement comes with an interval that contains the truth.

Models (see :class:`~digslam.envs.config.NoiseConfig`): ``uniform`` error in ``[-b, b]``; ``adversarial``
error exactly ``±b`` so that the truth sits exactly on a bound of the reported interval; ``biased`` error
``bias*b`` plus jitter, still inside ``[-b, b]``. Intervals ``[m - b, m + b]`` are widened by a few ulps so
that floating-point rounding can never exclude the truth.
"""

from __future__ import annotations

import numpy as np

from .config import NoiseConfig


def _widen(lo: np.ndarray, hi: np.ndarray, scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    pad = 4.0 * np.spacing(scale)
    return lo - pad, hi + pad


def measure(
    truth: np.ndarray,
    bound: float | np.ndarray,
    cfg: NoiseConfig,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Noisy measurement of ``truth`` with error bound ``bound``.

    Args:
        truth: True values (finite).
        bound: Error half-width ``b >= 0`` (scalar or broadcastable to ``truth``).
        cfg: Noise model.
        rng: Random generator (always advanced by the same amount, whatever the values).

    Returns:
        ``(measured, lo, hi)`` with ``lo <= truth <= hi`` exactly.
    """
    truth = np.asarray(truth, dtype=np.float64)
    b = np.asarray(bound, dtype=np.float64)
    u = rng.uniform(-1.0, 1.0, truth.shape)
    if cfg.model == "adversarial":
        side = np.where(u >= 0, 1.0, -1.0)
        m = truth + side * b
        far = truth + side * 2.0 * b
        lo = np.where(side > 0, truth, far)
        hi = np.where(side > 0, far, truth)
        plo, phi = _widen(lo, hi, np.maximum(np.abs(truth), 2.0 * b))
        return m, np.where(side > 0, truth, plo), np.where(side > 0, phi, truth)
    if cfg.model == "biased":
        e = (cfg.bias + (1.0 - abs(cfg.bias)) * u) * b
    else:
        e = u * b
    m = truth + e
    lo, hi = _widen(m - b, m + b, np.maximum(np.abs(m), b))
    return m, lo, hi


def outliers(
    n: int,
    prob: float,
    r_max: np.ndarray,
    bound: float,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Outlier draws: ``(flag (n,), lo (n,), hi (n,))``, a spurious echo uniform in ``[0, r_max]``."""
    flag = rng.uniform(0.0, 1.0, n) < prob
    m = rng.uniform(0.0, 1.0, n) * r_max
    return flag, np.maximum(m - bound, 0.0), m + bound
