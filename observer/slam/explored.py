"""Guaranteed explored zone of patch exploration with disks (thesis App. B, Eq. B.5–B.9, B.21–B.22).

A robot whose position at ``t_i`` lies in the box ``[x](t_i)`` sees the disk of radius ``r_i ∈ [r_lo_i,
r_hi_i]`` around it. The explored zone ``Z = ∪_i D(x(t_i), r_i)`` is the thick set ``[Z⁻, Z⁺]`` of
Eq. B.5 taken over the tube (Eq. B.9). At discrete times every selection of the boxes is a trajectory
of the tube, so rule (B.10, iii) makes the lower bound exact per time: ``Z⁻ = ∪_i C_i`` with
``C_i = ∩_{x∈[x](t_i)} D(x, r_lo_i)`` and ``Z⁺ = ∪_i ([x](t_i) ⊕ D(r_hi_i))``. A cell is

* clear (``⊂ Z⁻``, clarity test) when some ``i`` has ``max_{z,x} |z - x| < r_lo_i``;
* dark (``∩ Z⁺ = ∅``, dark test B.15) when every ``i`` has ``min_{z,x} |z - x| > r_hi_i``;
* penumbra (``⊂ Z⁺ \\ Z⁻``, the penumbra test B.19: a witness trajectory ``x^b`` sees each point and
  one ``x^a`` sees none) when some ``i`` has ``max_z min_x |z - x| < r_hi_i`` and every ``i`` has
  ``min_z max_x |z - x| > r_lo_i``.

Strict comparisons make every claim hold for open and closed disks alike. The cross intersections of
Eq. B.7 need a feasible set that is not a product of boxes: :func:`explored_hypotheses` joins the
classifications of several candidate tubes (Figure B.2), and continuity between samples is used by
the sweep tests of :mod:`.explored_sweep` (Theorem B.1).

>>> g = Grid((-3.0, -3.0), (3.0, 3.0), (6, 6))
>>> explored_disks_grid(g, np.array([[-0.1, -0.1]]), np.array([[0.1, 0.1]]), 1.6, 2.5)[:3].tolist()
[[-1, 0, 0, 0, 0, -1], [0, 0, 0, 0, 0, 0], [0, 0, 1, 1, 0, 0]]
>>> g = Grid((-2.0, -2.0), (2.0, 2.0), (4, 4))   # a wide box: no point is certainly seen
>>> explored_disks_grid(g, np.array([[-0.5, -0.5]]), np.array([[0.5, 0.5]]), 0.5, 2.0).tolist()
[[0, 2, 2, 0], [2, 2, 2, 2], [2, 2, 2, 2], [0, 2, 2, 0]]
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.types import Batch
from digslam.observer.record.grid import Grid
from digslam.observer.sets.separators import Sep
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA, UNKNOWN
from digslam.observer.thick.sep import ThickSep

__all__ = ["explored_disks_grid", "explored_hypotheses", "explored_union", "SepExploredDisks",
           "explored_disks_thick_sep", "explored_thick_sep", "check_tube", "check_interval", "BLOCK", "codes",
           "pair_test", "row_intervals"]  # fmt: skip

#: (time, pair) budget of one block of the vectorised kernels
BLOCK = 1 << 21


def check_tube(pos_lo: Any, pos_hi: Any, name: str = "pos") -> Batch:
    """Validate the tube ``[x](t_i)`` given as two ``(m, 2)`` arrays of finite bounds, ``lo <= hi``."""
    lo, hi = np.asarray(pos_lo, np.float64), np.asarray(pos_hi, np.float64)
    if lo.ndim != 2 or lo.shape[1] != 2 or lo.shape != hi.shape or lo.shape[0] < 1:
        got = f"{lo.shape}, {hi.shape}"
        raise ValueError(f"{name}_lo, {name}_hi: expected two arrays of shape (m, 2), got {got}")
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise ValueError(f"{name}_lo, {name}_hi: bounds must be finite")
    if (lo > hi).any():
        k = int(np.argwhere(lo > hi)[0, 0])
        raise ValueError(f"{name}_lo, {name}_hi: lower bound above upper bound at time index {k}")
    return lo, hi


def check_interval(lo: Any, hi: Any, m: int, name: str, nonneg: bool = False) -> Batch:
    """Broadcast a scalar or ``(m,)`` interval ``[lo, hi]`` to ``(m,)`` arrays and validate it."""
    try:
        a, b = (np.broadcast_to(np.asarray(v, np.float64), (m,)).copy() for v in (lo, hi))
    except ValueError:
        raise ValueError(f"{name}_lo, {name}_hi: expected scalars or arrays of shape ({m},)") from None
    if not (np.isfinite(a).all() and np.isfinite(b).all()) or (a > b).any():
        raise ValueError(f"{name}_lo, {name}_hi: expected finite bounds with {name}_lo <= {name}_hi")
    if nonneg and (a < 0).any():
        raise ValueError(f"{name}_lo: must be >= 0")
    return a, b


# ---- per-axis distance bounds between cell intervals [c] and box intervals [b] (outward rounded) ----
# One round-to-nearest operation is within half an ulp, so stepping its result one ulp outward
# (rounding.next_up / next_down) bounds the exact value: cheaper than the tight directed kernels on
# the (time, row) and (time, column) arrays of the grid path.
def _sub_up(a: Any, b: Any) -> np.ndarray:
    return rnd.next_up(np.subtract(a, b))


def _sub_dn(a: Any, b: Any) -> np.ndarray:
    return rnd.next_down(np.subtract(a, b))


def _sq_up(a: np.ndarray) -> np.ndarray:
    return rnd.next_up(a * a)


def _sq_dn(a: np.ndarray) -> np.ndarray:
    return np.maximum(rnd.next_down(a * a), 0.0)


def axis_bounds(clo: Any, chi: Any, blo: Any, bhi: Any) -> dict[str, np.ndarray]:
    """Per-axis bounds of the four disk tests between cell intervals ``[c]`` and box intervals ``[b]``:

    * ``clear``: upper bound of ``max_{z∈[c], x∈[b]} |z - x|``;
    * ``dark``: lower bound of ``min_{z∈[c], x∈[b]} |z - x|``;
    * ``upper``: upper bound of ``max_{z∈[c]} min_{x∈[b]} |z - x|``;
    * ``outside``: lower bound of ``min_{z∈[c]} max_{x∈[b]} |z - x|`` (``= dist([c], mid b) + rad b``).

    Four rounded differences serve all of them (``fl(a - b) = -fl(b - a)``).
    """
    p, q = _sub_up(chi, blo), _sub_up(bhi, clo)
    r1, r2 = _sub_up(blo, clo), _sub_up(chi, bhi)
    half = _sub_dn(bhi, blo) * 0.5
    return {"clear": np.maximum(p, q), "dark": np.maximum(0.0, -np.minimum(p, q)),
            "upper": np.maximum(0.0, np.maximum(r1, r2)),
            "outside": np.maximum(0.0, np.maximum(half, -np.minimum(r1, r2)))}  # fmt: skip


#: test name -> (rounding of the squared bound, radius used); "up" tests prove a cell inside (``< r²``),
#: "down" tests prove it outside (``> r²``)
TESTS = {"clear": ("up", "lo"), "dark": ("down", "hi"), "upper": ("up", "hi"), "outside": ("down", "lo")}


def pair_test(test: str, clo: np.ndarray, chi: np.ndarray, blo: np.ndarray, bhi: np.ndarray,
              r: np.ndarray) -> np.ndarray:  # fmt: skip
    """Rigorous per-pair disk test on ``(P, 2)`` cell and box bounds and ``(P,)`` radii (:data:`TESTS`)."""
    d = axis_bounds(clo, chi, blo, bhi)[test]
    if TESTS[test][0] == "up":
        return rnd.next_up(_sq_up(d[:, 0]) + _sq_up(d[:, 1])) < _sq_dn(r)
    return rnd.next_down(_sq_dn(d[:, 0]) + _sq_dn(d[:, 1])) > _sq_up(r)


def _first_true(f: np.ndarray, t: np.ndarray, pred: Any, sentinel: float) -> np.ndarray:
    """Per ``(i, c)``: first ``k`` with ``pred(f[i, k], t[i, c])``, the predicate being monotone in ``k``
    (False then True); ``f.shape[1]`` when never true. Branch-free binary search on flat indices over
    ``f`` padded to a power of two with ``sentinel`` (a value where ``pred`` holds)."""
    m, w = f.shape
    size = 1 << int(np.ceil(np.log2(w + 1)))
    pad = np.full((m, size), sentinel)
    pad[:, :w] = f
    flat = pad.ravel()
    pos = np.broadcast_to((np.arange(m, dtype=np.int64) * size - 1)[:, None], t.shape).copy()
    step = size >> 1
    while step:  # invariant: pred is False at every index below pos - base
        pos += step * ~pred(np.take(flat, pos + step), t)
        step >>= 1
    return pos - (np.arange(m, dtype=np.int64) * size - 1)[:, None]


def row_intervals(grid: Grid, blo: np.ndarray, bhi: np.ndarray, r_lo: np.ndarray, r_hi: np.ndarray
                  ) -> dict[str, tuple[np.ndarray, ...]]:  # fmt: skip
    """For each test of :data:`TESTS` and each (time, window column), the hull ``[a, b]`` of the rows
    of the *un-proved-claim* side: ``clear``/``upper`` keep the proved rows, ``dark``/``outside`` the
    rows NOT proved. Cells off the window of ``[x](t_i) ⊕ [-r_hi, r_hi]²`` are decided (dark, outside).

    The 2-d test is separable: ``f_y(row)² < R² - f_x(col)²`` with the column term rounded against the
    claim, so no pair arithmetic is rounded. ``f_y`` is quasi-convex in the row (max of a
    non-increasing and a non-decreasing term, monotone roundings), so the hull is the exact row set.
    Returns ``{test: (time, col, row_a, row_b)}`` of the non-empty intervals.
    """
    r0, r1, c0, c1 = disk_windows(grid, blo, bhi, r_hi)
    wr, wc = max(int((r1 - r0).max()), 1), max(int((c1 - c0).max()), 1)
    ny, nx = grid.shape
    rows = np.minimum(r0[:, None] + np.arange(wr), ny - 1)
    cols = np.minimum(c0[:, None] + np.arange(wc), nx - 1)
    fys = axis_bounds(grid.ys[rows + 1], grid.ys[rows], blo[:, 1:2], bhi[:, 1:2])
    fxs = axis_bounds(grid.xs[cols], grid.xs[cols + 1], blo[:, 0:1], bhi[:, 0:1])
    valid_r, valid_c = np.arange(wr) < (r1 - r0)[:, None], np.arange(wc) < (c1 - c0)[:, None]
    out: dict[str, tuple[np.ndarray, ...]] = {}
    keep: np.ufunc
    drop: np.ufunc
    for test, (rd, which) in TESTS.items():
        r = r_lo if which == "lo" else r_hi
        if rd == "up":  # proved iff fy2_up < t with t = R²_down - fx2_up rounded down
            fy2, t = _sq_up(fys[test]), _sub_dn(_sq_dn(r)[:, None], _sq_up(fxs[test]))
            keep, drop = np.less, np.greater_equal
        else:  # proved iff fy2_down > t with t = R²_up - fx2_down rounded up; keep rows NOT proved
            fy2, t = _sq_dn(fys[test]), _sub_up(_sq_up(r)[:, None], _sq_dn(fxs[test]))
            keep, drop = np.less_equal, np.greater
        fy2 = np.where(valid_r, fy2, np.inf)
        lmin = np.minimum.accumulate(fy2, axis=1)
        rmin = np.minimum.accumulate(fy2[:, ::-1], axis=1)[:, ::-1]
        a = _first_true(lmin, t, keep, -np.inf)
        b = _first_true(rmin, t, drop, np.inf) - 1
        ti, ci = np.nonzero((a <= b) & valid_c)
        out[test] = (ti, cols[ti, ci], r0[ti] + a[ti, ci], r0[ti] + b[ti, ci])
    return out


def mark(grid: Grid, ivals: tuple[np.ndarray, ...]) -> np.ndarray:
    """``bool (ny, nx)``: cells covered by some row interval (difference array along the rows)."""
    ny, nx = grid.shape
    _, col, ra, rb = ivals
    n = (ny + 1) * nx
    d = np.bincount(ra * nx + col, minlength=n) - np.bincount((rb + 1) * nx + col, minlength=n)
    return np.cumsum(d.reshape(ny + 1, nx), axis=0)[:ny] > 0


def disk_windows(grid: Grid, blo: np.ndarray, bhi: np.ndarray, r: np.ndarray) -> tuple:
    """Grid windows of ``[x](t_i) ⊕ [-r_i, r_i]²`` (outward): outside, every disk test is decided."""
    return grid.window(rnd.sub_down(blo, r[:, None]), rnd.add_up(bhi, r[:, None]))


def disk_masks(grid: Grid, pos_lo: np.ndarray, pos_hi: np.ndarray, r_lo: np.ndarray, r_hi: np.ndarray
               ) -> dict[str, np.ndarray]:  # fmt: skip
    """The four ``(ny, nx)`` reductions over time: ``clear`` (some ``i`` proves ``⊂ C_i``), ``dark``
    (no ``i`` fails the dark test), ``upper`` (some ``i`` proves ``⊂ [x]⊕D``), ``outside`` (no ``i``
    fails ``∩ C_i = ∅``)."""
    out = {k: np.zeros(grid.shape, bool) for k in TESTS}
    m = pos_lo.shape[0]
    step = max(1, BLOCK // max(1, int(np.ceil(2 * float(r_hi.max() + np.ptp(pos_hi - pos_lo) + 1)
                                             / min(grid.cell_size)))))  # fmt: skip
    for s in range(0, m, step):  # blocks of many (time, cell) pairs
        sl = slice(s, min(m, s + step))
        blo, bhi = pos_lo[sl], pos_hi[sl]
        for test, iv in row_intervals(grid, blo, bhi, r_lo[sl], r_hi[sl]).items():
            out[test] |= mark(grid, iv)
    out["dark"], out["outside"] = ~out["dark"], ~out["outside"]
    return out


def codes(clear: np.ndarray, dark: np.ndarray, upper: np.ndarray, outside: np.ndarray) -> np.ndarray:
    """Thick codes of :mod:`.thick.sep` from the four proofs (penumbra = ``⊂ Z⁺`` and ``∩ Z⁻ = ∅``)."""
    st = np.full(clear.shape, UNKNOWN, np.int8)
    st[upper & outside] = PENUMBRA
    st[clear] = CLEAR
    st[dark] = DARK
    return st


def explored_disks_grid(grid: Grid, pos_lo: Any, pos_hi: Any, r_lo: Any, r_hi: Any) -> np.ndarray:
    """Classify the cells of ``grid`` for disk patches (Eq. B.21–B.22), vectorised over (time, cell).

    Args:
        grid: the :class:`~.grid.Grid` to classify.
        pos_lo, pos_hi: ``(m, 2)`` tube of positions ``[x](t_i)``.
        r_lo, r_hi: scalars or ``(m,)``: the radius interval ``[r_lo_i, r_hi_i]``, ``0 <= r_lo <= r_hi``.

    Returns:
        ``int8 (ny, nx)``: ``CLEAR=1``, ``PENUMBRA=2``, ``DARK=-1``, ``UNKNOWN=0``.
    """
    lo, hi = check_tube(pos_lo, pos_hi)
    rl, rh = check_interval(r_lo, r_hi, lo.shape[0], "r", nonneg=True)
    mk = disk_masks(grid, lo, hi, rl, rh)
    return codes(mk["clear"], mk["dark"], mk["upper"], mk["outside"])


def explored_hypotheses(statuses: Sequence[np.ndarray]) -> np.ndarray:
    """Join the classifications of several candidate tubes (Eq. B.7, Figure B.2).

    With the feasible set the union of the hypotheses, ``Z⁻ = ∩_h Z⁻_h`` and ``Z⁺ = ∪_h Z⁺_h``: a cell
    clear under every hypothesis is clear (each may be proved at a different time: the cross
    intersections), dark under all is dark; inside some ``Z⁺_h`` and outside some ``Z⁻_h'`` is penumbra.
    """
    try:
        st = np.stack([np.asarray(s) for s in statuses])
    except ValueError:
        st = np.zeros((0,))
    if st.ndim != 3 or st.shape[0] < 1:
        raise ValueError(f"statuses: expected a non-empty list of 2-d code arrays, got shape {st.shape}")
    up = ((st == CLEAR) | (st == PENUMBRA)).any(0)
    out = ((st == DARK) | (st == PENUMBRA)).any(0)
    return codes((st == CLEAR).all(0), (st == DARK).all(0), up, out)


def explored_union(statuses: Sequence[np.ndarray]) -> np.ndarray:
    """Union of explored zones of several sensors (Eq. 5.9): ``[∪ Z⁻_s, ∪ Z⁺_s]``.

    Clear in some, dark in all; penumbra when inside some ``Z⁺_s`` and proved outside every ``Z⁻_s``.

    >>> explored_union([np.array([[1, 2, -1, 2]]), np.array([[-1, -1, -1, 0]])]).tolist()
    [[1, 2, -1, 0]]
    """
    st = np.stack([np.asarray(v) for v in statuses])
    if st.ndim != 3:
        raise ValueError(f"statuses: expected a non-empty list of 2-d code arrays, got shape {st.shape}")
    up = ((st == CLEAR) | (st == PENUMBRA)).any(0)
    out = ((st == DARK) | (st == PENUMBRA)).all(0)
    return codes((st == CLEAR).any(0), (st == DARK).all(0), up, out)


class SepExploredDisks(Sep):
    """Separator of ``Z⁻`` (``bound="lower"``) or ``Z⁺`` (``bound="upper"``) for disk patches.

    Closed form of the union of translated disks (Eq. B.21): a box is proved inside by one time and
    outside when every time proves it. Candidate (box, time) pairs come from a bounding-box filter in
    blocks, so the cost is ``O(N m)`` comparisons plus the rigorous tests of the near pairs.
    """

    n = 2

    def __init__(self, pos_lo: Any, pos_hi: Any, r_lo: Any, r_hi: Any, bound: str = "lower") -> None:
        if bound not in ("lower", "upper"):
            raise ValueError(f"bound: expected 'lower' or 'upper', got {bound!r}")
        self.lo, self.hi = check_tube(pos_lo, pos_hi)
        self.r_lo, self.r_hi = check_interval(r_lo, r_hi, self.lo.shape[0], "r", nonneg=True)
        self.bound = bound
        self.t_in, self.t_out = ("clear", "outside") if bound == "lower" else ("upper", "dark")
        self.r = self.r_lo if bound == "lower" else self.r_hi

    def prove(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        """``(inside, outside)`` masks of an ``(N, 2)`` batch."""
        n, m = lo.shape[0], self.lo.shape[0]
        inside = np.zeros(n, bool)
        notout = np.zeros(n, bool)
        wlo, whi = rnd.sub_down(self.lo, self.r[:, None]), rnd.add_up(self.hi, self.r[:, None])
        step = max(1, BLOCK // max(n, 1))
        for s in range(0, m, step):  # blocks of N x step pairs
            sl = slice(s, min(m, s + step))
            hit = ((lo[:, None, :] <= whi[None, sl]) & (hi[:, None, :] >= wlo[None, sl])).all(-1)
            bi, ti = np.nonzero(hit)
            ti = ti + s
            a = (lo[bi], hi[bi], self.lo[ti], self.hi[ti], self.r[ti])
            inside[bi[pair_test(self.t_in, *a)]] = True
            notout[bi[~pair_test(self.t_out, *a)]] = True
        return inside, ~notout

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        inside, outside = self.prove(lo, hi)
        empty = np.full_like(lo, np.inf), np.full_like(hi, -np.inf)
        xin = tuple(np.where(inside[:, None], e, b) for e, b in zip(empty, (lo, hi)))
        xout = tuple(np.where(outside[:, None], e, b) for e, b in zip(empty, (lo, hi)))
        return (xin[0], xin[1]), (xout[0], xout[1])


def explored_disks_thick_sep(pos_lo: Any, pos_hi: Any, r_lo: Any, r_hi: Any) -> ThickSep:
    """``ThickSep`` of the explored zone ``[Z⁻, Z⁺]`` of disk patches (for ``thick_pave``)."""
    return ThickSep(SepExploredDisks(pos_lo, pos_hi, r_lo, r_hi, "lower"),
                    SepExploredDisks(pos_lo, pos_hi, r_lo, r_hi, "upper"))  # fmt: skip


def explored_thick_sep(visible: ThickSep, pos_lo: Any, pos_hi: Any, eps: float, **proj_kw: Any) -> ThickSep:
    """``[Z⁻, Z⁺]`` for a thick visible set ``[V⁻, V⁺]`` given in the robot frame (position only).

    ``Z⁻ = ∪_i (V⁻ ⊖ -[x](t_i))`` (every position sees the point, Prop. 4.1) and
    ``Z⁺ = ∪_i ([x](t_i) ⊕ V⁺)`` (Prop. 4.2), through the Minkowski separators of
    :mod:`.minkowski` (projection at width ``eps``). Meant for a few tens of times.
    """
    from digslam.observer.core.interval import IntervalArray
    from digslam.observer.sets.minkowski import SepMinkowskiDiff, SepMinkowskiSum
    from digslam.observer.sets.separators import SepBox, SepUnion

    lo, hi = check_tube(pos_lo, pos_hi)
    if not isinstance(visible, ThickSep):
        raise ValueError(f"visible: expected a ThickSep, got {type(visible).__name__}")
    lower, upper = [], []
    for a, b in zip(lo, hi):  # one separator per time: a small tree, built once
        neg, box = IntervalArray(-b, -a), IntervalArray(a, b)
        lower.append(SepMinkowskiDiff(visible.lower, SepBox(neg), neg, eps, **proj_kw))
        upper.append(SepMinkowskiSum(SepBox(box), visible.upper, box, eps, **proj_kw))
    return ThickSep(SepUnion(*lower), SepUnion(*upper))
