"""The kernel of the separator algebra (:mod:`.separators`, thesis Eq. 2.54): folding separated batches.

:func:`fold_separated` accumulates the stacked results ``(4, N, n)`` of the separators of an intersection
or a union in one machine-code loop (:class:`~.separators.SepInter`, :class:`~.separators.SepUnion`).

>>> lo, hi = np.array([[0.0], [0.0]]), np.array([[4.0], [4.0]])
>>> s = np.array([[[0.0], [0.0]], [[1.0], [4.0]], [[1.0], [np.inf]], [[4.0], [-np.inf]]])
>>> acc = fold_separated(np.empty((0, 0, 0)), s, lo, hi, False)        # the first separator of an ∩
>>> acc[:, :, 0].tolist()           # x_in as given, x_out met with [x]; row 1 proved outside: empty
[[0.0, 0.0], [1.0, 4.0], [1.0, inf], [4.0, -inf]]
"""

from __future__ import annotations

import numpy as np

from digslam.observer.core.scalar_jit import njit

__all__ = ["fold_separated"]


@njit
def fold_separated(acc: np.ndarray, s: np.ndarray, lo: np.ndarray, hi: np.ndarray, union: bool) -> np.ndarray:
    """Fold one separated batch ``s (4, N, n)`` into ``acc`` by Eq. 2.54 (a new ``acc`` when it is
    ``(0, 0, 0)``): for ``&``, ``x_in ⊔= s_in`` and ``x_out ∩= s_out``; for ``|`` the other way round.
    The intersections are also met with ``[x]``; empty rows come out as ``[+inf, -inf]``."""
    nb, n = lo.shape
    h, m = (2, 0) if union else (0, 2)  # the part taking the hull, the part taking the meet
    if acc.shape[0] == 0:
        acc = np.empty((4, nb, n))
        acc[h], acc[h + 1] = np.inf, -np.inf
        for r in range(nb):  # element by element: an array copy would compile numba's shape check
            for i in range(n):
                acc[m, r, i], acc[m + 1, r, i] = lo[r, i], hi[r, i]
    for r in range(nb):
        empty = False
        for i in range(n):
            empty |= s[h, r, i] > s[h + 1, r, i]
        if not empty:
            for i in range(n):
                acc[h, r, i] = min(acc[h, r, i], s[h, r, i])
                acc[h + 1, r, i] = max(acc[h + 1, r, i], s[h + 1, r, i])
        empty = False
        for i in range(n):
            acc[m, r, i] = max(acc[m, r, i], s[m, r, i], lo[r, i])
            acc[m + 1, r, i] = min(acc[m + 1, r, i], s[m + 1, r, i], hi[r, i])
            empty |= acc[m, r, i] > acc[m + 1, r, i]
        if empty:
            acc[m, r], acc[m + 1, r] = np.inf, -np.inf
    return acc
