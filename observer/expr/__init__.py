"""Expressions and functions: build ``f(x)`` once and evaluate it on batch boxes.

Lives here: :mod:`.expr` (``Expr``, ``Function``: the expression DAG, natural and centred forms, Sec. 2.3),
:mod:`.ops`
(the elementary functions as expression nodes), :mod:`.backward` (the minimal backward step of every
operator, Sec. 3.2.2, used by forward-backward contractors), :mod:`.centred` (interval Jacobians and centred
forms, Sec. 2.3.3), :mod:`.centred_ctc` (the centred backward contraction, Eq. 2.20). Kernels:
:mod:`.tape_jit` (a function compiled to a tape and run per box),
:mod:`.hc4_jit` (HC4 forward-backward on the tape), :mod:`.centred_jit` (Jacobian and centred form on the
tape).

May import: :mod:`digslam.observer.core`; numpy, numba.
"""

from .centred import centred_image, jacobian
from .centred_ctc import centred_contract
from .expr import Expr, Function
from .ops import abs_, acos, asin, atan, atan2, cos, exp, log, maximum, minimum, pown, sin, sqr, sqrt, tan

__all__ = [
    "Expr",
    "Function",
    "abs_",
    "acos",
    "asin",
    "atan",
    "atan2",
    "centred_contract",
    "centred_image",
    "cos",
    "exp",
    "jacobian",
    "log",
    "maximum",
    "minimum",
    "pown",
    "sin",
    "sqr",
    "sqrt",
    "tan",
]
