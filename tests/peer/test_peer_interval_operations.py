"""codac's ``codac2_tests_Interval_operations`` re-expressed: arithmetic with unbounded and empty operands,
scalar operands (``±inf`` gives empty), ``sqrt``, ``log``, ``exp``, ``sin``/``cos`` (each case and its
seven symmetric forms, as codac's ``CHECK_trigo``), ``tan``, ``atan2`` and integer powers.

Each case: our result, codac's expected value, the 200-bit truth (:mod:`truth`), judged by :mod:`judge`.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from typing import Any

import pytest
import truth as T
from judge import EMPTY, judge, ours_of

from digslam.observer import Interval, atan2, cos, exp, log, pown, sin, sqrt, tan

oo = math.inf
MAX = sys.float_info.max
PI_LB, PI_UP = 3.141592653589793, 3.1415926535897936  # codac's Interval.pi() bounds
E = Interval.empty


def I(lo: float, hi: float | None = None) -> Any:  # noqa: E743, N802 - codac's spelling
    return Interval(lo, lo if hi is None else hi)


def _t(x: Any) -> T.Iv:
    """Truth operand of ours: an interval, or a float (a ±inf float is no real number)."""
    if isinstance(x, (int, float)):
        return T.scalar(float(x))
    lo, hi = ours_of(x)
    return T.iv(lo, hi)


def _p(x: Any) -> tuple[float, float]:
    return ours_of(x) if not isinstance(x, (int, float)) else (float(x), float(x))


CASES: list[tuple[str, Callable[[], Any], tuple[float, float], Callable[[], T.Iv], float]] = []


def case(name: str, ours: Callable[[], Any], peer: Any, truth: Callable[[], T.Iv], tol: float = 0.0) -> None:
    CASES.append((f"{name}#{len(CASES)}", ours, _p(peer), truth, tol))


def neg(x: Any) -> Any:
    return -x if not isinstance(x, (int, float)) else -float(x)


def check_add(x: Any, y: Any, expected: Any) -> None:
    """codac's CHECK_add / CHECK_add_scalar: both orders, and the subtraction forms."""
    ex, mex = expected, neg(expected)
    case("add", lambda: x + y, ex, lambda: T.add(_t(x), _t(y)))
    case("add", lambda: y + x, ex, lambda: T.add(_t(y), _t(x)))
    case("sub", lambda: neg(x) - y, mex, lambda: T.sub(_t(neg(x)), _t(y)))
    case("sub", lambda: neg(y) - x, mex, lambda: T.sub(_t(neg(y)), _t(x)))


def check_mul(x: Any, y: Any, expected: Any) -> None:
    case("mul", lambda: x * y, expected, lambda: T.mul(_t(x), _t(y)))
    case("mul", lambda: y * x, expected, lambda: T.mul(_t(y), _t(x)))


def check_div(x: Any, y: Any, expected: Any) -> None:
    xi = x if not isinstance(x, (int, float)) else I(x)
    yi = y if not isinstance(y, (int, float)) else I(y)
    case("div", lambda: xi / yi, expected, lambda: T.div(_t(xi), _t(yi)))
    case("div", lambda: xi / y, expected, lambda: T.div(_t(xi), _t(y)))


check_add(E(), I(0, 1), E())
check_add(I(0, 1), E(), E())
check_add(I(-oo, 1), I(0, 1), I(-oo, 2))
check_add(I(1, oo), I(0, 1), I(1, oo))
check_add(I(-oo, oo), I(0, 1), I(-oo, oo))
check_add(I(MAX, oo), 1, I(MAX, oo))
check_add(I(MAX, oo), -1, I(math.nextafter(MAX, 0), oo))
check_add(I(MAX, oo), I(MAX, oo), I(MAX, oo))
check_add(I(MAX, oo), -oo, E())
check_add(I(MAX, oo), oo, E())
check_add(I(-oo, -MAX), 1, I(-oo, math.nextafter(-MAX, 0)))
check_add(I(-oo, -MAX), -1, I(-oo, -MAX))
check_add(I(-oo, -MAX), I(-oo, -MAX), I(-oo, -MAX))
check_add(E(), oo, E())
check_add(E(), 0, E())
check_add(I(0, 1), 1, I(1, 2))
check_add(I(0, 1), -oo, E())
check_add(I(0, 1), oo, E())
check_add(I(-oo, 1), 1, I(-oo, 2))

