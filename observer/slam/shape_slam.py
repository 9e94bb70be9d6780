"""Inter-temporal shape SLAM (thesis §6.3, Algorithm 6.2, Eq. 6.5–6.14).

With translation-invariant observations ``Z(t_i) = M - x(t_i)`` (Eq. 6.12) the map leaves the network: two
measured thick shapes constrain the displacement between their times, ``Z(t_i) = Z(t_j) + p_ij`` with
``p_ij = x(t_j) - x(t_i)`` (Eq. 6.9–6.10). :func:`shape_slam` runs Algorithm 6.2 on a sliced tube:

1. ``[x](·) := C_d/dt([x](·))`` (:func:`~.tube.ctc_deriv`);
2. for every pair ``(t_i, t_j)`` whose scopes may overlap (the pre-test of Eq. 6.14,
   :func:`overlap_pretest`): ``[p_ij] := C_SRAC([p_ij], [Z(t_i)], [Z(t_j)])``
   (:func:`~.shape_registration.register_translation`), then ``C_-`` on ``([x](t_i), [x](t_j), [p_ij])``
   (:func:`ctc_minus`);
3. repeat until the tube stops shrinking (a bounded number of passes).

Each step is a sound contractor: the true trajectory and the true ``p_ij`` are never lost.

>>> xi, xj, p = (np.array([[0.0]]), np.array([[1.0]])), (np.array([[0.0]]), np.array([[10.0]])), \\
...     (np.array([[4.0]]), np.array([[5.0]]))
>>> [b[0].item() for b in ctc_minus(xi, xj, p)], [b[1].item() for b in ctc_minus(xi, xj, p)]
([0.0, 4.0, 4.0], [1.0, 6.0, 5.0])
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from digslam.observer.core import arith
from digslam.observer.core import rounding as rnd
from digslam.observer.core.boxes import empty_rows
from digslam.observer.core.types import Pair
from digslam.observer.slam.shape_registration import ThickImage, register_translation
from digslam.observer.tube.tube import Tube, ctc_deriv

__all__ = ["ctc_minus", "overlap_pretest", "ShapeSlamConfig", "ShapeSlamResult", "shape_slam"]


def ctc_minus(xi: Pair, xj: Pair, p: Pair) -> tuple[Pair, Pair, Pair]:
    """``C_-`` for ``p = x_j - x_i`` (Eq. 6.10, Example 2.4), forward-backward, on batches ``(N, n)``.

    ``[p] &= [x_j] - [x_i]``, ``[x_j] &= [x_i] + [p]``, ``[x_i] &= [x_j] - [p]``, outward rounded; an empty
    result is ``[+inf, -inf]``.
    """
    p = arith.intersect(p, arith.sub(xj, xi))
    xj = arith.intersect(xj, arith.add(xi, p))
    xi = arith.intersect(xi, arith.sub(xj, p))
    return _norm(xi), _norm(xj), _norm(p)


def _norm(b: Pair) -> Pair:
    e = empty_rows(*b)[:, None]
    return np.where(e, np.inf, b[0]), np.where(e, -np.inf, b[1])


def overlap_pretest(v_i: Pair, v_j: Pair, p: Pair, inner_i: Pair | None = None,
                    inner_j: Pair | None = None) -> np.ndarray:  # fmt: skip
    """Eq. 6.14 on boxes: ``[X] = [V](t_i) ∩ ([V](t_j) + [p_ij])`` for ``N`` pairs at once.

    ``V`` is enclosed by its hull ``v`` (so ``X⁺ = ∅`` is proved when the hulls cannot meet for any
    ``p ∈ [p]``), and optionally contains a box ``inner`` (so ``X⁻ ≠ ∅`` is proved when
    ``inner_i ∩ ⋂_{p ∈ [p]} (inner_j + p) ≠ ∅``).

    Args:
        v_i, v_j: ``(N, n)`` hulls of the scopes in the robot frames; p: ``(N, n)`` boxes ``[p_ij]``.
        inner_i, inner_j: optional ``(N, n)`` boxes inside the scopes.

    Returns:
        ``int8 (N,)``: ``-1`` no overlap (skip the pair), ``1`` overlap for sure, ``0`` undecided (test it).
    """
    for name, b in (("v_i", v_i), ("v_j", v_j), ("p", p)):
        if np.shape(b[0]) != np.shape(v_i[0]) or np.shape(b[1]) != np.shape(v_i[0]) or np.ndim(b[0]) != 2:
            raise ValueError(f"{name}: expected (lo, hi) of shape {np.shape(v_i[0])} (N, n)")
    moved = arith.add(v_j, p)
    with np.errstate(invalid="ignore"):
        apart = ((moved[0] > v_i[1]) | (moved[1] < v_i[0])).any(axis=1)
    apart |= empty_rows(*v_i) | empty_rows(*v_j) | empty_rows(*p)
    out = np.where(apart, np.int8(-1), np.int8(0)).astype(np.int8)
    if inner_i is not None and inner_j is not None:
        # ⋂_p (inner_j + p) = [inner_j⁻ + p⁺, inner_j⁺ + p⁻], rounded inward
        lo, hi = rnd.add_up(inner_j[0], p[1]), rnd.add_down(inner_j[1], p[0])
        meet = ((np.maximum(lo, inner_i[0]) <= np.minimum(hi, inner_i[1])) & (lo <= hi)).all(axis=1)
        out[meet & ~apart] = 1
    return out


@dataclass(frozen=True)
class ShapeSlamConfig:
    """Settings of :func:`shape_slam`.

    Attributes:
        max_passes: most passes of Algorithm 6.2 (each: ``C_d/dt``, all registrations, ``C_-``).
        tol: stop when a pass shrinks the summed gate widths by less than this fraction.
        eps_p: paving width of ``[p_ij]`` in the registration.
        min_dt: pairs closer in time than this are not registered (dropping constraints is sound).
        reregister: a pair is registered again when a width of ``[p_ij]`` fell under this fraction of
            its width at its last registration.
        samples: sample points per pixel side of the registration separators.
        cminus_sweeps: sweeps of ``C_-`` over all pairs per pass.
    """

    max_passes: int = 10
    tol: float = 1e-3
    eps_p: float = 0.5
    min_dt: float = 0.0
    reregister: float = 0.7
    samples: int = 1
    cminus_sweeps: int = 4

    def __post_init__(self) -> None:
        for k in ("max_passes", "samples", "cminus_sweeps"):
            v = getattr(self, k)
            if not (isinstance(v, int) and v >= 1):
                raise ValueError(f"{k}: must be an integer >= 1, got {v!r}")
        for k in ("tol", "eps_p", "min_dt", "reregister"):
            v = getattr(self, k)
            if not (isinstance(v, (int, float)) and np.isfinite(v) and v >= 0):
                raise ValueError(f"{k}: must be a finite number >= 0, got {v!r}")
        if self.eps_p <= 0:
            raise ValueError(f"eps_p: must be > 0, got {self.eps_p!r}")


@dataclass
class ShapeSlamResult:
    """Result of :func:`shape_slam`.

    Attributes:
        tube: the contracted tube; dead_reckoning: the tube of ``C_d/dt`` alone.
        pairs: ``(P, 2)`` indices ``(i, j)``, ``i < j``, of the measurements; p: ``(lo, hi)`` ``(P, 2)``.
        tested: ``(P,)`` pairs the pre-test kept at the last pass; registrations: registrations run.
        passes: passes run; consistent: False when a contraction emptied a box (data outside bounds).
        widths: max gate width of the tube after each pass; seconds: wall time.
    """

    tube: Tube
    dead_reckoning: Tube
    pairs: np.ndarray
    p: Pair
    tested: np.ndarray
    registrations: int
    passes: int
    consistent: bool
    widths: list[float] = field(default_factory=list)
    seconds: float = 0.0


def shape_slam(tube: Tube, u_lo: Any, u_hi: Any, gates: Any, shapes: list[ThickImage],
               config: ShapeSlamConfig | None = None) -> ShapeSlamResult:  # fmt: skip
    """Algorithm 6.2 for ``ẋ = u``, ``u ∈ [u]`` and ``Z(t_i) = M - x(t_i)`` (Eq. 6.12).

    Args:
        tube: the initial tube (e.g. ``[x](t_0) = x_0``, entire elsewhere), 2-d.
        u_lo, u_hi: ``(T, 2)`` velocity bounds per slice (:func:`~.tube.body_velocity`).
        gates: ``(m,)`` gate indices ``k_i`` of the measurement times ``t_i = tube.t[k_i]``.
        shapes: ``m`` thick images ``[Z](t_i)`` in the robot frames, on one lattice.
        config: :class:`ShapeSlamConfig`.

    Raises:
        ValueError: naming the argument.
    """
    cfg = ShapeSlamConfig() if config is None else config
    if not isinstance(tube, Tube) or tube.n != 2:
        raise ValueError(f"tube: expected a 2-d Tube, got {tube!r}")
    g = np.asarray(gates)
    if g.ndim != 1 or not np.issubdtype(g.dtype, np.integer) or ((g < 0) | (g > tube.T)).any():
        raise ValueError(f"gates: expected (m,) integer gate indices in [0, {tube.T}]")
    if np.unique(g).size != g.size:
        raise ValueError("gates: indices must be distinct")
    if len(shapes) != g.size or not all(isinstance(s, ThickImage) for s in shapes):
        raise ValueError(f"shapes: expected {g.size} ThickImage (one per gate)")
    t0 = time.perf_counter()
    x = ctc_deriv(tube, u_lo, u_hi)
    dr = x
    ii, jj = np.triu_indices(g.size, 1)
    keep = np.abs(tube.t[g[jj]] - tube.t[g[ii]]) >= cfg.min_dt
    ii, jj = ii[keep], jj[keep]
    n_p = ii.size
    p = (np.full((n_p, 2), -np.inf), np.full((n_p, 2), np.inf))
    last_w = np.full((n_p, 2), np.inf)
    scopes = [s.scope_box() for s in shapes]
    v_lo, v_hi = np.array([s[0] for s in scopes]), np.array([s[1] for s in scopes])
    tested, n_reg, widths, passes = np.zeros(n_p, bool), 0, [], 0
    for passes in range(1, cfg.max_passes + 1):  # noqa: B007 (passes is reported)
        if x.is_empty():
            break
        before = float(np.sum(x.widths()))
        G = (x.gate_lo[g].copy(), x.gate_hi[g].copy())
        _, _, p = ctc_minus((G[0][ii], G[1][ii]), (G[0][jj], G[1][jj]), p)
        tested = overlap_pretest((v_lo[ii], v_hi[ii]), (v_lo[jj], v_hi[jj]), p) >= 0
        tested &= ~empty_rows(*p)
        w = np.where(np.isfinite(p[1] - p[0]), p[1] - p[0], np.inf)
        todo = np.flatnonzero(tested & (w < cfg.reregister * last_w).any(axis=1))
        for k in todo:  # one registration (a batch paving of [p_ij]) per pair
            box = [(p[0][k, 0], p[1][k, 0]), (p[0][k, 1], p[1][k, 1])]
            lo, hi = register_translation(shapes[jj[k]], shapes[ii[k]], box, cfg.eps_p, samples=cfg.samples)
            p[0][k], p[1][k] = lo, hi
            last_w[k] = np.maximum(hi - lo, 0.0)
            n_reg += 1
        for _ in range(cfg.cminus_sweeps):  # C_- on every tested pair; shared gates meet all contractions
            xi, xj, p = ctc_minus((G[0][ii], G[1][ii]), (G[0][jj], G[1][jj]), p)
            for idx, b in ((ii, xi), (jj, xj)):
                np.maximum.at(G[0], idx[tested], b[0][tested])
                np.minimum.at(G[1], idx[tested], b[1][tested])
        if empty_rows(*p).any() or empty_rows(*G).any():
            x = _emptied(x)
            break
        x = x.copy()
        x.gate_lo[g], x.gate_hi[g] = G
        x = ctc_deriv(x, u_lo, u_hi)
        widths.append(float(x.widths().max()) if not x.is_empty() else 0.0)
        after = float(np.sum(x.widths()))
        if x.is_empty() or before - after <= cfg.tol * before:
            break
    return ShapeSlamResult(x, dr, np.stack([ii, jj], axis=1), p, tested, n_reg, passes, not x.is_empty(),
                           widths, time.perf_counter() - t0)  # fmt: skip


def _emptied(x: Tube) -> Tube:
    e = x.copy()
    e.gate_lo[:], e.gate_hi[:] = np.inf, -np.inf
    e.slice_lo[:], e.slice_hi[:] = np.inf, -np.inf
    return e
