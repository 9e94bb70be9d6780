"""Make the pictures of the page on real buildings (``docs/buildings.md``), in ``docs/_static/``.

* ``buildings_plans.png``: the ten shipped KTH plans, coloured by their split;
* ``buildings_levels.png``: levels of ``digslam/DigCoverageFloorplan-v0`` (one reset seed of each split)
  beside their plan: the whole plan with the window drawn on it, the window as cut from the plan, the level
  (the window turned) with the start pose;
* ``buildings_ros.png``: the page's worked example, the ROS map picture ``lab.pgm`` and the world its YAML
  file makes, in metres.

Rerun it when the plans, the loader, the generator or the floorplan ids' window size change::

    python docs/make_buildings.py

A few seconds; each picture is shrunk to a palette PNG of at most ``--width`` pixels (well under 150 kB).
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

import numpy as np

STATIC = Path(__file__).resolve().parent / "_static"
#: Reset seeds of ``digslam/DigCoverageFloorplan-v0`` shown in ``buildings_levels.png``, one per split.
LEVEL_SEEDS = (2, 1_000_005, 2_000_002)
SPLIT_COLOURS = {"train": "#0072B2", "validation": "#E69F00", "test": "#009E73"}  # Okabe-Ito
#: The label of a level's world (``Window.label``): plan, window corner (m) and rotation (degrees).
LABEL = re.compile(r"^(\S+) @ \(([-\d.]+), ([-\d.]+)\) rot (\d+)$")


def lab_image() -> np.ndarray:
    """The picture of the page's worked example (grey values, row 0 at the top)."""
    img = np.full((120, 200), 205, dtype=np.uint8)  # unknown (map_saver's grey), 10 m x 6 m at 0.05 m/px
    img[10:110, 10:190] = 254  # the floor: free
    img[10:110, 98:102] = 0  # a wall 0.2 m thick across the middle...
    img[50:70, 98:102] = 254  # ...with a 1 m door
    img[20:40, 30:60] = 0  # a cupboard
    return img


def write_lab(folder: Path) -> Path:
    """The page's worked example: ``lab.pgm`` and ``lab.yaml`` in ``folder``; returns the YAML's path."""
    (folder / "lab.pgm").write_bytes(b"P5\n200 120\n255\n" + lab_image().tobytes())
    (folder / "lab.yaml").write_text(
        "image: lab.pgm\nresolution: 0.05\norigin: [-2.0, -1.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n"
    )
    return folder / "lab.yaml"


def _plan_rgb(name: str) -> np.ndarray:
    """A shipped plan as RGB: walls black, the building's floor white, the outside light grey."""
    from digslam.envs.sim.generators.floorplan import PLANS_DIR
    from digslam.envs.sim.occupancy import load_plan

    m = load_plan(PLANS_DIR / f"{name}.npz")
    with np.load(PLANS_DIR / f"{name}.npz") as z:
        wall = z["wall"].astype(bool)
    rgb = np.full((*m.shape, 3), 0.85)
    rgb[m.free] = 1.0
    rgb[wall] = 0.0
    return rgb


def _save(fig: object, name: str, width: int) -> Path:
    from make_gallery import shrink

    out = STATIC / name
    with tempfile.TemporaryDirectory() as tmp:
        raw = Path(tmp) / name
        fig.savefig(raw, dpi=100)  # type: ignore[attr-defined]  # a matplotlib Figure
        shrink(raw, out, width, colors=64)
    print(f"{out.relative_to(STATIC.parent.parent)}: {out.stat().st_size // 1024} KB")
    return out


def plans_picture(width: int) -> Path:
    import matplotlib.pyplot as plt

    from digslam.envs.sim.generators.floorplan import SPLIT

    order = [(split, name) for split, names in SPLIT.items() for name in names]
    fig, axes = plt.subplots(5, 2, figsize=(10, 11), layout="constrained")
    for ax, (split, name) in zip(axes.T.flat, order, strict=True):
        rgb = _plan_rgb(name)
        if rgb.shape[0] > rgb.shape[1]:
            rgb = np.rot90(rgb)
        rows, cols = rgb.shape[:2]
        ax.imshow(rgb, extent=(0, cols / 10, 0, rows / 10), interpolation="nearest")
        ax.set_title(f"{name} ({split})", fontsize=10, color=SPLIT_COLOURS[split])
        for side in ax.spines.values():
            side.set_color(SPLIT_COLOURS[split])
            side.set_linewidth(3)
        ax.tick_params(labelsize=7)
    fig.suptitle("The shipped KTH plans by split (metres; the outside of the building grey)", fontsize=12)
    out = _save(fig, "buildings_plans.png", width)
    plt.close(fig)
    return out


