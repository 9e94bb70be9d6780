"""digslam.observer: the thesis's interval library and the guaranteed Dig-SLAM observer.

Intervals and boxes (:class:`IntervalArray`, :func:`Interval`, :func:`Box`), functions and their
natural inclusion (:class:`Function`), contractors (:class:`CtcFwdBwd` and the algebra), separators and
the paver, polar separators, thick sets and ThickSivia, tubes (:class:`Tube`, :func:`ctc_deriv`), and the
Dig-SLAM observer (:func:`dig_slam`, :class:`DigMap` on a :class:`Grid`), all acting on batches of boxes:
two float64 arrays ``lo, hi`` of shape ``(N, n)``.
"""

# ruff: noqa: E402  (the kernel caches are prepared before any kernel module is imported)
from digslam.observer import cache

cache.prepare()  # stale caches cleared, the kernel store first, the cold-start notice registered

from digslam.observer.core import arith, boxes, rounding, trig
from digslam.observer.core.interval import Box, Interval, IntervalArray, dot
from digslam.observer.expr.expr import Expr, Function
from digslam.observer.expr.ops import (
    abs_,
    acos,
    asin,
    atan,
    atan2,
    cos,
    exp,
    log,
    maximum,
    minimum,
    pown,
    sin,
    sqr,
    sqrt,
    tan,
)
from digslam.observer.online.observer import OnlineConfig, OnlineDigSlam
from digslam.observer.online.smoother import dig_slam
from digslam.observer.paving.paver import Paving, PavingTree, pave
from digslam.observer.paving.regular import classify_grid
from digslam.observer.paving.subpaving import SepSubpaving, load, save, simplify
from digslam.observer.polar.ctc import CtcPolar
from digslam.observer.polar.sep import (
    SepCtcPreimage,
    SepLandmark,
    SepPi,
    SepPiInv,
    SepPolarXY,
    complement_boxes,
    sep_landmark_fwdbwd,
)
from digslam.observer.record.grid import Grid
from digslam.observer.sets.contractors import Ctc, CtcCompose, CtcFixPoint, CtcFwdBwd, CtcInter, CtcUnion
from digslam.observer.sets.minkowski import SepMinkowskiDiff, SepMinkowskiSum, sep_negate
from digslam.observer.sets.projection import SepOnDims, SepProj
from digslam.observer.sets.registration import (
    SepRegistration,
    rigid2d,
    scaling,
    sep_cone,
    sep_inclusion,
    sep_intersection,
    transform_function,
    translation,
)
from digslam.observer.sets.sep_image import CtcImage, SepImage
from digslam.observer.sets.sep_inverse import SepInverse
from digslam.observer.sets.sep_polygon import CtcPolygonBoundary, CtcSegments, SepPolygon
from digslam.observer.sets.separators import Sep, SepBox, SepInter, SepNot, SepQInter, SepUnion
from digslam.observer.sets.transforms import CtcTransform, SepTransform, Transform, symmetric_union
from digslam.observer.slam.digmap import DigMap
from digslam.observer.slam.digslam import DigSlamConfig, DigSlamResult
from digslam.observer.slam.explicit_slam import (
    ExplicitSlamConfig,
    ExplicitSlamResult,
    explicit_slam,
    mission_tube,
)
from digslam.observer.slam.explored import (
    SepExploredDisks,
    explored_disks_grid,
    explored_disks_thick_sep,
    explored_hypotheses,
    explored_thick_sep,
    explored_union,
)
from digslam.observer.slam.explored_sweep import explored_sectors_grid, explored_sweep_grid, sweep_gates
from digslam.observer.slam.landmarks import (
    CtcLandmarks,
    IterationStats,
    Localization,
    contract_detections,
    contract_disjunctive,
    localize,
)
from digslam.observer.slam.measurements import RangeMeasurements, ShapeMeasurements
from digslam.observer.slam.raster_shape import RasterShape
from digslam.observer.slam.shape_registration import (
    SepTranslationInclusion,
    ThickImage,
    level_thick_image,
    register_translation,
)
from digslam.observer.slam.shape_slam import (
    ShapeSlamConfig,
    ShapeSlamResult,
    ctc_minus,
    overlap_pretest,
    shape_slam,
)
from digslam.observer.slam.shape_srac import SepShapeRegistration, shape_carve, shape_register
from digslam.observer.slam.shapes import free_zone, impact_zone, measurement_shapes
from digslam.observer.slam.thick_map import MapFunction, ThickMap
from digslam.observer.thick.carving import (
    SRACResult,
    ctc_image_equal,
    ctc_image_param,
    ctc_param_equal,
    ctc_param_meets,
    ctc_param_subset,
    param_hull,
    srac,
)
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA, UNKNOWN
from digslam.observer.thick.function import ThickFunction
from digslam.observer.thick.interval import ThickIntervalArray, thin
from digslam.observer.thick.inversion import SepFixedParam, thick_inverse_classical, thick_inverse_proj
from digslam.observer.thick.ops import thick_image, thick_image_param, thick_minkowski_sum, thick_product
from digslam.observer.thick.paver import ThickPaving, ThickTest, thick_pave
from digslam.observer.thick.sep import (
    ThickSep,
    thick_classify_grid,
    thick_relaxed_intersection,
)
from digslam.observer.thick.set import ctc_equal, ctc_subset
from digslam.observer.thick.sivia import ThickInverse, thick_sivia
from digslam.observer.thick.subset import (
    SubsetSupsetArray,
    ThickInverseSubsetSupset,
    thick_sivia_subset_supset,
)
from digslam.observer.tube.tube import (
    Tube,
    body_velocity,
    ctc_deriv,
    dead_reckoning,
    heading_from_compass,
    heading_from_gyro,
    unicycle_velocity,
)

