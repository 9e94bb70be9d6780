"""Batches of boxes: two float64 arrays ``lo, hi`` of shape ``(N, n)`` (thesis §2.3.1.2).

A box row is empty when any of its intervals is; empty rows are normalised to ``[+inf, -inf]`` in
every coordinate. Widths and volumes are rounded up (they bound the true measure from above).

>>> lo, hi = np.array([[1.0, 2.0]]), np.array([[2.0, 9.0]])     # Ex. 2.2, [x] = [1,2]×[2,9]
>>> float(width_euclid(lo, hi)[0]), float(width_inf(lo, hi)[0])     # √50 rounded up, 7
(7.0710678118654755, 7.0)
>>> (a_lo, a_hi), (b_lo, b_hi) = bisect(lo, hi)
>>> a_hi.tolist(), b_lo.tolist()
([[2.0, 5.5]], [[1.0, 5.5]])
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.types import Batch


def validate_batch(lo: Any, hi: Any, name: str = "boxes", n: int | None = None) -> Batch:
    """Check and convert a batch: float64 arrays of one shape ``(N, n)``, no NaN, ``lo <= hi``.

    A single box of shape ``(n,)`` is promoted to ``(1, n)``. Empty rows (``[+inf, -inf]``) pass. An
    interval ``[+inf, +inf]`` or ``[-inf, -inf]`` holds no real number (IEEE 1788) and is returned as
    the empty interval ``[+inf, -inf]`` (a copy is made then; the inputs are never modified).

    Raises:
        ValueError: naming ``name`` and saying what is wrong.
    """
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    if lo.ndim == 1:
        lo, hi = lo[None, :], hi[None, :] if hi.ndim == 1 else hi
    if lo.ndim != 2 or lo.shape != hi.shape:
        raise ValueError(f"{name}: expected lo and hi of one shape (N, n), got {lo.shape} and {hi.shape}")
    if n is not None and lo.shape[1] != n:
        raise ValueError(f"{name}: boxes have dimension {lo.shape[1]}, expected {n}")
    if np.isnan(lo).any() or np.isnan(hi).any():
        raise ValueError(f"{name}: NaN bound in row {int(np.argwhere(np.isnan(lo) | np.isnan(hi))[0, 0])}")
    top, bottom = lo == np.inf, hi == -np.inf
    bad = (lo > hi) & ~(top & bottom)
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise ValueError(f"{name}: lower bound {lo[r, c]} above upper bound {hi[r, c]} (row {r}, column {c})")
    point_inf = top ^ bottom  # [+inf, +inf] or [-inf, -inf]: no real number (IEEE 1788), read as empty
    if point_inf.any():
        lo, hi = np.where(point_inf, np.inf, lo), np.where(point_inf, -np.inf, hi)
    return lo, hi


def empty_rows(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``(N,)`` mask of empty boxes."""
    return np.asarray((lo > hi).any(axis=-1))


def normalize_empty(lo: np.ndarray, hi: np.ndarray) -> Batch:
    """Set every coordinate of an empty row to ``[+inf, -inf]``."""
    e = empty_rows(lo, hi)[..., None]
    return np.where(e, np.inf, lo), np.where(e, -np.inf, hi)