check_mul(E(), I(0, 1), E())
check_mul(I(0), I(-oo, oo), I(0))
check_mul(I(-1, 1), I(-oo, 0), I(-oo, oo))
check_mul(I(-oo, -1), I(-1, 0), I(0, oo))
check_mul(I(-oo, 1), I(-1, 0), I(-1, oo))
check_mul(I(0, 1), I(1, oo), I(0, oo))
check_mul(I(0, 1), I(-1, oo), I(-1, oo))
check_mul(I(-oo, -1), I(0, 1), I(-oo, 0))
check_mul(I(-oo, 1), I(0, 1), I(-oo, 1))
check_mul(I(0, 1), I(-oo, -1), I(-oo, 0))
check_mul(I(0, 1), I(-oo, 1), I(-oo, 1))
check_mul(I(1, oo), I(0, 1), I(0, oo))
check_mul(I(-1, oo), I(0, 1), I(-1, oo))
check_mul(I(1, 2), I(1, 2), I(1, 4))
check_mul(I(1, 2), I(-2, 3), I(-4, 6))
check_mul(I(-1, 1), I(-2, 3), I(-3, 3))
check_mul(I(1, 2), -oo, E())
check_mul(I(1, 2), oo, E())
check_mul(I(1, 2), -1, I(-2, -1))

check_div(E(), I(0, 1), E())
check_div(0, 0, E())
check_div(I(1, 2), 0, E())
check_div(I(-oo, oo), 0, E())
check_div(0, I(0, 1), I(0))
check_div(0, I(-oo, oo), I(0))
check_div(I(6, 12), I(2, 3), I(2, 6))
check_div(I(6, 12), I(-3, -2), I(-6, -2))
check_div(I(6, 12), I(-2, 3), I(-oo, oo))
check_div(I(-oo, -1), I(-1, 0), I(1, oo))
check_div(I(-oo, -1), I(0, 1), I(-oo, -1))
check_div(I(1, oo), I(-1, 0), I(-oo, -1))
check_div(I(1, oo), I(0, 1), I(1, oo))
check_div(I(-1, 1), I(-1, 1), I(-oo, oo))
for s, ex in ((-oo, E()), (oo, E()), (-1, I(-2, -1))):
    case("div_scalar", lambda s=s: I(1, 2) / s, ex, lambda s=s: T.div(T.iv(1, 2), T.scalar(s)))


def unary(
    name: str, f: Callable[[Any], Any], tf: Callable[[T.Iv], T.Iv], x: Any, ex: Any, tol: float = 0.0
) -> None:
    case(name, lambda: f(x), ex, lambda: tf(_t(x)), tol)


for x, ex in ((I(-oo, oo), I(0, oo)), (I(-oo, 0), I(0)), (I(-9, 4), I(0, 2)), (I(4, 9), I(2, 3)),
              (I(-9, -4), E()), (I(-9, oo), I(0, oo))):  # fmt: skip
    unary("sqrt", sqrt, T.sqrt, x, ex)
APPROX = 10 * sys.float_info.epsilon  # codac's default Approx tolerance
for x, ex, tol in ((E(), E(), 0), (I(-oo, oo), I(-oo, oo), 0), (I(0, oo), I(-oo, oo), 0), (I(-oo, 0), E(), 0),
                   (I(1, 2), I(0, math.log(2)), APPROX), (I(-1, 1), I(-oo, 0), APPROX),
                   (I(0, 1), I(-oo, 0), APPROX), (I(1, oo), I(0, oo), APPROX), (I(0), E(), 0),
                   (I(-2, -1), E(), 0)):  # fmt: skip
    unary("log", log, T.log, x, ex, tol)
