"""What the demo's frames draw over the map: scale bars, the estimated path and the magnified pose box.

The estimated path is the trail of the observer's pose box centres (never the ground truth), its older part
in paler shades. The pose box is often narrower than a pixel of the map, so the map shows it at least
:data:`MIN_BOX_PX` wide and the inset (:func:`inset_window`, :func:`inset_background`) shows it at its true
size, magnified around its centre, with the true position (the monitor's ground truth) inside it. Scale bars
(:func:`scale_bar`) give lengths in metres a round value (1, 2 or 5 times a power of ten).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

#: Least side (px) of the pose box's outline on the map (the robot's icon is about 10 px wide).
MIN_BOX_PX = 24
#: Least side (px) of the pose box's outline in the inset.
MIN_INSET_BOX_PX = 14
#: Least width (m) of the inset's window; the window is at least three pose boxes wide.
INSET_MIN_M = 0.1
#: Ages (steps) where the trail's shade changes: newer than 20 steps, 60, 150, then the oldest shade.
TRAIL_AGES = (20, 60, 150)


def round_length(x: float, up: bool = False) -> float:
    """The largest (``up``: smallest) length 1, 2 or 5 times a power of ten at most (at least) ``x`` > 0."""
    e = math.floor(math.log10(x))
    steps = [m * 10.0**k for k in (e - 1, e, e + 1) for m in (1, 2, 5)]
    return (
        min(s for s in steps if s >= x * (1 - 1e-9)) if up else max(s for s in steps if s <= x * (1 + 1e-9))
    )


def metres_label(m: float) -> str:
    """``m`` metres in words: ``2 m``, ``0.5 m``, ``5 cm``, ``2 mm``."""
    if m >= 0.1 - 1e-12:
        return f"{m:g} m"
    return f"{m * 100:g} cm" if m >= 0.01 - 1e-12 else f"{m * 1000:g} mm"


def width_label(w: float) -> str:
    """A pose box's width ``w`` (m) in words: three decimals, or two significant digits below a millimetre."""
    return f"{w:.3f} m" if w >= 0.001 or w == 0 else f"{w:.1e} m"


class Lettering:
    """Writes text on ``P``-mode pictures, each (text, font) rendered once and pasted after: PIL's text
    rendering is most of a frame's cost, and most of a frame's words repeat."""

    def __init__(self, limit: int = 4096) -> None:
        self.limit = limit
        self._masks: dict[tuple[str, int], tuple[Any, int, int]] = {}

    def __call__(self, img: Any, xy: tuple[float, float], text: str, font: Any, fill: int) -> None:
        """Write ``text`` in ``font``, palette index ``fill``, at ``xy`` (top-left, as ``ImageDraw.text``)."""
        from PIL import Image, ImageDraw

        key = (text, id(font))
        got = self._masks.get(key)
        if got is None:  # drawn on a roomy canvas, then cropped to the ink (hinting can widen the text)
            size = int(getattr(font, "size", 16))
            mask = Image.new("1", (int(font.getlength(text) * 1.25) + 2 * size, 2 * size), 0)
            ImageDraw.Draw(mask).text((size, 0), text, fill=1, font=font)
            x0, y0, x1, y1 = mask.getbbox() or (size, 0, size + 1, 1)
            mask, x0 = mask.crop((x0, y0, x1, y1)), x0 - size
            if len(self._masks) >= self.limit:
                self._masks.clear()
            got = self._masks[key] = (mask, x0, y0)
        mask, x0, y0 = got
        img.paste(fill, (int(round(xy[0])) + x0, int(round(xy[1])) + y0), mask)


def scale_bar(img: Any, d: Any, xy: tuple[float, float], px_per_m: float, max_px: float,
              colours: tuple[int, int], font: Any, write: Lettering) -> float:  # fmt: skip
    """Draw a scale bar at most ``max_px`` long with its bottom-left corner at ``xy`` on a paper box
    (``colours``: ink and paper indices; ``d`` draws on ``img``, ``write`` writes); return its length (m)."""
    (x, y), (ink, paper) = xy, colours
    m = round_length(max_px / px_per_m)
    n, label = m * px_per_m, metres_label(m)
    tw = font.getlength(label)
    d.rectangle((x, y - 20, x + n + tw + 16, y), fill=paper, outline=ink)
    d.rectangle((x + 5, y - 9, x + 5 + n, y - 5), fill=ink)
    for t in (x + 5, x + 5 + n):
        d.line((t, y - 14, t, y - 5), fill=ink, width=2)
    write(img, (x + n + 11, y - 17), label, font, ink)
    return m


