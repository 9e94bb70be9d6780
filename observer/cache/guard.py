"""The stale-kernel guard: editing any kernel source clears every compiled kernel of the project.

digslam's kernels live in the kernel store (:mod:`.store`), stamped with :func:`project_digest`; numba's
own folders serve where the store is off or read-only, and this module guards them.

numba caches a kernel on disk (``cache=True``) and checks only the file that defines it: when a kernel of
``a_jit.py`` calls one of ``b_jit.py`` and ``b_jit.py`` changes, the cached machine code of ``a_jit.py``
still holds the old ``b``, silently. :func:`guard` closes that hole. At the first import of
``digslam.observer`` it hashes the kernel sources of ``digslam`` (:func:`kernel_sources`: the files that
define a kernel and the files they import from, whose constants the kernels freeze) and compares the digest
with the one stamped beside the caches; on a mismatch it deletes the ``.nbi``/``.nbc`` files of those
sources in every folder numba may use (``__pycache__`` beside the source, ``NUMBA_CACHE_DIR``, numba's
user-wide cache) and writes the new stamp. So an edit costs one recompilation, never a run of old code.
Hashing takes a few milliseconds.
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
import tempfile
from collections.abc import Iterable
from pathlib import Path

#: The folder that holds the subpackages (``.../site-packages/digslam``, or a checkout).
PACKAGE = Path(__file__).resolve().parents[2]
#: The package folders whose sources are hashed (``digslam.observer``, ``digslam.envs``, ``digslam.agents``).
ROOTS = tuple(PACKAGE / name for name in ("observer", "envs", "agents"))
STAMP = "digslam-kernels.sha256"


_KERNEL = re.compile(rb"^\s*@(?:numba\.)?njit\b", re.M)
_IMPORT = re.compile(rb"^\s*from\s+(digslam(?:\.\w+)+|\.+\w*(?:\.\w+)*)\s+import", re.M)


def _imported(py_file: Path) -> list[Path]:
    """The source files of ``digslam`` that ``py_file`` imports from (``from digslam.x import``, ``from .x
    import``): a kernel compiles their module-level constants into its machine code."""
    out = []
    for name in _IMPORT.findall(py_file.read_bytes()):
        name = name.decode()
        if name.startswith("."):
            level = len(name) - len(name.lstrip("."))
            base = py_file.parents[level - 1].joinpath(*name.lstrip(".").split(".")) if name.strip(".") \
                else py_file.parents[level - 1]  # fmt: skip
        else:
            base = PACKAGE.joinpath(*name.split(".")[1:])
        for f in (base.with_suffix(".py"), base / "__init__.py"):
            if f.is_file():
                out.append(f)
                break
    return out


def kernel_sources(roots: Iterable[Path] = ROOTS) -> list[Path]:
    """Every ``.py`` file under ``roots`` that defines a kernel (an ``@njit`` line), and every source file
    they import from, recursively (a constant such as
    :data:`~digslam.observer.core.rounding.LIBM_ULPS` is frozen into the kernels that use it), sorted."""
    found = []
    for root in roots:
        for folder, subdirs, names in os.walk(root):
            subdirs[:] = [d for d in subdirs if d not in ("__pycache__", "__kernels__")]
            found += [Path(folder) / n for n in names if n.endswith(".py")]
    seen = {p for p in found if _KERNEL.search(p.read_bytes())}
    todo = list(seen)
    while todo:
        for f in _imported(todo.pop()):
            if f not in seen:
                seen.add(f)
                todo.append(f)
    return sorted(seen)


def digest(files: Iterable[Path]) -> str:
    """SHA-256 over the files' paths and contents; a path under :data:`PACKAGE` counts relative to it, so
    that the tree ``pip`` builds and the installed one agree."""
    h = hashlib.sha256()
    for p in files:
        name = p.relative_to(PACKAGE).as_posix() if p.is_relative_to(PACKAGE) else str(p)
        h.update(name.encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()


@functools.cache
def project_digest() -> str:
    """:func:`digest` of this project's :func:`kernel_sources`, computed once per process."""
    return digest(kernel_sources())


