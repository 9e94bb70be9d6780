"""The files of ``digslam certify``: ``map.png``, ``zones.geojson``, ``raster.npz`` and ``summary.json``.

:class:`Certified` is what a run proved on a grid: the explored-zone codes (clear, penumbra, dark,
:mod:`digslam.observer.thick.cells`), the dig zone ``M⁻`` and the pose tube. :func:`write_all` writes the four
files into a folder (the staged folder of :func:`~digslam.agents.cli.common.staged`, moved into place by the
caller): the map in the demo's colours (:data:`digslam.envs.dig_coverage.env.RGB`, Okabe-Ito) with ``M⁻``'s
outline, the pose boxes and a scale bar; the zones as one GeoJSON MultiPolygon each, in metres in the log's
odometry frame, from :func:`~digslam.observer.thick.polygons.mask_polygons` (exact cell edges); the raster
and the tube as arrays; the summary as JSON.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from digslam.observer.record.grid import Grid
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA
from digslam.observer.thick.polygons import mask_polygons, polygon_area

#: The files written, in the order they are listed.
FILES = ("summary.json", "map.png", "zones.geojson", "raster.npz")
#: Each zone's words (thesis Ch. 6 and App. B, as the demo's legend).
ZONES = {
    "clear": "proved free of obstacles and surely sensed",
    "penumbra": "maybe sensed, not proved (Z+ minus Z-)",
    "dark": "surely never sensed",
    "free": "the dig zone M-: proved free of obstacles",
}


@dataclass
class Certified:
    """What a run proved: ``code`` (int8 ``(ny, nx)``), ``free`` (``M⁻``), the pose tube's gates ``lo``,
    ``hi`` ``(n, 2)`` at times ``t`` and its headings ``psi`` ``(n, 2)``, on ``grid``."""

    grid: Grid
    code: np.ndarray
    free: np.ndarray
    t: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    psi: np.ndarray

    def masks(self) -> dict[str, np.ndarray]:
        """The four zones as boolean rasters."""
        return {"clear": self.code == CLEAR, "penumbra": self.code == PENUMBRA, "dark": self.code == DARK,
                "free": self.free}  # fmt: skip

    @property
    def cell_area(self) -> float:
        dx, dy = self.grid.cell_size
        return dx * dy


def write_geojson(path: Path, cert: Certified, frame_id: str) -> dict[str, float]:
    """Write the zones as a FeatureCollection (one MultiPolygon each); return their polygon areas (m²)."""
    feats, areas = [], {}
    for name, mask in cert.masks().items():
        polys = mask_polygons(mask, cert.grid)
        areas[name] = float(sum(polygon_area(p) for p in polys))
        coords = [[ring.tolist() for ring in p] for p in polys]
        props = {"zone": name, "meaning": ZONES[name], "area_m2": areas[name], "cells": int(mask.sum())}
        geom = {"type": "MultiPolygon", "coordinates": coords}
        feats.append({"type": "Feature", "properties": props, "geometry": geom})
    doc = {"type": "FeatureCollection", "name": "digslam certify zones", "frame_id": frame_id, "units": "m",
           "note": "planar coordinates in metres in the log's odometry frame, not longitude and latitude",
           "features": feats}  # fmt: skip
    path.write_text(json.dumps(doc))
    return areas


def write_raster(path: Path, cert: Certified, stamps: np.ndarray) -> None:
    """Write the codes, ``M⁻``, the grid's frame and the tube as a ``.npz``."""
    g = cert.grid
    np.savez_compressed(path, code=cert.code, free=cert.free, grid_lo=np.array(g.lo), grid_hi=np.array(g.hi),
                        shape=np.array(g.shape), resolution=np.array(g.cell_size), xs=g.xs, ys=g.ys,
                        tube_t=cert.t, tube_lo=cert.lo, tube_hi=cert.hi, heading=cert.psi, stamps=stamps,
                        codes=np.array([CLEAR, PENUMBRA, DARK]))  # fmt: skip


def _scale(width: float) -> float:
    """A round length (1, 2 or 5 times a power of ten) near a fifth of ``width``."""
    e = 10.0 ** np.floor(np.log10(width / 5))
    return float(min((m * e for m in (1, 2, 5, 10)), key=lambda v: abs(v - width / 5)))


def _rgb(code: Any) -> tuple[float, float, float]:
    """The demo's colour of a cell code, as matplotlib takes it."""
    from digslam.envs.dig_coverage.env import RGB

    r, g, b = RGB[int(code)]
    return (r / 255, g / 255, b / 255)


