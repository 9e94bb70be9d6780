"""The cold-start notice (:func:`digslam.observer.cache.notice.install`), the cold README example and the
README example just after an install (the kernel store built)."""

from __future__ import annotations

import io
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import pytest
from numba.core import event

from digslam.observer import cache
from digslam.observer.cache import notice as notices
from digslam.observer.cache.notice import Notice, install, kind_of, message


def _compiled_in(module: str) -> numba.core.registry.CPUDispatcher:
    """A new (uncached) numba function whose ``__module__`` is ``module``."""
    scope: dict = {"__name__": module}
    exec("def twice(x):\n    return 2 * x\n", scope)
    return numba.njit(cache=False)(scope["twice"])


def test_notice_prints_once_and_only_for_digslam(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("DIGSLAM_COMPILE_NOTICE", "1")  # shown although the stream is no terminal
    out = io.StringIO()
    notice = Notice(out)
    listener = install(notice)
    try:
        _compiled_in("user_code")(1)  # someone else's kernel: no notice
        assert out.getvalue() == ""
        f = _compiled_in("digslam.observer.fake_jit")
        f(1)  # compiles: the notice
        f(2)  # compiled already: no event
        f(2.5)  # a new signature compiles again, but the notice is shown once per process
        _compiled_in("digslam.envs.fake_jit")(3)
    finally:
        event.unregister("numba:compile", listener)
    assert out.getvalue() == message("interval") + "\n"


def test_notice_kinds_and_switch(monkeypatch: pytest.MonkeyPatch) -> None:
    assert kind_of("digslam.observer.expr.hc4_jit") == "interval"
    assert kind_of("digslam.observer.online.dig_jit") == "env"
    assert kind_of("digslam.envs.sim.geometry_jit") == "env"
    assert kind_of("numba.np.arrayobj") is None
    env_line = message("env")
    assert "digslam warmup" in env_line and f"about {cache.ESTIMATES['env']} s" in env_line
    out = io.StringIO()
    for switch in ("0", ""):  # off; unset, and the stream is no terminal (a pipe, a log, pytest's capture)
        monkeypatch.setenv("DIGSLAM_COMPILE_NOTICE", switch)
        assert not Notice(out).compiling("digslam.observer.x") and out.getvalue() == ""
    monkeypatch.setenv("DIGSLAM_COMPILE_NOTICE", "1")
    notice = Notice(out)
    assert not notice.compiling("numba.np.arrayobj") and out.getvalue() == ""
    assert notice.compiling("digslam.observer.x") and not notice.compiling("digslam.observer.x")
    assert out.getvalue() == message("interval") + "\n"


def test_the_process_notice_is_installed_once() -> None:
    import digslam.observer  # noqa: F401 - importing the kernels installs it

    assert notices._installed and install() is notices._installed[0]


README = """
from digslam.observer import Box, Function, Interval, SepInverse, pave

f = Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2)
ring = SepInverse(f, Interval(1, 2.25))
p = pave(Box([(-1, 5), (-0.5, 5.5)]), ring, eps=0.001)
print(p)
"""


def _readme_twice(kernel_store: str, build: bool = False) -> tuple[tuple[float, str], tuple[float, str]]:
    """``(seconds, stderr)`` of the README example in a fresh process with an empty numba cache and the kernel
    store ``kernel_store``, then again; with ``build``, the store is filled first as ``pip install`` does
    (``digslam warmup``'s interval job)."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = str(cache.empty_cache(Path(tmp, "numba")))
        env = {**os.environ, "NUMBA_CACHE_DIR": folder, "DIGSLAM_KERNEL_STORE": kernel_store,
               "DIGSLAM_COMPILE_NOTICE": "1"}  # stderr is a pipe  # fmt: skip
        if build:  # with a numba cache of its own, so that the measured runs start from an empty one
            code = "import sys; from digslam.agents.cli.warmup import build; sys.exit(build(('interval',)))"
            env_build = {**env, "NUMBA_CACHE_DIR": str(cache.empty_cache(Path(tmp, "build")))}
            subprocess.run(
                [sys.executable, "-c", code], env=env_build, cwd=tmp, capture_output=True, check=True
            )
        runs = []
        for _ in range(2):
            t0 = time.perf_counter()
            proc = subprocess.run([sys.executable, "-c", README], env=env, cwd=folder, capture_output=True,
                                  text=True, check=True)  # fmt: skip
            runs.append((time.perf_counter() - t0, proc.stderr))
    return runs[0], runs[1]


@pytest.mark.expensive
def test_cold_readme_example_announces_compilation_once(tmp_path: Path) -> None:
    """With nothing compiled anywhere (an empty store and numba cache), a first run says once that it
    compiles; the next one (loading the kernels) says nothing."""
    (_, cold_err), (_, warm_err) = _readme_twice(str(tmp_path / "empty-store"))
    notice = "digslam: compiling kernels, first run only"
    assert cold_err.count(notice) == 1 and notice not in warm_err


@pytest.mark.expensive
def test_cold_readme_example_within_three_times_warm(tmp_path: Path) -> None:
    """Just after an install (the kernel store built, numba's cache empty) the README's five lines answer
    within 3x their warm time, and compile nothing."""
    (cold, cold_err), (warm, _) = _readme_twice(str(tmp_path / "store"), build=True)
    assert "compiling kernels" not in cold_err
    assert cold <= 3 * warm, f"cold {cold:.1f} s, warm {warm:.1f} s"
