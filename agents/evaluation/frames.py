"""One frame of the demo's episode GIF: the observer's sets with a legend, the step, both coverages and the
pose box.

Each frame is the certified-coverage map (``MAP_SIZE`` px, one colour per set of the observer) beside a
panel (``PANEL_WIDTH`` px). The map carries a scale bar, the estimated path (the trail of the observer's
pose box centres, fading with age), this step's echoes drawn from the true pose, the true robot and the pose
box, outlined at least :data:`~.overlays.MIN_BOX_PX` wide. The panel names every set in the thesis's words,
reads out the step, the certified and the ground-truth coverage against the target and the pose box's width
(its widest side, m), and magnifies the map around the pose box (the inset): there the box has its true
size and the true position is seen inside it. The palette is Okabe and Ito's colour-blind-safe one:
proved-free cells are sky blue, never red, and the echoes are purple, apart from the penumbra's orange.
Frames are drawn straight into a fixed palette (no colour quantization), so writing the GIF is cheap.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from digslam.agents.evaluation import overlays as ov
from digslam.envs.dig_coverage.env import RGB
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA

if TYPE_CHECKING:  # the layer's and the raw env's types
    from digslam.envs.dig_coverage.wrapper import GuaranteedObserver
    from digslam.envs.explore.env import ExploreEnv

MAP_SIZE = 512
#: The panel: the read-out and legend column (``LEGEND_WIDTH`` px), then the inset's column.
LEGEND_WIDTH, INSET_COLUMN = 320, 200
PANEL_WIDTH = LEGEND_WIDTH + INSET_COLUMN
#: The inset: its side (px) and top-left corner in the inset's column.
INSET_SIZE, INSET_AT = 176, (12, 34)
#: Palette indices and colours (Okabe-Ito, plus black and white and the trail's shades of blue).
PALETTE: dict[str, tuple[int, int, int]] = {
    "background": (255, 255, 255),
    "clear": RGB[int(CLEAR)],  # sky blue: the env's render and the GIF share the sets' colours
    "penumbra": RGB[int(PENUMBRA)],  # orange
    "dark": RGB[int(DARK)],  # near black
    "predicted": (60, 64, 92),  # faint slate on the dark: the map predictor's guess, never a claim
    "obstacle": (150, 150, 150),  # grey
    "echo": (170, 51, 119),  # purple (Tol's): far from the penumbra's orange and the clear blue
    "robot": (0, 158, 115),  # bluish green
    "box": (255, 255, 255),
    "ink": (0, 0, 0),
    "bar": (220, 220, 220),
    "target": (204, 121, 167),  # reddish purple
    "trail0": (0, 30, 90),  # the estimated path, newest (navy) ...
    "trail1": (0, 70, 140),
    "trail2": (20, 105, 175),
    "trail3": (45, 135, 200),  # ... to oldest, near the clear blue
}
INDEX = {name: i for i, name in enumerate(PALETTE)}
TRAIL = tuple(INDEX[f"trail{k}"] for k in range(4))
#: The legend: the palette entry of each swatch and its words (thesis Ch. 6 and App. B).
LEGEND: tuple[tuple[str, str, str], ...] = (
    ("clear", "clear", "proved free of obstacles and surely sensed"),
    ("penumbra", "penumbra", "maybe sensed, not proved (Z+ minus Z-)"),
    ("dark", "dark", "surely never sensed"),
    ("obstacle", "obstacles", "true obstacles, hidden from the robot"),
    ("echo", "echoes", "this step's ranges, drawn from the true pose"),
    ("trail0", "estimated path", "the pose box centres, paler with age"),
    ("box", "pose box", f"the robot is proved inside; >= {ov.MIN_BOX_PX} px here"),
    ("robot", "true robot", "ground truth, hidden from the robot"),
)
#: The extra legend row of an agent that predicts the map (``FrameDrawer(..., prediction=True)``).
PREDICTED = ("predicted", "predicted free (a guess)", "the map predictor's p >= 0.5 on dark ground")
LEGEND_TOP, LEGEND_ROW = 174, 36


def _font(size: int) -> Any:
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except (TypeError, OSError):  # Pillow < 10.1 or no FreeType: the bitmap font
        return ImageFont.load_default()


def flat_palette() -> list[int]:
    """The GIF palette as PIL's flat list ``[r0, g0, b0, r1, ...]``, in :data:`PALETTE`'s order."""
    return [c for rgb in PALETTE.values() for c in rgb]


class FrameDrawer:
    """Draws frames of one certified-coverage environment (``layer``: its ``GuaranteedObserver``).

    :meth:`observe` adds a step's pose box centre to the estimated path; :meth:`frame` adds its own step's
    and draws the frame.
    """

    def __init__(self, layer: GuaranteedObserver, title: str, target: float | None, steps: int,
                 prediction: bool = False) -> None:  # fmt: skip
        from PIL import Image, ImageDraw

        from digslam.envs.sim.raster import FREE, rasterize

        self.layer, self.title, self.target, self.steps = layer, title, target, steps
        g = layer.grid
        self.ny, self.nx = g.shape
        self.scale = max(MAP_SIZE // max(self.ny, self.nx), 1)
        self.lo, self.hi = np.array(g.lo, np.float64), np.array(g.hi, np.float64)
        self.px = self.scale * self.nx / (self.hi[0] - self.lo[0])  # pixels per metre
        self.trail = ov.Trail()
        self._world: Any = None
        self._obstacles = np.zeros(g.shape, bool)
        self._raster = (rasterize, FREE)
        self.font, self.small, self.big = _font(14), _font(12), _font(16)
        self.write = ov.Lettering()
        panel = Image.new("P", (PANEL_WIDTH, MAP_SIZE), INDEX["background"])
        d = ImageDraw.Draw(panel)
        d.text((12, 10), title, fill=INDEX["ink"], font=self.big)  # the read-out's fixed words
        d.text((12, 34), "step", fill=INDEX["ink"], font=self.font)
        self._step_at = self.font.getlength("step ")
        self._value_at = []
        for row, label in enumerate(("certified coverage", "ground-truth coverage")):
            d.text((12, 58 + row * 34), label, fill=INDEX["ink"], font=self.font)
            self._value_at.append(self.font.getlength(label + " "))
            d.rectangle((12, 76 + row * 34, LEGEND_WIDTH - 18, 86 + row * 34), fill=INDEX["bar"])
        if target is not None:
            d.text((162, 126), f"(target {target:.2f}: purple tick)", fill=INDEX["ink"], font=self.small)
        d.text((12, LEGEND_TOP - 22), "legend (what the observer proves)", fill=INDEX["ink"], font=self.font)
        for k, (key, name, words) in enumerate(LEGEND + ((PREDICTED,) if prediction else ())):
            y = LEGEND_TOP + k * LEGEND_ROW
            self._swatch(d, key, 12, y)
            d.text((46, y - 1), name, fill=INDEX["ink"], font=self.font)
            d.text((46, y + 15), words, fill=INDEX["ink"], font=self.small)
        x0 = LEGEND_WIDTH
        d.line((x0, 8, x0, MAP_SIZE - 8), fill=INDEX["bar"], width=1)
        d.text((x0 + 12, 10), "the pose box, magnified", fill=INDEX["ink"], font=self.small)
        notes = ("white: the pose box, at its true", "size; green dot: the true",
                 "position (ground truth, hidden", "from the robot), always inside.",
                 "blue: the estimated path.")  # fmt: skip
        for k, line in enumerate(notes):
            d.text(
                (x0 + 12, INSET_AT[1] + INSET_SIZE + 56 + 16 * k), line, fill=INDEX["ink"], font=self.small
            )
        self.panel = panel

    @staticmethod
    def _swatch(d: Any, key: str, x: int, y: int) -> None:
        box = (x, y, x + 24, y + 24)
        if key == "box":
            d.rectangle(box, fill=INDEX["clear"])
            ov.outline(d, (x + 4, y + 4, x + 20, y + 20), 0, (INDEX["ink"], INDEX["box"]))
        elif key == "robot":
            d.ellipse((x + 4, y + 4, x + 20, y + 20), fill=INDEX["robot"], outline=INDEX["ink"])
        elif key == "echo":
            d.rectangle(box, fill=INDEX["clear"])
            d.arc((x - 20, y + 2, x + 20, y + 42), 300, 360, fill=INDEX["echo"], width=3)
        elif key == "trail0":
            d.rectangle(box, fill=INDEX["clear"])
            for k, c in enumerate(TRAIL[::-1]):
                d.line((x + 1 + 6 * k, y + 20 - 4 * k, x + 7 + 6 * k, y + 16 - 4 * k), fill=c, width=3)
        else:
            d.rectangle(box, fill=INDEX[key], outline=INDEX["ink"])

    def _pix(self, x: float, y: float) -> tuple[float, float]:
        return (x - self.lo[0]) * self.px, (self.hi[1] - y) * self.px

    def _pixels(self, xy: np.ndarray) -> np.ndarray:
        return np.column_stack(((xy[:, 0] - self.lo[0]) * self.px, (self.hi[1] - xy[:, 1]) * self.px))

    def observe(self, info: dict[str, Any], step: int) -> None:
        """Add the pose box of ``info`` (after ``step`` steps) to the estimated path; forget the path once the
        observer has withdrawn its claims."""
        box = np.asarray(info["pose_box"], np.float64)
        if info.get("consistent", True) and np.all(np.isfinite(box)):
            self.trail.add(step, box)
        else:
            self.trail.clear()

    @property
    def raw(self) -> ExploreEnv:
        """The raw env under the observer: the world and the robot that the frame draws (ground truth)."""
        return cast("ExploreEnv", self.layer.unwrapped)

    def _cells(self, info: dict[str, Any]) -> np.ndarray:
        world = self.raw.world
        if world is None:
            raise ValueError("env: no world yet; reset the env before drawing a frame")
        if world is not self._world:
            rasterize, free = self._raster
            res = (self.hi[0] - self.lo[0]) / self.nx
            cells = rasterize(world.edges, (*self.lo, *self.hi), res)[::-1][: self.ny, : self.nx]
            self._obstacles, self._world = cells != free, world
        sets = info if "explored" in info else self.layer.sets()  # info_sets: the info's copies
        explored, clear = np.asarray(sets["explored"]), np.asarray(sets["clear"], bool)
        idx = np.full((self.ny, self.nx), INDEX["penumbra"], np.uint8)
        idx[explored == DARK] = INDEX["dark"]
        idx[clear & (explored == CLEAR)] = INDEX["clear"]
        idx[self._obstacles & ~clear] = INDEX["obstacle"]
        return idx

    def frame(self, info: dict[str, Any], step: int, prediction: np.ndarray | None = None) -> Any:
        """The ``P``-mode frame of ``info`` (the wrapper's info after ``step`` steps; the observer's sets are
        the info's with ``info_sets=True``, else the layer's now, :meth:`GuaranteedObserver.sets`);
        ``prediction``, an agent's ``(m, m)`` predicted free probabilities of the map's pixels, is drawn
        faintly on the dark cells where it is at least 0.5."""
        from PIL import Image, ImageDraw

        self.observe(info, step)
        idx = self._cells(info)
        if prediction is not None:
            self._predicted(idx, np.asarray(prediction, np.float64))
        s = self.scale
        big = np.repeat(np.repeat(idx, s, axis=0), s, axis=1)
        canvas = np.full((MAP_SIZE, MAP_SIZE + PANEL_WIDTH), INDEX["background"], np.uint8)
        h, w = min(big.shape[0], MAP_SIZE), min(big.shape[1], MAP_SIZE)
        canvas[:h, :w] = big[:h, :w]
        img = Image.fromarray(canvas, "P")
        img.paste(self.panel, (MAP_SIZE, 0))
        d, ink, paper = ImageDraw.Draw(img), INDEX["ink"], INDEX["background"]
        self.trail.draw(d, self._pixels, step, TRAIL, 2)
        truth, rec = info["truth"], info["record"]
        x, y, th = (float(v) for v in np.asarray(truth.pose)[:3])
        cx, cy = self._pix(x, y)
        for k in range(len(rec.no_echo)):  # this step's echoes, drawn from the true pose
            if rec.no_echo[k]:
                continue
            r = 0.5 * float(rec.range[k][0] + rec.range[k][1]) * self.px
            a, g = th + float(rec.alpha[k]), float(rec.gamma[k])
            circle = (cx - r, cy - r, cx + r, cy + r)
            if g >= math.pi - 1e-9:
                d.ellipse(circle, outline=INDEX["echo"], width=2)
            else:  # PIL's angles go clockwise from +x in image coordinates (y down)
                d.arc(circle, math.degrees(-a - g), math.degrees(-a + g), fill=INDEX["echo"], width=3)
        rad = max(self.raw.config.robot_radius * self.px, 4.0)
        d.ellipse((cx - rad, cy - rad, cx + rad, cy + rad), fill=INDEX["robot"], outline=ink)
        d.line((cx, cy, cx + 2 * rad * math.cos(th), cy - 2 * rad * math.sin(th)), fill=ink, width=2)
        box = np.asarray(info["pose_box"], np.float64)
        ok = bool(info.get("consistent", True) and np.all(np.isfinite(box)))
        if ok:
            (x0, y0), (x1, y1) = self._pix(box[0, 0], box[1, 1]), self._pix(box[1, 0], box[0, 1])
            ov.outline(d, (x0, y0, x1, y1), ov.MIN_BOX_PX, (ink, INDEX["box"]))
        ov.scale_bar(img, d, (6, MAP_SIZE - 6), self.px, MAP_SIZE / 8, (ink, paper), self.small, self.write)
        self._readout(img, d, info, step, box if ok else None)
        ix, iy = MAP_SIZE + LEGEND_WIDTH + INSET_AT[0], INSET_AT[1]
        img.paste(self._inset(idx, box if ok else None, (x, y, th)), (ix, iy))
        if ok:
            side = ov.inset_window(float(np.max(box[1] - box[0])))
            per_metre = INSET_SIZE / side  # pixels per metre in the inset
            ov.scale_bar(img, d, (ix, iy + INSET_SIZE + 30), per_metre, INSET_SIZE / 2.5, (ink, paper),
                         self.small, self.write)  # fmt: skip
        return img

    def _predicted(self, idx: np.ndarray, p: np.ndarray) -> None:
        """Mark the dark cells of ``idx`` whose map pixel (the map's block of cells) is predicted free."""
        from digslam.envs.dig_coverage.maps_jit import block_starts

        rows = np.searchsorted(block_starts(self.ny, p.shape[0]), np.arange(self.ny), side="right") - 1
        cols = np.searchsorted(block_starts(self.nx, p.shape[1]), np.arange(self.nx), side="right") - 1
        free = p[np.ix_(rows, cols)] >= 0.5
        idx[free & (idx == INDEX["dark"])] = INDEX["predicted"]

    def _inset(self, idx: np.ndarray, box: np.ndarray | None, pose: tuple[float, float, float]) -> Any:
        """The inset: the map around the pose box's centre, magnified so the box has its true size, with the
        estimated path, the box and the true position."""
        from PIL import Image, ImageDraw

        n, ink = INSET_SIZE, INDEX["ink"]
        if box is None:
            img = Image.new("P", (n, n), INDEX["bar"])
            self.write(img, (10, n // 2 - 8), "claims withdrawn", self.font, ink)
            ImageDraw.Draw(img).rectangle((0, 0, n - 1, n - 1), outline=ink)
            return img
        c, side = 0.5 * (box[0] + box[1]), ov.inset_window(float(np.max(box[1] - box[0])))
        img = Image.fromarray(ov.inset_background(idx, self.lo, self.hi, c, side, n), "P")
        d = ImageDraw.Draw(img)
        k = n / side  # pixels per metre

        def to_px(xy: np.ndarray) -> np.ndarray:
            return np.column_stack(((xy[:, 0] - c[0]) * k + n / 2, (c[1] - xy[:, 1]) * k + n / 2))

        self.trail.draw(d, to_px, self.trail.steps[-1] if self.trail.steps else 0, TRAIL, 3, within=n)
        (x0, y0), (x1, y1) = to_px(np.array([[box[0, 0], box[1, 1]], [box[1, 0], box[0, 1]]]))
        ov.outline(d, (x0, y0, x1, y1), ov.MIN_INSET_BOX_PX, (ink, INDEX["box"]))
        (tx, ty), th = to_px(np.array([pose[:2]]))[0], pose[2]
        d.line((tx, ty, tx + 16 * math.cos(th), ty - 16 * math.sin(th)), fill=ink, width=2)
        d.ellipse((tx - 4, ty - 4, tx + 4, ty + 4), fill=INDEX["robot"], outline=ink)
        d.rectangle((0, 0, n - 1, n - 1), outline=ink)
        return img

    def _readout(self, img: Any, d: Any, info: dict[str, Any], step: int, box: np.ndarray | None) -> None:
        x0, ink, write = MAP_SIZE + 12, INDEX["ink"], self.write
        write(img, (x0 + self._step_at, 34), f"{step} / {self.steps}", self.font, ink)
        cert, true = float(info["certified_coverage"]), float(info["true_coverage"])
        for row, v in enumerate((cert, true)):
            y = 58 + row * 34
            write(img, (x0 + self._value_at[row], y), f"{v:.3f}", self.font, ink)
            bar = (x0, y + 18, x0 + LEGEND_WIDTH - 30, y + 28)
            d.rectangle((bar[0], bar[1], bar[0] + (bar[2] - bar[0]) * min(max(v, 0.0), 1.0), bar[3]),
                        fill=INDEX["clear"] if row == 0 else INDEX["obstacle"])  # fmt: skip
            if self.target is not None:
                tx = bar[0] + (bar[2] - bar[0]) * self.target
                d.line((tx, bar[1] - 3, tx, bar[3] + 3), fill=INDEX["target"], width=3)
        if box is not None:
            words = f"pose box {ov.width_label(float(np.max(box[1] - box[0])))} wide"
            write(img, (x0, 126), words, self.small, ink)
            write(img, (x0 + LEGEND_WIDTH, INSET_AT[1] + INSET_SIZE + 36), words, self.font, ink)
        else:
            d.rectangle((x0, 124, x0 + LEGEND_WIDTH - 18, 142), fill=INDEX["background"])
            write(img, (x0, 126), "data inconsistent: every claim withdrawn", self.small, ink)


__all__ = [
    "INDEX",
    "INSET_AT",
    "INSET_SIZE",
    "LEGEND",
    "LEGEND_ROW",
    "LEGEND_TOP",
    "LEGEND_WIDTH",
    "MAP_SIZE",
    "PALETTE",
    "PANEL_WIDTH",
    "TRAIL",
    "FrameDrawer",
    "flat_palette",
]
