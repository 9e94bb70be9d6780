"""Offline SLAM on a mission record (Ch. 6): from the record to the dig map, the tube and the explored zone.

Lives here: :mod:`.digmap` (``DigMap``, the dig zone M-, Sec. 6.3),
:mod:`.digslam` (Dig-SLAM's settings, result and tube pieces, and Alg. 6.3 as the thesis writes it),
:mod:`.explored` and :mod:`.explored_sweep` (the explored zone as a thick set, App. B.5), :mod:`.landmarks`
(landmark localization, Ex. 3.4), :mod:`.shapes` (sonar measurement shapes), :mod:`.shape_registration` and
:mod:`.shape_slam` (shape SLAM, Sec. 6.4) and :mod:`.explicit_slam` (explicit SLAM, Alg. 6.1). The offline
Dig-SLAM observer itself, ``dig_slam``, runs the online filter's kernels: :mod:`digslam.observer.online`.

May import: every folder of :mod:`digslam.observer` except :mod:`~digslam.observer.online`; numpy, scipy.
"""

from .digmap import (
    EDT_SLACK,
    DigMap,
)
from .digslam import (
    DigSlamConfig,
    DigSlamResult,
    dig_readings,
    explored_zone,
    impact_bound,
    odometry_velocity,
    thesis_dig_slam,
)
from .explicit_slam import (
    ExplicitSlamConfig,
    ExplicitSlamResult,
    MapFunction,
    Measurements,
    RangeMeasurements,
    RasterShape,
    SepShapeRegistration,
    ShapeMeasurements,
    ThickMap,
    explicit_slam,
    mission_tube,
    shape_carve,
    shape_register,
)
from .explored import (
    BLOCK,
    SepExploredDisks,
    check_interval,
    check_tube,
    codes,
    explored_disks_grid,
    explored_disks_thick_sep,
    explored_hypotheses,
    explored_thick_sep,
    explored_union,
    pair_test,
    row_intervals,
)
from .explored_sweep import (
    explored_sectors_grid,
    explored_sweep_grid,
    sweep_gates,
)
from .landmarks import (
    CtcLandmarks,
    IterationStats,
    Localization,
    contract_detections,
    contract_disjunctive,
    localize,
)
from .shape_registration import (
    SepTranslationInclusion,
    ThickImage,
    level_thick_image,
    register_translation,
)
from .shape_slam import (
    ShapeSlamConfig,
    ShapeSlamResult,
    ctc_minus,
    overlap_pretest,
    shape_slam,
)
from .shapes import (
    free_zone,
    impact_zone,
    measurement_shapes,
)

__all__ = [
    "BLOCK",
    "CtcLandmarks",
    "DigMap",
    "DigSlamConfig",
    "DigSlamResult",
    "EDT_SLACK",
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
    "check_interval",
    "check_tube",
    "codes",
    "contract_detections",
    "contract_disjunctive",
    "ctc_minus",
    "dig_readings",
    "thesis_dig_slam",
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
    "impact_bound",
    "impact_zone",
    "level_thick_image",
    "localize",
    "measurement_shapes",
    "mission_tube",
    "odometry_velocity",
    "overlap_pretest",
    "pair_test",
    "register_translation",
    "row_intervals",
    "shape_carve",
    "shape_register",
    "shape_slam",
    "sweep_gates",
]