def widths(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Per-coordinate widths rounded up; 0 in empty rows."""
    with np.errstate(invalid="ignore"):
        w = rnd.sub_up(hi, lo)
    return np.where(empty_rows(lo, hi)[..., None], 0.0, w)


def width_inf(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``w∞([x]) = max_i w([x_i])`` (Eq. 2.17)."""
    return widths(lo, hi).max(axis=-1)


def width_euclid(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``w([x]) = sqrt(Σ w([x_i])²)`` (Eq. 2.16), rounded up."""
    w = widths(lo, hi)
    s = rnd.mul_up(w[..., 0], w[..., 0])
    for k in range(1, w.shape[-1]):
        s = rnd.add_up(s, rnd.mul_up(w[..., k], w[..., k]))
    return rnd.sqrt_up(s)


def volume(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Product of the widths, rounded up (area in 2-d)."""
    w = widths(lo, hi)
    v = w[..., 0]
    for k in range(1, w.shape[-1]):
        v = rnd.mul_up(v, w[..., k])
    return np.nan_to_num(v, nan=0.0)


def midpoint(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """A point inside each interval: the midpoint when finite, a finite point for unbounded ones."""
    with np.errstate(invalid="ignore", over="ignore"):
        m = 0.5 * lo + 0.5 * hi
        big = np.finfo(np.float64).max
        m = np.where((lo == -np.inf) & (hi == np.inf), 0.0, m)
        m = np.where((lo == -np.inf) & (hi < np.inf), np.where(hi > 0, 0.0, hi - 1.0), m)
        m = np.where((lo > -np.inf) & (hi == np.inf), np.where(lo < 0, 0.0, np.minimum(lo + 1.0, big)), m)
        m = np.where((lo == -np.inf) & (hi == -big), -big, m)
        return np.where(lo > hi, np.nan, np.clip(m, lo, hi))


def bisect(lo: np.ndarray, hi: np.ndarray, ratio: float = 0.5) -> tuple[Batch, Batch]:
    """Cut every box across its widest coordinate (Algorithm 2.1's bisection).

    Returns:
        ``((lo1, hi1), (lo2, hi2))``: the left and right halves, sharing the cut coordinate.
    """
    if not 0.0 < ratio < 1.0:
        raise ValueError(f"ratio: must lie in (0, 1), got {ratio}")
    w = widths(lo, hi)
    k = np.argmax(w, axis=-1)
    rows = np.arange(lo.shape[0])
    a, b = lo[rows, k], hi[rows, k]
    cut = midpoint(a, b) if ratio == 0.5 else np.clip(a + ratio * (b - a), a, b)
    hi1, lo2 = hi.copy(), lo.copy()
    hi1[rows, k] = cut
    lo2[rows, k] = cut
    return (lo, hi1), (lo2, hi)


def box_difference(
    lo: np.ndarray, hi: np.ndarray, ilo: np.ndarray, ihi: np.ndarray
) -> tuple[Batch, np.ndarray]:
    """Closed pieces of ``[x] \\ [y]`` for ``[y] ⊂ [x]`` row by row (an empty ``[y]`` gives ``[x]``).

    Peels coordinate after coordinate: at most ``2n`` pieces per row, with disjoint interiors, whose
    union with ``[y]`` is ``[x]``. Degenerate (zero-width) pieces are dropped.

    Returns:
        ``((plo, phi), rows)``: the pieces as a batch and, for each piece, the row it came from.
    """
    x_ok = ~empty_rows(lo, hi)
    whole = np.flatnonzero(x_ok & empty_rows(ilo, ihi))
    idx = np.flatnonzero(x_ok & ~empty_rows(ilo, ihi))
    plos, phis, rows = [lo[whole]], [hi[whole]], [whole]
    lo, hi = lo[idx], hi[idx]
    ilo, ihi = np.clip(ilo[idx], lo, hi), np.clip(ihi[idx], lo, hi)
    cur_lo, cur_hi = lo.copy(), hi.copy()
    for k in range(lo.shape[1]):
        for cut_hi, bound in ((True, ilo), (False, ihi)):
            plo, phi = cur_lo.copy(), cur_hi.copy()
            (phi if cut_hi else plo)[:, k] = bound[:, k]
            keep = phi[:, k] > plo[:, k]
            plos.append(plo[keep])
            phis.append(phi[keep])
            rows.append(idx[keep])
        cur_lo[:, k], cur_hi[:, k] = ilo[:, k], ihi[:, k]
    return (np.concatenate(plos), np.concatenate(phis)), np.concatenate(rows)


#: rows per block in :func:`chunked`: keeps a kernel's temporaries in cache
CHUNK = 1 << 15


_R = TypeVar("_R")


def chunked(fn: Callable[[np.ndarray, np.ndarray], _R], lo: np.ndarray, hi: np.ndarray) -> _R:
    """``fn(lo, hi)`` applied block by block of :data:`CHUNK` rows, results concatenated.

    ``fn`` returns an array or nested tuples of arrays whose first axis is the row. Large batches go
    several times faster this way: each kernel's temporaries stay in cache instead of being freshly
    allocated (and page-faulted) megabytes.
    """
    if lo.shape[0] <= CHUNK:
        return fn(lo, hi)
    parts = [fn(lo[i : i + CHUNK], hi[i : i + CHUNK]) for i in range(0, lo.shape[0], CHUNK)]

    def cat(items: list[Any]) -> Any:
        if isinstance(items[0], tuple):
            return tuple(cat([it[k] for it in items]) for k in range(len(items[0])))
        return np.concatenate(items)

    return cat(parts)


__all__ = [
    "CHUNK",
    "bisect",
    "box_difference",
    "chunked",
    "empty_rows",
    "midpoint",
    "normalize_empty",
    "validate_batch",
    "volume",
    "width_euclid",
    "width_inf",
    "widths",
]
