"""Compiled kernel of the tour frontier agent (:mod:`.tour`): the shortest open tour over a few stops.

:func:`open_tours` is the Held-Karp dynamic programme (Bellman 1962; Held & Karp 1962) for the open
travelling-salesman path: for every stop ``i``, the length of the shortest path that starts at ``i`` and
visits every other stop once, ending anywhere. ``O(2^K K^2)`` for ``K`` stops (``K <= 12`` here: at most
``2^12 * 12`` table entries).

>>> d = np.array([[0.0, 1.0, 5.0], [1.0, 0.0, 1.0], [5.0, 1.0, 0.0]])
>>> open_tours(d).tolist()     # from 0: 0-1-2 (2); from 1: 1-0-2 or 1-2-0 (6); from 2: 2-1-0 (2)
[2.0, 6.0, 2.0]
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core.scalar_jit import njit

#: The most stops :func:`open_tours` takes (its table has ``2^K K`` entries).
MAX_STOPS = 12


@njit
def open_tours(d: np.ndarray) -> np.ndarray:
    """``(K,)``: for each stop ``i``, the length of the shortest path from ``i`` through every other stop of
    the ``(K, K)`` distance matrix ``d`` (not necessarily symmetric; ``inf`` entries allowed: a stop no path
    reaches makes every tour ``inf``). ``K`` at most :data:`MAX_STOPS`."""
    k = d.shape[0]
    out = np.zeros(k)
    if k <= 1:
        return out
    full = (1 << k) - 1
    # f[mask, j]: shortest path from j through every stop of mask (j in mask)
    f = np.full((full + 1, k), np.inf)
    for j in range(k):
        f[1 << j, j] = 0.0
    for mask in range(1, full + 1):
        for j in range(k):
            if not (mask >> j) & 1 or mask == 1 << j:
                continue
            rest = mask & ~(1 << j)
            best = np.inf
            for n in range(k):
                if (rest >> n) & 1:
                    v = d[j, n] + f[rest, n]
                    if v < best:
                        best = v
            f[mask, j] = best
    for i in range(k):
        out[i] = f[full, i]
    return out
