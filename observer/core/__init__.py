"""The ground everything stands on: outward rounding, interval arithmetic on batch boxes, and the scalar
kernel primitives.

Lives here: :mod:`.rounding` (the one place where rounding direction is decided, Sec. 2.2), :mod:`.arith` and
:mod:`.trig` (natural inclusion functions on ``(lo, hi)`` arrays, Sec. 2.3), :mod:`.boxes` (batch-box
helpers), :mod:`.interval` (the user-facing ``Interval``/``IntervalArray``/``Box``), :mod:`.types` (the shared
aliases ``Pair``, ``Batch``), :mod:`.config` (the one config base), :mod:`.cache` (the stale-kernel guard) and
:mod:`.origin` (which copy of ``digslam`` was imported). Compiled kernels: :mod:`.scalar_jit` (numba's
``njit``
with the project's settings and every scalar outward-rounded primitive), :mod:`.polar_ops_jit` and
:mod:`.polar_jit` (the minimal polar contractor, Sec. 4.3.2, a primitive of the expressions' ``atan2``
backward step), :mod:`.angles_jit` (the axis directions an angle range may hold) and :mod:`.grid_jit` (the
window of grid cells a box meets).

May import: numpy, numba and the standard library; nothing else of ``digslam``.

**Kernel rules** (the whole project follows them):

1. A file that defines a numba kernel is named ``<topic>_jit.py`` and sits beside the Python code of its
   topic (as in pynndescent/umap); it may also hold the thin Python entry points of its kernels. No other
   file defines a kernel.
2. A kernel calls only kernels of its own concept folder and the primitives of this folder
   (``digslam.observer.core``); ``tests/test_architecture.py`` fails otherwise.
3. Every scalar primitive (directed-rounding ``add_up``/``mul_dn``..., ``imul``, ``isqr``, ``idiv``,
   ``iexp``...) lives in :mod:`.scalar_jit`.
4. A kernel that needs more than about ten inputs takes them as named tuples (``typing.NamedTuple``, which
   numba passes as records) built by its Python caller, not as packed arrays read by position.
5. Kernels are cached on disk (``cache=True``). numba's cache checks only the defining file, so
   :mod:`.cache` hashes every kernel source of the project at import and clears the caches when any of
   them changed: an edit never runs old compiled code.
"""

# ruff: noqa: E402  (the guard runs before the kernel modules are imported)
from . import cache

cache.guard()  # before any kernel is loaded: an edited kernel source never runs old compiled code

from .angles_jit import (
    axes_in,
    sector_box,
)
from .arith import (
    abs_,
    add,
    div,
    empty_mask,
    exp,
    hull,
    intersect,
    log,
    maximum,
    minimum,
    mul,
    neg,
    pown,
    set_empty,
    sqr,
    sqrt,
    sub,
)
from .boxes import (
    CHUNK,
    bisect,
    box_difference,
    chunked,
    empty_rows,
    midpoint,
    normalize_empty,
    validate_batch,
    volume,
    width_euclid,
    width_inf,
    widths,
)
from .config import (
    Config,
    check,
    check_choice,
    check_finite_nonneg,
    check_finite_pos,
    check_in,
    check_int,
    config_dataclass,
    is_int,
    is_number,
    reject_unknown,
)
from .grid_jit import (
    window,
)
from .interval import (
    DEFER_TO,
    Box,
    Interval,
    IntervalArray,
    as_pair,
    dot,
)
from .polar_jit import (
    contract_pos,
    ctc_polar_batch,
    sep_pie_batch,
)
from .polar_ops_jit import (
    cos_sin,
    cross,
    disk_hull,
    lift,
    outside_hull,
    pdiv,
    pmul,
    point_angle,
)
from .rounding import (
    HALF_PI_DOWN,
    HALF_PI_UP,
    LIBM_ULPS,
    PI_DOWN,
    PI_UP,
    TWO_PI_DOWN,
    TWO_PI_UP,
    add_down,
    add_up,
    div_down,
    div_up,
    mul_down,
    mul_up,
    next_down,
    next_up,
    sqrt_down,
    sqrt_up,
    step_down,
    step_up,
    sub_down,
    sub_up,
    widen_down,
    widen_up,
)
from .scalar_jit import (
    add_dn,
    div_dn,
    dn,
    iabs,
    iadd,
    idiv,
    iexp,
    ilog,
    imul,
    ipown,
    isqr,
    isqrt,
    isub,
    ixdiv,
    meet,
    mul_dn,
    nil,
    njit,
    sqrt_dn,
    sub_dn,
    up,
    wdn,
    wup,
)
from .trig import (
    acos,
    asin,
    atan,
    atan2,
    cos,
    sin,
    tan,
)
from .types import (
    Batch,
    BoolArray,
    FloatArray,
    Pair,
)

__all__ = [
    "Batch",
    "BoolArray",
    "Box",
    "CHUNK",
    "Config",
    "DEFER_TO",
    "FloatArray",
    "HALF_PI_DOWN",
    "HALF_PI_UP",
    "Interval",
    "IntervalArray",
    "LIBM_ULPS",
    "PI_DOWN",
    "PI_UP",
    "Pair",
    "TWO_PI_DOWN",
    "TWO_PI_UP",
    "abs_",
    "acos",
    "add",
    "add_dn",
    "add_down",
    "add_up",
    "as_pair",
    "asin",
    "atan",
    "atan2",
    "axes_in",
    "sector_box",
    "bisect",
    "box_difference",
    "check",
    "check_choice",
    "check_finite_nonneg",
    "check_finite_pos",
    "check_in",
    "check_int",
    "chunked",
    "config_dataclass",
    "contract_pos",
    "cos",
    "cos_sin",
    "cross",
    "ctc_polar_batch",
    "disk_hull",
    "div",
    "div_dn",
    "div_down",
    "div_up",
    "dn",
    "dot",
    "empty_mask",
    "empty_rows",
    "exp",
    "hull",
    "iabs",
    "iadd",
    "idiv",
    "iexp",
    "ilog",
    "imul",
    "intersect",
    "ipown",
    "is_int",
    "is_number",
    "isqr",
    "isqrt",
    "isub",
    "ixdiv",
    "lift",
    "log",
    "maximum",
    "meet",
    "midpoint",
    "minimum",
    "mul",
    "mul_dn",
    "mul_down",
    "mul_up",
    "neg",
    "next_down",
    "next_up",
    "nil",
    "njit",
    "normalize_empty",
    "outside_hull",
    "pdiv",
    "pmul",
    "point_angle",
    "pown",
    "reject_unknown",
    "sep_pie_batch",
    "set_empty",
    "sin",
    "sqr",
    "sqrt",
    "sqrt_dn",
    "sqrt_down",
    "sqrt_up",
    "step_down",
    "step_up",
    "sub",
    "sub_dn",
    "sub_down",
    "sub_up",
    "tan",
    "up",
    "validate_batch",
    "volume",
    "wdn",
    "widen_down",
    "widen_up",
    "width_euclid",
    "width_inf",
    "widths",
    "window",
    "wup",
]
