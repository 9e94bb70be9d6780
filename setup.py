"""Build step of ``pip install``: compile every numba kernel into the built tree (the kernel store).

Everything else about the package is in ``pyproject.toml``. After setuptools copies the sources,
``build_py`` runs ``digslam warmup`` on the built tree (``digslam.observer.cache.store``), so that the
wheel carries its kernels compiled for this machine and the first call of an installed digslam needs no
compiler. It takes about a minute on 2 cores. ``DIGSLAM_BUILD_KERNELS=0`` skips it, an editable install
skips it, and a failed compilation only says so in one line: the kernels then compile at first use.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

from setuptools import setup
from setuptools.command.build_py import build_py


class BuildPyWithKernels(build_py):
    """``build_py``, then ``digslam warmup`` on the built tree."""

    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False) or os.environ.get("DIGSLAM_BUILD_KERNELS") == "0":
            return
        lib = os.path.abspath(self.build_lib)
        env = {**os.environ, "PYTHONPATH": os.pathsep.join([lib, os.environ.get("PYTHONPATH", "")])}
        env.pop("DIGSLAM_KERNEL_STORE", None)  # the store beside the built sources
        env.pop("NUMBA_CACHE_LOCATOR_CLASSES", None)
        code = "import sys; from digslam.agents.cli.warmup import build; sys.exit(build())"
        t0 = time.perf_counter()
        print("digslam: compiling the kernels into the wheel, about a minute (DIGSLAM_BUILD_KERNELS=0 skips)")
        proc = subprocess.run([sys.executable, "-c", code], cwd=lib, env=env, capture_output=True, text=True)
        for line in (proc.stdout + proc.stderr).strip().splitlines()[-8:]:
            print(f"digslam: {line}")
        print(f"digslam: kernels {'built' if proc.returncode == 0 else 'not all built'} in "
              f"{time.perf_counter() - t0:.0f} s")  # fmt: skip


setup(cmdclass={"build_py": BuildPyWithKernels})
