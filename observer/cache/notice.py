"""The cold-start notice: one line on stderr when this process compiles a kernel of digslam.

numba compiles a kernel on its first call and keeps the machine code on disk; a later process loads it in
milliseconds. A kernel that no cache holds (an editable install, ``DIGSLAM_BUILD_KERNELS=0``, an edited
kernel source, a signature the install did not compile: see :mod:`.store`) therefore waits for the
compiler, silently. :func:`install` registers a listener on numba's
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

import os
import sys
from typing import Any, TextIO

#: Seconds a cold start spends compiling, by what compiles first (measured, 2 cores, empty numba cache).
ESTIMATES = {"interval": 10, "env": 70}
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

    class _Listener(event.Listener):  # type: ignore[misc]  # numba is untyped: the base class is Any
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


__all__ = ["ENV_PREFIXES", "ESTIMATES", "NOTICE", "Notice", "install", "kind_of", "message"]
