"""Separators on batches and their algebra (thesis §2.4.2, Eq. 2.46–2.54).

A separator for a set ``X`` maps a batch ``[x]`` to two batches ``([x_in], [x_out])`` with
``[x_in] ∪ [x_out] = [x]``: ``[x] \\ [x_in]`` is proved inside ``X`` and ``[x] \\ [x_out]`` proved
outside (``x_in`` keeps the complement, ``x_out`` keeps the set). ``~S`` swaps them (Eq. 2.53),
``S₁ & S₂`` and ``S₁ | S₂`` follow Eq. 2.54, ``S₁ - S₂ = S₁ & ~S₂``, and :class:`SepQInter` is the
q-relaxed intersection.

>>> import numpy as np
>>> s = SepBox(Box([(0, 1), (0, 1)])) & ~SepBox(Box([(0.5, 2), (0.5, 2)]))   # an L shape
>>> xin, xout = s(Box([(0.6, 0.9), (0.6, 0.9)]))
>>> bool(xout.is_empty().any()), bool(xin.is_empty().any())                 # proved outside
(True, False)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core.boxes import empty_rows, normalize_empty, validate_batch
from digslam.observer.core.interval import IntervalArray, as_pair
from digslam.observer.core.types import Batch
from digslam.observer.sets.contractors import Ctc
from digslam.observer.sets.separators_jit import fold_separated


class Sep:
    """Base class: subclasses implement :meth:`separate` on raw ``(N, n)`` batches."""

    #: input dimension, or None when any dimension goes
    n: int | None = None

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        """Return ``((in_lo, in_hi), (out_lo, out_hi))``; inputs are not modified."""
        raise NotImplementedError(f"{type(self).__name__}.separate")

    def separate_stacked(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """:meth:`separate` as one ``(4, N, n)`` array ``in_lo, in_hi, out_lo, out_hi`` (what the paver
        and the algebra pass around; compiled separators produce it directly)."""
        (ilo, ihi), (olo, ohi) = self.separate(lo, hi)
        shape = (4, *np.shape(lo))
        res = np.empty(shape)
        res[0], res[1], res[2], res[3] = ilo, ihi, olo, ohi
        return res

    def __call__(self, boxes: IntervalArray | tuple[Any, Any]) -> tuple[Any, Any]:
        """Separate an :class:`IntervalArray` box ``(n,)`` / batch ``(N, n)``, or a ``(lo, hi)`` pair."""
        is_ia = isinstance(boxes, IntervalArray)
        lo, hi = boxes.pair if isinstance(boxes, IntervalArray) else boxes
        single = np.ndim(lo) == 1
        lo, hi = validate_batch(lo, hi, "boxes", self.n)
        res = []
        for b in self.separate(lo, hi):
            blo, bhi = normalize_empty(*b)
            if single:
                blo, bhi = blo[0], bhi[0]
            res.append(IntervalArray._raw(blo, bhi) if is_ia else (blo, bhi))
        return res[0], res[1]

    def __invert__(self) -> Sep:
        return SepNot(self)

    def __and__(self, other: Sep) -> Sep:
        return SepInter(self, other)

    def __or__(self, other: Sep) -> Sep:
        return SepUnion(self, other)

    def __sub__(self, other: Sep) -> Sep:
        return SepInter(self, SepNot(other))


def _dim(seps: tuple[Sep, ...]) -> int | None:
    dims = {s.n for s in seps if s.n is not None}
    if len(dims) > 1:
        raise ValueError(f"separators: mismatched dimensions {sorted(dims)}")
    return dims.pop() if dims else None


def inter_batch(a: Batch, b: Batch) -> Batch:
    """Row-wise intersection of two batches (empty rows normalised)."""
    return normalize_empty(np.maximum(a[0], b[0]), np.minimum(a[1], b[1]))


def hull_batch(a: Batch, b: Batch) -> Batch:
    """Row-wise hull of two batches whose empty rows are ``[+inf, -inf]``."""
    return np.minimum(a[0], b[0]), np.maximum(a[1], b[1])


_NONE = np.empty((0, 0, 0))


class _Stacked(Sep):
    """A separator computed on stacked ``(4, N, n)`` arrays; :meth:`separate` unpacks them."""

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        res = self.separate_stacked(lo, hi)
        return (res[0], res[1]), (res[2], res[3])


class SepNot(_Stacked):
    """Complement ``{S_out, S_in}`` (Eq. 2.53)."""

    def __init__(self, sep: Sep) -> None:
        self.sep, self.n = sep, sep.n

    def separate_stacked(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return self.sep.separate_stacked(lo, hi)[[2, 3, 0, 1]]

    def __invert__(self) -> Sep:
        return self.sep


class SepInter(_Stacked):
    """``S₁ ∩ … ∩ S_k = {⊔ S_iⁱⁿ, ∩ S_iᵒᵘᵗ}`` (Eq. 2.54)."""

    union = False

    def __init__(self, *seps: Sep) -> None:
        self.seps, self.n = seps, _dim(seps)

    def separate_stacked(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        lo, hi = np.ascontiguousarray(lo, dtype=np.float64), np.ascontiguousarray(hi, dtype=np.float64)
        acc = _NONE
        for s in self.seps:
            acc = fold_separated(acc, np.ascontiguousarray(s.separate_stacked(lo, hi)), lo, hi, self.union)
        return acc


class SepUnion(SepInter):
    """``S₁ ∪ … ∪ S_k = {∩ S_iⁱⁿ, ⊔ S_iᵒᵘᵗ}`` (Eq. 2.54)."""

    union = True


def relaxed_intersection(los: np.ndarray, his: np.ndarray, q: int) -> Batch:
    """Hull of the points lying in at least ``m - q`` of ``m`` boxes, per coordinate.

    Args:
        los, his: ``(m, N, n)`` stacks of batches (empty rows ``[+inf, -inf]`` count for nothing).
        q: number of boxes allowed to miss a point, ``0 <= q < m``.

    Returns:
        An ``(N, n)`` batch containing the q-relaxed intersection (coordinate-wise, so an outer
        enclosure of the box relaxed intersection).
    """
    m = los.shape[0]
    need = m - q
    # a candidate lower bound c = los[j] is valid when #{i : los[i] <= c <= his[i]} >= need
    inside_lo = (los[None] <= los[:, None]) & (los[:, None] <= his[None])  # (j, i, N, n)
    cnt_lo = inside_lo.sum(axis=1)
    lo = np.where(cnt_lo >= need, los, np.inf).min(axis=0)
    inside_hi = (los[None] <= his[:, None]) & (his[:, None] <= his[None])
    cnt_hi = inside_hi.sum(axis=1)
    hi = np.where(cnt_hi >= need, his, -np.inf).max(axis=0)
    return normalize_empty(lo, hi)


#: cells of the candidate grid (rows × corners × boxes) held at once by :func:`box_qinter`
_QINTER_CELLS = 1 << 22


def box_qinter(los: np.ndarray, his: np.ndarray, q: int) -> Batch:
    """Box q-intersection: the hull of the points lying in at least ``m - q`` of ``m`` boxes, exactly.

    The points in ``need = m - q`` boxes form the union, over the subsets ``S`` of ``need`` boxes, of
    the boxes ``∩S`` (Eq. 2.5). The lower corner of a non-empty ``∩S`` has every coordinate ``d`` equal
    to ``max_{i∈S} lo_{i,d}``, a lower bound of one of the boxes, and lies in every box of ``S``; its
    upper corner likewise. So the hull of the union is the hull of the points of the grid
    ``∏_d {lo_{j,d}}`` (lower bounds) and of the grid ``∏_d {hi_{j,d}}`` (upper bounds) that lie in
    ``need`` boxes or more: each such point belongs to the set and every corner of the union is one of
    them. Only comparisons and selections of the given bounds are made (no rounding), so the result is
    the exact hull, where :func:`relaxed_intersection` (coordinate by coordinate) is only an outer
    enclosure of it. The counts are batched products of the ``(m, m)`` containment tables of the
    coordinates: ``m^(n+1)`` multiply-adds a row against ``n m²`` comparisons for the coordinate-wise
    form (56 boxes of the plane: about 2.4× its time), so for many separators ``exact=False`` of
    :class:`SepQInter` is the cheaper choice.

    Args:
        los, his: ``(m, N, n)`` stacks of batches (empty rows ``[+inf, -inf]`` count for nothing).
        q: number of boxes allowed to miss a point, ``0 <= q < m``.

    Returns:
        The ``(N, n)`` batch of the hulls (an empty row where no point lies in ``m - q`` boxes).

    >>> los = np.array([[[1, 1]], [[3, 2]], [[1.5, 4.5]], [[2.5, 0]], [[1.5, 1.5]]])
    >>> his = np.array([[[5, 6]], [[7, 5.5]], [[2.5, 8]], [[5, 4]], [[8, 3]]])
    >>> box_qinter(los, his, 2)   # in 3 of the 5 boxes: [2.5, 5] × [1.5, 4]
    (array([[2.5, 1.5]]), array([[5., 4.]]))
    >>> relaxed_intersection(los, his, 2)   # coordinate by coordinate: [1.5, 5] × [1.5, 5.5]
    (array([[1.5, 1.5]]), array([[5. , 5.5]]))
    """
    m, n_rows, n = los.shape
    if not 0 <= q < m:
        raise ValueError(f"q: must lie in [0, {m}) for {m} boxes, got {q}")
    need = m - q
    box_lo, box_hi = np.moveaxis(los, 0, 1), np.moveaxis(his, 0, 1)  # (N, m, n)
    res_lo, res_hi = np.full((n_rows, n), np.inf), np.full((n_rows, n), -np.inf)
    letters = "abcdefghijklmnopqrstuvw"
    if n > len(letters):
        raise ValueError(f"box_qinter: at most {len(letters)} coordinates, got {n}")
    grid = ",".join(f"z{letters[d]}y" for d in range(n)) + "->z" + letters[:n]
    chunk = max(1, _QINTER_CELLS // max(1, m ** (n + 1)))
    exact = np.float32 if m < 1 << 24 else np.float64  # counts up to m are exact in the sums
    for a in range(0, n_rows, chunk):
        rows = slice(a, a + chunk)
        blo, bhi = box_lo[rows], box_hi[rows]
        for cand, res, pick in ((blo, res_lo, np.min), (bhi, res_hi, np.max)):
            # inside[d][r, j, i]: box i holds the candidate bound of box j on coordinate d
            inside = [
                ((blo[:, None, :, d] <= cand[:, :, None, d]) & (cand[:, :, None, d] <= bhi[:, None, :, d]))
                for d in range(n)
            ]
            if n == 1:
                count = inside[0].sum(axis=2)
            elif n == 2:  # one batched product of the two tables
                count = np.matmul(inside[0].astype(exact), inside[1].astype(exact).transpose(0, 2, 1))
            else:
                count = np.einsum(grid, *(t.astype(exact) for t in inside))
            ok = count >= need  # (r, j_0, ..., j_{n-1}): the grid point lies in `need` boxes
            for d in range(n):
                other = tuple(k + 1 for k in range(n) if k != d)
                hit = ok.any(axis=other) if other else ok  # (r, j): some grid point with this bound
                fill = np.inf if pick is np.min else -np.inf
                res[rows, d] = pick(np.where(hit, cand[:, :, d], fill), axis=1)
    return normalize_empty(res_lo, res_hi)


class SepQInter(Sep):
    """q-relaxed intersection of separators (Eq. 2.54): ``{S_iⁱⁿ (m-q-1)-relaxed, S_iᵒᵘᵗ q-relaxed}``.

    The set is the points belonging to at least ``m - q`` of the ``m`` sets (Eq. 2.5): robust to ``q``
    outliers. A point of ``[x]`` in the set lies in ``m - q`` of the outer boxes ``S_iᵒᵘᵗ([x])``, a
    point outside it in ``q + 1`` of the inner boxes ``S_iⁱⁿ([x])``; each part is the box
    q-intersection of those boxes.

    Args:
        seps: the ``m`` separators.
        q: the number of sets a point may miss, ``0 <= q < m``.
        exact: the exact box q-intersection (:func:`box_qinter`, ibex's ``qinter``) when True, the
            coordinate-wise enclosure of it (:func:`relaxed_intersection`, ibex's ``qinter_projf``)
            when False. Both are sound and the exact one is never wider: it is tighter where a
            point is in ``m - q`` boxes coordinate by coordinate but in fewer as a whole. Paving the
            points in 5 of 8 rings takes 1.5× the time with it (``benchmarks/bench_paver.py``,
            ``qinter_exact_over_relaxed``); its cost grows as ``m^(n+1)`` a box (:func:`box_qinter`).
    """

    def __init__(self, seps: list[Sep], q: int, exact: bool = True) -> None:
        if not seps:
            raise ValueError("seps: need at least one separator")
        if not 0 <= q < len(seps):
            raise ValueError(f"q: must lie in [0, {len(seps)}) for {len(seps)} separators, got {q}")
        if not isinstance(exact, (bool, np.bool_)):
            raise ValueError(f"exact: must be True or False, got {exact!r}")
        self.seps, self.q, self.n = list(seps), int(q), _dim(tuple(seps))
        self.exact = bool(exact)

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        parts = [s.separate(lo, hi) for s in self.seps]
        m = len(parts)
        ilo = np.stack([normalize_empty(*p[0])[0] for p in parts])
        ihi = np.stack([normalize_empty(*p[0])[1] for p in parts])
        olo = np.stack([normalize_empty(*p[1])[0] for p in parts])
        ohi = np.stack([normalize_empty(*p[1])[1] for p in parts])
        qinter = box_qinter if self.exact else relaxed_intersection
        xout = qinter(olo, ohi, self.q)
        xin = qinter(ilo, ihi, m - self.q - 1)
        return inter_batch(xin, (lo, hi)), inter_batch(xout, (lo, hi))


class SepCtcPair(Sep):
    """The separator ``{C_in, C_out}`` of two contractors (§2.4.2.1, Eq. 2.48–2.49): ``C_in`` is
    consistent with the complement of ``X`` (it removes points proved inside), ``C_out`` with ``X``.
    Every point of ``[x]`` is in ``X`` or not, so it stays in one of the two parts (Eq. 2.48).

    With ``ctc_in=None`` nothing is proved inside (``x_in = [x]``): the paver then keeps every box that
    ``C_out`` does not remove, as codac's ``pave`` does with a contractor.

    Args:
        ctc_in: a contractor for ``¬X``, or None.
        ctc_out: a contractor for ``X``, or None (nothing proved outside).

    Raises:
        ValueError: when both are None or their dimensions differ.
    """

    def __init__(self, ctc_in: Ctc | None, ctc_out: Ctc | None) -> None:
        if ctc_in is None and ctc_out is None:
            raise ValueError("ctc_in, ctc_out: give at least one contractor")
        dims: set[int] = {
            n for c in (ctc_in, ctc_out) if c is not None and (n := getattr(c, "n", None)) is not None
        }
        if len(dims) > 1:
            raise ValueError(f"ctc_in, ctc_out: mismatched dimensions {sorted(dims)}")
        self.ctc_in, self.ctc_out = ctc_in, ctc_out
        self.n = dims.pop() if dims else None

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        parts = []
        for c in (self.ctc_in, self.ctc_out):
            res = (lo.copy(), hi.copy()) if c is None else c.contract(lo.copy(), hi.copy())
            parts.append(inter_batch(normalize_empty(*res), (lo, hi)))
        return parts[0], parts[1]


class SepBox(Sep):
    """Separator of a box ``[y]``: ``x_out = [x] ∩ [y]``, ``x_in`` the hull of ``[x]`` minus ``[y]``."""

    def __init__(self, box: Any) -> None:
        ylo, yhi = as_pair(box, "box")
        if np.ndim(ylo) == 0:
            ylo, yhi = ylo[None], yhi[None]
        if np.ndim(ylo) != 1 or np.any(ylo > yhi):
            raise ValueError(f"box: expected one non-empty box (n,), got shape {np.shape(ylo)}")
        self.box, self.n = (ylo, yhi), ylo.shape[0]

    def pieces(self, lo: np.ndarray, hi: np.ndarray) -> list[Batch]:
        """Boxes enclosing ``[x] ∩ {y_k < a_k}`` and ``[x] ∩ {y_k > b_k}`` for every coordinate ``k``.

        The complement of ``[y] = [a, b]`` is open: each piece is the closed ``[x] ∩ {y_k <= a_k}``
        (``>= b_k``), except that it is empty when ``x_k⁻ >= a_k`` (``x_k⁺ <= b_k``), for then no point
        of ``[x]`` lies strictly beyond the bound (a box touching ``[y]`` from inside is not outside).
        """
        out = []
        for k in range(self.box[0].size):
            for side in (0, 1):
                plo, phi = lo.copy(), hi.copy()
                if side == 0:
                    phi[:, k] = np.minimum(hi[:, k], self.box[0][k])
                    none = lo[:, k] >= self.box[0][k]
                else:
                    plo[:, k] = np.maximum(lo[:, k], self.box[1][k])
                    none = hi[:, k] <= self.box[1][k]
                plo[none], phi[none] = np.inf, -np.inf
                out.append(normalize_empty(plo, phi))
        return out

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        xout = inter_batch((lo, hi), (self.box[0][None], self.box[1][None]))
        xin = (np.full_like(lo, np.inf), np.full_like(hi, -np.inf))
        for p in self.pieces(lo, hi):
            xin = hull_batch(xin, p)
        # a box inside [y], even touching its border, has no point outside: its x_in is empty
        return xin, xout


def check_separation(xin: Batch, xout: Batch, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``(N,)`` mask of rows where ``[x_in] ∪ [x_out]`` fails to be ``[x]`` (hull test; for tests)."""
    h = hull_batch(normalize_empty(*xin), normalize_empty(*xout))
    ok = empty_rows(lo, hi) | ((h[0] == lo).all(axis=1) & (h[1] == hi).all(axis=1))
    sub = ((xin[0] >= lo) & (xin[1] <= hi)).all(axis=1) | empty_rows(*xin)
    sub &= ((xout[0] >= lo) & (xout[1] <= hi)).all(axis=1) | empty_rows(*xout)
    return ~(ok & sub)


__all__ = [
    "Sep",
    "SepBox",
    "SepCtcPair",
    "SepInter",
    "SepNot",
    "SepQInter",
    "SepUnion",
    "box_qinter",
    "check_separation",
    "hull_batch",
    "inter_batch",
    "relaxed_intersection",
]