unary("log", log, T.log, I(0, 5e-324), I(-oo, math.log(5e-324)), APPROX)  # codac: ub > -744.5
for x, ex, tol in ((E(), E(), 0), (I(-oo, oo), I(0, oo), 0), (I(0, oo), I(1, oo), APPROX),
                   (I(-oo, 0), I(0, 1), APPROX), (I(0, 2), I(1, math.exp(2)), APPROX),
                   (I(-1, 1), I(math.exp(-1), math.exp(1)), APPROX), (I(1e100, 1e111), I(MAX, oo), 0),
                   (I(MAX, oo), I(MAX, oo), 0), (I(0, MAX), I(1, oo), APPROX)):  # fmt: skip
    unary("exp", exp, T.exp, x, ex, tol)


def check_trigo(x: Any, expected: Any) -> None:
    """codac's CHECK_trigo: sin on eight forms of the same angle set (Approx 1e-9)."""
    pi, hpi, tpi = I(PI_LB, PI_UP), I(PI_LB / 2, PI_UP / 2), I(2 * PI_LB, 2 * PI_UP)
    ex, mex = expected, -expected
    forms = [(sin, lambda: x, ex), (sin, lambda: pi - x, ex), (sin, lambda: x + tpi, ex), (sin, lambda: -x, mex),
             (cos, lambda: x - hpi, ex), (cos, lambda: hpi - x, ex), (cos, lambda: x + hpi, mex),
             (cos, lambda: x + tpi - hpi, ex)]  # fmt: skip
    for f, arg, e in forms:
        tf = T.sin if f is sin else T.cos
        case(
            f"trigo_{f.__name__}",
            lambda f=f, arg=arg: f(arg()),
            e,
            lambda tf=tf, arg=arg: tf(_t(arg())),
            1e-9,
        )


check_trigo(I(-oo, oo), I(-1, 1))
check_trigo(E(), E())
check_trigo(I(0, PI_UP / 2.0), I(0, 1))
check_trigo(I(0, PI_UP), I(0, 1))
check_trigo(I(0, 3 * PI_UP / 2.0), I(-1, 1))
check_trigo(I(PI_LB, 3 * PI_UP / 2.0), I(-1, 0))
check_trigo(I(0.5, 1.5), I(math.sin(0.5), math.sin(1.5)))
check_trigo(I(1.5, 3), I(math.sin(3.0), 1))
check_trigo(I(3, 4), I(math.sin(4.0), math.sin(3.0)))
check_trigo(I(3, 5), I(-1, math.sin(3.0)))
check_trigo(I(3, 2 * PI_UP + 1.5), I(-1, math.sin(1.5)))
check_trigo(I(5, 2 * PI_UP + 1.5), I(math.sin(5.0), math.sin(1.5)))
check_trigo(I(5, 2 * PI_UP + 3), I(math.sin(5.0), 1))

unary("tan", tan, T.tan, I(PI_LB, PI_UP) / 2.0, I(-oo, oo))
unary("tan", tan, T.tan, -I(PI_LB, PI_UP), I(-1e-8, 1e-8), 1e-8)  # codac: diam < 1e-8 and holds 0
unary("tan", tan, T.tan, I(3 * PI_LB / 4, 5 * PI_UP / 4), I(-1, 1), APPROX)
unary("tan", tan, T.tan, I(-oo, oo), I(-oo, oo))
unary("tan", tan, T.tan, I(-PI_UP / 4, PI_UP / 4), I(-1, 1), APPROX)
unary("tan", tan, T.tan, I(PI_LB / 4, (1 - 1e-10) * PI_LB / 2), I(1, math.tan((1 - 1e-10) * PI_LB / 2)), 1e-9)
unary(
    "tan", tan, T.tan, I(-(1 - 1e-10) * PI_LB / 2, PI_LB / 4), I(-math.tan((1 - 1e-10) * PI_LB / 2), 1), 1e-9
)
unary("tan", tan, T.tan, I(-1.57079632679489678, 1.1780972450961728626), I(-oo, oo))  # codac: non-empty


