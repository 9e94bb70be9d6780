"""One laser scan's beams merged into wider cones: a scan's free space, seen between its beams.

A LaserScan's beams are narrow cones (half-aperture ``|angle_increment| / 2`` by default): each alone holds
no whole map cell beyond a few metres, so digging beam by beam proves almost nothing free far away. But the
beams of one scan taken at one instant (``time_increment = 0``: one apex, one heading) whose cones tile the
field of view (half-aperture ``>= |angle_increment| / 2``, :func:`can_merge`) prove together what each proves
alone: the union of the cones ``i..j`` is the cone from the first beam's edge to the last's, free up to the
smallest lower range (thesis Eq. 6.21 on a union of sectors), and its nearest obstacle is within the largest
upper range. So the run ``i..j`` is one reading

    ``α = (a_i + a_j) / 2``, ``γ = |a_j - a_i| / 2 + γ_beam``, ``y = [min_k y_k⁻, max_k y_k⁺]``,
    ``r_max = max_k r_max_k``,

no echo (``[r_max, inf]``) when none of them echoed and their ``r_max`` agree. It is a reading like any other,
and each of its claims holds: it digs and certainly senses the union up to ``min y⁻`` (each beam saw its cone
that far); it marks as possibly sensed the union up to ``max y⁺`` (no beam saw further), so no cell a beam may
have seen is called dark; its echo is within ``max y⁺`` (weak: the reader keeps the beams themselves beside
the merged readings for the sharp impact constraints). A beam without a reading (NaN, ``-inf``, below
``range_min``) proves nothing of its cone, so it cuts a run. :func:`merge_beams` splits the scan into
``groups`` contiguous groups and keeps, in each, its longest run of beams with a reading. An outlier beam
spoils only its group's run, so ``q`` outliers among the beams spoil at most ``q`` merged readings besides
themselves.

The merged half-aperture is rounded down (a few ulps inside the union) so that a dug cell is inside the union;
the beams' own directions ``a_k`` are the reader's (:mod:`.bag_bridge`).

>>> a = np.radians([0.0, 1.0, 2.0, 3.0])
>>> rng = np.array([[2.0, 2.1], [3.0, 3.1], [4.0, np.inf], [1.0, 1.1]])
>>> out = merge_beams(a, np.radians(0.5), rng, np.array([False, False, False, False]), np.full(4, 20.0),
...                   reading=np.array([True, True, False, True]), groups=2)
>>> np.degrees(out[0]).round(6).tolist(), np.degrees(out[1]).round(6).tolist(), out[3].tolist()
([0.5, 3.0], [1.0, 0.5], [[2.0, 3.1], [1.0, 1.1]])
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["can_merge", "merge_beams"]

_EPS = np.finfo(np.float64).eps


def can_merge(angle_increment: float, gamma_beam: float, time_increment: float) -> bool:
    """Whether a scan's beams may be merged: taken at one instant and tiling the field of view."""
    return time_increment == 0.0 and gamma_beam >= 0.5 * abs(angle_increment) and angle_increment != 0.0


def merge_beams(
    alpha: np.ndarray, gamma_beam: float, rng: np.ndarray, no_echo: np.ndarray, r_max: np.ndarray,
    reading: np.ndarray, groups: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """``groups`` merged readings of one scan (see the module docstring).

    Args:
        alpha: ``(n,)`` the beams' directions in scan order (evenly spaced).
        gamma_beam: the beams' half-aperture.
        rng, no_echo, r_max: ``(n, 2)``, ``(n,)``, ``(n,)`` each beam's reading as the reader made it.
        reading: ``(n,)`` False where a beam has no reading (its interval ``[0, inf]`` proves nothing).
        groups: how many merged readings (``<= n``).

    Returns:
        ``(alpha, gamma, r_max, range, no_echo)`` of the ``groups`` merged readings; a group without a
        beam that read is a no-reading slot (``[0, inf]``, its beams' mean direction).
    """
    n = alpha.size
    sizes = np.array([len(c) for c in np.array_split(np.arange(n), groups)])
    g_start = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    group = np.repeat(np.arange(groups), sizes)
    out_a = 0.5 * (alpha[g_start] + alpha[g_start + sizes - 1])
    out_g, out_ne = np.full(groups, gamma_beam), np.zeros(groups, bool)
    out_r = np.maximum.reduceat(r_max, g_start)
    out_y = np.tile([0.0, np.inf], (groups, 1))
    # runs of beams that read, cut at the groups' borders: starts, ends (exclusive) and lengths
    first = reading & np.concatenate([[True], ~reading[:-1]])
    first[g_start] = reading[g_start]
    starts = np.flatnonzero(first)
    if starts.size == 0:
        return out_a, out_g, out_r, out_y, out_ne
    stop = ~reading | np.isin(np.arange(n), g_start)  # where a run cannot go on
    nxt = np.append(np.flatnonzero(stop), n)
    ends = nxt[np.searchsorted(nxt, starts, side="right")]
    length, g_of = ends - starts, group[starts]
    best = np.lexsort((starts, -length, g_of))  # per group: the longest run, the first one on a tie
    keep = best[np.concatenate([[True], g_of[best][1:] != g_of[best][:-1]])]
    i, j, g = starts[keep], ends[keep], g_of[keep]
    a_i, a_j = alpha[i], alpha[j - 1]
    out_a[g] = 0.5 * (a_i + a_j)
    half = 0.5 * np.abs(a_j - a_i) + gamma_beam
    out_g[g] = np.minimum(math.pi, half - 8 * _EPS * (np.abs(a_i) + np.abs(a_j) + half))
    cut = np.ravel(np.column_stack([i, j]))  # reduceat over [i, j) then skip the gaps between runs
    cut = cut[:-1] if cut[-1] >= n else cut
    lo = np.minimum.reduceat(rng[:, 0], cut)[::2][: len(i)]
    hi = np.maximum.reduceat(rng[:, 1], cut)[::2][: len(i)]
    r_hi = np.maximum.reduceat(r_max, cut)[::2][: len(i)]
    r_lo = np.minimum.reduceat(r_max, cut)[::2][: len(i)]
    quiet = np.minimum.reduceat(no_echo.astype(np.int8), cut)[::2][: len(i)] == 1
    ne = quiet & (r_lo == r_hi)  # no echo up to one range
    out_ne[g] = ne
    out_r[g] = r_hi
    out_y[g, 0] = np.where(ne, r_hi, lo)
    out_y[g, 1] = np.where(ne, np.inf, hi)
    return out_a, out_g, out_r, out_y, out_ne
