"""The kernel store (``digslam.observer.cache.store``): where digslam's kernels are cached, under which stamp.

Each process test runs a fresh interpreter with ``DIGSLAM_KERNEL_STORE`` and ``NUMBA_CACHE_DIR`` pointing
at new folders and records numba's ``numba:compile`` events, which fire only when a kernel really
compiles (never when it is loaded from a cache).
"""

from __future__ import annotations

import json
import os
import pickle
import subprocess
import sys
from pathlib import Path

import numba
import pytest
from numba.core import caching

from digslam.observer import cache
from digslam.observer.cache import store

RUN = """
import json
from numba.core import event
compiled = []
class Listener(event.Listener):
    def on_start(self, ev):
        func = getattr(ev.data.get("dispatcher"), "py_func", None)
        if func is not None and func.__module__.startswith("digslam."):
            compiled.append(func.__qualname__)
    def on_end(self, ev):
        pass
event.register("numba:compile", Listener())
from digslam.observer.core.scalar_jit import iadd
print(json.dumps({"sum": iadd(0.1, 0.2, 1.0, 1.0), "compiled": compiled}))
"""


def _run(tmp: Path, kernel_store: str) -> dict:
    env = {**os.environ, "DIGSLAM_KERNEL_STORE": kernel_store, "NUMBA_CACHE_DIR": str(tmp / "numba"),
           "DIGSLAM_COMPILE_NOTICE": "0"}  # fmt: skip
    cache.empty_cache(tmp / "numba")  # stamped, so that the guard leaves the shared caches alone
    out = subprocess.run([sys.executable, "-c", RUN], env=env, capture_output=True, text=True, timeout=600,
                         check=True, cwd=tmp)  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])


def _indexes(folder: Path) -> list[Path]:
    return sorted(folder.rglob("scalar_jit.iadd-*.nbi"))


def test_kernels_are_stored_beside_their_source_and_loaded_by_the_next_process(tmp_path: Path) -> None:
    kernels = tmp_path / "store"
    first = _run(tmp_path, str(kernels))
    assert "iadd" in first["compiled"]
    (index,) = _indexes(kernels)
    assert index.parent == kernels / "observer" / "core" / store.FOLDER
    assert not _indexes(tmp_path / "numba")  # not in numba's folder
    second = _run(tmp_path, str(kernels))
    assert second == {"sum": first["sum"], "compiled": []}  # loaded, nothing compiled


def _restamp(index: Path, stamp: str) -> None:
    """Rewrite a numba index as if an older version of the project had written it (numba's format: its
    version, pickled, then the pickled ``(stamp, overloads)``)."""
    with open(index, "rb") as f:
        version = pickle.load(f)
        _, overloads = pickle.loads(f.read())
    with open(index, "wb") as f:
        pickle.dump(version, f, protocol=-1)
        f.write(pickle.dumps((stamp, overloads), protocol=-1))


def test_an_entry_of_other_sources_is_recompiled_never_run(tmp_path: Path) -> None:
    """An entry stamped by other kernel sources (an edited callee in another file, an upgrade) is ignored."""
    kernels = tmp_path / "store"
    first = _run(tmp_path, str(kernels))
    (index,) = _indexes(kernels)
    _restamp(index, "digest of an older project numpy-0")
    again = _run(tmp_path, str(kernels))
    assert again["compiled"] == ["iadd"] and again["sum"] == first["sum"]  # its own entry only
    assert _run(tmp_path, str(kernels))["compiled"] == []  # overwritten with the current stamp


def test_the_store_off_leaves_numba_its_folders(tmp_path: Path) -> None:
    result = _run(tmp_path, "0")
    assert "iadd" in result["compiled"]
    assert _indexes(tmp_path / "numba") and not list(tmp_path.glob("**/" + store.FOLDER))


def test_scope_and_stamp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert caching.CacheImpl._locator_classes[0] is store.StoreLocator  # importing digslam installs it
    assert store.install() and caching.CacheImpl._locator_classes.count(store.StoreLocator) == 1
    scalar = cache.PACKAGE / "observer" / "core" / "scalar_jit.py"
    assert store.folder(scalar, tmp_path) == tmp_path / "observer" / "core" / store.FOLDER
    assert store.folder(tmp_path / "user_code.py", tmp_path) is None  # someone else's kernels: numba's
    monkeypatch.setenv(store.SWITCH, "0")
    assert store.root() is None and store.folder(scalar) is None
    monkeypatch.setenv(store.SWITCH, str(tmp_path))
    assert store.root() == tmp_path.resolve()
    import numpy

    assert store.stamp().split() == [cache.project_digest(), f"numpy-{numpy.__version__}"]


def test_the_stamp_covers_the_constants_that_kernels_freeze(tmp_path: Path) -> None:
    """A kernel compiles the module-level constants it reads (``LIBM_ULPS``) into its machine code, so the
    files they come from count as kernel sources, and editing one changes the digest."""
    names = {p.relative_to(cache.PACKAGE).as_posix() for p in cache.kernel_sources()}
    assert {"observer/core/rounding.py", "observer/core/scalar_jit.py", "envs/sim/arc_jit.py"} <= names
    root = tmp_path / "pkg"
    root.mkdir()
    (root / "k_jit.py").write_text("from .consts import K\n\n@njit\ndef f(x):\n    return K * x\n")
    (root / "consts.py").write_text("K = 2.0\n")
    (root / "other.py").write_text("X = 1\n")
    files = cache.kernel_sources([root])
    assert [p.name for p in files] == ["consts.py", "k_jit.py"]
    before = cache.digest(files)
    (root / "consts.py").write_text("K = 3.0\n")
    assert cache.digest(files) != before


def test_manifest_round_trip(tmp_path: Path) -> None:
    assert store.manifest(tmp_path) is None
    store.write_manifest(12.3, tmp_path, built_by="test")
    data = store.manifest(tmp_path)
    assert data is not None and data["seconds"] == 12.3 and data["numba"] == numba.__version__
    path = store.manifest_path(tmp_path)
    assert path is not None
    path.write_text(json.dumps({**data, "stamp": "other"}))
    assert store.manifest(tmp_path) is None  # built for other kernels: not this store's record


@pytest.mark.skipif(cache.PACKAGE.parent.name not in ("site-packages", "dist-packages")
                    or os.environ.get("DIGSLAM_BUILD_KERNELS") == "0",
                    reason="an editable install or a source tree: kernels compile at first use")  # fmt: skip
def test_an_installed_digslam_carries_its_kernels() -> None:
    """``pip install`` (setup.py's build step) compiled the kernels for this numba and numpy."""
    data = store.manifest(cache.PACKAGE)
    assert data is not None, (f"no kernel store built for this environment in {cache.PACKAGE} (numba "
                              f"{numba.__version__}); see setup.py")  # fmt: skip
    assert data["numba"] == numba.__version__ and data["entries"] > 100
