"""Where the compiled kernels are kept, and which copy of digslam compiled them.

Lives here: :mod:`.store` (the kernel store: every kernel of digslam cached beside its source under one
stamp, filled by ``pip install``), :mod:`.guard` (the stale-kernel guard of numba's own cache folders and
the digest of the kernel sources), :mod:`.notice` (the one-line cold-start notice) and :mod:`.origin` (which
copy of ``digslam`` Python imported). :mod:`digslam.observer` calls :func:`prepare` before it imports a
kernel module.

May import: numpy, numba and the standard library; nothing else of ``digslam``.
"""

from . import guard, notice, origin, store
from .guard import (
    PACKAGE,
    ROOTS,
    STAMP,
    cache_dirs,
    clear,
    digest,
    empty_cache,
    kernel_sources,
    project_digest,
    stamp_path,
)
from .notice import ENV_PREFIXES, ESTIMATES, NOTICE, Notice, kind_of, message
from .store import FOLDER, MANIFEST, SWITCH, StoreLocator, manifest, write_manifest


def prepare() -> None:
    """Before any kernel loads: clear numba's stale caches (:func:`.guard.guard`), put the kernel store first
    (:func:`.store.install`) and register the cold-start notice (:func:`.notice.install`)."""
    guard.guard()
    store.install()
    notice.install()


__all__ = [
    "ENV_PREFIXES",
    "ESTIMATES",
    "FOLDER",
    "MANIFEST",
    "NOTICE",
    "PACKAGE",
    "ROOTS",
    "STAMP",
    "SWITCH",
    "Notice",
    "StoreLocator",
    "cache_dirs",
    "clear",
    "digest",
    "empty_cache",
    "guard",
    "kernel_sources",
    "kind_of",
    "manifest",
    "message",
    "notice",
    "origin",
    "prepare",
    "project_digest",
    "stamp_path",
    "store",
    "write_manifest",
]
