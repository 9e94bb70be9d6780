"""Sliced tubes and the differential contractor ``C_d/dt`` (thesis §2.5.4, Eq. 2.75–2.77, Remark 2.12).

A tube ``[x](·)`` is an interval of trajectories. Here it is sliced over a time grid
``t_0 < ... < t_T``: a gate ``[x](t_k)`` at each grid time and a slice, the envelope of ``[x](τ)`` for
``τ ∈ [t_k, t_{k+1}]`` (closed, so a slice holds both of its gates). :func:`ctc_deriv` contracts a tube
with ``ẋ = u``, ``u ∈ [u]`` (the kernels and the soundness proof are in :mod:`digslam.observer.tube.ctc`),
which propagates a contraction made at one time (a position fix, a registration) to the whole trajectory.
:func:`heading_from_gyro`, :func:`heading_from_compass`, :func:`unicycle_velocity` and
:func:`dead_reckoning` build the guaranteed dead reckoning of Eq. 3.59, 6.12, 6.23 and B.20.

>>> t = np.arange(5.0)                                   # x' = u, u in [1, 2], x(0) = 0
>>> x = dead_reckoning(t, [0.0], [0.0], np.ones((4, 1)), np.full((4, 1), 2.0))
>>> x.gate_lo.ravel().tolist(), x.gate_hi.ravel().tolist()
([0.0, 1.0, 2.0, 3.0, 4.0], [0.0, 2.0, 4.0, 6.0, 8.0])
>>> fix = x.copy(); fix.gate_lo[4], fix.gate_hi[4] = 4.0, 4.0   # x(4) = 4 forces u = 1
>>> ctc_deriv(fix, np.ones((4, 1)), np.full((4, 1), 2.0)).gate_hi.ravel().tolist()
[0.0, 1.0, 2.0, 3.0, 4.0]
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from digslam.observer.core.boxes import width_inf
from digslam.observer.core.types import Pair
from digslam.observer.tube.ctc import body_velocity, deriv_arrays, unicycle_velocity

__all__ = ["Tube", "ctc_deriv", "unicycle_velocity", "body_velocity", "heading_from_gyro",
           "heading_from_compass", "dead_reckoning"]  # fmt: skip

_INF = np.inf


def _boxes(name: str, lo: ArrayLike, hi: ArrayLike, rows: int, n: int | None = None) -> Pair:
    """``(rows, n)`` float arrays (a 1-d input is one coordinate); empty rows normalised to ``[+∞, -∞]``."""
    lo_a, hi_a = np.array(lo, dtype=np.float64), np.array(hi, dtype=np.float64)
    if lo_a.ndim == 1 and lo_a.shape == hi_a.shape:
        lo_a, hi_a = lo_a[:, None], hi_a[:, None]
    if lo_a.ndim != 2 or lo_a.shape != hi_a.shape or lo_a.shape[0] != rows:
        raise ValueError(f"{name}: expected lo, hi of shape ({rows}, n), got {lo_a.shape} and {hi_a.shape}")
    if n is not None and lo_a.shape[1] != n:
        raise ValueError(f"{name}: dimension {lo_a.shape[1]}, expected {n}")
    if np.isnan(lo_a).any() or np.isnan(hi_a).any():
        row = int(np.argwhere(np.isnan(lo_a) | np.isnan(hi_a))[0, 0])
        raise ValueError(f"{name}: NaN bound in row {row}")
    empty = (lo_a == _INF) | (hi_a == -_INF)
    bad = (lo_a > hi_a) & ~empty
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise ValueError(f"{name}: lower bound {lo_a[r, c]} above upper bound {hi_a[r, c]} (row {r}, {c})")
    e = (empty | (lo_a > hi_a)).any(axis=1, keepdims=True)
    return np.where(e, _INF, lo_a), np.where(e, -_INF, hi_a)


class Tube:
    """Sliced tube over a time grid ``t[0] < ... < t[T]``: gates (boxes at the grid times) and slices
    (envelope boxes over ``[t_k, t_{k+1}]``). An empty gate or slice means no trajectory is consistent.

    Args:
        t: ``(T+1,)`` finite, strictly increasing times, ``T >= 1``.
        gate_lo, gate_hi: ``(T+1, n)`` (or ``(T+1,)`` for ``n = 1``).
        slice_lo, slice_hi: ``(T, n)``; by default the hull of the two gates of each slice (an
            assumption on the trajectory between grid times, not a consequence of the gates).

    Raises:
        ValueError: naming the argument (shape, order, NaN, ``lo > hi``).

    Attributes:
        inconsistent_at: set by :func:`ctc_deriv` on the empty tube it returns for inconsistent data:
            the first gate index where the contraction found an empty box (None otherwise).
    """

    inconsistent_at: int | None = None

    def __init__(self, t: ArrayLike, gate_lo: ArrayLike, gate_hi: ArrayLike,
                 slice_lo: ArrayLike | None = None, slice_hi: ArrayLike | None = None) -> None:  # fmt: skip
        ta = np.array(t, dtype=np.float64)
        if ta.ndim != 1 or ta.size < 2:
            raise ValueError(f"t: expected a 1-d array of at least 2 times, got shape {ta.shape}")
        with np.errstate(over="ignore", invalid="ignore"):
            steps = np.diff(ta)
        if not np.isfinite(ta).all() or not (steps > 0).all() or not np.isfinite(steps).all():
            raise ValueError("t: times must be finite and strictly increasing (with finite steps)")
        self.t = ta
        self.gate_lo, self.gate_hi = _boxes("gate", gate_lo, gate_hi, ta.size)
        n = self.gate_lo.shape[1]
        if slice_lo is None and slice_hi is None:
            self.slice_lo = np.minimum(self.gate_lo[:-1], self.gate_lo[1:])
            self.slice_hi = np.maximum(self.gate_hi[:-1], self.gate_hi[1:])
        elif slice_lo is None or slice_hi is None:
            raise ValueError("slice_lo: give both slice_lo and slice_hi, or neither")
        else:
            self.slice_lo, self.slice_hi = _boxes("slice", slice_lo, slice_hi, ta.size - 1, n)

    @classmethod
    def _trusted(cls, t: np.ndarray, glo: np.ndarray, ghi: np.ndarray, slo: np.ndarray, shi: np.ndarray
                 ) -> Tube:  # fmt: skip
        """A tube from arrays already checked (internal: results of the kernels), no copy."""
        x = cls.__new__(cls)
        x.t, x.gate_lo, x.gate_hi, x.slice_lo, x.slice_hi = t, glo, ghi, slo, shi
        return x

    @classmethod
    def entire(cls, t: ArrayLike, n: int) -> Tube:
        """The tube ``(-∞, +∞)ⁿ`` at every time."""
        size = np.size(t)
        if int(n) < 1:
            raise ValueError(f"n: dimension must be >= 1, got {n}")
        full = np.full((size, int(n)), _INF)
        return cls(t, -full, full, -full[:-1], full[:-1])

    @property
    def n(self) -> int:
        """Dimension of the state."""
        return int(self.gate_lo.shape[1])

    @property
    def T(self) -> int:  # noqa: N802 (thesis notation)
        """Number of slices."""
        return int(self.t.size - 1)

    @property
    def dt(self) -> np.ndarray:
        """``(T,)`` slice durations (rounded to nearest; :func:`ctc_deriv` encloses them exactly)."""
        return np.diff(self.t)

    def copy(self) -> Tube:
        """An independent copy."""
        return Tube(self.t, self.gate_lo, self.gate_hi, self.slice_lo, self.slice_hi)

    def __and__(self, other: Tube) -> Tube:
        """Intersection of two tubes on the same time grid."""
        if not isinstance(other, Tube) or other.t.shape != self.t.shape or not (other.t == self.t).all():
            raise ValueError("other: tubes must share the same time grid")
        if other.n != self.n:
            raise ValueError(f"other: dimension {other.n} differs from {self.n}")
        glo, ghi = np.maximum(self.gate_lo, other.gate_lo), np.minimum(self.gate_hi, other.gate_hi)
        slo, shi = np.maximum(self.slice_lo, other.slice_lo), np.minimum(self.slice_hi, other.slice_hi)
        return Tube(self.t, glo, np.where(glo > ghi, -_INF, ghi), slo, np.where(slo > shi, -_INF, shi))

    def _locate(self, ts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Gate index where ``ts`` is a grid time, else slice index, and the mask of grid times."""
        if np.isnan(ts).any() or (ts < self.t[0]).any() or (ts > self.t[-1]).any():
            raise ValueError(f"t: times must lie in [{self.t[0]}, {self.t[-1]}]")
        k = np.searchsorted(self.t, ts, side="right") - 1
        on_gate = self.t[k] == ts
        return np.where(on_gate, k, np.minimum(k, self.T - 1)), on_gate

    def __call__(self, t: ArrayLike) -> Pair:
        """Box at time ``t`` (the gate at a grid time, else the slice holding ``t``); ``(n,)`` for a
        scalar time, ``(m, n)`` for ``m`` times."""
        ts = np.asarray(t, dtype=np.float64)
        k, g = self._locate(ts.reshape(-1))
        lo = np.where(g[:, None], self.gate_lo[k], self.slice_lo[np.minimum(k, self.T - 1)])
        hi = np.where(g[:, None], self.gate_hi[k], self.slice_hi[np.minimum(k, self.T - 1)])
        return (lo[0], hi[0]) if ts.ndim == 0 else (lo, hi)

    def eval(self, ta: float, tb: float) -> Pair:
        """Hull of the tube over ``[ta, tb]``: the gates inside it and the slices meeting its interior."""
        if not ta <= tb:
            raise ValueError(f"ta: expected ta <= tb, got {ta} and {tb}")
        self._locate(np.array([ta, tb], dtype=np.float64))
        if ta == tb:
            return self(ta)
        gates = (self.t >= ta) & (self.t <= tb)
        sl = (self.t[:-1] < tb) & (self.t[1:] > ta)
        lo = np.minimum(self.gate_lo[gates].min(axis=0, initial=_INF), self.slice_lo[sl].min(axis=0))
        hi = np.maximum(self.gate_hi[gates].max(axis=0, initial=-_INF), self.slice_hi[sl].max(axis=0))
        return lo, hi

    def widths(self) -> np.ndarray:
        """``(T+1,)`` widest coordinate of each gate, rounded up (0 for an empty gate)."""
        return width_inf(self.gate_lo, self.gate_hi)

    def first_empty(self) -> int | None:
        """Index of the first empty gate or slice (slice ``k`` ranks with gate ``k``), None if none."""
        bad = np.asarray((self.gate_lo > self.gate_hi).any(axis=1))
        bad[:-1] |= (self.slice_lo > self.slice_hi).any(axis=1)
        return int(np.argmax(bad)) if bad.any() else None

    def is_empty(self) -> bool:
        """True when some gate or slice is empty: no trajectory lies in the tube (inconsistent data)."""
        return self.first_empty() is not None

    def contains(self, t_samples: ArrayLike, x_samples: ArrayLike) -> np.ndarray:
        """``(m,)`` mask: whether sample ``x(t_i)`` of a trajectory lies in the tube's box at ``t_i``."""
        ts = np.asarray(t_samples, dtype=np.float64).reshape(-1)
        xs = np.asarray(x_samples, dtype=np.float64).reshape(ts.size, -1)
        if xs.shape[1] != self.n:
            raise ValueError(f"x_samples: expected shape ({ts.size}, {self.n}), got {np.shape(x_samples)}")
        lo, hi = self(ts)
        return np.asarray(((lo <= xs) & (xs <= hi)).all(axis=1))

    def save_npz(self, path: str | Path) -> None:
        """Write the tube to an ``.npz`` file."""
        np.savez(path, t=self.t, gate_lo=self.gate_lo, gate_hi=self.gate_hi,
                 slice_lo=self.slice_lo, slice_hi=self.slice_hi)  # fmt: skip

    @classmethod
    def load_npz(cls, path: str | Path) -> Tube:
        """Read a tube written by :meth:`save_npz` (no pickle)."""
        with np.load(path, allow_pickle=False) as z:
            return cls(z["t"], z["gate_lo"], z["gate_hi"], z["slice_lo"], z["slice_hi"])

    def __repr__(self) -> str:
        return f"Tube(n={self.n}, T={self.T}, t=[{self.t[0]}, {self.t[-1]}], max width={self.widths().max()})"


