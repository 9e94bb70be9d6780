"""Reader and runner for the IEEE 1788 test vectors of ITF1788 (``*.itl`` files).

Only numpy and the standard library are needed to read the files; :func:`run_all` also imports the
kernels of :mod:`digslam.observer`.

An ``.itl`` file holds ``testcase NAME { ... }`` blocks of statements such as::

    add [1.0, 2.0] [1.0, 2.0] = [2.0, 4.0];
    pown [-infinity,0.0] -3 = [-infinity,0.0];
    atan2 [0.0, 1.0] [1.0, 2.0] = [0.0, 0X1.1B6E192EBBE45P+0] <= [0.0, 0X1.2P+0] signal UndefinedOperation;

:func:`iter_vectors` yields the *undecorated* vectors whose operands are intervals or numbers and whose
result is an interval: any statement with a decorated interval (``[1,2]_com``) or ``[nai]`` is left out.
For ``= tight <= accurate`` the tight result is kept; a ``signal X`` suffix is ignored.

Literals: hex floats (``0X1.921FB54442D18P+0``) go through :func:`float.fromhex`; decimal numbers are
rounded to the nearest float64, which is how the ITF1788 plugins hand them to a library (as numeric
literals of the host language); ``infinity``; ``[empty]`` is ``(+inf, -inf)``; ``[entire]`` is
``(-inf, +inf)``; ``[x]`` is the point ``(x, x)``.

Run ``python tests/itf1788.py [FOLDER]`` for a table of soundness and tightness per operation (FOLDER
defaults to ``$DIGSLAM_ITF1788``); it exits 2 when no vector was checked (no folder, or no ``.itl`` file
in it) and 1 when a result is unsound.
"""

from __future__ import annotations

import math
import re
import sys
from collections import defaultdict
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np

Interval = tuple[float, float]
Operand = Interval | int | float

EMPTY: Interval = (math.inf, -math.inf)
ENTIRE: Interval = (-math.inf, math.inf)

#: Environment variable naming the folder of ``*.itl`` files (the ``itl/`` folder of the ITF1788 project).
ENV_VAR = "DIGSLAM_ITF1788"
#: The folder when ``DIGSLAM_ITF1788`` is unset: ``<repo>/../shared/oracles/itf1788``.
FALLBACK_FOLDER = Path(__file__).resolve().parents[1].parent / "shared" / "oracles" / "itf1788"


def vectors_folder() -> Path:
    """``$DIGSLAM_ITF1788`` if set, else :data:`FALLBACK_FOLDER`."""
    import os

    env = os.environ.get(ENV_VAR)
    return Path(env).expanduser() if env else FALLBACK_FOLDER


DEFAULT_FOLDER = vectors_folder()


class Vector(NamedTuple):
    """One undecorated test vector."""

    file: str
    line: int
    testcase: str
    op: str
    operands: tuple[Operand, ...]
    expected: Interval

    def where(self) -> str:
        return f"{self.file}:{self.line} ({self.testcase})"


class _Skip(Exception):
    """The statement is outside what this reader handles (decorated, NaI, booleans, strings...)."""


# --------------------------------------------------------------------------------------------- parsing

_TOKEN = re.compile(
    r"""
      (?P<string>"[^"]*")
    | (?P<interval>\[[^\]]*\](?:_[A-Za-z]+)?)
    | (?P<le><=)
    | (?P<punct>[=;{}])
    | (?P<word>[^\s=;{}\[\]"]+)
    """,
    re.VERBOSE,
)
_BLOCK_COMMENT = re.compile(r"/\*.*?\*/", re.DOTALL)
_LINE_COMMENT = re.compile(r"//[^\n]*")
_INT = re.compile(r"[+-]?\d+")
_HEX = re.compile(r"[+-]?0[xX][0-9a-fA-F]*\.?[0-9a-fA-F]*(?:[pP][+-]?\d+)?")
_DEC = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_INFINITY = {
    "infinity": math.inf,
    "+infinity": math.inf,
    "-infinity": -math.inf,
    "inf": math.inf,
    "+inf": math.inf,
    "-inf": -math.inf,
}


