"""Polygon separator: a boundary-based separator for polygons with holes (thesis §2.5.1, Eq. 2.65–2.69).

The set is the points with an odd crossing number with respect to closed rings (outer boundaries
and holes alike, any orientation). :class:`CtcSegments` is the union of minimal segment contractors
(Eq. 2.67, 2.69); :class:`SepPolygon` classifies each piece of ``[x] minus C([x])`` with one robust
point-in-polygon test (Eq. 2.65–2.66). All deciding arithmetic is outward rounded: a point whose
orientation against an edge cannot be signed leaves its piece undetermined (in ``x_in`` and ``x_out``).

>>> s = SepPolygon([[(0, 0), (4, 0), (4, 4), (0, 4)], [(1, 1), (3, 1), (3, 3), (1, 3)]])
>>> (ilo, ihi), (olo, ohi) = s.separate(np.array([[1.5, 1.5]]), np.array([[2.5, 2.5]]))  # in the hole
>>> bool(olo[0, 0] > ohi[0, 0]), ilo.tolist()
(True, [[1.5, 1.5]])
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.boxes import box_difference, midpoint, normalize_empty
from digslam.observer.core.types import Batch
from digslam.observer.sets.contractors import Ctc
from digslam.observer.sets.separators import Sep

_CHUNK = 1 << 17  # elements of one (boxes x edges) block


def _diff(a: np.ndarray, b: np.ndarray) -> Batch:
    """Enclosure of the exact ``a - b`` (its sign is exact: ``a - b`` of floats never rounds to 0)."""
    return rnd.sub_down(a, b), rnd.sub_up(a, b)


def _prod(u: Batch, v: Batch) -> Batch:
    """Enclosure of the exact product of two one-signed intervals (differences from :func:`_diff`)."""
    su = np.where(u[1] > 0, 1, np.where(u[0] < 0, -1, 0))
    sv = np.where(v[1] > 0, 1, np.where(v[0] < 0, -1, 0))
    au, av = np.abs(u[0]), np.abs(u[1])
    bu, bv = np.abs(v[0]), np.abs(v[1])
    with np.errstate(invalid="ignore"):
        pmin = rnd.mul_down(np.minimum(au, av), np.minimum(bu, bv))
        pmax = rnd.mul_up(np.maximum(au, av), np.maximum(bu, bv))
    s = su * sv
    lo = np.where(s > 0, pmin, np.where(s < 0, -pmax, 0.0))
    return lo, np.where(s > 0, pmax, np.where(s < 0, -pmin, 0.0))


def orient(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> Batch:
    """Enclosure ``(lo, hi)`` of ``det(b - a, p - a)`` (= ``-det(b - a, a - p)`` of Eq. 2.67), broadcast.

    ``a, b, p`` are ``(..., 2)`` arrays; ``lo > 0`` proves ``p`` left of ``a -> b``, ``hi < 0`` right,
    and ``lo == hi == 0`` proves the three points collinear. NaN bounds (overflow) decide nothing.
    """
    p1 = _prod(_diff(b[..., 0], a[..., 0]), _diff(p[..., 1], a[..., 1]))
    p2 = _prod(_diff(b[..., 1], a[..., 1]), _diff(p[..., 0], a[..., 0]))
    return rnd.sub_down(p1[0], p2[1]), rnd.sub_up(p1[1], p2[0])


def _orient_sign_exact(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Exact sign of :func:`orient`: the enclosure first, rational arithmetic where it straddles 0."""
    a, b, p = np.broadcast_arrays(a, b, p)
    lo, hi = orient(a, b, p)
    s = np.where(lo > 0, 1, np.where(hi < 0, -1, 0))
    for i in np.argwhere(~((lo > 0) | (hi < 0) | ((lo == 0) & (hi == 0)))):
        (ax, ay), (bx, by), (px, py) = (map(Fraction, map(float, q[tuple(i)])) for q in (a, b, p))
        d = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
        s[tuple(i)] = (d > 0) - (d < 0)
    return s