def check_atan2(y: Any, x: Any, ex: Any, tol: float = APPROX) -> None:
    case("atan2", lambda: atan2(y, x), ex, lambda: T.atan2(_t(y), _t(x)), tol)


P = math.pi
check_atan2(I(-oo, oo), E(), E())
check_atan2(I(1), I(1), I(P / 4))
check_atan2(I(-1), I(-1), I(-3 * P / 4))
check_atan2(I(-1), I(1), I(-P / 4))
check_atan2(I(1), I(-1), I(3 * P / 4))
check_atan2(I(0, oo), I(0, oo), I(0, P / 2))
check_atan2(I(-oo, -5e-324), I(-oo, 0), I(-P, -P / 2))
check_atan2(I(-oo, 0), I(0, oo), I(-P / 2, 0))
check_atan2(I(0, oo), I(-oo, 0), I(P / 2, P))
check_atan2(I(1, oo), I(-1, 1), I(P / 4, 3 * P / 4))
check_atan2(I(-oo, -1), I(-1, 1), I(-3 * P / 4, -P / 4))
check_atan2(I(-1, 1), I(1, oo), I(-P / 4, P / 4))
check_atan2(I(-1, 1), I(-oo, -1), I(-P, P))
check_atan2(I(-oo, oo), I(-oo, oo), I(-P, P))
check_atan2(I(0), I(0), E())


def check_pow(x: Any, p: int, expected: Any, eps: float = 0.0) -> None:
    case("pow", lambda: pown(x, p), expected, lambda: T.pown(_t(x), p), eps)
    ex = expected if p % 2 == 0 else -expected
    case("pow", lambda: pown(-x, p), ex, lambda: T.pown(_t(-x), p), eps)


check_pow(I(-oo, oo), 4, I(0, oo))
check_pow(E(), 4, E())
check_pow(I(2, 3), 4, I(16, 81))
check_pow(I(-2, 3), 4, I(0, 81))
check_pow(I(-3, 2), 4, I(0, 81))
check_pow(I(2, oo), 4, I(16, oo))
check_pow(I(-oo, oo), 3, I(-oo, oo))
check_pow(E(), 3, E())
check_pow(I(2, 3), 3, I(8, 27))
check_pow(I(-2, 3), 3, I(-8, 27))
check_pow(I(-3, 2), 3, I(-27, 8))
check_pow(I(2, oo), 3, I(8, oo))
check_pow(I(-10, 10), -2, I(1.0 / 100, oo), sys.float_info.epsilon)
case("neg", lambda: -I(0, 1), I(-1, 0), lambda: T.neg(T.iv(0, 1)))
case("neg", lambda: -I(-oo, oo), I(-oo, oo), lambda: T.neg(T.iv(-oo, oo)))
case("neg", lambda: -I(-oo, 0), I(0, oo), lambda: T.neg(T.iv(-oo, 0)))
case("neg", lambda: -I(-oo, 1), I(-1, oo), lambda: T.neg(T.iv(-oo, 1)))
assert EMPTY == (oo, -oo)


@pytest.mark.parametrize(("name", "ours", "peer", "truth", "tol"), CASES, ids=[c[0] for c in CASES])
def test_interval_operation(name: str, ours: Callable[[], Any], peer: tuple[float, float],
                            truth: Callable[[], T.Iv], tol: float) -> None:  # fmt: skip
    judge(name, ours_of(ours()), peer, truth(), tol)
