"""Explicit shape-based SLAM (thesis §6.2.1–6.2.3, Algorithm 6.1, Eq. 6.1–6.4, 6.17–6.22).

The constraint network (6.3) has three variables: the trajectory ``x(·)``, the map ``M ⊂ R^q`` and the
measured shapes ``Z(t_i) = g_{x(t_i)}(M)`` (Eq. 6.1), with ``g_x`` bijective (Eq. 6.2). Algorithm 6.1
keeps the map explicitly, as a thick set ``[M] = [M⁻, M⁺]`` that starts as ``[∅, R^q]``, and alternates
the two contractors of the network until the tube stops shrinking:

1. ``[x](·) := C_d/dt([x](·))`` (§2.5.4, :func:`~.tube.ctc_deriv`);
2. for every ``t_i``: ``C_SRAC([x](t_i), [Z](t_i), [M])`` (Algorithm 5.1), i.e. carving
   ``[M] := [M] ⊓ g⁻¹_{[x](t_i)}([Z](t_i))`` (Prop. 5.3, Eq. 5.48, Theorem 5.1 Eq. 5.40–5.41):
   ``M⁻ := M⁻ ∪ ⋂_x g_x⁻¹(Z⁻)`` and ``M⁺ := M⁺ ∩ ⋃_x g_x⁻¹(Z⁺)``, then registration
   ``[x](t_i) := [x](t_i) ∩ ⟦{x | g_x(M⁻) ⊂ Z⁺, g_x⁻¹(Z⁻) ⊂ M⁺}⟧`` (Prop. 5.4, Remark 5.7, Eq. 5.56).

Here the map is a :class:`~.thick_map.ThickMap` on a :class:`~digslam.observer.record.grid.Grid` (two
boolean rasters, every claim about whole cells, :mod:`.thick_map`), and the measurements come in families
that act on all the gates of the tube at once (:mod:`.measurements`):

* :class:`~.measurements.ShapeMeasurements`: thick shapes ``[Z](t_i)`` given as rasters
  (:class:`~.raster_shape.RasterShape`) in the robot frame, double-sided (Eq. 6.4, §6.2.3.1) or one-sided
  (``Z⁺ = R^q``, §6.2.3.2), with any bijective map function (:class:`~.thick_map.MapFunction`: ``g``, its
  inverse, and their natural inclusion functions), carved and registered by :mod:`.shape_srac`;
* :class:`~.measurements.RangeMeasurements`: the one-sided range readings of a
  :class:`~digslam.observer.record.mission.MissionRecord` (disks and sonar sectors, Fig. 6.9) in the
  translation case ``g_x(m) = m - x`` (Eq. 6.16), with the impact constraint ``ΔZ ∩ g_x(comp M) ≠ ∅``
  (Eq. 6.17, contractor ``C_g^≠`` of Eq. 6.22): with one-sided shapes ``M⁺`` stays ``R^q`` and the
  registration of Prop. 5.4 is void (Eq. 6.19–6.21), so the impact zone is what localizes.

Special cases (tested in ``tests/observer/slam/test_explicit_slam.py``):

* Algorithm 6.3 (:func:`~.digslam.thesis_dig_slam`) is :func:`explicit_slam` with one
  :class:`~.measurements.RangeMeasurements` family: same schedule, same contractors, so the same tube and
  ``M⁻`` (bit for bit) under the same stopping rule;
* Algorithm 6.2 (:func:`~.shape_slam.shape_slam`) removes the map from the network by the inter-temporal
  constraint ``Z(t_i) = Z(t_j) + p_ij`` (Eq. 6.5–6.10). Registering ``Z(t_j)`` against the explicit map
  carved by ``Z(t_i)`` at ``[x](t_i)`` is the same constraint with ``x(t_i)`` blurred over its box, so at
  their fixpoints the explicit tube contains the inter-temporal one (up to the paving width ``eps_x``).

Every step is a sound contractor: the true trajectory stays in the tube and ``M⁻ ⊂ M ⊂ M⁺`` holds at cell
level, floating point included (outward-rounded natural inclusion and integer pixel windows).

>>> from digslam.observer.slam.measurements import ShapeMeasurements
>>> from digslam.observer.slam.raster_shape import RasterShape
>>> t = np.array([0.0, 1.0])
>>> tube = Tube(t, np.array([[0.0, 0.0], [-np.inf, -np.inf]]), np.array([[0.0, 0.0], [np.inf, np.inf]]))
>>> u = np.full((1, 2), -0.1), np.full((1, 2), 0.1)                     # |ẋ| <= 0.1 on each axis
>>> z = RasterShape(np.ones((2, 2), bool), np.ones((2, 2), bool), (-0.5, 0.5), 0.5)   # Z⁻ = [-0.5, 0.5]²
>>> grid = Grid((-2.0, -2.0), (2.0, 2.0), (8, 8))
>>> r = explicit_slam(tube, *u, [ShapeMeasurements(np.array([0]), [z])], grid)
>>> r.consistent, int(r.map.lower.sum()), r.tube.gate_hi[1].tolist()    # 4 cells in M⁻; x(1) within 0.1
(True, 4, [0.1, 0.1])
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from digslam.observer.core.boxes import empty_rows
from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord
from digslam.observer.slam.digslam import odometry_velocity
from digslam.observer.slam.measurements import Measurements
from digslam.observer.slam.thick_map import ThickMap
from digslam.observer.tube.tube import Tube, ctc_deriv, heading_from_compass

__all__ = ["ExplicitSlamConfig", "ExplicitSlamResult", "explicit_slam", "mission_tube"]


@dataclass(frozen=True)
class ExplicitSlamConfig:
    """Settings of :func:`explicit_slam`.

    Attributes:
        max_iter: most passes of the ``repeat`` loop.
        tol: stop when a pass shrinks the summed gate widths by at most this fraction (0: Algorithm 6.1's
            "until no more contraction on ``[x](·)``", exactly).
    """

    max_iter: int = 20
    tol: float = 0.0

    def __post_init__(self) -> None:
        if not (isinstance(self.max_iter, int) and self.max_iter >= 1):
            raise ValueError(f"max_iter: must be an integer >= 1, got {self.max_iter!r}")
        if not (np.isfinite(self.tol) and self.tol >= 0):
            raise ValueError(f"tol: must be a finite number >= 0, got {self.tol!r}")


@dataclass
class ExplicitSlamResult:
    """Output of :func:`explicit_slam`.

    Attributes:
        consistent: False when a gate became empty or ``M⁻ ⊄ M⁺`` (data outside their bounds).
        tube: the contracted tube; map: the thick map ``[M]`` (both None when inconsistent).
        dead_reckoning: gate widths of the first ``C_d/dt``.
        iterations: passes run; widths: per pass, the gate widths after ``C_SRAC`` and after ``C_d/dt``;
        seconds: wall time.
    """

    consistent: bool
    tube: Tube | None
    map: ThickMap | None
    dead_reckoning: np.ndarray
    iterations: int = 0
    widths: list[dict[str, np.ndarray]] = field(default_factory=list)
    seconds: float = 0.0


def explicit_slam(tube: Tube, u_lo: ArrayLike, u_hi: ArrayLike, measurements: Sequence[Measurements],
                  grid: Grid, config: ExplicitSlamConfig | None = None) -> ExplicitSlamResult:  # fmt: skip
    """Algorithm 6.1: ``[M] = [∅, R^q]``, then repeat ``C_d/dt`` and ``C_SRAC`` at every ``t_i``.

    The loop runs in Algorithm 6.3's order (``C_d/dt`` forward from ``[x](0)`` first; then per pass: carve
    with every gate, register every gate against the whole map, ``C_d/dt``), which is Algorithm 6.1's loop
    with its first ``C_d/dt`` hoisted out; carving before registering uses the newest map (each half of
    ``C_SRAC`` is a contractor, so either order is sound).

    Args:
        tube: the initial tube (``[x](0) = X₀``, entire elsewhere).
        u_lo, u_hi: ``(T, n)`` velocity bounds per slice (``ẋ ∈ [u]``, e.g. :func:`~.tube.body_velocity`).
        measurements: families of measurements (:class:`ShapeMeasurements`, :class:`RangeMeasurements`).
        grid: the cells of the map.
        config: :class:`ExplicitSlamConfig`.
    """
    cfg = config or ExplicitSlamConfig()
    if not isinstance(tube, Tube):
        raise ValueError(f"tube: expected a Tube, got {tube!r}")
    t0 = time.perf_counter()
    x = ctc_deriv(tube, u_lo, u_hi, forward=True, backward=False)
    m = ThickMap(grid)
    res = ExplicitSlamResult(True, None, m, x.widths())
    total = float(np.sum(x.widths()))
    dug_lo, dug_hi = np.full_like(x.gate_lo, np.nan), np.full_like(x.gate_hi, np.nan)
    for it in range(cfg.max_iter):
        changed = np.any((x.gate_lo != dug_lo) | (x.gate_hi != dug_hi), axis=1)
        for fam in measurements:
            fam.carve(m, x.gate_lo, x.gate_hi, changed)
        dug_lo, dug_hi = x.gate_lo.copy(), x.gate_hi.copy()
        lo, hi = x.gate_lo, x.gate_hi
        for fam in measurements:
            lo, hi = fam.contract(m, lo, hi)
        srac_w = np.where(empty_rows(lo, hi), 0.0, (hi - lo).max(axis=1))
        x = ctc_deriv(Tube(x.t, lo, hi, x.slice_lo, x.slice_hi), u_lo, u_hi)
        res.iterations = it + 1
        res.widths.append({"srac": srac_w, "deriv": x.widths()})
        if x.is_empty() or empty_rows(lo, hi).any() or not m.consistent():
            res.consistent, res.tube, res.map = False, None, None
            res.seconds = time.perf_counter() - t0
            return res
        new_total = float(np.sum(x.widths()))
        if total - new_total <= cfg.tol * total:
            break
        total = new_total
    res.tube = x
    res.seconds = time.perf_counter() - t0
    return res


def mission_tube(record: MissionRecord, x0_lo: ArrayLike, x0_hi: ArrayLike
                 ) -> tuple[Tube, np.ndarray, np.ndarray, Tube]:  # fmt: skip
    """The initial tube, velocity bounds and heading tube of a record, as :func:`~.digslam.thesis_dig_slam`
    builds them (compass and gyro fused, ``ẋ = R(ψ) v`` with the body-frame velocity ``v = (v_1, v_2)``,
    Eq. 3.59, 6.12, B.20: :func:`~.digslam.odometry_velocity`).

    Returns:
        ``(tube, u_lo, u_hi, heading)`` with ``[x](0) = X₀`` and entire gates elsewhere.
    """
    t = record.t
    heading = heading_from_compass(t, record.heading[:, 0], record.heading[:, 1],
                                   record.yaw_rate[1:, 0], record.yaw_rate[1:, 1])  # fmt: skip
    u_lo, u_hi = odometry_velocity(record, heading)
    n = t.shape[0]
    g_lo, g_hi = np.full((n, 2), -np.inf), np.full((n, 2), np.inf)
    g_lo[0], g_hi[0] = np.asarray(x0_lo, np.float64), np.asarray(x0_hi, np.float64)
    return Tube(t, g_lo, g_hi), u_lo, u_hi, heading
