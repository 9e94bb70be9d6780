"""digslam.observer: the thesis's interval library and the guaranteed Dig-SLAM observer.

Intervals and boxes (:class:`IntervalArray`, :func:`Interval`, :func:`Box`), functions and their
natural inclusion (:class:`Function`), contractors (:class:`CtcFwdBwd` and the algebra), separators and
the paver, polar separators, thick sets and ThickSivia, tubes (:class:`Tube`, :func:`ctc_deriv`), and the
Dig-SLAM observer (:func:`dig_slam`, :class:`DigMap` on a :class:`Grid`), all acting on batches of boxes:
two float64 arrays ``lo, hi`` of shape ``(N, n)``.
"""

from . import arith, boxes, rounding, trig
from .contractors import Ctc, CtcCompose, CtcFixPoint, CtcFwdBwd, CtcInter, CtcUnion
from .digmap import DigMap
from .digslam import DigSlamConfig, DigSlamResult, dig_slam
from .explicit_slam import (
    ExplicitSlamConfig,
    ExplicitSlamResult,
    MapFunction,
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
    SepExploredDisks,
    explored_disks_grid,
    explored_disks_thick_sep,
    explored_hypotheses,
    explored_thick_sep,
    explored_union,
)
from .explored_sweep import explored_sectors_grid, explored_sweep_grid, sweep_gates
from .expr import Expr, Function
from .grid import Grid
from .interval import Box, Interval, IntervalArray, dot
from .landmarks import (
    CtcLandmarks,
    IterationStats,
    Localization,
    contract_detections,
    contract_disjunctive,
    localize,
)
from .minkowski import SepMinkowskiDiff, SepMinkowskiSum, sep_negate
from .online import OnlineConfig, OnlineDigSlam
from .ops import abs_, acos, asin, atan, atan2, cos, exp, log, maximum, minimum, pown, sin, sqr, sqrt, tan
from .paver import Paving, PavingTree, pave
from .polar_ctc import CtcPolar
from .polar_sep import (
    SepCtcPreimage,
    SepLandmark,
    SepPi,
    SepPiInv,
    SepPolarXY,
    complement_boxes,
    sep_landmark_fwdbwd,
)
from .projection import SepOnDims, SepProj
from .registration import (
    SepRegistration,
    rigid2d,
    scaling,
    sep_cone,
    sep_inclusion,
    sep_intersection,
    transform_function,
    translation,
)
from .regular import classify_grid
from .sep_image import CtcImage, SepImage
from .sep_inverse import SepInverse
from .sep_polygon import CtcPolygonBoundary, CtcSegments, SepPolygon
from .separators import Sep, SepBox, SepInter, SepNot, SepQInter, SepUnion
from .shape_registration import SepTranslationInclusion, ThickImage, level_thick_image, register_translation
from .shape_slam import ShapeSlamConfig, ShapeSlamResult, ctc_minus, overlap_pretest, shape_slam
from .shapes import free_zone, impact_zone, measurement_shapes
from .subpaving import SepSubpaving, load, save, simplify
from .thick_carving import (
    SRACResult,
    ctc_image_equal,
    ctc_image_param,
    ctc_param_equal,
    ctc_param_meets,
    ctc_param_subset,
    param_hull,
    srac,
)
from .thick_function import ThickFunction
from .thick_interval import ThickIntervalArray, thin
from .thick_inversion import SepFixedParam, thick_inverse_classical, thick_inverse_proj
from .thick_ops import thick_image, thick_image_param, thick_minkowski_sum, thick_product
from .thick_paver import ThickPaving, ThickTest, thick_pave
from .thick_sep import (
    CLEAR,
    DARK,
    PENUMBRA,
    UNKNOWN,
    ThickSep,
    thick_classify_grid,
    thick_relaxed_intersection,
)
from .thick_set import ctc_equal, ctc_subset
from .thick_sivia import ThickInverse, thick_sivia
from .thick_subset import SubsetSupsetArray, ThickInverseSubsetSupset, thick_sivia_subset_supset
from .transforms import CtcTransform, SepTransform, Transform, symmetric_union
from .tube import (
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
