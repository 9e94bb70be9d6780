"""Paving a set: the paver and what it produces.

Lives here: :mod:`.paver` (``pave``, SIVIA with a separator, Alg. 3.1, kernels in :mod:`.paver_jit`),
:mod:`.subpaving` (subpavings as separators, saving and simplifying them), :mod:`.regular` (classifying a
regular grid) and :mod:`.draw` (matplotlib pictures of boxes and pavings; matplotlib imported on use).

May import: :mod:`digslam.observer.core`, :mod:`digslam.observer.sets`; numpy, numba.
"""

from .draw import draw_boxes, draw_grid, draw_paving, draw_polygon, new_figure, save_figure
from .paver import Paving, PavingTree, connected_subsets, pave
from .regular import classify_grid
from .subpaving import SepSubpaving, load, save, simplify

__all__ = [
    "classify_grid",
    "connected_subsets",
    "draw_boxes",
    "draw_grid",
    "draw_paving",
    "draw_polygon",
    "load",
    "new_figure",
    "pave",
    "save",
    "save_figure",
    "simplify",
    "Paving",
    "PavingTree",
    "SepSubpaving",
]
