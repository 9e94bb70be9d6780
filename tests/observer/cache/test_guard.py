"""The stale-kernel guard (``digslam.observer.cache.guard``): an edited kernel source never runs old code.

numba's cache checks only the file that defines a kernel. The hazard, reproduced: kernel ``a`` of
``a_jit.py`` calls kernel ``b`` of ``b_jit.py``; after ``b_jit.py`` changes, a fresh process still runs the
old ``b`` through ``a``'s cache. With the guard called at import, the new ``b`` runs.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

from digslam.observer.cache import guard as cache

A = """
from numba import njit
from b_jit import b

@njit(cache=True)
def a(x):
    return b(x) + 1.0
"""
B = """
from numba import njit

@njit(cache=True)
def b(x):
    return x * {k}
"""
RUN = """
import sys
sys.path.insert(0, {root!r})
if {guarded}:
    from pathlib import Path
    from digslam.observer.cache import guard as cache
    cache.guard([Path({root!r})], Path({root!r}) / "stamp")
from a_jit import a
print(a(1.0))
"""


def _run(root: Path, guarded: bool) -> float:
    code = textwrap.dedent(RUN.format(root=str(root), guarded=guarded))
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True
    )
    return float(out.stdout.split()[-1])


def _fresh(tmp: Path) -> Path:
    root = tmp / "pkg"
    root.mkdir()
    (root / "a_jit.py").write_text(A)
    (root / "b_jit.py").write_text(B.format(k=2.0))
    return root


def test_without_the_guard_numba_runs_the_old_callee(tmp_path: Path) -> None:
    root = _fresh(tmp_path)
    assert _run(root, guarded=False) == 3.0
    (root / "b_jit.py").write_text(B.format(k=10.0))
    assert _run(root, guarded=False) == 3.0  # stale: a's cache still holds b(x) = 2x


def test_with_the_guard_an_edit_recompiles(tmp_path: Path) -> None:
    root = _fresh(tmp_path)
    assert _run(root, guarded=True) == 3.0
    assert _run(root, guarded=True) == 3.0  # unchanged sources: the caches are kept
    (root / "b_jit.py").write_text(B.format(k=10.0))
    assert _run(root, guarded=True) == 11.0


def test_guard_keeps_caches_when_nothing_changed(tmp_path: Path) -> None:
    root = _fresh(tmp_path)
    stamp = tmp_path / "stamp"
    assert cache.guard([root], stamp) is True  # first sight: stamped
    assert cache.guard([root], stamp) is False
    (root / "b_jit.py").write_text(B.format(k=3.0))
    assert cache.guard([root], stamp) is True


def test_the_project_sources_are_all_hashed() -> None:
    names = {p.name for p in cache.kernel_sources()}
    assert {"scalar_jit.py", "tape_jit.py", "dig_jit.py", "arc_jit.py", "robot_jit.py"} <= names


def test_an_empty_cache_folder_is_stamped_so_the_guard_clears_nothing(tmp_path: Path) -> None:
    folder = cache.empty_cache(tmp_path / "numba")
    assert [p.name for p in folder.iterdir()] == [cache.STAMP]
    assert cache.guard(stamp=folder / cache.STAMP) is False  # the current digest: nothing to clear
