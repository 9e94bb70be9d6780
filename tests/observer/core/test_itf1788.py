"""The interval kernels against the IEEE 1788 test vectors of ITF1788 (undecorated vectors only).

Every kernel result must *contain* the expected (tightest) interval; tightness is reported by
``python tests/itf1788.py`` but not required here.
"""

from __future__ import annotations

import functools
import importlib.util
import math
import os
import sys
from pathlib import Path

import pytest

#: ``$DIGSLAM_ITF1788`` (the ``itl/`` folder of the ITF1788 test vectors), else ``<repo>/../shared/...``.
FOLDER = Path(
    os.environ.get("DIGSLAM_ITF1788")
    or Path(__file__).resolve().parents[3].parent / "shared" / "oracles" / "itf1788"
).expanduser()

if not FOLDER.is_dir() or not any(FOLDER.glob("*.itl")):
    if os.environ.get("DIGSLAM_ITF1788"):  # asked to check: finding nothing is a failure, not a skip
        raise RuntimeError(f"DIGSLAM_ITF1788={os.environ['DIGSLAM_ITF1788']}: no .itl test vectors there")
    pytest.skip(
        f"ITF1788 test vectors not found in {FOLDER}; set DIGSLAM_ITF1788 to their itl/ folder",
        allow_module_level=True,
    )


def _load_parser():
    name = "_digslam_tests_itf1788"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, Path(__file__).resolve().parents[2] / "itf1788.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


itf = _load_parser()

REQUIRED_OPS = (
    "add", "sub", "mul", "div", "sqr", "sqrt", "exp", "log", "sin", "cos", "tan", "atan", "atan2",
    "abs", "min", "max", "pown",
)  # fmt: skip
MAX_LISTED = 10


@functools.lru_cache(maxsize=1)
def _results():
    return itf.run_all(FOLDER)


def test_parser_finds_required_operations():
    counts: dict[str, int] = {}
    for v in itf.iter_vectors(FOLDER):
        counts[v.op] = counts.get(v.op, 0) + 1
    missing = [op for op in REQUIRED_OPS if counts.get(op, 0) == 0]
    assert not missing, f"no undecorated vectors found for {missing}"
    results = _results()
    not_run = [op for op in REQUIRED_OPS if op not in results or results[op].n_vectors == 0]
    assert not not_run, f"vectors found but none evaluated for {not_run}"


def test_parser_syntax(tmp_path):
    (tmp_path / "a.itl").write_text(
        "/* block\n comment */\n"
        "testcase t1 {\n"
        "    add [1.0, 2.0] [0X1P+0,0x2p0] = [2.0, 4.0]; // trailing comment\n"
        "    add [1.0, 2.0]_com [1.0, 2.0]_com = [2.0, 4.0]_com;\n"
        "    add [nai] [1.0, 2.0] = [nai];\n"
        "    pown [-infinity,0.0] -3 = [-infinity,0.0];\n"
        "    sqrt [-1.0] = [empty] signal UndefinedOperation;\n"
        "    atan2 [entire] [1.0] = [-0X1.921FB54442D19P+0, 0X1.921FB54442D19P+0] <= [-2.0, 2.0];\n"
        "    isEmpty [empty] = true;\n"
        '    b-textToInterval "[1,2]" = [1.0, 2.0];\n'
        "}\n"
        "testcase t2 { neg [empty] = [empty]; }\n",
        encoding="utf-8",
    )
    vecs = list(itf.iter_vectors(tmp_path))
    got = [(v.testcase, v.op, v.operands, v.expected) for v in vecs]
    inf = math.inf
    half_pi_up = float.fromhex("0X1.921FB54442D19P+0")
    assert got == [
        ("t1", "add", ((1.0, 2.0), (1.0, 2.0)), (2.0, 4.0)),
        ("t1", "pown", ((-inf, 0.0), -3), (-inf, 0.0)),
        ("t1", "sqrt", ((-1.0, -1.0),), (inf, -inf)),
        ("t1", "atan2", ((-inf, inf), (1.0, 1.0)), (-half_pi_up, half_pi_up)),
        ("t2", "neg", ((inf, -inf),), (inf, -inf)),
    ]
    assert isinstance(vecs[1].operands[1], int)
    assert vecs[0].line == 4


def test_sound_and_tight_predicates():
    empty, entire = itf.EMPTY, itf.ENTIRE
    assert itf.is_sound(empty, (1.0, 2.0)) and itf.is_sound(empty, empty)
    assert not itf.is_sound((1.0, 2.0), empty)
    assert itf.is_sound((1.0, 2.0), entire) and not itf.is_sound((1.0, 2.0), (1.5, 2.0))
    assert not itf.is_sound((1.0, 2.0), (math.nan, 2.0))
    assert itf.is_tight((-0.0, 0.0), (0.0, -0.0)) and itf.is_tight(empty, empty)
    assert not itf.is_tight(empty, (1.0, 2.0)) and not itf.is_tight((1.0, 2.0), entire)


@pytest.mark.parametrize("op", itf.SUPPORTED)
def test_kernel_is_sound(op):
    res = _results().get(op)
    if res is None or res.n_vectors == 0:
        pytest.skip(f"no undecorated ITF1788 vectors for {op}")
    if res.unsound:
        listed = "\n".join("  " + itf.fmt_unsound(v, ours) for v, ours in res.unsound[:MAX_LISTED])
        more = len(res.unsound) - MAX_LISTED
        tail = f"\n  ... and {more} more" if more > 0 else ""
        pytest.fail(
            f"{op}: {len(res.unsound)} of {res.n_vectors} ITF1788 vectors unsound "
            f"(result does not contain the expected interval):\n{listed}{tail}",
            pytrace=False,
        )
