"""Compiled kernel of the predicted gain: the area a range sensor would newly see from each candidate pixel.

:func:`visible_gain` casts ``n_rays`` rays of ``radius`` pixels from the centre of every candidate pixel over
a map of free probabilities ``p`` (a prediction, or the true map for the oracle). Along a ray, the chance that
the beam is still going is the product of the ``p`` of the pixels it crossed (a pixel half free stops half
the beams); each sample of an *unknown* pixel (dark or penumbra) adds that chance times its ``weight`` (the
predicted free share, less an uncertainty discount) times the area the sample stands for, ``r dr dθ``: the
expected newly seen free area in pixels², MapEx's estimated visible area on a predicted map. Samples are
``step`` pixels apart; a ray stops at the map's border.
"""

from __future__ import annotations

import math

import numpy as np

from digslam.observer.core.scalar_jit import njit


@njit(cache=True)
def visible_gain(p: np.ndarray, weight: np.ndarray, unknown: np.ndarray, rows: np.ndarray,
                 cols: np.ndarray, radius: float, n_rays: int, step: float) -> np.ndarray:  # fmt: skip
    """``(K,)`` expected newly seen free area (pixels²) from the centres of pixels ``(rows[k], cols[k])``
    (module docstring). ``p``, ``weight``: ``(m, m)`` float64 in ``[0, 1]``; ``unknown``: ``(m, m)`` bool."""
    m0, m1 = p.shape
    k = rows.shape[0]
    out = np.zeros(k)
    d_theta = 2.0 * math.pi / n_rays
    n_samples = int(radius / step)
    cs = np.empty(n_rays)
    sn = np.empty(n_rays)
    for j in range(n_rays):
        cs[j] = math.cos(j * d_theta)
        sn[j] = math.sin(j * d_theta)
    for i in range(k):
        r0 = rows[i] + 0.5
        c0 = cols[i] + 0.5
        total = 0.0
        for j in range(n_rays):
            alive = 1.0
            last_r, last_c = -1, -1
            for s in range(1, n_samples + 1):
                r = s * step
                fr = r0 - r * sn[j]
                fc = c0 + r * cs[j]
                if fr < 0.0 or fc < 0.0 or fr >= m0 or fc >= m1:
                    break
                ir = int(fr)
                ic = int(fc)
                if unknown[ir, ic]:
                    total += alive * weight[ir, ic] * r * step * d_theta
                if ir != last_r or ic != last_c:  # a pixel stops the beam once, however many samples
                    alive *= p[ir, ic]
                    last_r, last_c = ir, ic
                if alive < 1e-3:
                    break
        out[i] = total
    return out
