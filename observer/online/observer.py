"""Online guaranteed Dig-SLAM: Algorithm 6.3 (thesis §6.4, Eq. 6.21–6.23) run as a filter, one step at a time.

Each :meth:`OnlineDigSlam.update` takes the next single-step record and

1. predicts ``ψ_k ∈ [ψ_{k-1}] + [dt]·[ω_k]`` (intersected with the compass) and the heading over the
   slice, then ``x_k ∈ x_{k-1} + [dt]·R([ψ] on the slice)·[v_k]`` with the body-frame velocity
   ``v = (v_1, v_2)`` = (``speed``, ``lateral``) (``x' = R(ψ) v``, Eq. 3.59, 6.12, B.20; a unicycle record,
   ``lateral = [0, 0]``, gives Eq. 6.23's step to the bit; record ``k``'s velocity and yaw rate bound the
   truth over the slice ``[t_{k-1}, t_k]`` that ends at it: the data contract of
   :mod:`digslam.observer.record.mission`); compiled scalar outward rounding (:func:`.pose_jit.predict`,
   :func:`.pose_jit.rotate`), each correctly rounded operation stepped one ulp outward, ``cos``/``sin``
   widened by more than :data:`~.rounding.LIBM_ULPS`;
2. contracts the box with the impacts ``dist(x_k, comp M⁻) <= y⁺`` (Eq. 6.22) on a window
   (:func:`.pose_jit.contract`), then (``cones``, the default) with their directional form, each echo's
   cone meeting ``comp M⁻`` (:func:`.cones_jit.contract_cones`);
3. digs ``M⁻ := M⁻ ∪ g⁻¹_{[x_k]}(Z⁻)`` (Eq. 6.21) and grows the explored zone: certainly sensed =
   dug, possibly sensed = not proved outside every sensed sector, one compiled pass over the cells in
   sensor reach (:func:`.mark_jit.dig_and_mark`);
4. optionally (``smoothing_window = W``) contracts the last ``W`` boxes backward,
   ``x_j &= x_{j+1} - [d_j]``, and digs again the readings of the boxes that shrank; or
   (``loop_smoothing``, :mod:`.history`) at a loop closure, a backward-forward pass over the stored history
   that re-digs it and recomputes the possibly sensed zone, so that dark grows as the boxes shrink.

Steps 1–3 run as one compiled call (:func:`.step_jit.filter_step_flat`, the same kernels chained), and
:attr:`OnlineDigSlam.touched` grows by the smallest window holding the cells the step changed.

State is a fixed set of arrays (plus a ring of ``W`` steps, or the ``history`` steps of loop smoothing):
memory does not grow with the episode.
An empty box means the data contradict their bounds: the filter says so and stops, and withdraws its claims.

**What is claimed, and when** (``q = 0``). If every interval of the records contains the truth, the true
position lies in the box, every dug cell is free and every cell coded clear / dark was / was not sensed.
If some reading misses the truth, the filter detects it only when the box becomes empty, which may happen
later or never: until then that reading's claims stand, and one false long echo (or a range shifted up)
digs false free space at once. The filter never reads the record's ``outlier`` flag.

**q-relaxed mode** (``OnlineConfig(q=q)``, thesis §2.6.2, the relaxed intersection of Eq. 2.54). The premise
becomes: *at most* ``q`` *of the range readings of each step* (per step, not per window of steps: the
readings of different steps may hold ``q`` outliers each) miss the truth; the odometry, the compass and
``X₀`` still hold. Then, for every step,

* a cell is dug (``M⁻``) and certainly sensed (clear) only where at least ``q + 1`` readings of the step
  prove it free (per cell and step: counted in one pass, then dug where the count reaches ``q + 1``); one
  of them is an inlier, so the claim holds. With ``q >=`` the number of readings nothing is ever dug;
* the impact contraction (Eq. 6.22) keeps the positions consistent with all but at most ``q`` echoes,
  the hull of the q-relaxed intersection: ``dist(x, comp M⁻) <=`` the ``(q + 1)``-th smallest ``y⁺``
  (:func:`.pose_jit.impact_bound_q`);
* the possibly sensed zone grows with the maximum range ``r_max`` of every reading (an outlier's ``y⁺``
  may be below the truth), so no dark cell was sensed.

So up to ``q`` bad readings per step make no false claim at all. With more, the guarantee is that of
``q = 0`` with bad data: an empty box is still reported (the filter stops and withdraws its claims), but
claims made before that may be false. ``q = 0`` counts nothing: each reading digs at once
(:func:`.mark_jit.dig_and_mark`).

>>> from digslam.observer.record.mission import MissionRecord
>>> def step(k):
...     return MissionRecord(t=0.1 * k, speed=[0.99, 1.01], yaw_rate=[-0.01, 0.01], heading=[-1e-3, 1e-3],
...         alpha=[0.0], gamma=[np.pi], r_max=[5.0], range=[[1.99 - 0.1 * k, 2.01 - 0.1 * k]],
...         no_echo=[False], outlier=[False])                                     # a wall at x = 2
>>> f = OnlineDigSlam(Grid((-3.0, -3.0), (3.0, 3.0), (60, 60)))
>>> f.reset([0.0, 0.0], [0.0, 0.0], step(0))
>>> for k in range(1, 6):
...     f.update(step(k))
>>> f.consistent, f.steps, bool(f.pose_lo[0] <= 0.5 <= f.pose_hi[0]), bool(f.dig.free[30, 52])
(True, 6, True, False)
"""