def _rings(polygons: Any) -> list[np.ndarray]:
    """Validate rings: finite ``(k, 2)``, closing vertex optional, ``k >= 3``, no repeated vertex."""
    if isinstance(polygons, np.ndarray) and polygons.ndim == 2:
        polygons = [polygons]
    rings = []
    for i, r in enumerate(polygons):
        r = np.asarray(r, dtype=np.float64)
        if r.ndim != 2 or r.shape[1] != 2:
            raise ValueError(f"polygons[{i}]: expected vertices of shape (k, 2), got {r.shape}")
        if not np.isfinite(r).all():
            bad = np.argwhere(~np.isfinite(r))[0, 0]
            raise ValueError(f"polygons[{i}]: NaN or infinite vertex at index {bad}")
        if len(r) > 1 and (r[0] == r[-1]).all():
            r = r[:-1]
        if len(r) < 3:
            raise ValueError(f"polygons[{i}]: a ring needs at least three distinct vertices, got {len(r)}")
        rep = (r == np.roll(r, -1, axis=0)).all(axis=1)
        if rep.any():
            raise ValueError(f"polygons[{i}]: vertex {np.argmax(rep)} repeats the next (zero-length edge)")
        rings.append(r)
    if not rings:
        raise ValueError("polygons: need at least one ring")
    return rings


