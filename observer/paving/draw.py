"""Drawing pavings, box batches and classified grids with matplotlib (thesis colour convention).

Red boxes are proved inside, blue boxes proved outside and yellow boxes undetermined (Figure 2.11).
matplotlib is imported lazily inside the functions, so :mod:`digslam.observer` keeps importing with
numpy only. Figures are made with :class:`matplotlib.figure.Figure` directly (no pyplot, no GUI
backend), so drawing works headless (matplotlib is the ``viz`` extra, so this is not a doctest)::

    from digslam.observer import Box, Function, Interval, SepInverse, pave
    from digslam.observer.paving.draw import draw_paving, new_figure, save_figure

    ring = SepInverse(Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2), Interval(1, 2.25))
    fig, ax = new_figure()
    draw_paving(pave(Box([(-1, 5), (-0.5, 5.5)]), ring, 0.05), ax)   # red / blue / yellow
    save_figure(fig, "out/ring.png")
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Protocol

import numpy as np

from digslam.observer.core.types import Batch

__all__ = [
    "INSIDE_COLOR", "OUTSIDE_COLOR", "BOUNDARY_COLOR", "CLEAR_COLOR", "PENUMBRA_COLOR", "DARK_COLOR",
    "Paved", "new_figure", "draw_boxes", "draw_paving", "draw_grid", "draw_polygon", "save_figure",
]  # fmt: skip

#: thesis colours: inside (X⁻) red, outside blue, undetermined (ΔX) yellow
INSIDE_COLOR = "#e41a1c"
OUTSIDE_COLOR = "#377eb8"
BOUNDARY_COLOR = "#ffd700"
#: thick classification: clear (inside) red, penumbra orange, dark (outside) dark blue
CLEAR_COLOR = "#e41a1c"
PENUMBRA_COLOR = "#ff8c00"
DARK_COLOR = "#08306b"


class Paved(Protocol):
    """What :func:`draw_paving` draws: a :class:`~digslam.observer.paving.paver.Paving` or anything with its
    three ``(lo, hi)`` batches."""

    @property
    def inner(self) -> Batch: ...

    @property
    def outer(self) -> Batch: ...

    @property
    def boundary(self) -> Batch: ...


def new_figure(ncols: int = 1, nrows: int = 1, size: float = 5.0, **subplots_kw: Any) -> tuple[Any, Any]:
    """A headless :class:`~matplotlib.figure.Figure` with an ``nrows x ncols`` grid of axes.

    Returns ``(fig, ax)`` where ``ax`` is one Axes for a 1x1 grid, else an array of Axes.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(size * ncols, size * nrows), layout="constrained")
    ax = fig.subplots(nrows, ncols, squeeze=True, **subplots_kw)
    return fig, ax


def _axes(ax: Any) -> Any:
    if ax is None:
        return new_figure()[1]
    return ax


def draw_boxes(
    lo: Any,
    hi: Any,
    ax: Any = None,
    color: Any = BOUNDARY_COLOR,
    edgecolor: Any = "k",
    linewidth: float = 0.2,
    alpha: float | None = None,
    zorder: float = 1.0,
    label: str | None = None,
    autoscale: bool = True,
) -> Any:
    """Draw a batch of 2-d boxes ``(N, 2)`` as one collection (no per-box patch).

    A :class:`~matplotlib.collections.PolyCollection` built from an ``(N, 4, 2)`` vertex array: the
    vectorised form of a ``PatchCollection`` of rectangles, with no Python loop over the boxes.

    Empty rows (``lo > hi``) are skipped. Only the first two coordinates are drawn. ``edgecolor`` may
    be ``"none"`` for borderless boxes. Returns the Axes.
    """
    from matplotlib.collections import PolyCollection

    ax = _axes(ax)
    lo = np.asarray(lo, dtype=np.float64).reshape(-1, np.shape(lo)[-1] if np.ndim(lo) else 1)
    hi = np.asarray(hi, dtype=np.float64).reshape(lo.shape)
    if lo.shape[1] < 2:
        raise ValueError(f"draw_boxes: need boxes of dimension >= 2, got {lo.shape[1]}")
    keep = (lo[:, :2] <= hi[:, :2]).all(axis=1)
    lo, hi = lo[keep, :2], hi[keep, :2]
    # corners (N, 4, 2): (lo0, lo1), (hi0, lo1), (hi0, hi1), (lo0, hi1)
    verts = np.stack(
        [np.stack([lo[:, 0], lo[:, 1]], 1), np.stack([hi[:, 0], lo[:, 1]], 1),
         np.stack([hi[:, 0], hi[:, 1]], 1), np.stack([lo[:, 0], hi[:, 1]], 1)], axis=1,
    )  # fmt: skip
    coll = PolyCollection(
        verts,  # type: ignore[arg-type]  # matplotlib's stub: an (N, 4, 2) array is N polygons (its fast path)
        facecolors=color,
        edgecolors=edgecolor,
        linewidths=linewidth,
        alpha=alpha,
        zorder=zorder,
        label=label,
    )
    ax.add_collection(coll, autolim=autoscale)
    if autoscale and len(lo):
        ax.autoscale_view()
    return ax