def levels_picture(width: int) -> Path:
    import gymnasium as gym
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    import digslam.envs  # noqa: F401  (registers the environments)
    from digslam.envs.sim.raster import FREE
    from digslam.envs.splits import split_of

    fig, axes = plt.subplots(len(LEVEL_SEEDS), 3, figsize=(13, 3.4 * len(LEVEL_SEEDS)), layout="constrained",
                             gridspec_kw={"width_ratios": [2.4, 1, 1]})  # fmt: skip
    env = gym.make("digslam/DigCoverageFloorplan-v0")
    for (ax_plan, ax_cut, ax_level), seed in zip(axes, LEVEL_SEEDS, strict=True):
        _, info = env.reset(seed=seed)
        world = env.unwrapped.world
        match = LABEL.match(world.name)
        assert match, world.name
        plan, cx, cy, rot = match[1], float(match[2]), float(match[3]), int(match[4])
        split, colour = str(split_of(seed)), SPLIT_COLOURS[str(split_of(seed))]
        rgb = _plan_rgb(plan)
        rows, cols = rgb.shape[:2]
        x0, y0, x1, y1 = world.frame
        side = x1 - x0
        for ax in (ax_plan, ax_cut):
            ax.imshow(rgb, extent=(0, cols / 10, 0, rows / 10), interpolation="nearest")
            ax.add_patch(Rectangle((cx, cy), side, side, fill=False, lw=2.5, edgecolor=colour))
        ax_plan.set_title(f"{plan}: a {split} plan, {cols / 10:g} m x {rows / 10:g} m", fontsize=10)
        ax_cut.set_xlim(cx - 1, cx + side + 1)
        ax_cut.set_ylim(cy - 1, cy + side + 1)
        ax_cut.set_title(f"the window at ({cx:g}, {cy:g})", fontsize=10)
        free = world.raster(0.1) == FREE
        ax_level.imshow(np.where(free, 1.0, 0.25), extent=(x0, x1, y0, y1), origin="lower", cmap="gray",
                        vmin=0, vmax=1, interpolation="nearest")  # fmt: skip
        x, y, th = info["truth"].pose
        ax_level.plot([x], [y], "o", color="#D55E00", ms=7)
        ax_level.plot([x, x + 1.2 * np.cos(th)], [y, y + 1.2 * np.sin(th)], "-", color="#D55E00", lw=2)
        ax_level.set_title(f"seed {seed}: turned {rot} deg", fontsize=10)
        for spine in ax_level.spines.values():
            spine.set_color(colour)
            spine.set_linewidth(3)
        for ax in (ax_plan, ax_cut, ax_level):
            ax.tick_params(labelsize=7)
    env.close()
    fig.suptitle("digslam/DigCoverageFloorplan-v0: levels beside their plans (metres)", fontsize=12)
    out = _save(fig, "buildings_levels.png", width)
    plt.close(fig)
    return out


def ros_picture(width: int) -> Path:
    import matplotlib.pyplot as plt

    from digslam.envs.sim.occupancy import load_map

    with tempfile.TemporaryDirectory() as tmp:
        m = load_map(write_lab(Path(tmp)))
    grey = lab_image()
    world = m.world()
    fig, (ax_img, ax_world) = plt.subplots(1, 2, figsize=(11, 3.9), layout="constrained")
    ax_img.imshow(grey, cmap="gray", vmin=0, vmax=255, interpolation="nearest")
    ax_img.set_title("lab.pgm (pixels): free 254, wall 0, unknown 205", fontsize=10)
    ax_img.tick_params(labelsize=7)
    x0, y0, x1, y1 = m.frame
    ax_world.imshow(np.where(m.free, 1.0, 0.25), extent=(x0, x1, y0, y1), cmap="gray", vmin=0, vmax=1,
                    interpolation="nearest")  # fmt: skip
    for e in world.edges:
        ax_world.plot(e[[0, 2]], e[[1, 3]], "-", color="#0072B2", lw=1.2)
    ax_world.plot([0], [0], "+", color="#D55E00", ms=14, mew=2)
    ax_world.annotate("(0, 0)", (0, 0), (0.15, 0.15), color="#D55E00", fontsize=9)
    ax_world.set_title(f"load_map('lab.yaml').world(): {len(world.edges)} edges (metres)", fontsize=10)
    ax_world.set_xlim(x0 - 0.3, x1 + 0.3)
    ax_world.set_ylim(y0 - 0.3, y1 + 0.3)
    ax_world.tick_params(labelsize=7)
    out = _save(fig, "buildings_ros.png", width)
    plt.close(fig)
    return out


def main(argv: list[str] | None = None) -> None:
    import matplotlib

    matplotlib.use("Agg")
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=1000, help="largest width of a picture (default 1000)")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent))  # make_gallery's shrink
    STATIC.mkdir(exist_ok=True)
    plans_picture(args.width)
    levels_picture(args.width)
    ros_picture(args.width)


if __name__ == "__main__":
    main()
