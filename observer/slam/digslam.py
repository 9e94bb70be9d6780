"""Dig-SLAM on a whole record (thesis §6.4, Eq. 6.18–6.24): its settings and result, the pieces that act on a
tube, and Algorithm 6.3 as the thesis writes it.

:func:`~digslam.observer.online.smoother.dig_slam` is the offline observer to use: the fixpoint of every
contractor of the online filter over the record (its kernels live in :mod:`digslam.observer.online`), never
less sharp than the filter. :func:`thesis_dig_slam` here is Algorithm 6.3 itself, the reference that
:func:`~.explicit_slam.explicit_slam` specialises and that the thesis's Fig. 6.13 counts. It iterates the two
contractors of the constraint network (6.24) to a fixpoint:

1. ``[x](·) := C_d/dt([x](·))`` with ``ẋ = R(ψ) v`` and the body-frame velocity ``v = (v_1, v_2)``
   (Eq. 3.59, 6.12, B.20; Eq. 6.23 is the unicycle ``v_2 = 0``), forward and backward;
2. ``M⁻ := M⁻ ∪ g⁻¹_{[x](t_i)}(Z(t_i))`` for every reading (Eq. 6.21, :meth:`DigMap.dig_disks`,
   :meth:`DigMap.dig_sectors`);
3. ``[x](t_i) := C_g^≠([x](t_i), ΔZ(t_i), M⁻)`` (Eq. 6.22, :meth:`DigMap.contract_impacts`).

Every step is a sound contractor, so the order does not matter for the guarantee: each iteration digs with
all the gates, then contracts all the gates against the whole ``M⁻`` (a Jacobi sweep of Algorithm 6.3, at
least as strong as its sequential loop since ``M⁻`` only grows). An empty gate means the data contradict
their bounds: the result then says so (``consistent`` is False) and carries no sets.

Data contract (:mod:`.record`): ``speed[k]``, ``lateral[k]`` (the body-frame velocity ``v_1``, ``v_2``) and
``yaw_rate[k]`` bound the true values over the whole slice ``[t_{k-1}, t_k]`` that ends at ``t_k``;
``heading[k]`` bounds the heading at ``t_k``; ``range[k]`` bounds the ranges from the pose at ``t_k``.
A measured odometry increment ``mean_velocity[k]`` also bounds the gate increment
``x_k - x_{k-1} ∈ [dt]·R([ψ_{k-1}])·[v̄]`` (:func:`odometry_increment`, used by ``C_d/dt``'s gate passes).

>>> from digslam.observer.record.mission import MissionRecord
>>> n = 11
>>> rec = MissionRecord(t=np.arange(n) * 0.1, speed=np.tile([0.99, 1.01], (n, 1)),
...     yaw_rate=np.tile([-0.01, 0.01], (n, 1)), heading=np.tile([-0.001, 0.001], (n, 1)),
...     alpha=np.zeros((n, 1)), gamma=np.full((n, 1), np.pi), r_max=np.full((n, 1), 5.0),
...     range=np.stack([2 - np.arange(n) * 0.1 - 0.01, 2 - np.arange(n) * 0.1 + 0.01], 1)[:, None],
...     no_echo=np.zeros((n, 1), bool), outlier=np.zeros((n, 1), bool))        # a wall at x = 2
>>> res = thesis_dig_slam(rec, Grid((-3.0, -3.0), (3.0, 3.0), (120, 120)), [0.0, 0.0], [0.0, 0.0])
>>> res.consistent, bool(res.dig.free[60, 60]), bool(res.dig.free[60, 110])   # origin free, x=2.5 not
(True, True, False)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from digslam.observer.core import rounding as rnd
from digslam.observer.core.config import Config, check, check_finite_nonneg, check_int, config_dataclass
from digslam.observer.core.types import Pair
from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord
from digslam.observer.slam.digmap import DigMap
from digslam.observer.slam.explored import explored_disks_grid, explored_union
from digslam.observer.thick.cells import CLEAR, DARK, UNKNOWN
from digslam.observer.tube.ctc import increments
from digslam.observer.tube.tube import Tube, body_velocity, ctc_deriv, heading_from_compass


@config_dataclass
class DigSlamConfig(Config):
    """Settings of :func:`dig_slam`.

    Attributes:
        max_iter: most fixpoint iterations (each digs, contracts the impacts and runs ``C_d/dt``).
        tol: stop when an iteration shrinks the summed gate widths by less than this fraction.
        impacts: apply the impact contractor (Eq. 6.22); without it the result is dead reckoning plus
            digging (the thesis's "before contraction").
        cones: with ``impacts``, also its directional form, each echo's cone meeting ``comp M⁻``
            (:func:`~digslam.observer.online.smoother.dig_slam` only).
        cone_every: in the filter pass of ``dig_slam``, the cones every ``cone_every`` steps (as
            :class:`~digslam.observer.online.observer.OnlineConfig`); its fixpoint sweeps apply them at
            every step.
        q: the q-relaxed mode (thesis §2.6.2): at most ``q`` of the range readings of one step miss the truth
            (``dig_slam`` only; :func:`thesis_dig_slam` refuses ``q > 0``).
        explored: add the explored-zone proofs of App. B on the final tube (:func:`explored_zone`: clear,
            proved penumbra, dark). None (default): :func:`thesis_dig_slam` computes them and
            ``dig_slam`` does not (its explored zone is the filter kernels' certainly and possibly sensed
            cells from the final boxes; the proofs add nothing to an omnidirectional sensor's and cost
            about 0.2 ms per step); False: neither (``thesis_dig_slam`` then has no explored zone). The
            proofs trust every reading: ``dig_slam`` refuses ``explored=True`` with ``q > 0``.
    """

    max_iter: int = 10
    tol: float = 5e-3
    impacts: bool = True
    cones: bool = True
    cone_every: int = 4
    q: int = 0
    explored: bool | None = None

    def __post_init__(self) -> None:
        check_int("max_iter", self.max_iter, 1)
        check_finite_nonneg("tol", self.tol)
        for name in ("impacts", "cones", "explored"):
            v = getattr(self, name)
            ok = isinstance(v, bool | np.bool_) or (v is None and name == "explored")
            check(ok, name, f"must be a bool{' or None' if name == 'explored' else ''}, got {v!r}")
        check_int("cone_every", self.cone_every, 1)
        check_int("q", self.q, 0, " (outliers allowed per step)")


@dataclass
class DigSlamResult:
    """Output of :func:`dig_slam`.

    Attributes:
        consistent: False when some gate became empty (the data contradict their bounds).
        first_empty: index of the first empty gate, or None.
        tube: the contracted position tube (None when inconsistent).
        dig: the dig zone ``M⁻`` (None when inconsistent).
        explored: the explored zone ``[Z⁻, Z⁺]`` on the grid (App. B), int8 codes of
            :mod:`.thick.sep` (clear, penumbra, dark, unknown); None when inconsistent (or, for
            :func:`thesis_dig_slam`, without ``explored``).
        heading: the heading tube used for the velocity (compass and gyro fused).
        iterations: fixpoint iterations run.
        widths: per iteration, gate widths ``(T+1,)`` before the impact contractor, after it, and after
            ``C_d/dt`` (keys ``"before"``, ``"impacts"``, ``"deriv"``); Fig. 6.13.
        dead_reckoning: gate widths of the initial dead-reckoning tube.
        online_widths: gate widths of the online filter's boxes on the same record (``dig_slam`` only).
    """

    consistent: bool
    first_empty: int | None
    tube: Tube | None
    dig: DigMap | None
    heading: Tube
    iterations: int
    widths: list[dict[str, np.ndarray]] = field(default_factory=list)
    dead_reckoning: np.ndarray | None = None
    explored: np.ndarray | None = None
    online_widths: np.ndarray | None = None

    def clear_mask(self) -> np.ndarray:
        """Certified coverage: proved free and certainly explored (``(ny, nx)`` bool)."""
        if self.dig is None or self.explored is None:
            raise ValueError("clear_mask: no explored zone (an inconsistent record, or explored=False)")
        return self.dig.free & (self.explored == CLEAR)


def explored_zone(grid: Grid, record: MissionRecord, tube: Tube, heading: Tube) -> np.ndarray:
    """Explored zone of the readings (App. B patches): each sensor saw up to its true range.

    The visible set of a reading is the disk or sector of radius ``y ∈ [y⁻, y⁺]`` (``r_max`` exactly for
    no echo) around the pose of the gate. Disks go through :func:`explored_disks_grid` (clear, penumbra
    and dark proofs). Sectors take the fast sound path: clear where the cell is inside the sector of
    radius ``y⁻`` for every pose and heading (:meth:`DigMap.dig_sectors`), dark where it is proved outside
    the disk of radius ``y⁺`` around every pose, unknown elsewhere (the full sector tests of
    :func:`.explored_sweep.explored_sectors_grid` prove penumbra too but cost far more per reading).
    The sensors' zones are joined by :func:`explored_union`. The cones must be centred and read at the
    record's instant (``record.centred``).
    """
    if not record.centred:
        raise ValueError("record: the explored-zone proofs take centred cones read at the record's instant")
    lo_r = record.range[..., 0]
    hi_r = np.where(record.no_echo, record.r_max, record.range[..., 1])
    parts = []
    k, s = np.nonzero(record.gamma >= rnd.PI_DOWN)
    if k.size:
        parts.append(explored_disks_grid(grid, tube.gate_lo[k], tube.gate_hi[k], lo_r[k, s], hi_r[k, s]))
    k, s = np.nonzero(record.gamma < rnd.PI_DOWN)
    if k.size:
        st = explored_disks_grid(grid, tube.gate_lo[k], tube.gate_hi[k], np.zeros(k.size), hi_r[k, s])
        sure = DigMap(grid)
        sure.dig_sectors(tube.gate_lo[k], tube.gate_hi[k], heading.gate_lo[k, 0], heading.gate_hi[k, 0],
                         record.alpha[k, s], record.gamma[k, s], lo_r[k, s])  # fmt: skip
        part = np.where(st == DARK, DARK, UNKNOWN).astype(np.int8)
        part[sure.free] = CLEAR
        parts.append(part)
    return explored_union(parts)


def dig_readings(
    dig: DigMap, record: MissionRecord, tube: Tube, heading: Tube, gates: np.ndarray | None = None
) -> None:
    """Eq. 6.21 for every reading (of the ``gates`` selected by a boolean mask, or all): omnidirectional
    readings dig disks, sonar cones dig sectors."""
    ok = np.isfinite(record.range[..., 0]) & (record.range[..., 0] > 0)
    if gates is not None:
        ok &= gates[:, None]
    k, s = np.nonzero(ok)
    lo, hi = tube.gate_lo[k], tube.gate_hi[k]
    r = record.range[k, s, 0]
    omni = record.gamma[k, s] >= rnd.PI_DOWN
    dig.dig_disks(lo[omni], hi[omni], r[omni])
    c = ~omni
    dig.dig_sectors(lo[c], hi[c], heading.gate_lo[k[c], 0], heading.gate_hi[k[c], 0],
                    record.alpha[k[c], s[c]], record.gamma[k[c], s[c]], r[c])  # fmt: skip


def odometry_velocity(record: MissionRecord, heading: Tube) -> Pair:
    """Per-slice velocity boxes ``[u_k] ⊃ {R(ψ) v}`` of ``ẋ = R(ψ) v`` (Eq. 3.59, 6.12, B.20):
    ``v = (v_1, v_2) ∈ ([speed_k], [lateral_k])`` and ``ψ`` in the heading tube's slice ``k``
    (:func:`~.tube.body_velocity`; a unicycle record, ``lateral = [0, 0]``, gives the tube of Eq. 6.23 to
    the bit).

    Returns:
        ``(u_lo, u_hi)`` of shape ``(T, 2)``, slice ``k`` bounded by record ``k + 1``'s odometry.
    """
    v_lo = np.stack([record.speed[1:, 0], record.lateral[1:, 0]], axis=1)
    v_hi = np.stack([record.speed[1:, 1], record.lateral[1:, 1]], axis=1)
    return body_velocity(v_lo, v_hi, heading.slice_lo[:, 0], heading.slice_hi[:, 0])


def odometry_increment(record: MissionRecord, heading: Tube) -> Pair | None:
    """Per-slice bounds of the gate increments ``x_{k+1} - x_k`` from the odometry increment
    ``mean_velocity`` (the velocity averaged over the slice in the body frame at its start):
    ``x_{k+1} - x_k = dt_k R(ψ_k) v̄`` lies in ``[dt_k]·R([ψ_k])·[v̄]`` with ``[ψ_k]`` the heading tube's gate
    (:func:`~.tube.body_velocity` on the gates, :func:`~digslam.observer.tube.ctc.increments`, outward
    rounded). None when no slice measures it (a unicycle record, or one saved before the field existed).

    Returns:
        ``(d_lo, d_hi)`` of shape ``(T, 2)`` (``[-inf, inf]`` on the slices that do not measure it), or None.
    """
    mv = record.mean_velocity[1:]
    if not np.isfinite(mv).any():
        return None
    u_lo, u_hi = body_velocity(mv[..., 0], mv[..., 1], heading.gate_lo[:-1, 0], heading.gate_hi[:-1, 0])
    d_lo, d_hi = increments(record.t, u_lo, u_hi)
    unmeasured = ~np.isfinite(mv).all(axis=(1, 2))
    d_lo[unmeasured], d_hi[unmeasured] = -np.inf, np.inf
    return d_lo, d_hi


def impact_bound(record: MissionRecord) -> np.ndarray:
    """Per time, the smallest upper range bound over the echoing sensors (``inf`` if none echoed)."""
    hi = np.where(record.no_echo, np.inf, record.range[..., 1])
    return hi.min(axis=1)


def thesis_dig_slam(
    record: MissionRecord, grid: Grid, x0_lo: Any, x0_hi: Any, config: DigSlamConfig | None = None
) -> DigSlamResult:
    """Run Algorithm 6.3 as the thesis writes it on a recorded mission, to its fixpoint (the module
    docstring; :func:`~digslam.observer.online.smoother.dig_slam` is sharper: it adds the filter's cone
    contractor, the odometry displacement boxes and the q-relaxed readings).

    Args:
        record: a stacked mission of ``T + 1`` samples (see the data contract above).
        grid: the cells of ``M⁻`` (they must cover the region the robot senses).
        x0_lo, x0_hi: the initial position box ``X₀`` (Eq. 6.15).
        config: :class:`DigSlamConfig` (defaults when None).

    Returns:
        A :class:`DigSlamResult`; check ``consistent`` before using the sets.

    Raises:
        ValueError: on a single-step record, or an initial box that is not a 2-d box.
    """
    cfg = config or DigSlamConfig()
    if cfg.q:
        raise ValueError("config: thesis_dig_slam has no q-relaxed mode (q must be 0); use dig_slam")
    if record.t.ndim != 1 or len(record) < 2:
        raise ValueError("record: expected a stacked mission of at least two samples")
    if not record.centred:
        raise ValueError(
            "record: thesis_dig_slam takes centred cones read at the record's instant (mount "
            "and slack zero); use dig_slam for mounted sensors"
        )
    x0_lo, x0_hi = np.asarray(x0_lo, dtype=np.float64), np.asarray(x0_hi, dtype=np.float64)
    if x0_lo.shape != (2,) or x0_hi.shape != (2,) or np.any(x0_lo > x0_hi) or np.isnan(x0_lo + x0_hi).any():
        raise ValueError(f"x0_lo, x0_hi: expected a 2-d box, got {x0_lo} and {x0_hi}")
    t = record.t
    heading = heading_from_compass(t, record.heading[:, 0], record.heading[:, 1],
                                   record.yaw_rate[1:, 0], record.yaw_rate[1:, 1])  # fmt: skip
    if heading.is_empty():  # compass and gyro contradict each other
        at = heading.inconsistent_at if heading.inconsistent_at is not None else heading.first_empty()
        return DigSlamResult(False, at, None, None, heading, 0)
    u_lo, u_hi = odometry_velocity(record, heading)
    inc = odometry_increment(record, heading)
    n = t.shape[0]
    g_lo, g_hi = np.full((n, 2), -np.inf), np.full((n, 2), np.inf)
    g_lo[0], g_hi[0] = x0_lo, x0_hi
    tube = ctc_deriv(Tube(t, g_lo, g_hi), u_lo, u_hi, forward=True, backward=False, increment=inc)
    dig = DigMap(grid)
    res = DigSlamResult(True, None, tube, dig, heading, 0, dead_reckoning=tube.widths())
    r_hi = impact_bound(record)
    total = float(np.sum(tube.widths()))
    dug_lo, dug_hi = np.full_like(tube.gate_lo, np.nan), np.full_like(tube.gate_hi, np.nan)
    for it in range(cfg.max_iter):
        before = tube.widths()
        # a gate dug before and unchanged since digs nothing new
        changed = np.any((tube.gate_lo != dug_lo) | (tube.gate_hi != dug_hi), axis=1)
        dig_readings(dig, record, tube, heading, changed)
        dug_lo, dug_hi = tube.gate_lo.copy(), tube.gate_hi.copy()
        if cfg.impacts:
            lo, hi = dig.contract_impacts(tube.gate_lo, tube.gate_hi, r_hi)
            tube = Tube(t, lo, hi, tube.slice_lo, tube.slice_hi)
        after = tube.widths()
        tube = ctc_deriv(tube, u_lo, u_hi, increment=inc)
        res.iterations = it + 1
        res.widths.append({"before": before, "impacts": after, "deriv": tube.widths()})
        if tube.is_empty():
            at = tube.inconsistent_at if tube.inconsistent_at is not None else tube.first_empty()
            return DigSlamResult(False, at, None, None, heading, it + 1, res.widths, res.dead_reckoning)
        new_total = float(np.sum(tube.widths()))
        if not cfg.impacts or total - new_total <= cfg.tol * total:
            break
        total = new_total
    res.tube = tube
    if cfg.explored is not False:
        res.explored = explored_zone(grid, record, tube, heading)
    return res


__all__ = [
    "DigSlamConfig",
    "DigSlamResult",
    "dig_readings",
    "thesis_dig_slam",
    "explored_zone",
    "impact_bound",
    "odometry_increment",
    "odometry_velocity",
]
