"""A :class:`~.expr.Function` flattened into a tape for compiled forward-backward (thesis §2.4.1.2).

The traced DAG becomes an ``int64`` array ``code`` of shape ``(K, 4)`` — ``(op, arg0, arg1, param)``
per node, in topological order — and a ``float64`` array ``cst`` ``(K, 2)`` holding the constants.
Compiled kernels (:mod:`.hc4_jit`) run the natural inclusion function (Eq. 2.21) and the projection
rules of :mod:`.backward` on it, one box at a time in machine code; :func:`fwd_op` evaluates one node
with the outward-rounded scalar primitives of :mod:`digslam.observer.core.scalar_jit` (empty =
``(inf, -inf)``; an operand with an infinite point gives the empty interval). Functions using an
operation without a scalar rule (trigonometric, ``min``, ``max``, ``atan2``) get no tape and keep the
numpy path.

>>> t = Tape.of(Function(lambda x: (x[0] - 2) ** 2 + x[1]))
>>> t.code[:, 0].tolist(), t.outputs.tolist()
([0, 1, 0, 3, 7, 2], [5])
>>> Tape.of(Function(lambda x: sin(x[0]))) is None
True
"""

from __future__ import annotations

from typing import Any

import numpy as np

from digslam.observer.core.scalar_jit import (
    iabs,
    iadd,
    iexp,
    ilog,
    imul,
    ipown,
    isqr,
    isqrt,
    isub,
    ixdiv,
    njit,
)

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


@njit(forceinline=True, error_model="numpy")
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


__all__ = [
    "ABS",
    "ADD",
    "CONST",
    "DIV",
    "EXP",
    "LOG",
    "MUL",
    "NEG",
    "OPCODES",
    "POWN",
    "SQR",
    "SQRT",
    "SUB",
    "Tape",
    "VAR",
    "fwd_op",
]
