"""Elementary functions that work on expressions, interval arrays and plain numbers alike.

The same ``sin`` builds a node while a :class:`~.expr.Function` is traced, evaluates an inclusion
function on an :class:`~.interval.IntervalArray`, and is ``numpy.sin`` on floats.

>>> from digslam.observer import Interval
>>> cos(Interval(0, 1)).issubset(Interval(0.54, 1.0))                   # cos is decreasing on [0, 1]
np.True_
>>> Interval(-2, 1) * cos(Interval(np.pi / 6, np.pi / 3))            # Ex. 2.3: [-√3, √3/2]
Interval(-1.7320508075688..., 0.8660254037844...)
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from digslam.observer.core import arith, trig
from digslam.observer.core.interval import IntervalArray, as_pair
from digslam.observer.expr.expr import Expr, lift

__all__ = [
    "sqr", "sqrt", "exp", "log", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "abs_",
    "minimum", "maximum", "pown",
]  # fmt: skip


def _unary(name: str, kernel: Callable[..., Any], point: Callable[[Any], Any]) -> Callable[[Any], Any]:
    def f(x: Any) -> Any:
        if isinstance(x, Expr):
            return Expr(name, (x,))
        if isinstance(x, IntervalArray):
            return IntervalArray._raw(*kernel(x.pair))
        return point(x)

    f.__name__ = name
    f.__doc__ = f"``{name}`` on an Expr (node), an IntervalArray (inclusion function) or numbers.\n\n" + (
        kernel.__doc__ or ""
    )
    return f


def _binary(name: str, kernel: Callable[..., Any], point: Callable[[Any, Any], Any]) -> Callable[..., Any]:
    def f(a: Any, b: Any) -> Any:
        if isinstance(a, Expr) or isinstance(b, Expr):
            return Expr(name, (lift(a), lift(b)))
        if isinstance(a, IntervalArray) or isinstance(b, IntervalArray):
            return IntervalArray._raw(*kernel(as_pair(a, "a"), as_pair(b, "b")))
        return point(a, b)

    f.__name__ = name
    f.__doc__ = f"``{name}`` on expressions, interval arrays or numbers.\n\n" + (kernel.__doc__ or "")
    return f


sqr = _unary("sqr", arith.sqr, np.square)
sqrt = _unary("sqrt", arith.sqrt, np.sqrt)
exp = _unary("exp", arith.exp, np.exp)
log = _unary("log", arith.log, np.log)
sin = _unary("sin", trig.sin, np.sin)
cos = _unary("cos", trig.cos, np.cos)
tan = _unary("tan", trig.tan, np.tan)
asin = _unary("asin", trig.asin, np.arcsin)
acos = _unary("acos", trig.acos, np.arccos)
atan = _unary("atan", trig.atan, np.arctan)
abs_ = _unary("abs", arith.abs_, np.abs)
atan2 = _binary("atan2", trig.atan2, np.arctan2)
minimum = _binary("min", arith.minimum, np.minimum)
maximum = _binary("max", arith.maximum, np.maximum)


def pown(x: Any, n: int) -> Any:
    """``xⁿ`` for an integer ``n`` on expressions, interval arrays or numbers."""
    if not isinstance(n, (int, np.integer)):
        raise ValueError(f"pown: n must be an integer, got {n!r}")
    if isinstance(x, (Expr, IntervalArray)):
        return x**n
    return np.power(np.asarray(x, dtype=np.float64), float(n))