def _empty_like(x: Tube, at: int | None) -> Tube:
    e = Tube._trusted(x.t, np.full_like(x.gate_lo, _INF), np.full_like(x.gate_hi, -_INF),
                      np.full_like(x.slice_lo, _INF), np.full_like(x.slice_hi, -_INF))  # fmt: skip
    e.inconsistent_at = at
    return e


def ctc_deriv(x: Tube, u_lo: ArrayLike, u_hi: ArrayLike, forward: bool = True, backward: bool = True,
              increment: Pair | None = None) -> Tube:  # fmt: skip
    """``C_d/dt`` for ``ẋ = u`` with ``u(τ) ∈ [u_k]`` for ``τ`` in slice ``k`` (Eq. 2.76, Remark 2.12).

    Gates ``x_{k+1} &= x_k + dt_k[u_k]`` (forward), ``x_k &= x_{k+1} - dt_k[u_k]`` (backward), slices
    ``&= (x_k + [0,dt_k][u_k]) & (x_{k+1} - [0,dt_k][u_k])``, gates ``&=`` both adjacent slices; outward
    rounded, vectorised over time (max-plus closed form, proof in :mod:`digslam.observer.tube.ctc`).

    Args:
        x: the tube to contract (not modified).
        u_lo, u_hi: ``(T, n)`` (or ``(T,)`` for ``n = 1``) derivative bounds per slice.
        forward, backward: which gate passes to run (the slices are always contracted).
        increment: optional ``(T, n)`` bounds ``(d_lo, d_hi)`` of the gate increments ``x_{k+1} - x_k``
            themselves (an odometry increment), intersected with ``dt_k[u_k]`` in the gate passes.

    Returns:
        A new tube; if the data are inconsistent (an empty gate, slice or ``[u_k]``), the tube whose
        every gate and slice is empty (:meth:`Tube.is_empty`, :meth:`Tube.first_empty` ``== 0``), with
        :attr:`Tube.inconsistent_at` the first gate found empty (forward pass first, so with a known
        start it is the first time the data contradict the past).
    """
    if not isinstance(x, Tube):
        raise ValueError(f"x: expected a Tube, got {type(x).__name__}")
    u = _boxes("u", u_lo, u_hi, x.T, x.n)
    if x.is_empty():
        return _empty_like(x, x.first_empty())
    if (u[0] > u[1]).any():
        return _empty_like(x, int(np.argmax((u[0] > u[1]).any(axis=1))))
    glo, ghi, slo, shi, bad = deriv_arrays(
        x.t, (x.gate_lo, x.gate_hi), (x.slice_lo, x.slice_hi), u, forward, backward, increment
    )
    return _empty_like(x, bad) if bad is not None else Tube._trusted(x.t, glo, ghi, slo, shi)


