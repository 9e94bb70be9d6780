"""Which copy of ``digslam`` Python imported: the installed one, or a source folder that shadows it.

``digslam`` is a namespace package (``digslam.observer``, ``digslam.envs`` and ``digslam.agents`` are mapped
from the repository's ``observer/``, ``envs/`` and ``agents/``), so a folder named ``digslam`` holding those
sources (a clone under its default name) in the current directory, or anywhere on ``sys.path`` before the
installed copy, is imported instead of the installed package, silently, and numba writes its caches into
it. :func:`warn_if_shadowed` says so in one line on stderr (once per process); ``digslam.envs``,
``digslam.agents`` and the ``digslam`` command call it.
"""

from __future__ import annotations

import functools
import json
import sys
from pathlib import Path
from urllib.parse import unquote, urlparse


@functools.cache
def installed_root() -> Path | None:
    """The folder that holds the installed subpackages (``.../site-packages/digslam``, or the checkout of an
    editable install); None when no ``digslam`` distribution is installed."""
    from importlib import metadata

    for dist in metadata.distributions(name="digslam"):  # a source tree's egg-info comes without either
        try:
            info = json.loads(dist.read_text("direct_url.json") or "{}")
        except ValueError:
            info = {}
        if info.get("dir_info", {}).get("editable") and str(info.get("url", "")).startswith("file:"):
            return Path(unquote(urlparse(info["url"]).path))
        site = Path(str(dist.locate_file("digslam")))
        if site.is_dir():
            return site
    return None


def shadowing(module_file: str | Path) -> Path | None:
    """The installed root when ``module_file`` (a subpackage's ``__init__.py``) lies elsewhere, else None.

    Only a folder named ``digslam`` can shadow the namespace package, so nothing is looked up otherwise.
    """
    here = Path(module_file).resolve().parent  # .../<root>/envs
    root = here.parent
    if root.name != "digslam":
        return None
    inst = installed_root()
    if inst is None or not (inst / here.name).is_dir():
        return None
    return None if inst.resolve() == root else inst


@functools.cache
def _warn(module: str, found: str, installed: str) -> None:
    print(f"digslam: warning: {module} was imported from {found}, a folder named digslam on sys.path (e.g. "
          f"the current directory), not from the installed package ({installed}), and numba writes its "
          "caches there; run Python from another folder, or install that checkout with `pip install -e`",
          file=sys.stderr)  # fmt: skip


def warn_if_shadowed(module: str = "digslam.agents") -> bool:
    """Print one line on stderr (once) if ``module`` was imported from a shadowing source folder."""
    mod = sys.modules.get(module)
    path = getattr(mod, "__file__", None)
    if path is None:
        return False
    inst = shadowing(path)
    if inst is None:
        return False
    _warn(module, str(Path(path).resolve().parent), str(inst))
    return True


__all__ = ["installed_root", "shadowing", "warn_if_shadowed"]
