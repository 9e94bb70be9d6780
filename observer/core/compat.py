"""Old module paths, kept for one release: ``digslam.observer.online_jit`` still imports, with a warning.

Before the concept folders, every module sat flat in its package (``digslam.observer.thick_carving``,
``digslam.envs.explore_env``...). :func:`install_aliases` adds a finder to :data:`sys.meta_path` that answers
those names with the module at its new path (the same module object, so ``isinstance`` checks, numba's
caches and monkeypatching see one module) and emits a :class:`DeprecationWarning` naming the new path.
Each package's ``__init__`` installs its own table (:data:`OBSERVER`, ``digslam.envs.MOVED``...).
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import warnings
from collections.abc import Mapping, Sequence
from types import ModuleType

#: ``digslam.observer`` modules that moved: old name -> new dotted path.
OBSERVER: dict[str, str] = {
    "rounding": "core.rounding", "arith": "core.arith", "trig": "core.trig", "boxes": "core.boxes",
    "interval": "core.interval", "jit": "core.scalar_jit", "polar_jit": "core.polar_jit",
    "polar_jit_ops": "core.polar_ops_jit",
    "ops": "expr.ops", "backward": "expr.backward", "centred": "expr.centred",
    "jit_centred": "expr.centred_jit", "jit_tape": "expr.tape_jit", "jit_hc4": "expr.hc4_jit",
    "contractors": "sets.contractors", "separators": "sets.separators", "sep_inverse": "sets.sep_inverse",
    "sep_image": "sets.sep_image", "sep_polygon": "sets.sep_polygon", "transforms": "sets.transforms",
    "registration": "sets.registration", "minkowski": "sets.minkowski", "projection": "sets.projection",
    "testing": "sets.testing",
    "paver": "paving.paver", "subpaving": "paving.subpaving", "regular": "paving.regular",
    "draw": "paving.draw",
    "polar_ctc": "polar.ctc", "polar_sep": "polar.sep",
    "thick_interval": "thick.interval", "thick_function": "thick.function", "thick_sep": "thick.sep",
    "thick_set": "thick.set", "thick_paver": "thick.paver", "thick_sivia": "thick.sivia",
    "thick_subset": "thick.subset", "thick_ops": "thick.ops", "thick_inversion": "thick.inversion",
    "thick_carving": "thick.carving",
    "tube_ctc": "tube.ctc",
    "record": "slam.record", "grid": "slam.grid", "digmap": "slam.digmap", "digslam": "slam.digslam",
    "explored": "slam.explored", "explored_sweep": "slam.explored_sweep", "landmarks": "slam.landmarks",
    "shapes": "slam.shapes", "shape_registration": "slam.shape_registration", "shape_slam": "slam.shape_slam",
    "explicit_slam": "slam.explicit_slam",
    "online_explored": "online.window", "online_jit": "online.dig_jit", "online_jit_mark": "online.mark_jit",
    "online_jit_pose": "online.pose_jit", "online_jit_step": "online.step_jit",
}  # fmt: skip


class _AliasLoader(importlib.abc.Loader):
    def __init__(self, target: str) -> None:
        self.target = target

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        return importlib.import_module(self.target)

    def exec_module(self, module: ModuleType) -> None:  # the target is already executed
        pass


class _AliasFinder(importlib.abc.MetaPathFinder):
    def __init__(self) -> None:
        self.table: dict[str, str] = {}

    def find_spec(self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
                  ) -> importlib.machinery.ModuleSpec | None:  # fmt: skip
        new = self.table.get(fullname)
        if new is None:
            return None
        warnings.warn(f"{fullname} moved to {new}; the old path works until the next release",
                      DeprecationWarning, stacklevel=2)  # fmt: skip
        return importlib.machinery.ModuleSpec(fullname, _AliasLoader(new))


_FINDER = _AliasFinder()


def install_aliases(package: str, moved: Mapping[str, str]) -> None:
    """Answer ``package.<old>`` with ``package.<new>`` for every ``old: new`` of ``moved`` (with a warning);
    a ``new`` that starts with ``digslam.`` is taken as it is."""
    _FINDER.table.update({f"{package}.{old}": new if new.startswith("digslam.") else f"{package}.{new}"
                          for old, new in moved.items()})  # fmt: skip
    if _FINDER not in sys.meta_path:
        sys.meta_path.insert(0, _FINDER)


__all__ = ["OBSERVER", "install_aliases"]
