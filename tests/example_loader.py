"""Import an example script by path (the examples are scripts, not a package).

``examples/`` is added to ``sys.path`` before a script runs, as when it runs as ``python examples/<name>.py``,
so that its ``from _common import ...`` finds ``examples/_common.py``.
"""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def load(name: str) -> ModuleType:
    """Import ``examples/<name>.py`` (cached in ``sys.modules`` under a private name)."""
    if str(EXAMPLES) not in sys.path:
        sys.path.append(str(EXAMPLES))
    key = f"_digslam_example_{name}"
    if key in sys.modules:
        return sys.modules[key]
    spec = importlib.util.spec_from_file_location(key, EXAMPLES / f"{name}.py")
    assert spec is not None and spec.loader is not None, f"no example named {name}"
    mod = importlib.util.module_from_spec(spec)
    sys.modules[key] = mod
    spec.loader.exec_module(mod)
    return mod


def run_cache(out: Path, eps: dict[str, float]) -> Callable[[str], dict]:
    """``get(name)`` runs ``examples/<name>.py``'s ``run(eps=eps[name], out=out)`` once and caches it."""
    cache: dict[str, dict] = {}

    def get(name: str) -> dict:
        if name not in cache:
            cache[name] = load(name).run(eps=eps[name], out=out)
        return cache[name]

    return get
