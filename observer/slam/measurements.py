"""Families of measurements for explicit SLAM: the two halves of ``C_SRAC`` on all the gates of the tube.

A :class:`Measurements` family carves the thick map with the gates and contracts the gates against the map
(thesis Algorithm 6.1, line 4). :class:`ShapeMeasurements` are thick shapes on rasters with any bijective
map function (Eq. 6.1, §6.2.3, :mod:`.shape_srac`); :class:`RangeMeasurements` are the one-sided range
readings of a :class:`~digslam.observer.record.mission.MissionRecord` (disks and sonar sectors, Fig. 6.9)
in the translation case ``g_x(m) = m - x`` (Eq. 6.16), carved by digging (Eq. 6.21) and contracted by the
impact constraint ``ΔZ ∩ g_x(comp M) ≠ ∅`` (Eq. 6.17, contractor ``C_g^≠`` of Eq. 6.22): with one-sided
shapes ``M⁺`` stays ``R^q`` and the registration of Prop. 5.4 is void (Eq. 6.19–6.21), so the impact zone
is what localizes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from digslam.observer.core.types import Batch
from digslam.observer.record.mission import MissionRecord
from digslam.observer.slam.digslam import dig_readings, impact_bound
from digslam.observer.slam.raster_shape import RasterShape
from digslam.observer.slam.shape_srac import shape_carve, shape_register
from digslam.observer.slam.thick_map import MapFunction, ThickMap
from digslam.observer.tube.tube import Tube

__all__ = ["Measurements", "RangeMeasurements", "ShapeMeasurements"]


class Measurements(Protocol):
    """A family of measurements at some gates of the tube: the two halves of ``C_SRAC`` on all of them."""

    def carve(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray, changed: np.ndarray) -> None:
        """Carve ``[M]`` with the gates ``(lo, hi)`` ``(T+1, n)`` (only the ``changed`` ones need to)."""

    def contract(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray) -> Batch:
        """The contracted gates ``(lo, hi)``."""


@dataclass
class ShapeMeasurements:
    """Thick shapes ``[Z](t_i)`` at gates ``k_i`` with a bijective map function (Eq. 6.1, §6.2.3).

    Attributes:
        gates: ``(m,)`` gate indices; shapes: ``m`` :class:`RasterShape` in the robot frame.
        g: the map function (default: the translation ``g_x(m) = m - x`` of Eq. 6.16).
        eps: paving width of the state boxes in the registration (Prop. 5.4).
        register: run the registration (False: carving only, the map is built from the tube).
    """

    gates: np.ndarray
    shapes: Sequence[RasterShape]
    g: MapFunction = field(default_factory=MapFunction.translation)
    eps: float = 0.05
    register: bool = True

    def __post_init__(self) -> None:
        self.gates = np.asarray(self.gates)
        if self.gates.ndim != 1 or not np.issubdtype(self.gates.dtype, np.integer):
            raise ValueError("gates: expected (m,) integer gate indices")
        if len(self.shapes) != self.gates.size or not all(isinstance(s, RasterShape) for s in self.shapes):
            raise ValueError(f"shapes: expected {self.gates.size} RasterShape (one per gate)")
        if not (np.isfinite(self.eps) and self.eps > 0):
            raise ValueError(f"eps: must be > 0, got {self.eps!r}")

    def carve(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray, changed: np.ndarray) -> None:
        for k, z in zip(self.gates.tolist(), self.shapes, strict=True):
            if changed[k]:
                shape_carve(m, z, self.g, lo[k : k + 1], hi[k : k + 1])

    def contract(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray) -> Batch:
        if not self.register:
            return lo, hi
        lo, hi = lo.copy(), hi.copy()
        for k, z in zip(self.gates.tolist(), self.shapes, strict=True):
            lo[k], hi[k] = shape_register(m, z, self.g, lo[k], hi[k], self.eps)
        return lo, hi


@dataclass
class RangeMeasurements:
    """One-sided range readings of a record (Fig. 6.9, §6.2.3.2) in the translation case (Eq. 6.16).

    ``[Z](t) = [Z⁻, R²]`` with ``Z⁻`` the free disk or sector (carving: Eq. 6.21, only ``M⁻`` moves) and the
    impact zone ``ΔZ`` with ``ΔZ ∩ g_x(comp M) ≠ ∅`` (Eq. 6.17, ``C_g^≠`` of Eq. 6.22).

    Attributes:
        record: the mission record; heading: its heading tube (see :func:`mission_tube`).
        impacts: apply ``C_g^≠``.
    """

    record: MissionRecord
    heading: Tube
    impacts: bool = True

    def carve(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray, changed: np.ndarray) -> None:
        dig_readings(m, self.record, Tube._trusted(self.record.t, lo, hi, lo[:-1], hi[:-1]), self.heading,
                     changed)  # fmt: skip

    def contract(self, m: ThickMap, lo: np.ndarray, hi: np.ndarray) -> Batch:
        if not self.impacts:
            return lo, hi
        return m.contract_impacts(lo, hi, impact_bound(self.record))