__all__ = [
    "arith", "boxes", "rounding", "trig",
    "Ctc", "CtcCompose", "CtcFixPoint", "CtcFwdBwd", "CtcInter", "CtcUnion",
    "Paving", "PavingTree", "classify_grid", "pave", "SepInverse",
    "CtcImage", "SepImage", "CtcPolygonBoundary", "CtcSegments", "SepPolygon",
    "CtcTransform", "SepTransform", "Transform", "symmetric_union",
    "SepMinkowskiDiff", "SepMinkowskiSum", "sep_negate", "SepOnDims", "SepProj", "SepRegistration",
    "rigid2d", "scaling", "sep_cone", "sep_inclusion", "sep_intersection", "transform_function",
    "translation",
    "CtcPolar", "SepCtcPreimage", "SepLandmark", "SepPi", "SepPiInv", "SepPolarXY", "complement_boxes",
    "sep_landmark_fwdbwd",
    "SepFixedParam", "thick_inverse_classical", "thick_inverse_proj", "ThickPaving", "ThickTest",
    "thick_pave", "ThickInverse", "thick_sivia",
    "SubsetSupsetArray", "ThickInverseSubsetSupset", "thick_sivia_subset_supset",
    "Tube", "body_velocity", "ctc_deriv", "dead_reckoning", "heading_from_compass", "heading_from_gyro",
    "unicycle_velocity", "Grid", "DigMap", "DigSlamConfig", "DigSlamResult", "dig_slam",
    "SepExploredDisks", "explored_disks_grid", "explored_disks_thick_sep", "explored_hypotheses",
    "explored_thick_sep", "explored_union", "explored_sectors_grid", "explored_sweep_grid", "sweep_gates",
    "CtcLandmarks", "IterationStats", "Localization", "contract_detections", "contract_disjunctive",
    "localize", "free_zone", "impact_zone", "measurement_shapes",
    "SRACResult", "ctc_image_equal", "ctc_image_param", "ctc_param_equal", "ctc_param_meets",
    "ctc_param_subset", "param_hull", "srac", "thick_image", "thick_image_param", "thick_minkowski_sum",
    "thick_product", "OnlineConfig", "OnlineDigSlam",
    "SepTranslationInclusion", "ThickImage", "level_thick_image", "register_translation", "ShapeSlamConfig",
    "ShapeSlamResult", "ctc_minus", "overlap_pretest", "shape_slam",
    "ExplicitSlamConfig", "ExplicitSlamResult", "MapFunction", "RangeMeasurements", "RasterShape",
    "SepShapeRegistration", "ShapeMeasurements", "ThickMap", "explicit_slam", "mission_tube", "shape_carve",
    "shape_register",
    "CLEAR", "DARK", "PENUMBRA", "UNKNOWN", "ThickSep", "thick_classify_grid", "thick_relaxed_intersection",
    "ctc_equal", "ctc_subset", "ThickFunction", "ThickIntervalArray", "thin",
    "SepSubpaving", "load", "save", "simplify",
    "Sep", "SepBox", "SepInter", "SepNot", "SepQInter", "SepUnion",
    "Expr", "Function", "Box", "Interval", "IntervalArray", "dot",
    "abs_", "acos", "asin", "atan", "atan2", "cos", "exp", "log", "maximum", "minimum", "pown", "sin",
    "sqr", "sqrt", "tan",
]  # fmt: skip
