"""The paver (thesis §2.4.3, Algorithm 2.1), one generation of boxes per separator call.

``pave(X0, sep, eps)`` separates the whole list ``L`` at once: the parts removed by ``S_in`` are
stored as inner boxes (``X⁻``), those removed by ``S_out`` as outer boxes, and ``[x_in] ∩ [x_out]``
is either stored as a boundary box (``w∞ < ε``) or bisected into the next generation. Then
``X⁻ = inner ⊂ X ⊂ X⁺ = inner ∪ boundary`` (Eq. 2.58).

>>> ring = SepInverse(Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2), Interval(1, 2.25))
>>> p = pave(Box([(-1, 5), (-0.5, 5.5)]), ring, 0.1)
>>> 0.9 * 3.92699 < p.inner_area < 3.92699 < p.inner_area + p.boundary_area       # 5π/4
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from digslam.observer.core.boxes import empty_rows, validate_batch, volume
from digslam.observer.core.interval import IntervalArray
from digslam.observer.core.scalar_jit import njit
from digslam.observer.core.types import Batch
from digslam.observer.sets.separators import Sep


@dataclass
class PavingTree:
    """The bisection tree: node ``j`` holds the box ``x(j)`` it was given; pieces point to nodes."""

    lo: np.ndarray
    hi: np.ndarray
    parent: np.ndarray
    left: np.ndarray  # -1 for leaves; right child is left + 1

    @property
    def size(self) -> int:
        return self.lo.shape[0]


@dataclass
class Paving:
    """Result of :func:`pave`.

    Attributes:
        inner: boxes proved inside ``X`` (``X⁻``), as an ``(lo, hi)`` batch.
        outer: boxes proved outside ``X``.
        boundary: undetermined boxes smaller than ``ε`` (``X⁺ = inner ∪ boundary``).
        inner_node, outer_node, boundary_node: the tree node each box came from.
        tree: the bisection tree.
        bisections: number of bisections.
    """

    inner: Batch
    outer: Batch
    boundary: Batch
    inner_node: np.ndarray
    outer_node: np.ndarray
    boundary_node: np.ndarray
    tree: PavingTree
    bisections: int
    eps: float = field(default=0.0)

    @property
    def inner_area(self) -> float:
        """Total volume (area in 2-d) proved inside."""
        return float(volume(*self.inner).sum()) if self.inner[0].size else 0.0

    @property
    def outer_area(self) -> float:
        """Total volume proved outside."""
        return float(volume(*self.outer).sum()) if self.outer[0].size else 0.0

    @property
    def boundary_area(self) -> float:
        """Total volume left undetermined."""
        return float(volume(*self.boundary).sum()) if self.boundary[0].size else 0.0

    def __repr__(self) -> str:
        return (
            f"Paving(inner={len(self.inner[0])}, outer={len(self.outer[0])}, "
            f"boundary={len(self.boundary[0])}, "
            f"bisections={self.bisections}, areas=({self.inner_area:.6g}, {self.outer_area:.6g}, "
            f"{self.boundary_area:.6g}))"
        )


def pave(
    x0: IntervalArray | Any,
    sep: Sep,
    eps: float,
    ratio: float = 0.5,
    max_boxes: int = 50_000_000,
    *,
    cut: str = "ratio",
    max_volume: float | None = None,
) -> Paving:
    """Pave ``x0`` with the separator ``sep`` down to boxes of width ``eps`` (Algorithm 2.1).

    An undetermined box ``[x_in] ∩ [x_out]`` is bisected across its widest side while ``w∞ >= eps``
    (and, with ``max_volume``, while its volume is ``>= max_volume``). Where it is cut is a policy:

    * ``cut="ratio"`` (Algorithm 2.1): at ``ratio`` of the side, so the boundary boxes that stop come
      out with ``w∞`` anywhere between about ``eps / 2`` and ``eps``.
    * ``cut="grid"``: a side of width ``w >= eps`` is seen as ``m = ⌊w / eps⌋ + 1`` equal cells, each
      narrower than ``eps``, and cut at the cell boundary nearest its middle. The cells survive the
      next cuts, so the boundary comes out in boxes just under ``eps`` and needs fewer of them.

    ``max_volume`` bounds the volume of every boundary box: a box with ``w∞ < eps`` is still cut (at
    ``ratio``) while its volume is ``>= max_volume``. Boxes that straddle the boundary at a slant are
    fat, and cutting them buys the most undetermined volume per bisection, while boxes along a
    boundary near the axes are thin and stay whole. With ``cut="grid", max_volume=eps**2 / 2`` the
    landmark of §3.4.1.1 takes fewer bisections and leaves less undetermined area than codac's ``pave``
    at ε = 0.01 and 0.001 (``benchmarks/bench_polar.py``). Every box left undetermined has ``w∞ < eps``
    whatever the policy, unless its widest side is too narrow to be split in floating point (an
    ``eps`` below the resolution of the coordinates).

    Args:
        x0: the initial box, an :class:`IntervalArray` of shape ``(n,)`` or ``(lo, hi)``.
        sep: the separator of the set to characterise.
        eps: the width ``w∞`` under which an undetermined box is no longer bisected (``> 0``).
        ratio: where the widest side is cut, in ``(0, 1)`` (codac cuts at 0.49); with ``cut="grid"``,
            only the cuts that ``max_volume`` asks for.
        max_boxes: guard on the number of boxes held in one generation.
        cut: ``"ratio"`` or ``"grid"``, see above.
        max_volume: if given (``> 0``), the volume from which a box with ``w∞ < eps`` is still cut.

    Raises:
        ValueError: on an empty or unbounded initial box, ``eps <= 0``, a dimension mismatch, an
            unknown ``cut`` or a ``max_volume`` that is not a positive number.

    >>> ring = SepInverse(Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2), Interval(1, 2.25))
    >>> a = pave(Box([(-1, 5), (-0.5, 5.5)]), ring, 0.01)
    >>> b = pave(Box([(-1, 5), (-0.5, 5.5)]), ring, 0.01, cut="grid", max_volume=0.01**2 / 2)
    >>> b.bisections < a.bisections, b.boundary_area < 1.25 * a.boundary_area
    (True, True)
    """
    lo0, hi0 = x0.pair if isinstance(x0, IntervalArray) else x0
    if not (isinstance(eps, (int, float, np.floating)) and eps > 0 and np.isfinite(eps)):
        raise ValueError(f"eps: must be a positive finite number, got {eps!r}")
    if not 0.0 < ratio < 1.0:
        raise ValueError(f"ratio: must lie in (0, 1), got {ratio!r}")
    if cut not in ("ratio", "grid"):
        raise ValueError(f"cut: must be 'ratio' or 'grid', got {cut!r}")
    if max_volume is not None and not (
        isinstance(max_volume, (int, float, np.floating)) and max_volume > 0 and np.isfinite(max_volume)
    ):
        raise ValueError(f"max_volume: must be None or a positive finite number, got {max_volume!r}")
    policy = (float(eps), float(ratio), cut == "grid", np.inf if max_volume is None else float(max_volume))
    lo, hi = validate_batch(lo0, hi0, "x0", sep.n)
    if lo.shape[0] != 1:
        raise ValueError(f"x0: expected one initial box, got {lo.shape[0]}")
    if empty_rows(lo, hi).any():
        raise ValueError("x0: the initial box is empty")
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise ValueError("x0: the initial box must be bounded")
    base, n = 0, lo.shape[1]
    t_lo, t_hi, t_left = [lo], [hi], []
    n_nodes = 1
    parts: dict[str, list[Any]] = {k: [] for k in ("in", "out", "bd", "in_n", "out_n", "bd_n")}
    bisections = 0
    while lo.shape[0]:
        if lo.shape[0] > max_boxes:
            raise ValueError(f"max_boxes: a generation holds {lo.shape[0]} boxes; raise eps or max_boxes")
        parts_sep = sep.separate_stacked(lo, hi)
        out, rows, left, cnt = _generation(lo, hi, parts_sep, *policy, base, n_nodes)
        c_in, c_out, c_bd, c_ch = cnt.tolist()
        o1, o2 = 2 * n * len(lo), 4 * n * len(lo)
        o3 = o2 + len(lo)
        big = len(lo) > 256  # views would pin the whole (2, (4n+3)N, n) buffer until the end: copy
        for key, a, b in (("in", 0, c_in), ("out", o1, o1 + c_out), ("bd", o2, o2 + c_bd)):
            parts[key].append((out[0, a:b].copy(), out[1, a:b].copy()) if big else (out[0, a:b], out[1, a:b]))
            parts[key + "_n"].append(rows[a:b].copy() if big else rows[a:b])
        t_left.append(left)
        lo, hi = out[0, o3 : o3 + c_ch], out[1, o3 : o3 + c_ch]
        if big:
            lo, hi = lo.copy(), hi.copy()
        base = n_nodes
        t_lo.append(lo)
        t_hi.append(hi)
        n_nodes += c_ch
        bisections += c_ch // 2
    left = np.concatenate(t_left)
    tree = PavingTree(np.concatenate(t_lo), np.concatenate(t_hi), _parents(left, n_nodes), left)

    def cat(key: str) -> Batch:
        return np.concatenate([p[0] for p in parts[key]]), np.concatenate([p[1] for p in parts[key]])

    return Paving(
        cat("in"), cat("out"), cat("bd"),
        np.concatenate(parts["in_n"]), np.concatenate(parts["out_n"]), np.concatenate(parts["bd_n"]),
        tree, bisections, float(eps),
    )  # fmt: skip


@njit(inline="always")
def _diff(lo: np.ndarray, hi: np.ndarray, r: int, y: np.ndarray, out: np.ndarray, rows: np.ndarray,
          c: int) -> int:  # fmt: skip
    """Write the closed pieces of ``[x_r] \\ [y]`` (``[y] ⊂ [x_r]``; ``y = (2, n)``) from slot ``c``, as
    :func:`.boxes.box_difference` does; return the next free slot."""
    n = lo.shape[1]
    if y[0, 0] > y[1, 0]:
        for i in range(n):
            out[0, c, i], out[1, c, i] = lo[r, i], hi[r, i]
        rows[c] = r
        return c + 1
    for k in range(n):
        for side in range(2):
            if (y[0, k] > lo[r, k]) if side == 0 else (hi[r, k] > y[1, k]):
                for i in range(n):
                    inner = i < k
                    out[0, c, i] = y[0, i] if inner else lo[r, i]
                    out[1, c, i] = y[1, i] if inner else hi[r, i]
                if side == 0:
                    out[1, c, k] = y[0, k]
                else:
                    out[0, c, k] = y[1, k]
                rows[c] = r
                c += 1
    return c


@njit(inline="always")
def _meet_row(lo: np.ndarray, hi: np.ndarray, r: int, a: np.ndarray, j: int, y: np.ndarray) -> None:
    """``y = [a_r] ∩ [x_r]`` (``a`` is ``x_in`` for ``j = 0``, ``x_out`` for ``j = 2``); empty as
    ``[+inf, -inf]``."""
    empty = False
    for k in range(lo.shape[1]):
        y[0, k], y[1, k] = max(a[j, r, k], lo[r, k]), min(a[j + 1, r, k], hi[r, k])
        empty |= y[0, k] > y[1, k]
    if empty:
        y[0, :], y[1, :] = np.inf, -np.inf


@njit
def _generation(lo: np.ndarray, hi: np.ndarray, sep: np.ndarray, eps: float, ratio: float, grid: bool,
                max_vol: float, base: int, n_nodes: int) -> tuple[np.ndarray, ...]:  # fmt: skip
    """One step of Algorithm 2.1 on a generation ``(N, n)`` separated into ``sep = (in_lo, in_hi, out_lo,
    out_hi)``: the pieces of ``[x] \\ [x_in]`` (inner) and ``[x] \\ [x_out]`` (outer), the boxes
    ``[x_in] ∩ [x_out]`` with ``w∞ < ε`` (widths rounded up) and volume ``< max_vol`` (boundary), and
    the others bisected across their widest side (children; the cut is :func:`_cut`). Returns ``(boxes
    (2, M, n), nodes (M,), left (N,), counts (4,))``: the four groups lie from offsets ``0, 2nN, 4nN,
    4nN + N`` on, each box with the tree node it came from (row ``r`` is node ``base + r``); ``left`` is
    the first child's node (``n_nodes + 2j``) or -1."""
    nb, n = lo.shape
    off = np.array([0, 2 * n * nb, 4 * n * nb, 4 * n * nb + nb])
    out = np.empty((2, 4 * n * nb + 3 * nb, n))
    rows = np.empty(4 * n * nb + 3 * nb, np.int64)
    cnt = off.copy()
    left = np.full(nb, -1, np.int64)
    a, b = np.empty((2, n)), np.empty((2, n))
    for r in range(nb):
        _meet_row(lo, hi, r, sep, 0, a)
        _meet_row(lo, hi, r, sep, 2, b)
        cnt[0] = _diff(lo, hi, r, a, out, rows, cnt[0])
        cnt[1] = _diff(lo, hi, r, b, out, rows, cnt[1])
        wmax, kmax, live, vol = -1.0, 0, True, 1.0
        for k in range(n):
            b[0, k], b[1, k] = max(a[0, k], b[0, k]), min(a[1, k], b[1, k])
            live &= b[0, k] <= b[1, k]
            d = b[1, k] - b[0, k]
            t = d - b[1, k]
            e = (b[1, k] - (d - t)) + (-b[0, k] - t)  # TwoSum: the width rounded up
            w = np.nextafter(d, np.inf) if e > 0 else d
            vol *= d
            if w > wmax:
                wmax, kmax = w, k
        if not live:
            continue
        split = wmax >= eps or vol >= max_vol
        cut = _cut(b[0, kmax], b[1, kmax], wmax, eps, ratio, grid) if split else np.nan
        g = 3 if b[0, kmax] < cut < b[1, kmax] else 2  # a side too narrow to cut stays a boundary box
        c = cnt[g]
        for side in range(g - 1):
            for i in range(n):
                out[0, c + side, i], out[1, c + side, i] = b[0, i], b[1, i]
            rows[c + side] = r
        if g == 3:
            out[1, c, kmax], out[0, c + 1, kmax] = cut, cut
            left[r] = n_nodes + c - off[3]
        cnt[g] = c + g - 1
    return out, rows + base, left, cnt - off


@njit(inline="always")
def _cut(lo_k: float, hi_k: float, w: float, eps: float, ratio: float, grid: bool) -> float:
    """Where to cut the side ``[lo_k, hi_k]`` (rounded-up width ``w``): at ``ratio``, or (``grid`` and
    ``w >= eps``) at the boundary nearest the middle of ``⌊w / eps⌋ + 1`` equal cells."""
    if grid and w >= eps:
        m = np.floor(w / eps) + 1.0
        f = np.floor(0.5 * m) / m
    else:
        f = ratio
    c = 0.5 * lo_k + 0.5 * hi_k if f == 0.5 else lo_k + f * (hi_k - lo_k)
    return min(max(c, lo_k), hi_k)


def _parents(left: np.ndarray, n_nodes: int) -> np.ndarray:
    parent = np.full(n_nodes, -1, dtype=np.int64)
    internal = np.flatnonzero(left >= 0)
    parent[left[internal]] = internal
    parent[left[internal] + 1] = internal
    return parent


__all__ = [
    "Paving",
    "PavingTree",
    "pave",
]