def _view(cert: Certified, lo: np.ndarray, hi: np.ndarray) -> tuple[float, float, float, float] | None:
    """What the map shows: the cells sensed (clear or penumbra) and the pose boxes, with a 5 % margin, inside
    the frame (the frame itself reaches the longest trusted range around the dead reckoning)."""
    g = cert.grid
    rows, cols = np.nonzero(cert.code != DARK)
    x = [g.xs[cols.min()], g.xs[cols.max() + 1]] if cols.size else []
    y = [g.ys[rows.max() + 1], g.ys[rows.min()]] if rows.size else []
    x += [float(lo[:, 0].min()), float(hi[:, 0].max())] if len(lo) else []
    y += [float(lo[:, 1].min()), float(hi[:, 1].max())] if len(lo) else []
    if not x:
        return None
    pad = 0.05 * max(max(x) - min(x), max(y) - min(y), 10 * g.cell_size[0])
    return (max(g.lo[0], min(x) - pad), max(g.lo[1], min(y) - pad), min(g.hi[0], max(x) + pad),
            min(g.hi[1], max(y) + pad))  # fmt: skip


def write_map(path: Path, cert: Certified, title: str) -> None:
    """Draw the zones, ``M⁻``'s outline and the pose boxes, with the demo's legend and a scale bar."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.patches import Patch
    from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

    from digslam.envs.dig_coverage.env import RGB

    g = cert.grid
    img = np.zeros((*g.shape, 3))
    for code in (CLEAR, PENUMBRA, DARK):
        img[cert.code == code] = np.array(RGB[int(code)]) / 255
    w, h = g.hi[0] - g.lo[0], g.hi[1] - g.lo[1]
    fig, ax = plt.subplots(figsize=(8.0, max(3.0, min(12.0, 8.0 * h / w))), dpi=150)
    ax.imshow(img, extent=g.extent, interpolation="nearest", origin="upper")
    rings = [r for p in mask_polygons(cert.free, g) for r in p]
    ax.add_collection(LineCollection(rings, colors="white", linewidths=0.6))
    ok = np.isfinite(cert.lo).all(axis=1) & np.isfinite(cert.hi).all(axis=1)
    lo, hi = cert.lo[ok], cert.hi[ok]
    pick = np.unique(np.linspace(0, max(len(lo) - 1, 0), min(len(lo), 60)).astype(int))
    b_lo, b_hi = lo[pick], hi[pick]  # at most 60 boxes of the tube, evenly in time, the last included
    corner_a, corner_b = np.stack([b_hi[:, 0], b_lo[:, 1]], 1), np.stack([b_lo[:, 0], b_hi[:, 1]], 1)
    boxes = np.stack([b_lo, corner_a, b_hi, corner_b], axis=1)
    ax.add_collection(
        PolyCollection(list(boxes), facecolors="none", edgecolors=(0.0, 0.62, 0.45), linewidths=0.5)
    )
    view = _view(cert, lo, hi)
    if view is not None:
        ax.set_xlim(view[0], view[2])
        ax.set_ylim(view[1], view[3])
        w, h = view[2] - view[0], view[3] - view[1]
    bar = _scale(w)
    ax.add_artist(AnchoredSizeBar(ax.transData, bar, f"{bar:g} m", "lower right", color="white",
                                  frameon=False, size_vertical=h / 200))  # fmt: skip
    legend = [Patch(color=_rgb(c), label=f"{n}: {ZONES[n]}")
              for n, c in (("clear", CLEAR), ("penumbra", PENUMBRA), ("dark", DARK))]  # fmt: skip
    legend += [Patch(facecolor="none", edgecolor="white", label="M- (proved free): outline"),
               Patch(facecolor="none", edgecolor=(0.0, 0.62, 0.45), label="pose boxes (the robot is proved "
                     "inside)")]  # fmt: skip
    ax.legend(
        handles=legend, loc="upper left", bbox_to_anchor=(0.0, -0.08), fontsize=7, frameon=False, ncol=2
    )
    ax.set_facecolor(_rgb(DARK))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title, fontsize=9)
    ax.set_aspect("equal")
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)


def write_all(folder: Path, cert: Certified | None, summary: dict[str, Any], stamps: np.ndarray,
              frame_id: str, title: str, start: float) -> list[str]:  # fmt: skip
    """Write every file into ``folder`` (only ``summary.json`` when nothing was certified); return their
    names. The polygons' areas go into the summary as ``zones_m2``, and ``seconds`` is the time since
    ``start`` (``time.perf_counter``) when the summary is written, last."""
    names = ["summary.json"]
    if cert is not None:
        summary["zones_m2"] = write_geojson(folder / "zones.geojson", cert, frame_id)
        write_raster(folder / "raster.npz", cert, stamps)
        write_map(folder / "map.png", cert, title)
        names += ["map.png", "zones.geojson", "raster.npz"]
    summary["seconds"] = time.perf_counter() - start
    text = json.dumps(summary, indent=2, default=_plain, allow_nan=False)
    (folder / "summary.json").write_text(text + "\n")
    return names


def _plain(v: Any) -> Any:
    """numpy scalars and arrays as JSON values."""
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    return str(v)


__all__ = ["FILES", "ZONES", "Certified", "write_all", "write_geojson", "write_map", "write_raster"]
