"""Thick sets (Ch. 5): sets known between an inner and an outer approximation.

Lives here: :mod:`.interval` (thick intervals and Booleans, Sec. 5.2), :mod:`.function` (thick functions),
:mod:`.cells` (the cell codes clear, penumbra, dark and unknown, Eq. 5.4), :mod:`.sep` (``ThickSep``, Sec.
5.3), :mod:`.set` (thick set predicates), :mod:`.paver` (``thick_pave``), :mod:`.sivia` (thick SIVIA, Alg.
5.1), :mod:`.subset` (subset-supset representation, Fig. A.8), :mod:`.ops` (thick images, products, Minkowski
sums), :mod:`.inversion` (thick inversion, Sec. 5.4) and :mod:`.carving` (thick carving and SRAC, Sec. 5.5).

May import: :mod:`digslam.observer.core`, :mod:`~digslam.observer.expr`, :mod:`~digslam.observer.sets`,
:mod:`~digslam.observer.paving`; numpy.
"""

# UNKNOWN is the cell code of .cells (0); the thick Boolean's unknown (-1) is .interval.UNKNOWN.
from .carving import (
    SRACResult,
    ctc_image_equal,
    ctc_image_param,
    ctc_param_equal,
    ctc_param_meets,
    ctc_param_subset,
    param_hull,
    srac,
)
from .cells import CLEAR, DARK, PENUMBRA, UNKNOWN
from .function import (
    ThickFunction,
)
from .interval import (
    FALSE,
    TRUE,
    ThickIntervalArray,
    thin,
)
from .inversion import (
    SepFixedParam,
    thick_inverse_classical,
    thick_inverse_proj,
)
from .ops import (
    thick_image,
    thick_image_param,
    thick_minkowski_sum,
    thick_product,
)
from .paver import (
    ThickPaving,
    ThickTest,
    thick_pave,
)
from .sep import (
    ThickSep,
    thick_classify_grid,
    thick_relaxed_intersection,
)
from .set import (
    ctc_equal,
    ctc_subset,
)
from .sivia import (
    ThickInverse,
    thick_sivia,
)
from .subset import (
    SubsetSupsetArray,
    ThickInverseSubsetSupset,
    thick_sivia_subset_supset,
)

__all__ = [
    "CLEAR",
    "DARK",
    "FALSE",
    "PENUMBRA",
    "SRACResult",
    "SepFixedParam",
    "SubsetSupsetArray",
    "TRUE",
    "ThickFunction",
    "ThickIntervalArray",
    "ThickInverse",
    "ThickInverseSubsetSupset",
    "ThickPaving",
    "ThickSep",
    "ThickTest",
    "UNKNOWN",
    "ctc_equal",
    "ctc_image_equal",
    "ctc_image_param",
    "ctc_param_equal",
    "ctc_param_meets",
    "ctc_param_subset",
    "ctc_subset",
    "param_hull",
    "srac",
    "thick_classify_grid",
    "thick_image",
    "thick_image_param",
    "thick_inverse_classical",
    "thick_inverse_proj",
    "thick_minkowski_sum",
    "thick_pave",
    "thick_product",
    "thick_relaxed_intersection",
    "thick_sivia",
    "thick_sivia_subset_supset",
    "thin",
]