def _strip_comments(text: str) -> str:
    # keep the newlines of block comments so that line numbers stay right
    text = _BLOCK_COMMENT.sub(lambda m: "\n" * m.group(0).count("\n"), text)
    return _LINE_COMMENT.sub("", text)


def parse_number(s: str) -> float:
    """A float64 from an ITL number literal (hex exactly, decimal to nearest, ``infinity``)."""
    t = s.strip()
    low = t.lower()
    if low in _INFINITY:
        return _INFINITY[low]
    if _HEX.fullmatch(t):
        return float.fromhex(t)
    if _DEC.fullmatch(t):
        return float(t)
    raise _Skip(f"not a number literal: {s!r}")


def parse_interval(tok: str) -> Interval:
    """``(lo, hi)`` from an undecorated interval literal; raises :class:`_Skip` otherwise."""
    if not tok.endswith("]"):
        raise _Skip("decorated interval")
    body = tok[1:-1].strip().lower()
    if body == "empty":
        return EMPTY
    if body == "entire":
        return ENTIRE
    if body == "nai":
        raise _Skip("NaI")
    parts = [p.strip() for p in body.split(",")]
    if len(parts) == 1:
        lo = hi = parse_number(parts[0])
    elif len(parts) == 2:
        lo, hi = parse_number(parts[0]), parse_number(parts[1])
    else:
        raise _Skip(f"bad interval literal {tok!r}")
    if not (lo <= hi) or lo == math.inf or hi == -math.inf:
        raise _Skip(f"invalid interval {tok!r}")
    return lo, hi


def _parse_operand(tok: str) -> Operand:
    if tok.startswith("["):
        return parse_interval(tok)
    if tok.startswith('"'):
        raise _Skip("string operand")
    if _INT.fullmatch(tok):
        return int(tok)
    return parse_number(tok)


def _parse_statement(tokens: Sequence[str]) -> tuple[str, tuple[Operand, ...], Interval]:
    if "=" not in tokens:
        raise _Skip("no '='")
    eq = tokens.index("=")
    if eq == 0:
        raise _Skip("no operation")
    op, lhs, rhs = tokens[0], tokens[1:eq], tokens[eq + 1 :]
    if not rhs:
        raise _Skip("no result")
    # any decorated interval or NaI anywhere (operands, tight or accurate result) -> not undecorated
    for t in tokens:
        if t.startswith("[") and (not t.endswith("]") or t[1:-1].strip().lower() == "nai"):
            raise _Skip("decorated")
    result = rhs[0]  # '= tight <= accurate': the tight one; 'signal X' ignored
    if not result.startswith("["):
        raise _Skip("result is not an interval")
    return op, tuple(_parse_operand(t) for t in lhs), parse_interval(result)


def iter_file(path: Path) -> Iterator[Vector]:
    """The undecorated interval vectors of one ``.itl`` file, in order."""
    text = _strip_comments(path.read_text(encoding="utf-8", errors="replace"))
    testcase = ""
    stmt: list[str] = []
    stmt_line = 0
    in_header = False
    for m in _TOKEN.finditer(text):
        tok = m.group(0)
        line = text.count("\n", 0, m.start()) + 1
        if in_header:  # 'testcase NAME {'
            if tok == "{":
                in_header = False
            else:
                testcase = tok
            continue
        if not stmt and tok == "testcase":
            in_header = True
            continue
        if tok == "}":
            stmt = []
            continue
        if tok == ";":
            if stmt:
                try:
                    op, operands, expected = _parse_statement(stmt)
                except _Skip:
                    pass
                else:
                    yield Vector(path.name, stmt_line, testcase, op, operands, expected)
            stmt = []
            continue
        if not stmt:
            stmt_line = line
        stmt.append(tok)


def iter_vectors(folder: str | Path = DEFAULT_FOLDER) -> Iterator[Vector]:
    """The undecorated interval vectors of all ``.itl`` files of ``folder`` (sorted by file name)."""
    for path in sorted(Path(folder).glob("*.itl")):
        yield from iter_file(path)


