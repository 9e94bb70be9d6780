"""Contractors and separators: the set algebra of Ch. 3 on batch boxes.

Lives here: :mod:`.contractors` (``Ctc`` and its combinators, forward-backward ``CtcFwdBwd``),
:mod:`.separators` (``Sep`` returning (inner, outer), ``&``, ``|``, ``~``, q-relaxed intersection, Sec.
3.3-3.4) with its kernel in :mod:`.separators_jit`, :mod:`.sep_inverse` (``SepInverse``, Eq. 3.9),
:mod:`.sep_image` (image separators), :mod:`.sep_polygon`, :mod:`.transforms` (separators through a
transformation), :mod:`.registration` (registration separators, Ch. 4), :mod:`.minkowski` (Minkowski sum and
difference, Sec. 4.4), :mod:`.projection` (``SepProj``, Sec. 3.5) and :mod:`.testing` (a soundness check for
any separator).

May import: :mod:`digslam.observer.core`, :mod:`digslam.observer.expr`; numpy, numba.
"""

from .contractors import Ctc, CtcCompose, CtcFixPoint, CtcFwdBwd, CtcInter, CtcUnion
from .minkowski import SepMinkowskiDiff, SepMinkowskiSum, sep_negate
from .projection import SepOnDims, SepProj
from .registration import (
    ParamTransform,
    SepRegistration,
    Transformation,
    rigid2d,
    scaling,
    sep_cone,
    sep_inclusion,
    sep_intersection,
    transform_function,
    translation,
)
from .sep_image import CtcImage, SepImage
from .sep_inverse import SepInverse
from .sep_polygon import CtcPolygonBoundary, CtcSegments, SepPolygon
from .separators import (
    Sep,
    SepBox,
    SepCtcPair,
    SepInter,
    SepNot,
    SepQInter,
    SepUnion,
    box_qinter,
    check_separation,
    relaxed_intersection,
)
from .testing import assert_separator_sound, random_boxes
from .transforms import CtcTransform, SepTransform, Transform, symmetric_union

__all__ = [
    "assert_separator_sound",
    "box_qinter",
    "check_separation",
    "random_boxes",
    "relaxed_intersection",
    "rigid2d",
    "scaling",
    "sep_cone",
    "sep_inclusion",
    "sep_intersection",
    "sep_negate",
    "symmetric_union",
    "transform_function",
    "translation",
    "Ctc",
    "CtcCompose",
    "CtcFixPoint",
    "CtcFwdBwd",
    "CtcImage",
    "CtcInter",
    "CtcPolygonBoundary",
    "CtcSegments",
    "CtcTransform",
    "CtcUnion",
    "ParamTransform",
    "Sep",
    "SepBox",
    "SepCtcPair",
    "SepImage",
    "SepInter",
    "SepInverse",
    "SepMinkowskiDiff",
    "SepMinkowskiSum",
    "SepNot",
    "SepOnDims",
    "SepPolygon",
    "SepProj",
    "SepQInter",
    "SepRegistration",
    "SepTransform",
    "SepUnion",
    "Transform",
    "Transformation",
]