def draw_paving(
    paving: Paved,
    ax: Any = None,
    inner_color: Any = INSIDE_COLOR,
    outer_color: Any = OUTSIDE_COLOR,
    boundary_color: Any = BOUNDARY_COLOR,
    edgecolor: Any = "k",
    linewidth: float = 0.2,
    show_outer: bool = True,
    frame: Any = None,
    title: str | None = None,
) -> Any:
    """Draw a :class:`~digslam.observer.Paving`: inner red, outer blue, boundary yellow (Figure 2.11).

    Args:
        paving: the result of :func:`~digslam.observer.pave` (or anything with ``inner``, ``outer``,
            ``boundary`` batches).
        ax: target Axes (a new figure's when ``None``).
        edgecolor, linewidth: box borders (``"none"`` for no border).
        show_outer: also draw the outer boxes.
        frame: optional ``(lo, hi)`` / box to set the axis limits (default: the drawn boxes).
        title: optional axes title.

    Returns the Axes (equal aspect).
    """
    ax = _axes(ax)
    layers = [(paving.inner, inner_color, "inside")]
    if show_outer:
        layers.insert(0, (paving.outer, outer_color, "outside"))
    layers.append((paving.boundary, boundary_color, "undetermined"))
    for (lo, hi), color, label in layers:
        if len(lo):
            draw_boxes(lo, hi, ax, color=color, edgecolor=edgecolor, linewidth=linewidth, label=label)
    if frame is not None:
        _set_frame(ax, frame)
    ax.set_aspect("equal")
    if title:
        ax.set_title(title)
    return ax


def _set_frame(ax: Any, frame: Any) -> None:
    if hasattr(frame, "pair"):
        flo, fhi = frame.pair
    else:
        flo, fhi = frame
    flo, fhi = np.asarray(flo, dtype=np.float64).ravel(), np.asarray(fhi, dtype=np.float64).ravel()
    ax.set_xlim(flo[0], fhi[0])
    ax.set_ylim(flo[1], fhi[1])


def draw_grid(
    status: Any,
    extent: Any,
    ax: Any = None,
    thick: bool = False,
    penumbra: int | None = None,
    colors: dict[int, Any] | None = None,
    alpha: float | None = None,
) -> Any:
    """Draw a :func:`~digslam.observer.classify_grid` array (row 0 at the top, Remark 2.7).

    Args:
        status: ``(ny, nx)`` integer array, by default ``1`` inside, ``0`` undetermined, ``-1`` outside.
        extent: ``(xmin, xmax, ymin, ymax)``, or a 2-d box / ``(lo, hi)`` pair.
        thick: thick-set classification colours: clear red (``1``), penumbra orange (``0``, or the
            ``penumbra`` code), dark blue (``-1``); otherwise the paving colours red / yellow / blue.
        penumbra: a separate code for the penumbra (e.g. ``2``); with it ``0`` stays undetermined yellow.
        colors: explicit ``{code: colour}`` mapping (overrides the above).

    Returns the Axes.
    """
    from matplotlib.colors import to_rgba

    ax = _axes(ax)
    st = np.asarray(status)
    if st.ndim != 2:
        raise ValueError(f"draw_grid: status must be 2-d (ny, nx), got shape {st.shape}")
    if hasattr(extent, "pair") or (len(extent) == 2 and np.ndim(extent[0]) == 1):
        lo, hi = extent.pair if hasattr(extent, "pair") else extent
        extent = (float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]))
    if colors is None:
        if thick:
            colors = {1: CLEAR_COLOR, 0: PENUMBRA_COLOR, -1: DARK_COLOR}
        else:
            colors = {1: INSIDE_COLOR, 0: BOUNDARY_COLOR, -1: OUTSIDE_COLOR}
        if penumbra is not None:
            colors[0] = BOUNDARY_COLOR
            colors[int(penumbra)] = PENUMBRA_COLOR
    codes = sorted(colors)
    index = np.full(st.shape, -1, dtype=np.int64)
    for i, c in enumerate(codes):
        index[st == c] = i
    rgba = np.zeros(st.shape + (4,))
    table = np.array([to_rgba(colors[c]) for c in codes])
    known = index >= 0
    rgba[known] = table[index[known]]
    if alpha is not None:
        rgba[known, 3] *= alpha
    # an explicit RGBA image keeps the codes exact (no colormap normalisation)
    ax.imshow(rgba, extent=tuple(extent), origin="upper", interpolation="nearest")
    ax.set_aspect("equal")
    return ax


def draw_polygon(
    rings: Any,
    ax: Any = None,
    edgecolor: Any = "k",
    facecolor: Any = "none",
    linewidth: float = 1.0,
    zorder: float = 3.0,
    **kw: Any,
) -> Any:
    """Draw polygon rings (``(k, 2)`` arrays) as closed outlines; holes follow the even-odd rule."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    ax = _axes(ax)
    if isinstance(rings, np.ndarray) and rings.ndim == 2:
        rings = [rings]
    verts, codes = [], []
    for r in rings:
        r = np.asarray(r, dtype=np.float64)
        verts.extend(list(r) + [r[0]])
        codes.extend([MplPath.MOVETO] + [MplPath.LINETO] * (len(r) - 1) + [MplPath.CLOSEPOLY])
    patch = PathPatch(
        MplPath(np.array(verts), codes),
        edgecolor=edgecolor,
        facecolor=facecolor,
        linewidth=linewidth,
        zorder=zorder,
        **kw,
    )
    ax.add_patch(patch)
    return ax


def save_figure(fig: Any, path: str | Path, dpi: int = 150, **kw: Any) -> Path:
    """Save ``fig`` to ``path`` (creating parent folders) and return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if hasattr(fig, "get_figure") and not hasattr(fig, "savefig"):
        fig = fig.get_figure()
    fig.savefig(path, dpi=dpi, **kw)
    return path