class Trail:
    """The estimated path: the centres (m) of the observer's pose boxes and the step of each."""

    def __init__(self) -> None:
        self.steps: list[int] = []
        self.xy: list[tuple[float, float]] = []

    def add(self, step: int, box: np.ndarray) -> None:
        """Add the centre of ``box`` (``[[x_lo, y_lo], [x_hi, y_hi]]``) after ``step`` steps (once a step)."""
        if self.steps and step <= self.steps[-1]:
            return
        c = 0.5 * (box[0] + box[1])
        self.steps.append(int(step))
        self.xy.append((float(c[0]), float(c[1])))

    def clear(self) -> None:
        """Forget the path (the observer withdrew its claims)."""
        self.steps.clear()
        self.xy.clear()

    def draw(self, d: Any, to_px: Any, step: int, shades: tuple[int, ...], width: int,
             within: float | None = None) -> None:  # fmt: skip
        """Draw the path with ``d`` (``to_px``: metres ``(n, 2)`` -> pixels ``(n, 2)``), its part newer than
        ``TRAIL_AGES[k]`` steps in ``shades[k]`` (the oldest part in ``shades[-1]``); ``within``: a square
        picture's side (px), the path drawn from its first point near the picture."""
        if len(self.xy) < 2:
            return
        px, steps = to_px(np.asarray(self.xy, np.float64)), np.asarray(self.steps)
        if within is not None:  # only the part from the first point inside the window (less to draw)
            inside = np.flatnonzero(np.all((px > -within) & (px < 2 * within), axis=1))
            first = max(int(inside[0]) - 1, 0) if inside.size else len(px)
            px, steps = px[first:], steps[first:]
        cuts = (
            [0] + [int(np.searchsorted(steps, step - a, side="right")) for a in TRAIL_AGES[::-1]] + [len(px)]
        )
        for k in range(len(cuts) - 1):  # oldest first: the newer parts are drawn on top
            seg = px[max(cuts[k] - 1, 0) : cuts[k + 1]]
            if len(seg) > 1:
                d.line([tuple(p) for p in seg], fill=shades[len(shades) - 1 - k], width=width, joint="curve")


def inset_window(box_width: float) -> float:
    """Side (m) of the inset's window for a pose box ``box_width`` wide: a round length at least three
    boxes and :data:`INSET_MIN_M` wide."""
    return round_length(max(3.0 * box_width, INSET_MIN_M), up=True)


def inset_background(cells: np.ndarray, lo: np.ndarray, hi: np.ndarray, centre: np.ndarray, side: float,
                     size: int) -> np.ndarray:  # fmt: skip
    """The ``(size, size)`` picture of ``cells`` (``(ny, nx)`` palette indices over the box ``lo``-``hi``,
    row 0 at the top) in the square window ``side`` metres wide centred on ``centre`` (nearest cell)."""
    ny, nx = cells.shape
    t = (np.arange(size) + 0.5) / size - 0.5
    cols = np.floor((centre[0] + side * t - lo[0]) / (hi[0] - lo[0]) * nx).astype(np.int64)
    rows = np.floor((hi[1] - (centre[1] - side * t)) / (hi[1] - lo[1]) * ny).astype(np.int64)
    return cells[np.clip(rows, 0, ny - 1)[:, None], np.clip(cols, 0, nx - 1)[None, :]]


def outline(d: Any, rect: tuple[float, float, float, float], least: float, colours: tuple[int, int]) -> None:
    """Outline ``rect`` (pixels), grown about its centre to at least ``least`` px a side, in a white line
    edged with ink (``colours``: ink and white indices) so that it reads on every set's colour."""
    x0, y0, x1, y1 = rect
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    hw, hh = 0.5 * max(x1 - x0, least), 0.5 * max(y1 - y0, least)
    ink, white = colours
    d.rectangle((cx - hw - 1, cy - hh - 1, cx + hw + 1, cy + hh + 1), outline=ink, width=4)
    d.rectangle((cx - hw, cy - hh, cx + hw, cy + hh), outline=white, width=2)


__all__ = [
    "INSET_MIN_M",
    "Lettering",
    "MIN_BOX_PX",
    "MIN_INSET_BOX_PX",
    "TRAIL_AGES",
    "Trail",
    "inset_background",
    "inset_window",
    "metres_label",
    "outline",
    "round_length",
    "scale_bar",
    "width_label",
]
