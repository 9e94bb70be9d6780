"""The demo's episode GIF: the observer's sets with a legend, the step and both coverages.

Each frame is the certified-coverage map (``MAP_SIZE`` px, one colour per set of the observer) beside a
panel (``PANEL_WIDTH`` px) that names every set in the thesis's words and reads out the step, the certified
and the ground-truth coverage against the target, and the tube width (widest side of the pose box). The
palette is Okabe and Ito's colour-blind-safe one: proved-free cells are sky blue, never red.

Frames are drawn straight into a fixed palette (no colour quantization), so writing the GIF is cheap;
:func:`demo_episode` runs one episode and returns its curves as an
:class:`~digslam.agents.evaluation.evaluate.EvalResult` for the coverage figure.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from digslam.agents.evaluation.evaluate import EvalResult, make_env
from digslam.envs.dig_coverage.env import RGB
from digslam.observer.thick.sep import CLEAR, DARK, PENUMBRA

MAP_SIZE = 512
PANEL_WIDTH = 320
#: Palette indices and colours (Okabe-Ito, plus black and white).
PALETTE: dict[str, tuple[int, int, int]] = {
    "background": (255, 255, 255),
    "clear": RGB[int(CLEAR)],  # sky blue: the env's render and the GIF share the sets' colours
    "penumbra": RGB[int(PENUMBRA)],  # orange
    "dark": RGB[int(DARK)],  # near black
    "obstacle": (150, 150, 150),  # grey
    "echo": (213, 94, 0),  # vermillion
    "robot": (0, 158, 115),  # bluish green
    "box": (255, 255, 255),
    "ink": (0, 0, 0),
    "bar": (220, 220, 220),
    "target": (204, 121, 167),  # reddish purple
}
INDEX = {name: i for i, name in enumerate(PALETTE)}
#: The legend: the palette entry of each swatch and its words (thesis Ch. 6 and App. B).
LEGEND: tuple[tuple[str, str, str], ...] = (
    ("clear", "clear", "proved free of obstacles and surely sensed"),
    ("penumbra", "penumbra", "maybe sensed, not proved (Z+ minus Z-)"),
    ("dark", "dark", "surely never sensed"),
    ("obstacle", "obstacles", "true obstacles, hidden from the robot"),
    ("echo", "echoes", "obstacles as sensed: this step's ranges"),
    ("robot", "true robot", "ground truth, hidden from the robot"),
    ("box", "pose box", "the robot is proved to be inside"),
)
LEGEND_TOP, LEGEND_ROW = 178, 44


def _font(size: int) -> Any:
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except (TypeError, OSError):  # Pillow < 10.1 or no FreeType: the bitmap font
        return ImageFont.load_default()


def _flat_palette() -> list[int]:
    return [c for rgb in PALETTE.values() for c in rgb]


class FrameDrawer:
    """Draws frames of one certified-coverage environment (``layer``: its ``GuaranteedObserver``)."""

    def __init__(self, layer: Any, title: str, target: float | None, steps: int) -> None:
        from PIL import Image, ImageDraw

        from digslam.envs.sim.raster import FREE, rasterize

        self.layer, self.title, self.target, self.steps = layer, title, target, steps
        g = layer.grid
        self.ny, self.nx = g.shape
        self.scale = max(MAP_SIZE // max(self.ny, self.nx), 1)
        self.lo, self.hi = np.array(g.lo, np.float64), np.array(g.hi, np.float64)
        self.px = self.scale * self.nx / (self.hi[0] - self.lo[0])  # pixels per metre
        self._world: Any = None
        self._obstacles = np.zeros(g.shape, bool)
        self._raster = (rasterize, FREE)
        self.font, self.small, self.big = _font(14), _font(12), _font(16)
        panel = Image.new("P", (PANEL_WIDTH, MAP_SIZE), INDEX["background"])
        d = ImageDraw.Draw(panel)
        d.text((12, LEGEND_TOP - 24), "legend (what the observer proves)", fill=INDEX["ink"], font=self.font)
        for k, (key, name, words) in enumerate(LEGEND):
            y = LEGEND_TOP + k * LEGEND_ROW
            self._swatch(d, key, 12, y)
            d.text((46, y - 1), name, fill=INDEX["ink"], font=self.font)
            d.text((46, y + 16), words, fill=INDEX["ink"], font=self.small)
        self.panel = panel

    @staticmethod
    def _swatch(d: Any, key: str, x: int, y: int) -> None:
        box = (x, y, x + 24, y + 24)
        if key == "box":
            d.rectangle(box, fill=INDEX["dark"])
            d.rectangle((x + 4, y + 4, x + 20, y + 20), outline=INDEX["ink"], width=3)
            d.rectangle((x + 5, y + 5, x + 19, y + 19), outline=INDEX["box"], width=1)
        elif key == "robot":
            d.ellipse((x + 4, y + 4, x + 20, y + 20), fill=INDEX["robot"], outline=INDEX["ink"])
        elif key == "echo":
            d.rectangle(box, fill=INDEX["clear"])
            d.arc((x - 20, y + 2, x + 20, y + 42), 300, 360, fill=INDEX["echo"], width=3)
        else:
            d.rectangle(box, fill=INDEX[key], outline=INDEX["ink"])

    def _pix(self, x: float, y: float) -> tuple[float, float]:
        return (x - self.lo[0]) * self.px, (self.hi[1] - y) * self.px

    def frame(self, info: dict[str, Any], step: int) -> Any:
        """The ``P``-mode frame of ``info`` (the wrapper's info after ``step`` steps; the observer's sets are
        the info's with ``info_sets=True``, else the layer's now, :meth:`GuaranteedObserver.sets`)."""
        from PIL import Image, ImageDraw

        layer = self.layer
        raw = layer.env.unwrapped
        if raw.world is not self._world:
            rasterize, free = self._raster
            res = (self.hi[0] - self.lo[0]) / self.nx
            cells = rasterize(raw.world.edges, (*self.lo, *self.hi), res)[::-1][: self.ny, : self.nx]
            self._obstacles, self._world = cells != free, raw.world
        from digslam.observer.thick.sep import CLEAR, DARK

        sets = info if "explored" in info else layer.sets()  # info_sets: the info's copies
        explored, clear = np.asarray(sets["explored"]), np.asarray(sets["clear"], bool)
        idx = np.full((self.ny, self.nx), INDEX["penumbra"], np.uint8)
        idx[explored == DARK] = INDEX["dark"]
        idx[clear & (explored == CLEAR)] = INDEX["clear"]
        idx[self._obstacles & ~clear] = INDEX["obstacle"]
        s = self.scale
        big = np.repeat(np.repeat(idx, s, axis=0), s, axis=1)
        canvas = np.full((MAP_SIZE, MAP_SIZE + PANEL_WIDTH), INDEX["background"], np.uint8)
        h, w = min(big.shape[0], MAP_SIZE), min(big.shape[1], MAP_SIZE)
        canvas[:h, :w] = big[:h, :w]
        img = Image.fromarray(canvas, "P")
        img.paste(self.panel, (MAP_SIZE, 0))
        d = ImageDraw.Draw(img)
        truth, rec = info["truth"], info["record"]
        x, y, th = (float(v) for v in np.asarray(truth.pose)[:3])
        cx, cy = self._pix(x, y)
        for k in range(len(rec.no_echo)):  # this step's echoes, drawn from the true pose
            if rec.no_echo[k]:
                continue
            r = 0.5 * float(rec.range[k][0] + rec.range[k][1]) * self.px
            a, g = th + float(rec.alpha[k]), float(rec.gamma[k])
            box = (cx - r, cy - r, cx + r, cy + r)
            if g >= math.pi - 1e-9:
                d.ellipse(box, outline=INDEX["echo"], width=2)
            else:  # PIL's angles go clockwise from +x in image coordinates (y down)
                d.arc(box, math.degrees(-a - g), math.degrees(-a + g), fill=INDEX["echo"], width=3)
        rad = max(raw.config.robot_radius * self.px, 4.0)
        d.ellipse((cx - rad, cy - rad, cx + rad, cy + rad), fill=INDEX["robot"], outline=INDEX["ink"])
        d.line((cx, cy, cx + 2 * rad * math.cos(th), cy - 2 * rad * math.sin(th)), fill=INDEX["ink"], width=2)
        box = np.asarray(info["pose_box"], np.float64)
        if info.get("consistent", True) and np.all(np.isfinite(box)):
            (x0, y0), (x1, y1) = self._pix(box[0, 0], box[1, 1]), self._pix(box[1, 0], box[0, 1])
            d.rectangle((x0 - 2, y0 - 2, x1 + 2, y1 + 2), outline=INDEX["ink"], width=3)
            d.rectangle((x0 - 1, y0 - 1, x1 + 1, y1 + 1), outline=INDEX["box"], width=1)
        self._readout(d, info, step, box)
        return img

    def _readout(self, d: Any, info: dict[str, Any], step: int, box: np.ndarray) -> None:
        x0, ink = MAP_SIZE + 12, INDEX["ink"]
        d.text((x0, 10), self.title, fill=ink, font=self.big)
        d.text((x0, 34), f"step {step} / {self.steps}", fill=ink, font=self.font)
        cert, true = float(info["certified_coverage"]), float(info["true_coverage"])
        for row, (label, v) in enumerate((("certified coverage", cert), ("ground-truth coverage", true))):
            y = 58 + row * 34
            d.text((x0, y), f"{label} {v:.3f}", fill=ink, font=self.font)
            bar = (x0, y + 18, x0 + PANEL_WIDTH - 30, y + 28)
            d.rectangle(bar, fill=INDEX["bar"])
            d.rectangle((bar[0], bar[1], bar[0] + (bar[2] - bar[0]) * min(max(v, 0.0), 1.0), bar[3]),
                        fill=INDEX["clear"] if row == 0 else INDEX["obstacle"])  # fmt: skip
            if self.target is not None:
                tx = bar[0] + (bar[2] - bar[0]) * self.target
                d.line((tx, bar[1] - 3, tx, bar[3] + 3), fill=INDEX["target"], width=3)
        if info.get("consistent", True) and np.all(np.isfinite(box)):
            tube = float(np.max(box[1] - box[0]))
            tail = f"  (target {self.target:.2f}: purple tick)" if self.target is not None else ""
            d.text((x0, 126), f"tube width {tube:.3f} m{tail}", fill=ink, font=self.small)
        else:
            d.text((x0, 126), "data inconsistent: every claim withdrawn", fill=INDEX["echo"], font=self.small)


def _observer_layer(env: Any) -> Any:
    e = env
    while e is not None and not hasattr(e, "filter"):
        e = getattr(e, "env", None)
    if e is None:
        raise ValueError("env: not a certified-coverage environment (no GuaranteedObserver inside)")
    return e


def demo_episode(
    policy: Any,
    env_id: str = "digslam/DigCoverage-v0",
    path: str | Path = "episode.gif",
    steps: int = 600,
    seed: int = 0,
    env_kwargs: dict[str, Any] | None = None,
    fps: int = 15,
    stride: int = 2,
    name: str = "agent",
    scale: int = 1,
) -> Any:
    """Run one episode of ``policy``, write its GIF to ``path`` (every ``stride``-th step and the last, each
    frame shrunk ``scale`` times) and return its :class:`~digslam.agents.evaluation.evaluate.EvalResult` (one
    episode, curves padded after an early end, ``lengths`` the steps run)."""
    for key, v in (("steps", steps), ("fps", fps), ("stride", stride), ("scale", scale)):
        if not (isinstance(v, int) and v >= 1):
            raise ValueError(f"{key}: must be an integer >= 1, got {v!r}")
    env = make_env(env_id, steps, env_kwargs)
    if hasattr(policy, "reset") and callable(policy.reset) and not hasattr(policy, "policy"):
        policy.reset()
    cert, true = np.empty(steps + 1), np.empty(steps + 1)
    try:
        obs, info = env.reset(seed=seed)
        title = f"{env_id.split('/')[-1]}: {name}"
        drawer = FrameDrawer(_observer_layer(env), title, info.get("target"), steps)
        frames = [drawer.frame(info, 0)]
        cert[0], true[0] = info["certified_coverage"], info["true_coverage"]
        state, start, n = None, np.ones(1, dtype=bool), 0
        for n in range(1, steps + 1):
            action, state = policy.predict(obs, state=state, episode_start=start, deterministic=True)
            start = np.zeros(1, dtype=bool)
            action = np.clip(np.asarray(action, dtype=np.float32).reshape(env.action_space.shape), -1, 1)
            obs, _, terminated, truncated, info = env.step(action)
            cert[n], true[n] = info["certified_coverage"], info["true_coverage"]
            done = terminated or truncated
            if n % stride == 0 or done or n == steps:
                frames.append(drawer.frame(info, n))
            if done:
                cert[n + 1 :], true[n + 1 :] = cert[n], true[n]
                break
    finally:
        env.close()
    if scale > 1:
        frames = [f.resize((f.width // scale, f.height // scale), 0) for f in frames]  # 0: nearest
    write_gif(frames, path, fps)
    box = np.asarray(info.get("pose_box", np.full((2, 2), np.nan)), dtype=np.float64)
    tube = float(np.max(box[1] - box[0])) if np.all(np.isfinite(box)) else math.nan
    return EvalResult({name: cert[None]}, {name: true[None]}, {name: np.array([float(info.get("bumps", 0))])},
                      {name: np.array([tube])}, {name: np.array([float(n)])}, env_id, seed, 1)  # fmt: skip


def write_gif(frames: list[Any], path: str | Path, fps: int) -> Path:
    """Write ``P``-mode frames sharing :data:`PALETTE` as a looping GIF."""
    pal = _flat_palette()
    for f in frames:
        f.putpalette(pal)
    p = Path(path)
    frames[0].save(p, format="GIF", save_all=True, append_images=frames[1:],
                   duration=max(int(1000 / fps), 20), loop=0, optimize=False)  # fmt: skip
    return p


def record_episode_gif(
    policy: Any,
    env_id: str = "digslam/DigCoverage-v0",
    path: str | Path = "episode.gif",
    steps: int = 300,
    seed: int = 0,
    env_kwargs: dict[str, Any] | None = None,
    fps: int = 15,
    stride: int = 1,
    scale: int = 1,
) -> Path:
    """Animated GIF of one episode of ``policy``: the frames of :mod:`.pictures` (the observer's sets in a
    colour-blind-safe palette, a legend in the thesis's words, the step, both coverages and the tube width;
    :func:`demo_episode`). ``stride`` keeps every ``stride``-th frame and ``scale`` shrinks
    each frame by that factor (file size)."""
    demo_episode(policy, env_id, path, steps=steps, seed=seed, env_kwargs=env_kwargs, fps=fps, stride=stride,
                 scale=scale)  # fmt: skip
    return Path(path)


__all__ = [
    "record_episode_gif",
    "LEGEND",
    "MAP_SIZE",
    "PALETTE",
    "PANEL_WIDTH",
    "FrameDrawer",
    "demo_episode",
    "write_gif",
]