# ---------------------------------------------------------------------------------------------- kernels


class Op(NamedTuple):
    """How to evaluate one ITL operation: ``n_intervals`` interval operands, then number operands."""

    n_intervals: int
    n_numbers: int
    fn: Callable[..., tuple[np.ndarray, np.ndarray]]


def kernels() -> dict[str, Op]:
    """ITL operation name -> kernel of :mod:`digslam.observer` (imported here, not at module load)."""
    from digslam.observer.core import arith, trig

    def recip(a):
        one = np.ones_like(a[0])
        return arith.div((one, one.copy()), a)

    return {
        "pos": Op(1, 0, lambda a: (a[0] + 0.0, a[1] + 0.0)),
        "neg": Op(1, 0, arith.neg),
        "add": Op(2, 0, arith.add),
        "sub": Op(2, 0, arith.sub),
        "mul": Op(2, 0, arith.mul),
        "div": Op(2, 0, arith.div),
        "recip": Op(1, 0, recip),
        "sqr": Op(1, 0, arith.sqr),
        "sqrt": Op(1, 0, arith.sqrt),
        "pown": Op(1, 1, arith.pown),
        "abs": Op(1, 0, arith.abs_),
        "min": Op(2, 0, arith.minimum),
        "max": Op(2, 0, arith.maximum),
        "exp": Op(1, 0, arith.exp),
        "log": Op(1, 0, arith.log),
        "intersection": Op(2, 0, arith.intersect),
        "convexHull": Op(2, 0, arith.hull),
        "sin": Op(1, 0, trig.sin),
        "cos": Op(1, 0, trig.cos),
        "tan": Op(1, 0, trig.tan),
        "asin": Op(1, 0, trig.asin),
        "acos": Op(1, 0, trig.acos),
        "atan": Op(1, 0, trig.atan),
        "atan2": Op(2, 0, trig.atan2),
    }


#: The operations :func:`run_all` evaluates (the keys of :func:`kernels`).
SUPPORTED = (
    "pos", "neg", "add", "sub", "mul", "div", "recip", "sqr", "sqrt", "pown", "abs", "min", "max",
    "exp", "log", "intersection", "convexHull", "sin", "cos", "tan", "asin", "acos", "atan", "atan2",
)  # fmt: skip


def _fits(v: Vector, spec: Op) -> bool:
    ops = v.operands
    if len(ops) != spec.n_intervals + spec.n_numbers:
        return False
    if not all(isinstance(o, tuple) for o in ops[: spec.n_intervals]):
        return False
    return all(isinstance(o, int) for o in ops[spec.n_intervals :]) if spec.n_numbers else True


def is_empty(lo: float, hi: float) -> bool:
    return lo > hi


def is_sound(expected: Interval, ours: Interval) -> bool:
    """``ours ⊇ expected`` (the empty set is in everything; NaN bounds are never sound)."""
    elo, ehi = expected
    lo, hi = ours
    if math.isnan(lo) or math.isnan(hi):
        return False
    if is_empty(elo, ehi):
        return True
    if is_empty(lo, hi):
        return False
    return lo <= elo and hi >= ehi


def is_tight(expected: Interval, ours: Interval) -> bool:
    """Same bounds (``-0.0 == 0.0``); two empty intervals are equal."""
    elo, ehi = expected
    lo, hi = ours
    if is_empty(elo, ehi) or is_empty(lo, hi):
        return is_empty(elo, ehi) and is_empty(lo, hi)
    return lo == elo and hi == ehi


class OpResult(NamedTuple):
    n_vectors: int
    n_sound: int
    n_tight: int
    unsound: list[tuple[Vector, Interval]]  # (vector, our result)


