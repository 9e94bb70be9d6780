"""Initial localization among indistinguishable point landmarks (thesis §3.4.3, Eq. 3.66–3.70).

The map ``𝕄`` is a finite set of points and a range-bearing detection ``y_i = (ρ_i, φ_i)`` made at
``t_i`` says ``∃ m ∈ 𝕄, m = p(t_i) + ρ_i (cos(ψ(t_i) + φ_i), sin(ψ(t_i) + φ_i))`` (Eq. 3.67–3.68)
without saying which ``m``. The constraint network (Eq. 3.70)

    (i) ẋ = f(x, u)  (ii) m_i ∈ 𝕄  (iii) a_i = m_i - p(t_i)  (iv) α_i = ψ(t_i) + φ_i  (v) a_i = π(ρ_i, α_i)

is contracted with :func:`~.tube.ctc_deriv` on the heading and position tubes (i), the landmark-map
contractor :class:`CtcLandmarks` (ii: the hull of the landmarks inside a box), forward-backward
additions (iii, iv) and the minimal polar contractor :class:`~.polar.ctc.CtcPolar` (v). Iterating to
the fixpoint (:func:`localize`) solves the data association without any combinatorial search: a
detection whose box ``[m_i]`` holds one landmark is associated, and since no contractor removes a
consistent value, that landmark is the true one whenever the data bounds hold.

>>> lm = CtcLandmarks([[0.0, 0.0], [1.0, 2.0], [3.0, 1.0], [5.0, 5.0]])
>>> lo, hi = lm.contract(np.array([[0.5, 0.0], [4.0, 0.0]]), np.array([[3.5, 3.0], [4.5, 9.0]]))
>>> lo.tolist(), hi.tolist()                # hull of (1, 2), (3, 1); no landmark in the second box
([[1.0, 1.0], [inf, inf]], [[3.0, 2.0], [-inf, -inf]])
>>> lm.count(np.array([[-1.0, -1.0]]), np.array([[9.0, 9.0]])).tolist()
[4]
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from digslam.observer.core import arith as A
from digslam.observer.core.boxes import normalize_empty, validate_batch
from digslam.observer.core.types import Batch, Pair
from digslam.observer.polar.ctc import CtcPolar
from digslam.observer.sets.contractors import Ctc
from digslam.observer.tube.tube import Tube, body_velocity, ctc_deriv

_INF = np.inf
_CHUNK = 1 << 22  # candidate (box, landmark) pairs examined at once
_POLAR = CtcPolar()  # the compiled minimal polar contractor, Eq. 3.34 (step v)


class CtcLandmarks(Ctc):
    """Landmark-map contractor of Eq. 3.70 (ii): ``[m] ↦ ⟦[m] ∩ 𝕄⟧`` for a finite map ``𝕄 ⊂ ℝ²``.

    The landmarks are sorted on ``x`` once; a batch of boxes finds its ``x`` windows by binary search
    and filters them on ``y``, all boxes at once (work ``O(N log L + Σ window sizes)``). The result is
    exact: landmark coordinates are compared, never computed.

    Args:
        landmarks: ``(L, 2)`` finite coordinates, ``L >= 1``.
    """

    n = 2

    def __init__(self, landmarks: ArrayLike) -> None:
        m = np.array(landmarks, dtype=np.float64)
        if m.ndim != 2 or m.shape[1] != 2 or m.shape[0] < 1:
            raise ValueError(f"landmarks: expected shape (L, 2) with L >= 1, got {m.shape}")
        if not np.isfinite(m).all():
            raise ValueError("landmarks: coordinates must be finite")
        self.order = np.lexsort((m[:, 1], m[:, 0]))  #: sorted position -> index in ``landmarks``
        self.landmarks = m  #: the map as given
        self.points = m[self.order]
        self._x = self.points[:, 0].copy()

    def pairs(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All ``(box, landmark)`` with the landmark in the box: ``(box rows, indices into landmarks)``,
        grouped by box in increasing order (landmarks in ``x`` order within a box)."""
        lo, hi = validate_batch(lo, hi, "boxes", 2)
        boxes, idx = [], []
        for b0, b1 in self._chunks(lo, hi):
            b, j = self._pairs(lo[b0:b1], hi[b0:b1])
            boxes.append(b + b0)
            idx.append(j)
        b, j = np.concatenate(boxes), np.concatenate(idx)
        return b, self.order[j]

    def _windows(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        i0 = np.searchsorted(self._x, lo[:, 0], side="left")
        i1 = np.searchsorted(self._x, hi[:, 0], side="right")
        return i0, np.maximum(i1 - i0, 0)

    def _chunks(self, lo: np.ndarray, hi: np.ndarray) -> list[tuple[int, int]]:
        """Row ranges whose windows hold at most about ``_CHUNK`` candidates each (bounded memory)."""
        _, n = self._windows(lo, hi)
        cum = np.concatenate([[0], np.cumsum(n)])
        cuts = np.searchsorted(cum, np.arange(_CHUNK, cum[-1], _CHUNK), side="right") - 1
        edges = np.unique(np.concatenate([[0], np.maximum(cuts, 1), [lo.shape[0]]]))
        return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:], strict=True)] or [(0, 0)]

    def _pairs(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(box row, sorted landmark index)`` pairs for the landmarks inside each box (one chunk)."""
        i0, n = self._windows(lo, hi)
        box = np.repeat(np.arange(lo.shape[0]), n)
        j = np.repeat(i0 - (np.cumsum(n) - n), n) + np.arange(int(n.sum()))
        y = self.points[j, 1]
        keep = (y >= lo[box, 1]) & (y <= hi[box, 1])
        return box[keep], j[keep]

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> Batch:
        """``⟦[m] ∩ 𝕄⟧`` for a batch ``(N, 2)``: the hull of the landmarks in each box, empty if none."""
        out_lo, out_hi = np.full(lo.shape, _INF), np.full(hi.shape, -_INF)
        for b0, b1 in self._chunks(lo, hi):
            box, j = self._pairs(lo[b0:b1], hi[b0:b1])
            if box.size == 0:
                continue
            start = np.flatnonzero(np.concatenate([[True], box[1:] != box[:-1]]))
            end = np.concatenate([start[1:], [box.size]]) - 1
            rows = box[start] + b0
            pts = self.points[j]
            out_lo[rows, 0], out_hi[rows, 0] = pts[start, 0], pts[end, 0]  # x-sorted within a box
            out_lo[rows, 1] = np.minimum.reduceat(pts[:, 1], start)
            out_hi[rows, 1] = np.maximum.reduceat(pts[:, 1], start)
        return out_lo, out_hi

    def count(self, lo: ArrayLike, hi: ArrayLike) -> np.ndarray:
        """``(N,)`` number of landmarks inside each box."""
        blo, bhi = validate_batch(lo, hi, "boxes", 2)
        return np.bincount(self.pairs(blo, bhi)[0], minlength=blo.shape[0])

    def unique(self, lo: ArrayLike, hi: ArrayLike) -> np.ndarray:
        """``(N,)`` index into ``landmarks`` of the only landmark inside each box, ``-1`` when 0 or >= 2."""
        blo, bhi = validate_batch(lo, hi, "boxes", 2)
        box, idx = self.pairs(blo, bhi)
        cnt = np.bincount(box, minlength=blo.shape[0])
        out = np.full(blo.shape[0], -1, dtype=np.int64)
        one = cnt[box] == 1
        out[box[one]] = idx[one]
        return out


def _col(lo: np.ndarray, hi: np.ndarray, i: int) -> Pair:
    return lo[:, i], hi[:, i]


def contract_detections(lmap: CtcLandmarks, p: Batch, psi: Pair, m: Batch, rho: Pair, phi: Pair,
                        passes: int = 2) -> tuple[Batch, Pair, Batch]:  # fmt: skip
    """Eq. 3.70 (ii)–(v) on ``D`` detections at once: returns the contracted ``(p, ψ, m)``.

    ``m &= ⟦m ∩ 𝕄⟧``; ``a = m - p``, ``α = ψ + φ``; ``(a, ρ, α) &= C_Π``; then backward
    ``m &= p + a``, ``p &= m - a``, ``ψ &= α - φ``; ``passes`` times (outward rounded throughout).

    Args:
        lmap: the map contractor; p: ``(D, 2)`` positions at ``t_i``; psi: ``(D,)`` headings;
        m: ``(D, 2)`` landmark boxes; rho, phi: ``(D,)`` range and bearing (robot frame) intervals.
    """
    (plo, phi_), (mlo, mhi) = p, m
    plo, phi_, mlo, mhi = plo.copy(), phi_.copy(), mlo.copy(), mhi.copy()
    for _ in range(passes):
        mlo, mhi = lmap.contract(*normalize_empty(mlo, mhi))
        ax, ay = A.sub(_col(mlo, mhi, 0), _col(plo, phi_, 0)), A.sub(_col(mlo, mhi, 1), _col(plo, phi_, 1))
        alpha = A.add(psi, phi)
        box = _POLAR.contract(np.stack([ax[0], ay[0], rho[0], alpha[0]], 1),
                              np.stack([ax[1], ay[1], rho[1], alpha[1]], 1))  # fmt: skip
        a = (box[0][:, :2], box[1][:, :2])
        mx = A.intersect(_col(mlo, mhi, 0), A.add(_col(plo, phi_, 0), _col(*a, 0)))
        my = A.intersect(_col(mlo, mhi, 1), A.add(_col(plo, phi_, 1), _col(*a, 1)))
        px = A.intersect(_col(plo, phi_, 0), A.sub(mx, _col(*a, 0)))
        py = A.intersect(_col(plo, phi_, 1), A.sub(my, _col(*a, 1)))
        psi = A.intersect(psi, A.sub((box[0][:, 3], box[1][:, 3]), phi))
        mlo, mhi = normalize_empty(np.stack([mx[0], my[0]], 1), np.stack([mx[1], my[1]], 1))
        plo, phi_ = normalize_empty(np.stack([px[0], py[0]], 1), np.stack([px[1], py[1]], 1))
    mlo, mhi = lmap.contract(*normalize_empty(mlo, mhi))
    return (plo, phi_), psi, (mlo, mhi)


def _group_hull(d: np.ndarray, lo: np.ndarray, hi: np.ndarray, rows: int) -> Batch:
    """Per group ``d`` (sorted), the hull of the non-empty rows ``(lo, hi)``; empty for groups without any."""
    out_lo, out_hi = np.full((rows, lo.shape[1]), _INF), np.full((rows, lo.shape[1]), -_INF)
    if d.size:
        start = np.flatnonzero(np.concatenate([[True], d[1:] != d[:-1]]))
        out_lo[d[start]] = np.minimum.reduceat(lo, start, axis=0)
        out_hi[d[start]] = np.maximum.reduceat(hi, start, axis=0)
    return normalize_empty(out_lo, out_hi)


def contract_disjunctive(lmap: CtcLandmarks, p: Batch, psi: Pair, m: Batch, rho: Pair, phi: Pair,
                         max_candidates: int = 32) -> tuple[Batch, Pair, Batch]:  # fmt: skip
    """Eq. 3.70 (ii)–(v) with ``m_i`` ranging over the landmarks of ``[m_i]`` one by one (constructive
    disjunction): ``[p_i] = ⊔_j C(p_i | m_i = m_j)``, ``[m_i]`` the hull of the ``m_j`` not refuted, same
    for ``ψ_i``. Stronger than the hull contractor (two close landmarks can be told apart) and still
    linear in the number of (detection, candidate) pairs, with no search across detections. Detections
    with more than ``max_candidates`` candidates are left as they are (a wide box gains nothing).
    """
    (plo, phh), (mlo, mhi) = p, normalize_empty(*m)
    d, j = lmap.pairs(mlo, mhi)
    cnt = np.bincount(d, minlength=plo.shape[0])
    skip = cnt > max_candidates
    d, j = d[~skip[d]], j[~skip[d]]
    q = lmap.landmarks[j]
    sel = lambda a, i: (a[0][d, i], a[1][d, i])  # noqa: E731
    qx, qy = (q[:, 0], q[:, 0]), (q[:, 1], q[:, 1])
    ax, ay = A.sub(qx, sel(p, 0)), A.sub(qy, sel(p, 1))
    alpha = A.add((psi[0][d], psi[1][d]), (phi[0][d], phi[1][d]))
    blo, bhi = _POLAR.contract(np.stack([ax[0], ay[0], rho[0][d], alpha[0]], 1),
                               np.stack([ax[1], ay[1], rho[1][d], alpha[1]], 1))  # fmt: skip
    px, py = A.sub(qx, (blo[:, 0], bhi[:, 0])), A.sub(qy, (blo[:, 1], bhi[:, 1]))
    ps = A.sub((blo[:, 3], bhi[:, 3]), (phi[0][d], phi[1][d]))
    keep = ~(blo > bhi).any(axis=1)
    lo = np.stack([px[0], py[0], ps[0], q[:, 0], q[:, 1]], 1)[keep]
    hi = np.stack([px[1], py[1], ps[1], q[:, 0], q[:, 1]], 1)[keep]
    hlo, hhi = _group_hull(d[keep], lo, hi, plo.shape[0])
    hlo[skip], hhi[skip] = -_INF, _INF
    new_p = normalize_empty(np.maximum(plo, hlo[:, :2]), np.minimum(phh, hhi[:, :2]))
    new_psi = A.intersect(psi, (hlo[:, 2], hhi[:, 2]))
    return new_p, new_psi, normalize_empty(np.maximum(mlo, hlo[:, 3:]), np.minimum(mhi, hhi[:, 3:]))


@dataclass
class IterationStats:
    """One row of Table 3.3: candidates per detection after an iteration of :func:`localize`."""

    iteration: int
    min_candidates: int  #: fewest landmarks in a ``[m_i]``
    max_candidates: int  #: most landmarks in a ``[m_i]``
    unique: int  #: detections whose ``[m_i]`` holds exactly one landmark
    max_width: float  #: widest position gate (∞-norm, m)
    seconds: float  #: time of this iteration


@dataclass
class Localization:
    """Result of :func:`localize`: tubes, landmark boxes, associations and the per-iteration table."""

    position: Tube
    heading: Tube
    m_lo: np.ndarray
    m_hi: np.ndarray
    associations: np.ndarray  #: ``(D,)`` index into ``landmarks``, ``-1`` while ambiguous
    history: list[IterationStats] = field(default_factory=list)
    width_history: list[np.ndarray] = field(default_factory=list)  #: position gate widths per iteration
    consistent: bool = True  #: False when some box came out empty (the data contradict the bounds)

    @property
    def full_association_at(self) -> int | None:
        """First iteration at which every detection is uniquely associated (None if never)."""
        d = self.associations.size
        return next((h.iteration for h in self.history if h.unique == d), None)


def _intervals(name: str, lo: ArrayLike, hi: ArrayLike, size: int | None = None) -> Pair:
    a, b = np.array(lo, dtype=np.float64).reshape(-1), np.array(hi, dtype=np.float64).reshape(-1)
    if a.shape != b.shape or (size is not None and a.size != size):
        want = f"({size},)" if size is not None else "one shape"
        raise ValueError(f"{name}: expected lo and hi of shape {want}, got {np.shape(lo)} and {np.shape(hi)}")
    if np.isnan(a).any() or np.isnan(b).any() or (a > b).any():
        raise ValueError(f"{name}: bounds must be non-NaN with lo <= hi")
    return a, b


def _moved(a: np.ndarray, b: np.ndarray) -> float:
    """Largest move of a bound between two arrays of bounds (0 where both are equal, infinities too)."""
    with np.errstate(invalid="ignore"):
        d = np.where(a == b, 0.0, np.abs(a - b))
    return float(np.nan_to_num(d, nan=np.inf).max())


def localize(
    t: ArrayLike,
    v: tuple[ArrayLike, ArrayLike],
    omega: tuple[ArrayLike, ArrayLike],
    psi0: tuple[float, float],
    k: ArrayLike,
    rho: tuple[ArrayLike, ArrayLike],
    phi: tuple[ArrayLike, ArrayLike],
    landmarks: ArrayLike,
    max_iter: int = 50,
    passes: int = 2,
    tol: float = 1e-3,
    disjunctive: bool = True,
) -> Localization:
    """Fixpoint of the network Eq. 3.70 from an unknown start ``p(t_0) ∈ ℝ²`` (thesis §3.4.3.4).

    Each iteration contracts every detection (:func:`contract_detections`), intersects the results
    into the gates ``t_{k_i}``, then runs ``C_d/dt`` forward and backward on the heading tube
    (``ψ̇ = ω``) and on the position tube (``ṗ = R(ψ) v``, :func:`~.tube.body_velocity`). It stops at
    the fixpoint (no bound moved by more than ``tol``) or after ``max_iter`` iterations. With
    ``disjunctive`` (default) each detection is also contracted candidate by candidate
    (:func:`contract_disjunctive`); with ``disjunctive=False`` only the thesis's hull contractor is used.

    Args:
        t: ``(T+1,)`` time grid; v: ``(v_lo, v_hi)`` body-frame velocity ``(T, 2)`` per slice;
        omega: ``(ω_lo, ω_hi)`` yaw rate ``(T,)``; psi0: initial heading interval;
        k: ``(D,)`` gate index of each detection; rho, phi: ``(D,)`` range and bearing intervals;
        landmarks: ``(L, 2)`` map; max_iter: iteration cap; passes: local passes per detection;
        tol: stopping threshold (m, rad); disjunctive: add the candidate-by-candidate contraction.
    """
    lmap = CtcLandmarks(landmarks)
    pos = Tube.entire(t, 2)
    T = pos.T
    om = _intervals("omega", *omega, T)
    p0 = _intervals("psi0", *psi0, 1)
    kk = np.asarray(k)
    if (
        kk.ndim != 1
        or kk.size < 1
        or not np.issubdtype(kk.dtype, np.integer)
        or not (0 <= kk).all()
        or not (kk <= T).all()
    ):
        raise ValueError(f"k: expected a non-empty 1-d array of integer gate indices in [0, {T}]")
    r, f = _intervals("rho", *rho, kk.size), _intervals("phi", *phi, kk.size)
    if not tol >= 0:
        raise ValueError(f"tol: expected a number >= 0, got {tol}")
    if int(max_iter) < 1 or int(passes) < 1:
        raise ValueError(f"max_iter: max_iter and passes must be >= 1, got {max_iter} and {passes}")
    head = Tube.entire(t, 1)
    head.gate_lo[0], head.gate_hi[0] = p0[0][0], p0[1][0]
    head = ctc_deriv(head, *om)
    vel = (np.asarray(v[0], dtype=np.float64), np.asarray(v[1], dtype=np.float64))
    body_velocity(*vel, head.slice_lo[:, 0], head.slice_hi[:, 0])  # validates v before the loop
    m = (np.full((kk.size, 2), -_INF), np.full((kk.size, 2), _INF))
    res = Localization(pos, head, *m, np.full(kk.size, -1, dtype=np.int64))
    for it in range(1, int(max_iter) + 1):
        t0 = time.perf_counter()
        before = (pos.gate_lo.copy(), pos.gate_hi.copy(), head.gate_lo.copy(), head.gate_hi.copy())
        p, psi = (pos.gate_lo[kk], pos.gate_hi[kk]), (head.gate_lo[kk, 0], head.gate_hi[kk, 0])
        p, psi, m = contract_detections(lmap, p, psi, m, r, f, passes)
        if disjunctive:
            p, psi, m = contract_disjunctive(lmap, p, psi, m, r, f)
        pos, head = pos.copy(), head.copy()
        np.maximum.at(pos.gate_lo, kk, p[0])
        np.minimum.at(pos.gate_hi, kk, p[1])
        np.maximum.at(head.gate_lo[:, 0], kk, psi[0])
        np.minimum.at(head.gate_hi[:, 0], kk, psi[1])
        ok = not (head.is_empty() or pos.is_empty())
        if ok:
            head = ctc_deriv(head, *om)
            ok = not head.is_empty()
        if ok:
            pos = ctc_deriv(pos, *body_velocity(*vel, head.slice_lo[:, 0], head.slice_hi[:, 0]))
            ok = not pos.is_empty()
        cnt = lmap.count(*normalize_empty(*m))
        res = Localization(
            pos, head, m[0], m[1], lmap.unique(*normalize_empty(*m)), res.history, res.width_history, ok
        )
        res.width_history.append(pos.widths())
        res.history.append(IterationStats(it, int(cnt.min()), int(cnt.max()), int((cnt == 1).sum()),
                                          float(pos.widths().max()), time.perf_counter() - t0))  # fmt: skip
        after = (pos.gate_lo, pos.gate_hi, head.gate_lo, head.gate_hi)
        if not ok or all(_moved(a, b) <= tol for a, b in zip(before, after, strict=True)):
            break
    return res


__all__ = [
    "CtcLandmarks",
    "IterationStats",
    "Localization",
    "contract_detections",
    "contract_disjunctive",
    "localize",
]
