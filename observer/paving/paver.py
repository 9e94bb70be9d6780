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
from digslam.observer.core.types import Batch
from digslam.observer.paving.paver_jit import pave_generation
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

    def connected_subsets(self) -> list[Batch]:
        """The connected components of ``X⁺ = inner ∪ boundary`` (:func:`connected_subsets`), each an
        ``(lo, hi)`` batch of its boxes, the largest first."""
        lo = np.concatenate([self.inner[0], self.boundary[0]])
        hi = np.concatenate([self.inner[1], self.boundary[1]])
        return [(lo[c], hi[c]) for c in connected_subsets(lo, hi)]

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
        out, rows, left, cnt = pave_generation(lo, hi, parts_sep, *policy, base, n_nodes)
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


def _parents(left: np.ndarray, n_nodes: int) -> np.ndarray:
    parent = np.full(n_nodes, -1, dtype=np.int64)
    internal = np.flatnonzero(left >= 0)
    parent[left[internal]] = internal
    parent[left[internal] + 1] = internal
    return parent


def connected_subsets(lo: np.ndarray, hi: np.ndarray) -> list[np.ndarray]:
    """Group closed boxes into the connected components of their union.

    Two boxes are joined when they intersect (``lo_a <= hi_b`` and ``lo_b <= hi_a`` on every
    coordinate, faces and corners included), and the union of a component is connected; boxes of
    different components are disjoint, so the components of the union are exactly these groups.

    Args:
        lo, hi: an ``(N, n)`` batch of non-empty boxes.

    Returns:
        One ascending index array per component, the largest component first (ties: the one holding
        the lowest index first).

    >>> lo = np.array([[0.0, 0.0], [1.0, 1.0], [3.0, 0.0]])
    >>> hi = np.array([[1.0, 1.0], [2.0, 2.0], [4.0, 1.0]])     # the first two touch at a corner
    >>> [c.tolist() for c in connected_subsets(lo, hi)]
    [[0, 1], [2]]
    """
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    if lo.ndim != 2 or lo.shape != hi.shape:
        raise ValueError(f"connected_subsets: expected two (N, n) arrays, got {lo.shape} and {hi.shape}")
    if lo.shape[0] and empty_rows(lo, hi).any():
        raise ValueError("connected_subsets: the boxes must be non-empty")
    n_box = lo.shape[0]
    parent = np.arange(n_box)

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = int(parent[i])
        return i

    order = np.argsort(lo[:, 0], kind="stable")  # sweep on the first coordinate
    slo, shi = lo[order], hi[order]
    for k in range(n_box):
        end = int(np.searchsorted(slo[:, 0], shi[k, 0], side="right"))  # later boxes starting before hi
        if end <= k + 1:
            continue
        touch = ((slo[k + 1 : end] <= shi[k]) & (slo[k] <= shi[k + 1 : end])).all(axis=1)
        for j in (k + 1 + np.flatnonzero(touch)).tolist():
            a, b = root(int(order[k])), root(int(order[j]))
            if a != b:
                parent[max(a, b)] = min(a, b)
    roots = np.array([root(i) for i in range(n_box)], dtype=np.int64)
    groups = [np.flatnonzero(roots == r) for r in np.unique(roots)]
    return sorted(groups, key=lambda g: (-g.size, int(g[0])))


__all__ = [
    "Paving",
    "PavingTree",
    "connected_subsets",
    "pave",
]