def _subpath(py_file: Path) -> str:
    # numba's _CacheLocator.get_suitable_cache_subpath: "<parent name>_<sha1 of the parent path>"
    parent = os.path.dirname(os.path.abspath(py_file))
    return os.path.basename(parent) + "_" + hashlib.sha1(parent.encode()).hexdigest()


def _numba_cache_dir() -> str:
    """``NUMBA_CACHE_DIR`` as numba read it ("" when unset; numba sets its config attributes at run time)."""
    from numba.core import config

    return str(getattr(config, "CACHE_DIR", "") or "")


def cache_dirs(py_file: Path) -> list[Path]:
    """The folders where numba may keep the caches of ``py_file``."""
    from numba.misc.appdirs import AppDirs

    dirs = [py_file.parent / "__pycache__", Path(AppDirs(appname="numba", appauthor=False).user_cache_dir)]
    if _numba_cache_dir():
        dirs.insert(0, Path(_numba_cache_dir()))
    return [dirs[0] if d == py_file.parent / "__pycache__" else d / _subpath(py_file) for d in dirs]


def empty_cache(folder: str | os.PathLike[str]) -> Path:
    """Make ``folder`` an empty ``NUMBA_CACHE_DIR`` that already holds the current stamp, so that a process
    pointed at it compiles (or loads from the kernel store) without :func:`guard` clearing the caches of
    every other folder (an unstamped folder would look like an edit)."""
    path = Path(folder)
    path.mkdir(parents=True, exist_ok=True)
    (path / STAMP).write_text(project_digest() + "\n")
    return path


def stamp_path() -> Path:
    """Where the digest is kept: ``NUMBA_CACHE_DIR`` if set, else beside this file's caches (if writable),
    else numba's user-wide cache folder."""
    from numba.misc.appdirs import AppDirs

    if _numba_cache_dir():
        return Path(_numba_cache_dir()) / STAMP
    here = Path(__file__).resolve().parent / "__pycache__"
    try:
        here.mkdir(exist_ok=True)
        tempfile.TemporaryFile(dir=here).close()
        return here / STAMP
    except OSError:
        return Path(AppDirs(appname="numba", appauthor=False).user_cache_dir) / STAMP


def clear(files: Iterable[Path]) -> int:
    """Delete the numba caches of ``files``; returns how many cache files went."""
    n = 0
    for f in files:
        for d in cache_dirs(f):
            if d.is_dir():
                for c in list(d.glob(f"{f.stem}.*.nbi")) + list(d.glob(f"{f.stem}.*.nbc")):
                    try:
                        c.unlink()
                        n += 1
                    except FileNotFoundError:  # another process cleared it first
                        pass
    return n


def guard(roots: Iterable[Path] = ROOTS, stamp: Path | None = None) -> bool:
    """Clear every kernel cache of ``roots`` when a kernel source changed since the last stamp (kept in
    ``stamp``, default :func:`stamp_path`); True if it cleared."""
    roots = tuple(roots)
    files = kernel_sources(roots)
    new = project_digest() if roots == ROOTS else digest(files)
    stamp = stamp_path() if stamp is None else stamp
    try:
        old = stamp.read_text().strip()
    except OSError:
        old = None
    if old == new:
        return False
    clear(files)
    try:
        stamp.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=stamp.parent)
        with os.fdopen(fd, "w") as fh:
            fh.write(new + "\n")
        os.replace(tmp, stamp)
    except OSError:  # a read-only install without a user cache: numba cannot cache either
        pass
    return True


__all__ = ["PACKAGE", "ROOTS", "STAMP", "cache_dirs", "clear", "digest", "empty_cache", "guard",
           "kernel_sources", "project_digest", "stamp_path"]  # fmt: skip