from __future__ import annotations

import math
import time
from collections import deque
from typing import Any

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.config import Config, check, check_int, config_dataclass
from digslam.observer.online.dig_types import NO_MEAN, CellSets, PoseBox, StepRecord
from digslam.observer.online.history import StepHistory
from digslam.observer.online.mark_jit import dig_and_mark_q
from digslam.observer.online.step_jit import filter_step_flat
from digslam.observer.online.window import WindowDigMap
from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA

__all__ = ["OnlineConfig", "OnlineDigSlam"]

_INF = math.inf


@config_dataclass
class OnlineConfig(Config):
    """Settings of :class:`OnlineDigSlam`.

    Attributes:
        smoothing_window: fixed-lag backward smoothing over the last ``W`` steps (0 = off).
        impacts: apply the impact contractor (Eq. 6.22).
        cones: with ``impacts``, also its directional form: each echo's cone meets ``comp M⁻``
            (:mod:`.cones_jit`), which bounds the position on both sides between walls.
        cone_every: apply the directional form every ``cone_every`` steps (the box grows by the odometry
            bounds, about 0.2 mm a step by default, far less than the slices the cones cut; 1: every step).
        q: the q-relaxed mode (thesis §2.6.2): at most ``q`` of the range readings of ONE step are outliers
            (their intervals may miss the truth; which ones is unknown). 0 (default): none, every claim as
            in Algorithm 6.3. See the module docstring.
        loop_smoothing: smoothing at loop closures (:mod:`.history`): when the box has shrunk by more than
            this share of its widest width since the last pass, a backward-forward pass over the stored
            steps re-digs them and recomputes the possibly sensed zone. 0 (default): off.
        history: the steps kept for ``loop_smoothing`` (memory bound: this many steps of the record plus one
            grid mask; older steps are frozen).
    """

    smoothing_window: int = 0
    impacts: bool = True
    cones: bool = True
    cone_every: int = 4
    q: int = 0
    loop_smoothing: float = 0.0
    history: int = 4000

    def __post_init__(self) -> None:
        check_int("smoothing_window", self.smoothing_window, 0)
        v = self.loop_smoothing
        ok = isinstance(v, int | float) and not isinstance(v, bool) and 0.0 <= v < 1.0
        check(ok, "loop_smoothing", f"must be a share in [0, 1) (0: off), got {v!r}")
        check_int("history", self.history, 2)
        for name in ("impacts", "cones"):
            v = getattr(self, name)
            check(isinstance(v, bool | np.bool_), name, f"must be a bool, got {v!r}")
        check_int("q", self.q, 0, " (outliers allowed per step)")
        check_int("cone_every", self.cone_every, 1)


#: The lateral velocity of a record built without one (a unicycle, the record's default); never written.
_NO_SLIP = np.zeros(2)


def band_of(psi: np.ndarray) -> tuple[float, float]:
    """The heading interval ``(ψ⁻, ψ⁺)`` of a ``(2,)`` state array, as floats."""
    return float(psi[0]), float(psi[1])


