"""A :class:`~.expr.Function` flattened into a tape for compiled forward-backward (thesis §2.4.1.2).

The traced DAG becomes an ``int64`` array ``code`` of shape ``(K, 4)`` — ``(op, arg0, arg1, param)``
per node, in topological order — and a ``float64`` array ``cst`` ``(K, 2)`` holding the constants.
Compiled kernels (:mod:`.jit_hc4`) run the natural inclusion function (Eq. 2.21) and the projection
rules of :mod:`.backward` on it, one box at a time in machine code. This module also holds the
outward-rounded scalar interval operations those kernels need beyond :mod:`.jit` (empty =
``(inf, -inf)``; an operand with an infinite point gives the empty interval, :func:`.jit.nil`).
Functions using an operation without a scalar rule (trigonometric, ``min``, ``max``, ``atan2``)
get no tape and keep the numpy path.

>>> t = Tape.of(Function(lambda x: (x[0] - 2) ** 2 + x[1]))
>>> t.code[:, 0].tolist(), t.outputs.tolist()
([0, 1, 0, 3, 7, 2], [5])
>>> Tape.of(Function(lambda x: sin(x[0]))) is None
True
>>> lo, hi = ixdiv(1.0, 2.0, 0.0, 1.0)       # set-based division: [1,2]/[0,1] = [1, +inf]
>>> 1.0 - 1e-15 < lo <= 1.0 and hi == float("inf")
True
>>> iadd(0.1, 0.2, 1.0, 1.0)[0] < 1.1 < iadd(0.1, 0.2, 1.0, 1.0)[1]     # outward rounded
True
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from digslam.observer.core.scalar_jit import (
    add_dn,
    add_up,
    dn,
    imul,
    isqr,
    isqrt,
    mul_dn,
    mul_up,
    nil,
    njit,
    up,
    wdn,
    wup,
)

_INF = math.inf
VAR, CONST, ADD, SUB, MUL, DIV, NEG, SQR, SQRT, EXP, LOG, ABS, POWN = range(13)
#: op name -> tape code
OPCODES = {"var": VAR, "const": CONST, "add": ADD, "sub": SUB, "mul": MUL, "div": DIV, "neg": NEG,
           "sqr": SQR, "sqrt": SQRT, "exp": EXP, "log": LOG, "abs": ABS, "pown": POWN}  # fmt: skip


class Tape:
    """The flat form of a traced function: ``code (K, 4)``, ``cst (K, 2)``, ``outputs (m,)``."""

    def __init__(self, code: np.ndarray, cst: np.ndarray, outputs: np.ndarray, n: int) -> None:
        self.code, self.cst, self.outputs, self.n = code, cst, outputs, n

    @staticmethod
    def of(f: Any) -> Tape | None:
        """The tape of a :class:`~.expr.Function` (cached on it), or ``None`` if an op has no rule."""
        if "_tape" not in f.__dict__:
            f._tape = Tape._build(f)
        return f._tape

    @staticmethod
    def _build(f: Any) -> Tape | None:
        if any(op not in OPCODES for op, _, _ in f.nodes):
            return None
        code = np.full((len(f.nodes), 4), -1, dtype=np.int64)
        cst = np.zeros((len(f.nodes), 2))
        for k, (op, args, p) in enumerate(f.nodes):
            code[k, 0] = OPCODES[op]
            code[k, 1 : 1 + len(args)] = args
            if op in ("var", "pown"):
                code[k, 3] = int(p)
            elif op == "const":
                cst[k] = p
        return Tape(code, cst, np.asarray(f.outputs, dtype=np.int64), f.n)


@njit(inline="always")
def meet(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """``[a] ∩ [b]`` (Eq. 2.3)."""
    lo, hi = max(al, bl), min(ah, bh)
    return (lo, hi) if lo <= hi and lo < _INF and hi > -_INF else (_INF, -_INF)


@njit(inline="always")
def _nan_lo(x: float) -> float:
    return -_INF if x != x else x


@njit(inline="always")
def _nan_hi(x: float) -> float:
    return _INF if x != x else x


@njit(inline="always")
def iadd(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """``[a] + [b]`` (Eq. 2.5)."""
    if nil(al, ah) or nil(bl, bh):
        return _INF, -_INF
    return _nan_lo(add_dn(al, bl)), _nan_hi(add_up(ah, bh))


@njit(inline="always")
def isub(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """``[a] - [b]``."""
    if nil(al, ah) or nil(bl, bh):
        return _INF, -_INF
    return _nan_lo(add_dn(al, -bh)), _nan_hi(add_up(ah, -bl))


@njit(inline="always")
def _qdn(a: float, b: float) -> float:
    return 0.0 if a == 0.0 else dn(a / b)


@njit(inline="always")
def _qup(a: float, b: float) -> float:
    return 0.0 if a == 0.0 else up(a / b)


@njit
def ixdiv(al: float, ah: float, bl: float, bh: float) -> tuple[float, float]:
    """``[a]/[b]``, set-based (IEEE 1788), as :func:`.arith.div`: unbounded when ``0 ∈ [b]``."""
    if nil(al, ah) or nil(bl, bh) or (bl == 0.0 and bh == 0.0):
        return _INF, -_INF
    if bl > 0.0 or bh < 0.0:
        lo, hi = _INF, -_INF
        for x in (al, ah):
            for y in (bl, bh):
                q = _qdn(x, y)
                lo = lo if q != q else min(lo, q)  # inf/inf corners are dominated
                q = _qup(x, y)
                hi = hi if q != q else max(hi, q)
        return lo, hi
    if al == 0.0 and ah == 0.0:
        return 0.0, 0.0
    if bl == 0.0:  # [b] = [0, bh], bh > 0
        if al >= 0.0:
            return _qdn(al, bh), _INF
        if ah <= 0.0:
            return -_INF, _qup(ah, bh)
    elif bh == 0.0:  # [b] = [bl, 0], bl < 0
        if al >= 0.0:
            return -_INF, _qup(al, bl)
        if ah <= 0.0:
            return _qdn(ah, bl), _INF
    return -_INF, _INF


@njit
def iexp(al: float, ah: float) -> tuple[float, float]:
    """``exp([a])``, libm results widened by ``LIBM_ULPS``."""
    if nil(al, ah):
        return _INF, -_INF
    lo = 1.0 if al == 0.0 else max(wdn(math.exp(al)), 0.0)
    hi = 1.0 if ah == 0.0 else wup(math.exp(ah))
    return lo, hi


@njit
def ilog(al: float, ah: float) -> tuple[float, float]:
    """``log([a] ∩ (0, +∞))``; empty when ``[a] <= 0``."""
    if nil(al, ah) or ah <= 0.0:
        return _INF, -_INF
    lo = -_INF if al <= 0.0 else (0.0 if al == 1.0 else wdn(math.log(al)))
    hi = 0.0 if ah == 1.0 else (_INF if ah == _INF else wup(math.log(ah)))
    return lo, hi


@njit
def _pow_pos(x: float, n: int, up: bool) -> float:
    """Directed ``x**n`` for ``x >= 0``, ``n >= 1`` (square and multiply, monotone steps)."""
    r, b = 1.0, x
    while n:
        if n & 1:
            r = mul_up(r, b) if up else mul_dn(r, b)
        n >>= 1
        if n:
            b = mul_up(b, b) if up else mul_dn(b, b)
    return r


@njit
def ipown(al: float, ah: float, n: int) -> tuple[float, float]:
    """``[a]ⁿ`` for an integer ``n``, as :func:`.arith.pown`."""
    if nil(al, ah):
        return _INF, -_INF
    if n == 0:
        return 1.0, 1.0
    if n < 0:
        pl, ph = ipown(al, ah, -n)
        return ixdiv(1.0, 1.0, pl, ph)
    if n % 2 == 0:
        mig = 0.0 if al <= 0.0 <= ah else min(abs(al), abs(ah))
        return _pow_pos(mig, n, False), _pow_pos(max(abs(al), abs(ah)), n, True)
    lo = _pow_pos(al, n, False) if al >= 0.0 else -_pow_pos(-al, n, True)
    hi = _pow_pos(ah, n, True) if ah >= 0.0 else -_pow_pos(-ah, n, False)
    return lo, hi


@njit(inline="always")
def iabs(al: float, ah: float) -> tuple[float, float]:
    """``|[a]|``."""
    if nil(al, ah):
        return _INF, -_INF
    if al >= 0.0:
        return al, ah
    return (-ah, -al) if ah <= 0.0 else (0.0, max(-al, ah))


@njit(inline="always", error_model="numpy")
def fwd_op(op: int, al: float, ah: float, bl: float, bh: float, p: int) -> tuple[float, float]:
    """Natural inclusion (Eq. 2.21) of one tape node ``op`` from its arguments' enclosures."""
    if op == ADD:
        return iadd(al, ah, bl, bh)
    if op == SUB:
        return isub(al, ah, bl, bh)
    if op == MUL:
        return imul(al, ah, bl, bh)
    if op == DIV:
        return ixdiv(al, ah, bl, bh)
    if op == NEG:
        return -ah, -al
    if op == SQR:
        return isqr(al, ah)
    if op == SQRT:
        return isqrt(al, ah)
    if op == EXP:
        return iexp(al, ah)
    if op == LOG:
        return ilog(al, ah)
    if op == ABS:
        return iabs(al, ah)
    return ipown(al, ah, p)


__all__ = ["Tape", "OPCODES", "up", "dn", "meet", "iadd", "isub", "imul", "ixdiv", "isqr", "isqrt", "iabs",
           "iexp", "ilog", "ipown", "fwd_op"]  # fmt: skip