def evaluate(vectors: Sequence[Vector], spec: Op) -> list[Interval]:
    """Our results for ``vectors`` of one operation: one kernel call per group of number operands."""
    groups: dict[tuple, list[int]] = defaultdict(list)
    for i, v in enumerate(vectors):
        groups[tuple(v.operands[spec.n_intervals :])].append(i)
    out: list[Interval] = [EMPTY] * len(vectors)
    for numbers, idx in groups.items():
        args = []
        for k in range(spec.n_intervals):
            arr = np.array([vectors[i].operands[k] for i in idx], dtype=np.float64).reshape(len(idx), 2)
            args.append((arr[:, 0].copy(), arr[:, 1].copy()))
        with np.errstate(all="ignore"):
            lo, hi = spec.fn(*args, *numbers)
        lo = np.broadcast_to(np.asarray(lo, dtype=np.float64), (len(idx),))
        hi = np.broadcast_to(np.asarray(hi, dtype=np.float64), (len(idx),))
        for j, i in enumerate(idx):
            out[i] = (float(lo[j]), float(hi[j]))
    return out


def run_all(folder: str | Path = DEFAULT_FOLDER) -> dict[str, OpResult]:
    """``op -> (n_vectors, n_sound, n_tight, unsound examples)`` over every supported vector."""
    specs = kernels()
    by_op: dict[str, list[Vector]] = defaultdict(list)
    for v in iter_vectors(folder):
        spec = specs.get(v.op)
        if spec is not None and _fits(v, spec):
            by_op[v.op].append(v)
    results: dict[str, OpResult] = {}
    for op in SUPPORTED:
        vecs = by_op.get(op, [])
        if not vecs:
            continue
        ours = evaluate(vecs, specs[op])
        sound = [is_sound(v.expected, r) for v, r in zip(vecs, ours, strict=True)]
        tight = [is_tight(v.expected, r) for v, r in zip(vecs, ours, strict=True)]
        unsound = [(v, r) for v, r, s in zip(vecs, ours, sound, strict=True) if not s]
        results[op] = OpResult(len(vecs), sum(sound), sum(tight), unsound)
    return results


# ----------------------------------------------------------------------------------------------- output


def fmt_interval(x: Operand) -> str:
    if not isinstance(x, tuple):
        return repr(x)
    lo, hi = x
    if is_empty(lo, hi):
        return "[empty]"
    return f"[{lo!r}, {hi!r}]"


def fmt_unsound(v: Vector, ours: Interval) -> str:
    args = " ".join(fmt_interval(o) for o in v.operands)
    return f"{v.where()}: {v.op} {args} = {fmt_interval(v.expected)}, ours {fmt_interval(ours)}"


def table(results: dict[str, OpResult]) -> str:
    rows = [f"{'operation':<14}{'vectors':>9}{'sound':>9}{'tight':>9}{'tight %':>10}"]
    tot = [0, 0, 0]
    for op, r in results.items():
        share = 100 * r.n_tight / r.n_vectors
        rows.append(f"{op:<14}{r.n_vectors:>9}{r.n_sound:>9}{r.n_tight:>9}{share:>9.1f}%")
        tot = [tot[0] + r.n_vectors, tot[1] + r.n_sound, tot[2] + r.n_tight]
    if tot[0]:
        rows.append(f"{'total':<14}{tot[0]:>9}{tot[1]:>9}{tot[2]:>9}{100 * tot[2] / tot[0]:>9.1f}%")
    return "\n".join(rows)


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    folder = Path(args[0]) if args else vectors_folder()
    how = (f"point {ENV_VAR} (or the first argument) at the itl/ folder of the ITF1788 test vectors "
           "(oheim/ITF1788 on GitHub)")  # fmt: skip
    if not folder.is_dir():
        print(f"itf1788: no folder {folder}; {how}", file=sys.stderr)
        return 2
    results = run_all(folder)
    if not sum(r.n_vectors for r in results.values()):
        print(f"itf1788: no test vector checked in {folder} (no .itl file there); {how}", file=sys.stderr)
        return 2
    print(table(results))
    bad = [(v, r) for res in results.values() for v, r in res.unsound]
    if bad:
        print(f"\n{len(bad)} unsound vectors:")
        for v, r in bad:
            print("  " + fmt_unsound(v, r))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