def _check_simple(rings: list[np.ndarray]) -> None:
    """Raise if an edge meets a non-adjacent edge, or two adjacent edges overlap (exact predicates)."""
    a = np.concatenate(rings)
    b = np.concatenate([np.roll(r, -1, axis=0) for r in rings])
    ring = np.concatenate([np.full(len(r), i) for i, r in enumerate(rings)])
    k = np.concatenate([np.arange(len(r)) for r in rings])
    size = np.concatenate([np.full(len(r), len(r)) for r in rings])
    # adjacent edges (i -> i+1) fold back when collinear with opposite directions on some axis
    nxt = np.concatenate([np.roll(np.arange(len(r)), -1) for r in rings]) + np.repeat(
        np.cumsum([0] + [len(r) for r in rings[:-1]]), [len(r) for r in rings]
    )
    c = b[nxt]
    fold = (_orient_sign_exact(a, b, c) == 0) & (np.sign(b - a) * np.sign(c - b) < 0).any(axis=1)
    if fold.any():
        e = np.argmax(fold)
        nx = (k[e] + 1) % size[e]
        raise ValueError(f"polygons[{ring[e]}]: edges {k[e]} and {nx} overlap (the ring folds back)")
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    step = max(1, _CHUNK // len(a))
    for s in range(0, len(a), step):
        p, q = np.nonzero(np.arange(s, min(s + step, len(a)))[:, None] < np.arange(len(a))[None])
        p += s
        near = (lo[p] <= hi[q]).all(axis=1) & (lo[q] <= hi[p]).all(axis=1)
        adj = (ring[p] == ring[q]) & (((k[p] + 1) % size[p] == k[q]) | ((k[q] + 1) % size[q] == k[p]))
        p, q = p[near & ~adj], q[near & ~adj]
        d = [_orient_sign_exact(a[u], b[u], w) for u, w in ((p, a[q]), (p, b[q]), (q, a[p]), (q, b[p]))]
        hit = (d[0] * d[1] < 0) & (d[2] * d[3] < 0)
        for dd, u, w in ((d[0], p, a[q]), (d[1], p, b[q]), (d[2], q, a[p]), (d[3], q, b[p])):
            hit |= (dd == 0) & (lo[u] <= w).all(axis=1) & (w <= hi[u]).all(axis=1)
        if hit.any():
            e, f = p[np.argmax(hit)], q[np.argmax(hit)]
            r, g = ring[e], ring[f]
            if r == g:
                raise ValueError(f"polygons[{r}]: edges {k[e]} and {k[f]} meet (self-intersecting ring)")
            why = "rings must not touch"
            raise ValueError(f"polygons[{r}]: edge {k[e]} meets edge {k[f]} of polygons[{g}] ({why})")


def _meets(lo: np.ndarray, hi: np.ndarray, slo: np.ndarray, shi: np.ndarray) -> np.ndarray:
    """``(N, E)`` mask: box ``[lo_i, hi_i]`` meets box ``[slo_e, shi_e]`` (closed, exact comparisons)."""
    m = (slo[:, 0] <= hi[:, 0, None]) & (lo[:, 0, None] <= shi[:, 0])
    return m & (slo[:, 1] <= hi[:, 1, None]) & (lo[:, 1, None] <= shi[:, 1])


class CtcSegments(Ctc):
    """Union of minimal contractors on segments ``[a_i, b_i]`` (Eq. 2.67–2.69), outward rounded.

    Each segment is ``a + t (b - a)``, ``t ∈ [0, 1]``; the box bounds give an enclosure of the ``t``
    range, mapped back to an enclosure of the clipped segment's hull. Vectorised over boxes x edges.
    """

    n = 2

    def __init__(self, a: Any, b: Any) -> None:
        self.a, self.b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
        if self.a.ndim != 2 or self.a.shape[1] != 2 or self.a.shape != self.b.shape:
            shapes = f"{self.a.shape} and {self.b.shape}"
            raise ValueError(f"segments: expected a and b of one shape (E, 2), got {shapes}")
        if not (np.isfinite(self.a).all() and np.isfinite(self.b).all()):
            raise ValueError("segments: NaN or infinite endpoint")
        self.d = _diff(self.b, self.a)
        self.sgn = np.sign(self.b - self.a)
        self.seg_lo, self.seg_hi = np.minimum(self.a, self.b), np.maximum(self.a, self.b)

    def _block(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        # only (box, edge) pairs whose bounding boxes meet can give a non-empty contraction
        near = _meets(lo, hi, self.seg_lo, self.seg_hi)
        r, e = np.nonzero(near)
        lo, hi, a, dlo, dhi, s = lo[r], hi[r], self.a[e], self.d[0][e], self.d[1][e], self.sgn[e]
        tl, tu = np.zeros(len(r)), np.ones(len(r))
        with np.errstate(invalid="ignore", divide="ignore"):
            for k in range(2):
                n1, n2 = _diff(lo[:, k], a[:, k]), _diff(hi[:, k], a[:, k])
                pos = s[:, k] > 0
                num_l, num_u = np.where(pos, n1[0], -n2[1]), np.where(pos, n2[1], -n1[0])
                mlo, mhi = np.where(pos, dlo[:, k], -dhi[:, k]), np.where(pos, dhi[:, k], -dlo[:, k])
                t_l = rnd.div_down(num_l, np.where(num_l >= 0, mhi, mlo))
                t_u = rnd.div_up(num_u, np.where(num_u >= 0, mlo, mhi))
                flat = s[:, k] == 0  # the bounding-box test already put a_k inside [lo_k, hi_k]
                tl = np.fmax(tl, np.where(flat, 0.0, t_l))  # a NaN bound constrains nothing
                tu = np.fmin(tu, np.where(flat, 1.0, t_u))
            xl, xu = np.empty(lo.shape), np.empty(hi.shape)
            for k in range(2):
                pos, neg = s[:, k] > 0, s[:, k] < 0
                low = rnd.add_down(a[:, k], rnd.mul_down(np.where(pos, tl, tu), dlo[:, k]))
                up = rnd.add_up(a[:, k], rnd.mul_up(np.where(pos, tu, tl), dhi[:, k]))
                low = np.maximum(np.where(pos | neg, low, a[:, k]), self.seg_lo[e, k])
                up = np.minimum(np.where(pos | neg, up, a[:, k]), self.seg_hi[e, k])
                xl[:, k], xu[:, k] = np.maximum(low, lo[:, k]), np.minimum(up, hi[:, k])
        ok = (tl <= tu)[:, None] & (xl <= xu)
        out_lo, out_hi = np.full(near.shape[:1] + (2,), np.inf), np.full(near.shape[:1] + (2,), -np.inf)
        if len(r):
            ok = np.asarray(ok.all(axis=1))[:, None]
            starts = np.flatnonzero(np.r_[True, r[1:] != r[:-1]])
            out_lo[r[starts]] = np.minimum.reduceat(np.where(ok, xl, np.inf), starts)
            out_hi[r[starts]] = np.maximum.reduceat(np.where(ok, xu, -np.inf), starts)
        return normalize_empty(out_lo, out_hi)

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        step = max(1, _CHUNK // max(1, len(self.a)))
        parts = [self._block(lo[s : s + step], hi[s : s + step]) for s in range(0, len(lo), step)]
        if not parts:
            return lo.copy(), hi.copy()
        return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


class CtcPolygonBoundary(CtcSegments):
    """Minimal contractor on the border ``ΔP`` of validated polygon rings (Eq. 2.68–2.69, Remark 2.5)."""

    def __init__(self, polygons: Any) -> None:
        self.rings = _rings(polygons)
        _check_simple(self.rings)
        nxt = [np.roll(r, -1, axis=0) for r in self.rings]
        super().__init__(np.concatenate(self.rings), np.concatenate(nxt))


class SepPolygon(Sep):
    """Boundary-based polygon separator ``S_P`` (Eq. 2.65–2.66, §2.5.1.1), even-odd rule.

    Args:
        polygons: closed rings, each ``(k, 2)`` (a repeated closing vertex is optional); holes are rings
            inside outer rings. A single ``(k, 2)`` array is one ring.

    Raises:
        ValueError: naming the ring index: fewer than three vertices, NaN/inf, a zero-length edge, an
            edge meeting a non-adjacent edge (self-intersection) or another ring, a fold-back.
    """

    n = 2

    def __init__(self, polygons: Any) -> None:
        self.ctc = CtcPolygonBoundary(polygons)
        self.rings = self.ctc.rings

    def test(self, pts: np.ndarray) -> np.ndarray:
        """Robust point test ``T_P`` (Eq. 2.65): ``+1`` proved inside, ``-1`` outside, ``0`` undecided."""
        a, b = self.ctc.a, self.ctc.b
        out = np.empty(len(pts), dtype=np.int8)
        step = max(1, _CHUNK // len(a))
        for s in range(0, len(pts), step):
            p = pts[s : s + step, None, :]
            py = p[..., 1]
            up = (a[:, 1] <= py) & (b[:, 1] > py)
            down = (b[:, 1] <= py) & (a[:, 1] > py)
            inbox = _meets(p[:, 0], p[:, 0], self.ctc.seg_lo, self.ctc.seg_hi)
            r, e = np.nonzero(up | down | inbox)  # the only edges whose orientation matters
            lo, hi = orient(a[e], b[e], p[r, 0])
            left, right = lo > 0, hi < 0
            m = len(p)
            unknown = np.bincount(r, weights=~(left | right), minlength=m) > 0
            odd = np.bincount(r, weights=(up[r, e] & left) | (down[r, e] & right), minlength=m) % 2 == 1
            out[s : s + step] = np.where(unknown, 0, np.where(odd, 1, -1))
        return out

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        clo, chi = self.ctc.contract(lo, hi)
        (plo, phi), rows = box_difference(lo, hi, clo, chi)
        st = self.test(midpoint(plo, phi)) if len(rows) else np.zeros(0, dtype=np.int8)
        res = []
        for keep in (st <= 0, st >= 0):  # x_in keeps outside pieces, x_out inside ones; undecided in both
            rlo, rhi = clo.copy(), chi.copy()
            np.minimum.at(rlo, rows[keep], plo[keep])
            np.maximum.at(rhi, rows[keep], phi[keep])
            res.append(normalize_empty(rlo, rhi))
        return res[0], res[1]


__all__ = [
    "CtcPolygonBoundary",
    "CtcSegments",
    "SepPolygon",
    "orient",
]
