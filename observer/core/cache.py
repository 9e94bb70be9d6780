"""The compiled-kernel cache: the stale-kernel guard and the cold-start notice.

**The stale-kernel guard**: editing any kernel source clears every compiled kernel of the project.

numba caches a kernel on disk (``cache=True``) and checks only the file that defines it: when a kernel of
``a_jit.py`` calls one of ``b_jit.py`` and ``b_jit.py`` changes, the cached machine code of ``a_jit.py``
still holds the old ``b``, silently. :func:`guard` closes that hole. At the first import of
``digslam.observer`` it hashes every source file of ``digslam`` that mentions ``njit`` (the kernel files and
:mod:`.scalar_jit`, which defines the decorator) and compares the digest with the one stamped beside the
caches; on a mismatch it deletes the ``.nbi``/``.nbc`` files of those sources in every folder numba may use
(``__pycache__`` beside the source, ``NUMBA_CACHE_DIR``, numba's user-wide cache) and writes the new stamp.
So an edit costs one recompilation, never a run of old code. Hashing takes a few milliseconds.

**The cold-start notice**: one line on stderr when this process compiles a kernel of digslam.

numba compiles a kernel on its first call and keeps the machine code on disk; a later process loads it in
milliseconds. A cold start (fresh install, emptied cache, an edited kernel source, see the guard above)
therefore waits for the compiler, silently. :func:`install` registers a listener on numba's
``numba:compile`` event, which numba fires only when it really compiles (a cache miss, never when it
loads a kernel from its cache). The first such event for a function of ``digslam`` prints, once per
process, to stderr::

    digslam: compiling kernels, first run only, about 10 s; `digslam warmup` does it ahead of time

The figure depends on what compiles first: the interval library (:data:`ESTIMATES` ``"interval"``),
or the environments and the online observer (``"env"``), measured cold on 2 cores
(``benchmarks/bench_cold_start.py``). It is shown when stderr is a terminal, so that logs, pipes and
captured output (a test asserting one line of stderr) stay as they were; ``DIGSLAM_COMPILE_NOTICE=1``
shows it always, ``DIGSLAM_COMPILE_NOTICE=0`` never (``digslam warmup`` sets it in its worker processes).
"""

from __future__ import annotations

import hashlib
import os
import sys
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import Any, TextIO

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


#: Seconds a cold start spends compiling, by what compiles first (measured, 2 cores, empty numba cache).
ESTIMATES = {"interval": 10, "env": 45}
#: Module prefixes whose first compilation means the environment path (the rest is the interval library).
ENV_PREFIXES = ("digslam.envs", "digslam.agents", "digslam.observer.online")


def message(kind: str) -> str:
    """The notice for ``kind`` (a key of :data:`ESTIMATES`)."""
    return (
        f"digslam: compiling kernels, first run only, about {ESTIMATES[kind]} s; "
        "`digslam warmup` does it ahead of time"
    )


def kind_of(module: str) -> str | None:
    """``"env"`` or ``"interval"`` for a module of digslam, ``None`` for any other module."""
    if not module.startswith("digslam."):
        return None
    return "env" if module.startswith(ENV_PREFIXES) else "interval"


class Notice:
    """Prints :func:`message` to ``stream`` (default ``sys.stderr``) at the first compilation of a digslam
    function it is told of, and never again."""

    def __init__(self, stream: TextIO | None = None) -> None:
        self.stream, self.shown = stream, False

    def compiling(self, module: str) -> bool:
        """Note that a function of ``module`` compiles; True if this call printed the notice."""
        kind = kind_of(module)
        if self.shown or kind is None:
            return False
        self.shown = True
        stream = self.stream or sys.stderr
        switch = os.environ.get("DIGSLAM_COMPILE_NOTICE", "")
        if switch == "0" or (switch != "1" and not _isatty(stream)):
            return False
        print(message(kind), file=stream, flush=True)
        return True


def _isatty(stream: TextIO) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # no such method, or a closed stream
        return False


def _listener(notice: Notice) -> Any:
    from numba.core import event

    class _Listener(event.Listener):  # type: ignore[misc]
        def on_start(self, ev: Any) -> None:
            func = getattr(ev.data.get("dispatcher"), "py_func", None)
            notice.compiling(getattr(func, "__module__", "") or "")

        def on_end(self, ev: Any) -> None:
            pass

    return _Listener()


#: The notice of this process (:func:`install` registers it once).
NOTICE = Notice()
_installed: list[Any] = []


def install(notice: Notice = NOTICE) -> Any:
    """Register ``notice`` on numba's ``numba:compile`` event (idempotent for the process's notice);
    returns the listener (``numba.core.event.unregister("numba:compile", it)`` removes it)."""
    from numba.core import event

    if notice is NOTICE and _installed:
        return _installed[0]
    listener = _listener(notice)
    event.register("numba:compile", listener)
    if notice is NOTICE:
        _installed.append(listener)
    return listener


__all__ = [
    "ENV_PREFIXES",
    "ESTIMATES",
    "NOTICE",
    "ROOTS",
    "STAMP",
    "Notice",
    "cache_dirs",
    "clear",
    "digest",
    "guard",
    "install",
    "kernel_sources",
    "kind_of",
    "message",
    "stamp_path",
]
