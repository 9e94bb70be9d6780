"""The kernel store: compiled kernels beside the sources under one stamp, filled when digslam is installed.

numba compiles a kernel at its first call and caches the machine code; a later process loads it in
milliseconds. Its caches live in numba's folders (``NUMBA_CACHE_DIR``, ``__pycache__`` beside the source, a
user-wide folder), so a fresh install, an emptied cache or a new ``NUMBA_CACHE_DIR`` starts cold: tens of
seconds of compilation before the first answer. The store moves that work to the install:

* **Where**: every kernel of ``digslam`` (any function of a source under :data:`~.guard.ROOTS`) is cached
  in a folder ``__kernels__`` beside its source file, before numba's own folders (:class:`StoreLocator`,
  first in numba's locator list). ``pip install`` builds the wheel with every kernel compiled into those
  folders (``setup.py``'s ``build_py`` runs ``digslam warmup`` on the built tree, :func:`build`), so the
  first call of an installed digslam loads machine code compiled for this machine.
* **Stamp**: an entry is valid only for the exact project it was compiled from: its stamp
  (:func:`stamp`) is the digest of every kernel source of ``digslam`` (:func:`~.guard.digest`, relative
  paths, so the tree built by ``pip`` and the installed one agree) with the numpy version; numba adds its
  own version and the CPU. Any other entry is ignored and overwritten, never run: an edited
  callee in another file cannot leave old machine code in its caller (the hazard of
  :func:`~.guard.guard`), and an upgrade or another machine recompiles instead of loading.
* **Fallback**: a kernel compiled later (a signature the build did not meet) is added to the store. Where
  the store's folder is not writable (a read-only install), or with ``DIGSLAM_KERNEL_STORE=0``, numba's
  own locators serve, guarded by :func:`~.guard.guard`. ``DIGSLAM_KERNEL_STORE=<folder>`` keeps the store
  in ``<folder>`` instead (mirroring the package layout): ``benchmarks/bench_cold_start.py`` builds a fresh
  one there, as ``pip install`` does.

Costs: the install compiles for about a minute on 2 cores (``DIGSLAM_BUILD_KERNELS=0`` skips it; an editable
install skips it too, its kernels compile at first use into the same folders); the store takes about
13 MB (3 MB in the wheel).
"""

from __future__ import annotations

import functools
import json
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from numba.core import caching

from digslam.observer.cache import guard

#: The folder beside each kernel source that holds its compiled kernels.
FOLDER = "__kernels__"
#: The environment variable: unset (the store beside the sources), ``0`` (off), or a folder.
SWITCH = "DIGSLAM_KERNEL_STORE"
#: The file, in the store folder of this module, that says how and when the store was built.
MANIFEST = "digslam-kernels.json"
#: The folder that holds ``observer/``, ``envs/`` and ``agents/`` (``site-packages/digslam`` or a checkout).
PACKAGE = guard.PACKAGE


def root() -> Path | None:
    """The store's root (``None``: off), from :data:`SWITCH`."""
    value = os.environ.get(SWITCH, "")
    if value == "0":
        return None
    return Path(value).resolve() if value else PACKAGE


def folder(py_file: str | os.PathLike[str], base: Path | None = None) -> Path | None:
    """The store folder of the kernels of ``py_file`` under ``base`` (default :func:`root`); ``None`` for a
    file outside digslam's kernel roots or with the store off."""
    base = root() if base is None else base
    if base is None:
        return None
    path = Path(py_file).resolve()  # ROOTS are resolved too (a venv may reach site-packages by a link)
    if not any(path.is_relative_to(r) for r in guard.ROOTS):
        return None
    return base / path.parent.relative_to(PACKAGE) / FOLDER


@functools.cache
def stamp() -> str:
    """The stamp of every store entry: the kernel sources' digest and numpy's version (numba keeps its own
    version in each index, and each numba release pins its llvmlite)."""
    import numpy

    return f"{guard.project_digest()} numpy-{numpy.__version__}"


class StoreLocator(caching.InTreeCacheLocator):  # type: ignore[misc]  # numba is untyped: the base class is Any
    """numba's cache locator for digslam's kernels: the store folder (:func:`folder`), stamped with
    :func:`stamp` instead of the defining file's own hash."""

    def __init__(self, py_func: Callable[..., Any], py_file: str) -> None:
        super().__init__(py_func, py_file)
        self._cache_path = str(folder(py_file))

    def get_source_stamp(self) -> str:
        return stamp()

    @classmethod
    def from_function(cls, py_func: Callable[..., Any], py_file: str) -> StoreLocator | None:
        if folder(py_file) is None:
            return None
        return super().from_function(py_func, py_file)  # None where the folder cannot be written


def install() -> bool:
    """Put :class:`StoreLocator` first in numba's locators (idempotent); False where
    ``NUMBA_CACHE_LOCATOR_CLASSES`` names the locators (numba then ignores the list)."""
    classes = caching.CacheImpl._locator_classes
    if StoreLocator not in classes:
        classes.insert(0, StoreLocator)
    return not os.environ.get("NUMBA_CACHE_LOCATOR_CLASSES")


def files(base: Path | None = None) -> list[Path]:
    """The compiled entries (``.nbi`` indexes and ``.nbc`` data) in the store under ``base``."""
    base = root() if base is None else base
    if base is None:
        return []
    found: list[Path] = []
    for r in guard.ROOTS:
        sub = base / r.relative_to(PACKAGE)
        found += [p for p in sub.rglob(f"{FOLDER}/*") if p.suffix in (".nbi", ".nbc")]
    return sorted(found)


def manifest_path(base: Path | None = None) -> Path | None:
    """Where the store under ``base`` keeps :data:`MANIFEST`."""
    here = folder(__file__, base)
    return None if here is None else here / MANIFEST


def write_manifest(seconds: float, base: Path | None = None, **extra: Any) -> None:
    """Record a build of the store: its stamp, the numba version, the build's seconds, the entries."""
    import numba

    path = manifest_path(base)
    if path is None:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    data = {"stamp": stamp(), "numba": numba.__version__, "python": sys.version.split()[0],
            "seconds": round(seconds, 1), "entries": len(files(base)), **extra}  # fmt: skip
    path.write_text(json.dumps(data, indent=1) + "\n")


def manifest(base: Path | None = None) -> dict[str, Any] | None:
    """The build record of the store under ``base`` if it matches this process's kernels, else ``None``."""
    path = manifest_path(base)
    try:
        data = json.loads(path.read_text()) if path else None
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and data.get("stamp") == stamp() else None


__all__ = ["FOLDER", "MANIFEST", "SWITCH", "StoreLocator", "files", "folder", "install", "manifest",
           "manifest_path", "root", "stamp", "write_manifest"]  # fmt: skip
