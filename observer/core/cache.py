"""The stale-kernel guard: editing any kernel source clears every compiled kernel of the project.

numba caches a kernel on disk (``cache=True``) and checks only the file that defines it: when a kernel of
``a_jit.py`` calls one of ``b_jit.py`` and ``b_jit.py`` changes, the cached machine code of ``a_jit.py``
still holds the old ``b``, silently. :func:`guard` closes that hole. At the first import of
``digslam.observer`` it hashes every source file of ``digslam`` that mentions ``njit`` (the kernel files and
:mod:`.scalar_jit`, which defines the decorator) and compares the digest with the one stamped beside the
caches; on a mismatch it deletes the ``.nbi``/``.nbc`` files of those sources in every folder numba may use
(``__pycache__`` beside the source, ``NUMBA_CACHE_DIR``, numba's user-wide cache) and writes the new stamp.
So an edit costs one recompilation, never a run of old code. Hashing takes a few milliseconds.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

#: The package folders whose sources are hashed (``digslam.observer``, ``digslam.envs``, ``digslam.agents``).
ROOTS = tuple(Path(__file__).resolve().parents[2] / name for name in ("observer", "envs", "agents"))
STAMP = "digslam-kernels.sha256"


def kernel_sources(roots: Iterable[Path] = ROOTS) -> list[Path]:
    """Every ``.py`` file under ``roots`` that mentions ``njit``, sorted."""
    found = []
    for root in roots:
        for folder, subdirs, names in os.walk(root):
            subdirs[:] = [d for d in subdirs if d != "__pycache__"]
            found += [Path(folder) / n for n in names if n.endswith(".py")]
    return sorted(p for p in found if b"njit" in p.read_bytes())


def digest(files: Iterable[Path]) -> str:
    """SHA-256 over the files' paths and contents."""
    h = hashlib.sha256()
    for p in files:
        h.update(str(p).encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()


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
    files = kernel_sources(roots)
    new = digest(files)
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


__all__ = ["ROOTS", "STAMP", "cache_dirs", "clear", "digest", "guard", "kernel_sources", "stamp_path"]