def _scalar(name: str, lo: ArrayLike, hi: ArrayLike) -> Pair:
    return _boxes(name, np.reshape(np.asarray(lo, dtype=np.float64), (1, -1)),
                  np.reshape(np.asarray(hi, dtype=np.float64), (1, -1)), 1)  # fmt: skip


def heading_from_gyro(
    t: ArrayLike, psi0_lo: float, psi0_hi: float, yaw_rate_lo: ArrayLike, yaw_rate_hi: ArrayLike
) -> Tube:
    """1-d heading tube ``ψ̇ = ω``, ``ω ∈ [ω_k]`` on slice ``k``, from ``ψ(t_0) ∈ [ψ0]`` (unwrapped angle).

    Args:
        t: ``(T+1,)`` grid; psi0_lo, psi0_hi: initial heading; yaw_rate_lo, yaw_rate_hi: ``(T,)``.
    """
    p = _scalar("psi0", psi0_lo, psi0_hi)
    x = Tube.entire(t, 1)
    x.gate_lo[0], x.gate_hi[0] = p[0][0, 0], p[1][0, 0]
    return ctc_deriv(x, yaw_rate_lo, yaw_rate_hi, forward=True, backward=False)


def heading_from_compass(
    t: ArrayLike,
    heading_lo: ArrayLike,
    heading_hi: ArrayLike,
    yaw_rate_lo: ArrayLike | None = None,
    yaw_rate_hi: ArrayLike | None = None,
) -> Tube:
    """1-d heading tube from compass intervals at the gates (``(T+1,)``, unwrapped), fused with a gyro.

    Without a yaw rate the slices are the hull of their two gates (an assumption: the heading stays
    between its samples). With ``[ω]`` (``(T,)``) the slices are ``(ψ_k + [0,dt]ω) & (ψ_{k+1} - [0,dt]ω)``
    and the gates are contracted by the gyro forward and backward (:func:`ctc_deriv`): guaranteed.
    """
    if (yaw_rate_lo is None) != (yaw_rate_hi is None):
        raise ValueError("yaw_rate_lo: give both yaw_rate_lo and yaw_rate_hi, or neither")
    x = Tube(t, heading_lo, heading_hi)
    if x.n != 1:
        raise ValueError(f"heading_lo: expected shape (T+1,), got {np.shape(heading_lo)}")
    if yaw_rate_lo is None or yaw_rate_hi is None:
        return x
    full = np.full((x.T, 1), _INF)
    return ctc_deriv(Tube(t, x.gate_lo, x.gate_hi, -full, full), yaw_rate_lo, yaw_rate_hi)


def dead_reckoning(
    t: ArrayLike, x0_lo: ArrayLike, x0_hi: ArrayLike, u_lo: ArrayLike, u_hi: ArrayLike
) -> Tube:
    """Guaranteed integration of ``ẋ = u`` from ``x(t_0) ∈ [x0]`` (``(n,)``): :func:`ctc_deriv` forward."""
    x0 = _scalar("x0", x0_lo, x0_hi)
    x = Tube.entire(t, x0[0].shape[1])
    x.gate_lo[0], x.gate_hi[0] = x0[0][0], x0[1][0]
    return ctc_deriv(x, u_lo, u_hi, forward=True, backward=False)
