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

from .boxes import bisect, box_difference, empty_rows, normalize_empty, validate_batch, volume, width_inf
from .interval import IntervalArray
from .separators import Sep, inter_batch

Batch = tuple[np.ndarray, np.ndarray]


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
    x0: IntervalArray | Any, sep: Sep, eps: float, ratio: float = 0.5, max_boxes: int = 50_000_000
) -> Paving:
    """Pave ``x0`` with the separator ``sep`` down to boxes of width ``eps`` (Algorithm 2.1).

    Args:
        x0: the initial box, an :class:`IntervalArray` of shape ``(n,)`` or ``(lo, hi)``.
        sep: the separator of the set to characterise.
        eps: the width ``w∞`` under which an undetermined box is no longer bisected (``> 0``).
        ratio: where the widest side is cut, in ``(0, 1)`` (codac cuts at 0.49).
        max_boxes: guard on the number of boxes held in one generation.

    Raises:
        ValueError: on an empty or unbounded initial box, ``eps <= 0``, or a dimension mismatch.
    """
    lo0, hi0 = x0.pair if isinstance(x0, IntervalArray) else x0
    if not (isinstance(eps, (int, float, np.floating)) and eps > 0 and np.isfinite(eps)):
        raise ValueError(f"eps: must be a positive finite number, got {eps!r}")
    if not 0.0 < ratio < 1.0:
        raise ValueError(f"ratio: must lie in (0, 1), got {ratio!r}")
    lo, hi = validate_batch(lo0, hi0, "x0", sep.n)
    if lo.shape[0] != 1:
        raise ValueError(f"x0: expected one initial box, got {lo.shape[0]}")
    if empty_rows(lo, hi).any():
        raise ValueError("x0: the initial box is empty")
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise ValueError("x0: the initial box must be bounded")
    node = np.zeros(1, dtype=np.int64)
    t_lo, t_hi, t_left = [lo], [hi], []
    n_nodes = 1
    parts: dict[str, list[Any]] = {k: [] for k in ("in", "out", "bd", "in_n", "out_n", "bd_n")}
    bisections = 0
    while lo.shape[0]:
        if lo.shape[0] > max_boxes:
            raise ValueError(f"max_boxes: a generation holds {lo.shape[0]} boxes; raise eps or max_boxes")
        xin, xout = (normalize_empty(*b) for b in sep.separate(lo, hi))
        xin, xout = inter_batch(xin, (lo, hi)), inter_batch(xout, (lo, hi))
        for key, contracted in (("in", xin), ("out", xout)):
            pieces, rows = box_difference(lo, hi, *contracted)
            parts[key].append(pieces)
            parts[key + "_n"].append(node[rows])
        b_lo, b_hi = inter_batch(xin, xout)
        live = ~empty_rows(b_lo, b_hi)
        small = live & (width_inf(b_lo, b_hi) < eps)
        parts["bd"].append((b_lo[small], b_hi[small]))
        parts["bd_n"].append(node[small])
        split = np.flatnonzero(live & ~small)
        left = np.full(lo.shape[0], -1, dtype=np.int64)
        left[split] = n_nodes + 2 * np.arange(split.size)
        t_left.append(left)
        (l_lo, l_hi), (r_lo, r_hi) = bisect(b_lo[split], b_hi[split], ratio)
        k = split.size
        lo = np.empty((2 * k, lo.shape[1]))
        hi = np.empty_like(lo)
        lo[0::2], hi[0::2], lo[1::2], hi[1::2] = l_lo, l_hi, r_lo, r_hi
        node = n_nodes + np.arange(2 * k)
        t_lo.append(lo)
        t_hi.append(hi)
        n_nodes += 2 * k
        bisections += k
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


def classify_grid(x0: IntervalArray | Any, sep: Sep, shape: tuple[int, int]) -> np.ndarray:
    """Regular paving of a 2-d box: classify each cell of an ``(ny, nx)`` grid with ``sep``.

    Cells are the boxes of a regular grid over ``x0`` (a batch, so the same separator as the paver
    runs once on all cells). Rows follow the image convention (Remark 2.7): row 0 is the top
    (largest ``y``).

    Returns:
        ``int8`` array ``(ny, nx)``: ``1`` proved inside, ``-1`` proved outside, ``0`` undetermined.
    """
    lo0, hi0 = x0.pair if isinstance(x0, IntervalArray) else x0
    lo0, hi0 = np.asarray(lo0, dtype=np.float64), np.asarray(hi0, dtype=np.float64)
    ny, nx = shape
    if lo0.shape != (2,) or nx < 1 or ny < 1:
        raise ValueError(f"classify_grid: need a 2-d box and a positive shape, got {lo0.shape} and {shape}")
    xs = np.linspace(lo0[0], hi0[0], nx + 1)
    ys = np.linspace(hi0[1], lo0[1], ny + 1)  # top to bottom
    gx, gy = np.meshgrid(np.arange(nx), np.arange(ny))
    lo = np.stack([xs[gx.ravel()], ys[gy.ravel() + 1]], axis=1)
    hi = np.stack([xs[gx.ravel() + 1], ys[gy.ravel()]], axis=1)
    xin, xout = sep.separate(lo, hi)
    status = np.zeros(nx * ny, dtype=np.int8)
    status[empty_rows(*xin)] = 1
    status[empty_rows(*xout)] = -1
    return status.reshape(ny, nx)
