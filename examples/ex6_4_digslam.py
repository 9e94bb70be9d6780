"""§6.4.2 (Figures 6.10, 6.12, 6.13): range-only Dig-SLAM in an unstructured environment.

A robot loops for 20 minutes in the polygon room of Fig. 6.10 (frame [-10, 10]²), measuring its speed
(±0.001 m/s), its heading (±0.001 rad), its yaw rate (±0.001 rad/s) and the distance to the nearest
obstacle (±0.01 m) every 0.1 s; its initial position is known. Dig-SLAM (Algorithm 6.3 as the thesis
writes it, :func:`~digslam.observer.slam.digslam.thesis_dig_slam`) runs to its fixpoint and draws the tube,
the dig zone ``M⁻`` against the true map and the explored zone (Fig. 6.12), and the tube width over time for
dead reckoning and for each iteration (Fig. 6.13).

Usage: ``python examples/ex6_4_digslam.py [--out DIR] [--duration S] [--cell M] [--seed N]``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, report, save_figure

from digslam.envs.sim.generators import ThesisRoom
from digslam.envs.sim.missions import loop_mission
from digslam.observer.record.grid import Grid
from digslam.observer.slam.digslam import DigSlamResult, thesis_dig_slam


def run(duration: float = 1200.0, cell: float = 0.05, seed: int = 0, out: str | Path | None = None) -> dict:
    """Simulate the mission, run Dig-SLAM, draw Figs. 6.12–6.13 into ``out``; return the figures."""
    world = ThesisRoom().generate(0)
    record, truth = loop_mission(world, duration=duration, seed=seed)
    grid = Grid.from_cell_size((-10.0, -10.0), (10.0, 10.0), cell)
    t0 = time.perf_counter()
    res = thesis_dig_slam(record, grid, truth[0, :2], truth[0, :2])
    seconds = time.perf_counter() - t0
    inside = np.all((truth[:, :2] >= res.tube.gate_lo) & (truth[:, :2] <= res.tube.gate_hi), axis=1)
    stats = {
        "seconds": seconds,
        "iterations": res.iterations,
        "dead_reckoning_max_width": float(res.dead_reckoning.max()),
        "max_width": float(res.tube.widths().max()),
        "mean_width": float(res.tube.widths().mean()),
        "dig_area": float(res.dig.free.sum() * np.prod(grid.cell_size)),
        "truth_in_tube": bool(inside.all()),
        "clear_area": float((res.explored == 1).sum() * np.prod(grid.cell_size)),
        "penumbra_area": float((res.explored == 2).sum() * np.prod(grid.cell_size)),
    }
    if out is not None:
        draw(res, world, truth, grid, out)
    return stats


def draw(res: DigSlamResult, world: object, truth: np.ndarray, grid: Grid, out: str | Path) -> None:
    """Fig. 6.12 (tube and ``M⁻`` over the true map) and Fig. 6.13 (widths over time)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection

    from digslam.observer.paving.draw import draw_grid

    fig, (a, b, c) = plt.subplots(1, 3, figsize=(19, 6.2))
    rings = [np.vstack([r, r[:1]]) for r in world.rings]  # type: ignore[attr-defined]
    k = np.arange(0, res.tube.T + 1, 20)
    lo, hi = res.tube.gate_lo[k], res.tube.gate_hi[k]
    quads = np.stack([lo, np.c_[hi[:, 0], lo[:, 1]], hi, np.c_[lo[:, 0], hi[:, 1]]], axis=1)
    a.add_collection(PolyCollection(quads, facecolors="none", edgecolors="tab:blue", linewidths=0.3))
    a.plot(truth[:, 0], truth[:, 1], "k", lw=0.6)
    a.set_title(f"tube (every 2 s), {res.iterations} iterations")
    b.imshow(res.dig.free, extent=grid.extent, cmap="Reds", vmin=0, vmax=1.6, interpolation="nearest")
    b.set_title("dig zone $M^-$ (red) and the true map")
    draw_grid(res.explored, grid.extent, ax=c, thick=True, penumbra=2)
    c.set_title("explored zone: clear red, penumbra orange, dark blue")
    for ax in (a, b, c):
        for r in rings:
            ax.plot(r[:, 0], r[:, 1], "k", lw=1.0)
        ax.set_xlim(-10, 10)
        ax.set_ylim(-10, 10)
        ax.set_aspect("equal")
    fig.tight_layout()
    save_figure(fig, out, "fig6_12_digslam.png", dpi=110)
    fig, ax = plt.subplots(figsize=(9, 4))
    t = res.tube.t
    ax.plot(t, res.dead_reckoning, "r", lw=1, label="dead reckoning")
    for i, w in enumerate(res.widths):
        ax.plot(t, w["impacts"], "k", lw=0.6, alpha=0.5, label="after $C_g^{\\neq}$" if i == 0 else None)
        ax.plot(t, w["deriv"], "b", lw=0.8, alpha=0.4 + 0.6 * (i + 1) / len(res.widths),
                label="after $C_{d/dt}$" if i == 0 else None)  # fmt: skip
    ax.set_yscale("log")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("tube width (m)")
    ax.legend()
    fig.tight_layout()
    save_figure(fig, out, "fig6_13_widths.png", dpi=110)


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__.splitlines()[0], duration=1200.0, seed=0)
    ap.add_argument("--cell", type=float, default=0.05, help="grid cell size in m (default 0.05)")
    a = ap.parse_args(argv)
    r = run(a.duration, a.cell, a.seed, a.out)
    report(r)
    return r


if __name__ == "__main__":
    main()