def _step_record(rec: MissionRecord, dt: float) -> StepRecord:
    """The kernels' view of a single-step record (:class:`.dig_types.StepRecord`): its arrays, not copied
    (``lateral`` unset, as in a record built without ``MissionRecord.__init__``: ``[0, 0]``, a unicycle;
    ``mean_velocity`` unset: not measured; ``mount`` and ``slack`` unset: centred cones)."""
    lat = rec.lateral if rec.lateral is not None else _NO_SLIP
    mean = rec.mean_velocity if rec.mean_velocity is not None else NO_MEAN
    mount = rec.mount if rec.mount is not None else np.zeros((rec.alpha.shape[0], 2))
    slack = rec.slack if rec.slack is not None else np.zeros((rec.alpha.shape[0], 2))
    return StepRecord(dt, rec.speed, lat, rec.yaw_rate, rec.heading, rec.alpha, rec.gamma, rec.r_max,
                      rec.range, rec.no_echo, mean, mount, slack)  # fmt: skip


class OnlineDigSlam:
    """The online Dig-SLAM filter (see the module docstring).

    Args:
        grid: the cells of ``M⁻`` and of the explored zone (they must cover what the robot senses).
        config: :class:`OnlineConfig` (defaults when None).

    Attributes:
        pose_lo, pose_hi: ``(2,)`` position box at the last step (``[+inf, -inf]`` once inconsistent).
        heading_lo, heading_hi: heading interval at the last step.
        dig: the dig zone ``M⁻`` (:class:`~.window.WindowDigMap`; ``dig.free`` bool ``(ny, nx)``).
        sensed_sure, sensed_maybe: ``(ny, nx)`` bool, certainly / possibly sensed cells.
        cells: those sets as the kernels take them (:class:`.dig_types.CellSets`: ``dig.free``,
            ``sensed_sure``, ``sensed_maybe`` and the per-cell counts of the q-relaxed mode), per episode.
        consistent, inconsistent_step: False and the step index (``reset`` is step 0) once the data
            contradicted their bounds; the sets then carry no guarantee and ``update`` does nothing.
        steps: steps folded in (``reset`` counts one); last_update_seconds: wall time of the last update.
        touched: window ``(r0, r1, c0, c1)`` of the cells changed since :meth:`take_touched`.
    """

    def __init__(self, grid: Grid, config: OnlineConfig | None = None) -> None:
        if not isinstance(grid, Grid):
            raise ValueError(f"grid: expected a Grid, got {type(grid).__name__}")
        if config is not None and not isinstance(config, OnlineConfig):
            raise ValueError(f"config: expected an OnlineConfig, got {type(config).__name__}")
        self.grid, self.config = grid, config or OnlineConfig()
        self._ring: deque = deque(maxlen=self.config.smoothing_window + 1)
        impacts = self.config.impacts
        self._impacts, self._q = (2 if self.config.cones else 1) if impacts else 0, int(self.config.q)
        self._window, self._cone_every = int(self.config.smoothing_window), int(self.config.cone_every)
        self._t_prev = -math.inf
        self._blank()

    def _blank(self) -> None:
        self.pose_lo, self.pose_hi = np.full(2, _INF), np.full(2, -_INF)
        self.heading_lo, self.heading_hi = _INF, -_INF
        self.dig = WindowDigMap(self.grid)
        self.sensed_sure = np.zeros(self.grid.shape, dtype=bool)
        self.sensed_maybe = np.zeros(self.grid.shape, dtype=bool)
        # per-cell reading counts and stamps of the q-relaxed mode (zero between steps; unused when q = 0)
        self._cnt = np.zeros((2, *self.grid.shape) if self._q else (2, 1, 1), dtype=np.int32)
        self._lst = np.zeros(self.grid.shape[0] * self.grid.shape[1] + 1 if self._q else 1, dtype=np.int32)
        #: The cell sets as the kernels read them (:class:`.dig_types.CellSets`), built once per episode.
        self.cells = CellSets(self.dig.free, self.sensed_sure, self.sensed_maybe, self._cnt, self._lst)
        # the same, and the grid's frame, as plain tuples: what :func:`.step_jit.filter_step_flat` takes
        self._cells_t, self._frame_t = tuple(self.cells), tuple(self.dig.frame)
        self.consistent = False
        self.inconsistent_step: int | None = None
        self.steps, self.last_update_seconds = 0, 0.0
        self._prev: MissionRecord | None = None
        self._ring.clear()
        self.touched = (0, self.grid.shape[0], 0, self.grid.shape[1])
        cfg = self.config
        #: The loop-closure history (:class:`.history.StepHistory`), or None when ``loop_smoothing`` is off.
        self.history = (StepHistory(self.grid.shape, cfg.history, cfg.loop_smoothing, self._q)
                        if cfg.loop_smoothing else None)  # fmt: skip

    def _check_record(self, rec: Any, name: str = "rec") -> MissionRecord:
        if not isinstance(rec, MissionRecord) or rec.t.ndim != 0:
            raise ValueError(f"{name}: expected a single-step MissionRecord (scalar t)")
        prev = self._prev
        if name == "rec" and prev is not None:
            self._step_dt(rec, prev)
        return rec

    @staticmethod
    def _step_dt(rec: MissionRecord, prev: MissionRecord) -> float:
        """``t_k - t_{k-1}`` of ``rec`` after ``prev`` (raises if they do not follow each other)."""
        if rec.alpha.shape[-1] != prev.alpha.shape[-1]:  # n_sensors
            n = prev.n_sensors
            raise ValueError(f"rec: {rec.n_sensors} sensors, the episode started with {n}")
        t, t0 = float(rec.t), float(prev.t)
        if not t > t0:
            raise ValueError(f"rec: time {t} does not follow {t0}")
        return t - t0

    def reset(self, x0_lo: Any, x0_hi: Any, first: MissionRecord) -> None:
        """Start an episode from the box ``X₀`` (Eq. 6.15) and the record at ``t_0``."""
        lo, hi = np.array(x0_lo, dtype=np.float64).ravel(), np.array(x0_hi, dtype=np.float64).ravel()
        g = self.grid
        if lo.shape != (2,) or hi.shape != (2,) or not (np.isfinite(lo).all() and np.isfinite(hi).all()):
            raise ValueError(f"x0_lo, x0_hi: expected a finite 2-d box, got {x0_lo} and {x0_hi}")
        if np.any(lo > hi) or np.any(lo < g.lo) or np.any(hi > g.hi):
            raise ValueError(f"x0_lo, x0_hi: expected lo <= hi inside the grid's frame, got {lo} and {hi}")
        first = self._check_record(first, "first")
        self._blank()
        self.pose_lo, self.pose_hi = lo, hi
        self.heading_lo, self.heading_hi = float(first.heading[0]), float(first.heading[1])
        self.consistent = True
        self._measure(first, None)

    def update(self, rec: MissionRecord) -> None:
        """Fold in the next single-step record (does nothing once inconsistent)."""
        prev = self._prev
        if prev is None:
            raise ValueError("rec: call reset() before update()")
        if not isinstance(rec, MissionRecord) or rec.t.ndim != 0:
            raise ValueError("rec: expected a single-step MissionRecord (scalar t)")
        t = float(rec.t)
        if rec.alpha.shape[-1] != prev.alpha.shape[-1] or not t > self._t_prev:
            self._step_dt(rec, prev)  # raises, naming what is wrong
        dt = t - self._t_prev
        if not self.consistent:
            return
        start = time.perf_counter()
        # the kernels' StepRecord as a plain tuple of its fields (not copied): see filter_step_flat
        record = _step_record(rec, dt)
        step = tuple(record)
        # the kernel overwrites copies of the state: the arrays handed out are never changed
        lo, hi, psi = self.pose_lo.copy(), self.pose_hi.copy(), np.array((self.heading_lo, self.heading_hi))
        impacts = self._impacts
        if impacts == 2 and self.steps % self._cone_every:
            impacts = 1  # the cones every cone_every steps (skipping a contractor claims nothing false)
        code, r0, r1, c0, c1, d = filter_step_flat(self._cells_t, self._frame_t, step, lo, hi, psi, impacts,
                                                   self._q)  # fmt: skip
        if code:
            return self._fail(start)
        self.pose_lo, self.pose_hi = lo, hi
        self.heading_lo, self.heading_hi = psi.tolist()
        if r0 < r1 and c0 < c1:
            self._touch(r0, r1, c0, c1)
        if self._window:
            band = (self.heading_lo, self.heading_hi)
            self._ring.append([record, self.pose_lo.copy(), self.pose_hi.copy(), band, d])
        self._prev, self._t_prev = rec, t
        self.steps += 1
        if self._window and not self._smooth():
            return self._fail(start)
        h = self.history
        if h is not None:
            h.push(step, float(rec.t), self.pose_lo, self.pose_hi, band_of(psi), d, self.cells,
                   self.dig.frame)  # fmt: skip
            if h.due(self.pose_lo, self.pose_hi):
                ok, changed = h.smooth(self.cells, self.dig.frame)
                if not ok:
                    return self._fail(start)
                self.pose_lo, self.pose_hi = h.lo[h.n - 1].copy(), h.hi[h.n - 1].copy()
                if changed:
                    self.touched = (0, self.grid.shape[0], 0, self.grid.shape[1])
        self.last_update_seconds = time.perf_counter() - start
        return None

    # ------------------------------------------------------------------ internals
    def _fail(self, start: float) -> None:
        self.consistent, self.inconsistent_step = False, self.steps
        self.pose_lo, self.pose_hi = np.full(2, _INF), np.full(2, -_INF)
        self.heading_lo, self.heading_hi = _INF, -_INF
        self.steps += 1
        self.last_update_seconds = time.perf_counter() - start

    def _dig(self, step: StepRecord, lo: np.ndarray, hi: np.ndarray, psi: tuple[float, float],
             mark: bool = False) -> None:  # fmt: skip
        """Eq. 6.21 for the readings of one step (the dug cells are certainly sensed: radius ``<= r_max``;
        with ``q > 0`` only the cells proved free by ``q + 1`` of them); with ``mark``, grow the possibly
        sensed zone with the upper ranges (``q > 0``: the maximum ranges), :func:`.dig_and_mark_q`."""
        box = PoseBox(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]), float(psi[0]), float(psi[1]))
        r0, r1, c0, c1 = dig_and_mark_q(self.cells, self.dig.frame, box, step, mark, self._q)
        self._touch(r0, r1, c0, c1)

    def _touch(self, r0: int, r1: int, c0: int, c1: int) -> None:
        """Grow :attr:`touched` to hold the window ``[r0:r1, c0:c1]`` of changed cells."""
        if r0 < r1 and c0 < c1:
            t0, t1, u0, u1 = self.touched
            if t0 >= t1:
                self.touched = (r0, r1, c0, c1)
            else:
                self.touched = (min(t0, r0), max(t1, r1), min(u0, c0), max(u1, c1))

    def _measure(self, rec: MissionRecord, d: tuple[float, float, float, float] | None) -> None:
        """Dig the readings of the first step and grow the possibly sensed zone; push the step."""
        psi, step = (self.heading_lo, self.heading_hi), _step_record(rec, 0.0)
        self._dig(step, self.pose_lo, self.pose_hi, psi, mark=True)
        if self.config.smoothing_window:
            self._ring.append([step, self.pose_lo.copy(), self.pose_hi.copy(), psi, d])
        if self.history is not None:
            self.history.push(step, float(rec.t), self.pose_lo, self.pose_hi, psi, None, self.cells,
                              self.dig.frame)  # fmt: skip
        self._prev, self._t_prev = rec, float(rec.t)
        self.steps += 1

    def _smooth(self) -> bool:
        """Backward pass ``x_j &= x_{j+1} - [d_j]`` over the ring; digs again the boxes that shrank."""
        ring = list(self._ring)
        for j in range(len(ring) - 2, -1, -1):
            _, lo, hi, psi, _ = ring[j]
            d = np.array(ring[j + 1][4])  # the displacement box (d_x⁻, d_y⁻, d_x⁺, d_y⁺) of step j + 1
            nlo = np.maximum(lo, rnd.step_down(ring[j + 1][1] - d[2:]))
            nhi = np.minimum(hi, rnd.step_up(ring[j + 1][2] - d[:2]))
            if not np.all(nlo <= nhi):
                return False
            if np.array_equal(nlo, lo) and np.array_equal(nhi, hi):
                break
            ring[j][1], ring[j][2] = nlo, nhi
            self._dig(ring[j][0], nlo, nhi, psi)
        return True

    # ------------------------------------------------------------------ outputs
    def take_touched(self) -> tuple[int, int, int, int]:
        """Rows ``r0:r1`` and columns ``c0:c1`` holding every cell of ``dig.free``, ``sensed_sure`` and
        ``sensed_maybe`` changed since the last call (the whole grid after ``reset``); then clears it."""
        out, self.touched = self.touched, (0, 0, 0, 0)
        return out

    def explored(self) -> np.ndarray:
        """``(ny, nx)`` int8: CLEAR (certainly sensed), PENUMBRA (possibly), DARK (certainly not)."""
        out = np.full(self.grid.shape, DARK, dtype=np.int8)
        out[self.sensed_maybe] = PENUMBRA
        out[self.sensed_sure] = CLEAR
        return out

    def clear_mask(self) -> np.ndarray:
        """Certified coverage: proved free and certainly explored."""
        return self.sensed_sure & self.dig.free
