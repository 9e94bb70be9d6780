"""The ground everything stands on: outward rounding, interval arithmetic on batch boxes, and the scalar
kernel primitives.

Lives here: :mod:`.rounding` (the one place where rounding direction is decided, Sec. 2.2), :mod:`.arith` and
:mod:`.trig` (natural inclusion functions on ``(lo, hi)`` arrays, Sec. 2.3), :mod:`.boxes` (batch-box
helpers), :mod:`.interval` (the user-facing ``Interval``/``IntervalArray``/``Box``), :mod:`.types` (the shared
aliases ``Pair``, ``Batch``) and :mod:`.config` (the one config base). Compiled kernels:
:mod:`.scalar_jit` (numba's ``njit`` with the project's settings and every scalar outward-rounded
primitive), :mod:`.polar_ops_jit` and :mod:`.polar_jit` (the minimal polar contractor, Sec. 4.3.2, a
primitive of the expressions' ``atan2`` backward step), :mod:`.angles_jit` (the axis directions an angle
range may hold) and :mod:`.grid_jit` (the window of grid cells a box meets).

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
5. Kernels are cached on disk (``cache=True``) in the kernel store, stamped with a digest of every
   kernel source (:mod:`digslam.observer.cache`): an edit never runs old compiled code.
"""

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
from .interval import Box, Interval, IntervalArray, dot
from .types import Batch, BoolArray, FloatArray, Pair

__all__ = [
    "Batch",
    "BoolArray",
    "Box",
    "Config",
    "FloatArray",
    "Interval",
    "IntervalArray",
    "Pair",
    "check",
    "check_choice",
    "check_finite_nonneg",
    "check_finite_pos",
    "check_in",
    "check_int",
    "config_dataclass",
    "dot",
    "is_int",
    "is_number",
    "reject_unknown",
]
