"""Offline SLAM on a mission record (Ch. 6): from the record to the dig map, the tube and the explored zone.

Lives here: :mod:`.digmap` (``DigMap``, the dig zone M-, Sec. 6.3),
:mod:`.digslam` (Dig-SLAM's settings, result and tube pieces, and Alg. 6.3 as the thesis writes it),
:mod:`.explored` and :mod:`.explored_sweep` (the explored zone as a thick set, App. B.5), :mod:`.landmarks`
(landmark localization, Ex. 3.4), :mod:`.shapes` (sonar measurement shapes), :mod:`.shape_registration` and
:mod:`.shape_slam` (shape SLAM, Sec. 6.4) and explicit SLAM (Alg. 6.1): :mod:`.explicit_slam` (the
algorithm, its settings and result), :mod:`.thick_map` (the thick map and the map function),
:mod:`.raster_shape` (a thick shape on a pixel raster), :mod:`.shape_srac` (carving and registration with a
raster shape, Prop. 5.3-5.4) and :mod:`.measurements` (the families of measurements it iterates on). The
offline Dig-SLAM observer itself, ``dig_slam``, runs the online filter's kernels:
:mod:`digslam.observer.online`.

May import: every folder of :mod:`digslam.observer` except :mod:`~digslam.observer.online`; numpy, scipy.
"""

from .digmap import DigMap
from .digslam import DigSlamConfig, DigSlamResult, explored_zone, thesis_dig_slam
from .explicit_slam import ExplicitSlamConfig, ExplicitSlamResult, explicit_slam, mission_tube
from .explored import (
    SepExploredDisks,
    explored_disks_grid,
    explored_disks_thick_sep,
    explored_hypotheses,
    explored_thick_sep,
    explored_union,
)
from .explored_sweep import explored_sectors_grid, explored_sweep_grid, sweep_gates
from .landmarks import (
    CtcLandmarks,
    IterationStats,
    Localization,
    contract_detections,
    contract_disjunctive,
    localize,
)
from .measurements import Measurements, RangeMeasurements, ShapeMeasurements
from .raster_shape import RasterShape
from .shape_registration import SepTranslationInclusion, ThickImage, level_thick_image, register_translation
from .shape_slam import ShapeSlamConfig, ShapeSlamResult, ctc_minus, overlap_pretest, shape_slam
from .shape_srac import SepShapeRegistration, shape_carve, shape_register
from .shapes import free_zone, impact_zone, measurement_shapes
from .thick_map import MapFunction, ThickMap

__all__ = [
    "CtcLandmarks",
    "DigMap",
    "DigSlamConfig",
    "DigSlamResult",
    "ExplicitSlamConfig",
    "ExplicitSlamResult",
    "IterationStats",
    "Localization",
    "MapFunction",
    "Measurements",
    "RangeMeasurements",
    "RasterShape",
    "SepExploredDisks",
    "SepShapeRegistration",
    "SepTranslationInclusion",
    "ShapeMeasurements",
    "ShapeSlamConfig",
    "ShapeSlamResult",
    "ThickImage",
    "ThickMap",
    "contract_detections",
    "contract_disjunctive",
    "ctc_minus",
    "explicit_slam",
    "explored_disks_grid",
    "explored_disks_thick_sep",
    "explored_hypotheses",
    "explored_sectors_grid",
    "explored_sweep_grid",
    "explored_thick_sep",
    "explored_union",
    "explored_zone",
    "free_zone",
    "impact_zone",
    "level_thick_image",
    "localize",
    "measurement_shapes",
    "mission_tube",
    "overlap_pretest",
    "register_translation",
    "shape_carve",
    "shape_register",
    "shape_slam",
    "sweep_gates",
    "thesis_dig_slam",
]
