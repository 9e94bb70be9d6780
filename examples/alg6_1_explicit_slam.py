"""Algorithm 6.1 (§6.2.1–6.2.3, Fig. 6.1–6.3): explicit shape-based SLAM in a field of rocks.

A robot loops for ``duration`` s through a field of star-shaped rocks (the simulator's ``RockField``, rocks
near the loop removed so that it is collision-free) with a suite of 8 sonar cones. Two kinds of thick shapes
are measured, both in the robot frame with the translation map function ``g_x(m) = m - x`` (Eq. 6.16; the
heading is known from the compass and gyro, as in §6.3.2):

* double-sided shapes (Eq. 6.4, §6.2.3.1), every ``period`` s: an imaging sonar classifies the pixels of
  its scope (a disk of radius ``scope`` m) into free (``Z⁻``), occupied (outside ``Z⁺``) and uncertain
  (the penumbra, with everything outside the scope); the simulator builds them from its exact raster of
  the world (``World.raster``) at the true pose, so they contain the truth;
* one-sided shapes (§6.2.3.2) every 0.1 s: each sonar cone's free sector ``Z⁻`` and its impact arc
  ``ΔZ`` (Eq. 6.17, 6.22).

:func:`~digslam.observer.slam.explicit_slam.explicit_slam` carves the thick map ``[M] = [∅, R²]`` and
contracts
the tube until nothing contracts. The figure shows the tube against dead reckoning, the map's clear
(``M⁻``), penumbra and dark (``comp M⁺``) parts over the true rocks, and the tube width over time.

Usage: ``python examples/alg6_1_explicit_slam.py [--out DIR] [--duration S] [--seed N]``.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.envs.config import NoiseConfig
from digslam.envs.sim.generators import RockField
from digslam.envs.sim.missions import loop_mission
from digslam.envs.sim.raster import FREE, OCCUPIED
from digslam.envs.sim.sensors import SensorSuite
from digslam.envs.sim.world import World
from digslam.observer.record.grid import Grid
from digslam.observer.slam.explicit_slam import (
    ExplicitSlamConfig,
    ExplicitSlamResult,
    explicit_slam,
    mission_tube,
)
from digslam.observer.slam.measurements import RangeMeasurements, ShapeMeasurements
from digslam.observer.slam.raster_shape import RasterShape
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA

CELL = 0.25  # pixel side of the shapes and cell side of the map (a dyadic number: exact lattice)
LOOP = np.array([(0.0, 0.0), (4.0, -4.5), (7.0, 0.0), (4.0, 5.0), (-1.0, 6.5), (-6.0, 4.0), (-7.0, -2.0),
                 (-4.0, -6.0)])  # fmt: skip


def rock_world(seed: int, clear: float = 0.8) -> World:
    """A rock field without the rocks within ``clear`` m of the loop's polyline."""
    w = RockField(n=40, radius=(0.9, 2.0)).generate(seed)
    a, b = LOOP, np.roll(LOOP, -1, axis=0)
    keep = [w.rings[0]]
    for r in w.rings[1:]:
        p = r[:, None, :]
        d = b - a
        s = np.clip(((p - a) * d).sum(-1) / (d * d).sum(-1), 0, 1)
        dist = np.hypot(*(p - a - s[..., None] * d).transpose(2, 0, 1)).min()
        if dist > clear:
            keep.append(r)
    return World(w.frame, keep, "rocks")


def sonar_suite(n: int = 8, gamma: float = math.pi / 10, r_max: float = 5.0) -> SensorSuite:
    alpha = np.array([2 * math.pi * k / n for k in range(n)])
    alpha = np.where(alpha > math.pi, alpha - 2 * math.pi, alpha)
    return SensorSuite(alpha, np.full(n, gamma), np.full(n, r_max))


def double_sided_shape(world: World, x: np.ndarray, scope: float, cell: float = CELL) -> RasterShape:
    """``[Z] = [Z⁻, Z⁺]`` of ``Z = M - x`` (``M`` the free space) seen in a disk of radius ``scope``.

    Pixel ``P`` of the robot frame is in ``Z⁻`` when every cell of the world's exact raster (``cell / 4``)
    met by ``P + x`` (dilated by 1e-9 m) is free, outside ``Z⁺`` when every one is occupied; pixels not
    entirely in the scope disk, or reaching outside the frame, are in the penumbra.
    """
    half = int(math.ceil(scope / cell))
    n = 2 * half
    res = cell / 4  # a finer exact raster: a pixel meets 5 x 5 of its cells, not 2 x 2 coarse ones
    raster = world.raster(res)  # row 0 at the bottom of the frame
    x0, y0 = world.frame[0], world.frame[1]
    js = np.arange(-half, half)
    px_lo = js * cell  # pixel column j covers [j e, (j+1) e] in the robot frame
    lower, upper = np.zeros((n, n), bool), np.ones((n, n), bool)
    for i in range(n):  # image row i (top down) covers y in [(half - i - 1) e, (half - i) e]
        ylo, yhi = (half - i - 1) * cell + x[1] - 1e-9, (half - i) * cell + x[1] + 1e-9
        xlo, xhi = px_lo + x[0] - 1e-9, px_lo + cell + x[0] + 1e-9
        r0, r1 = int(math.floor((ylo - y0) / res)), int(math.floor((yhi - y0) / res))
        c0, c1 = np.floor((xlo - x0) / res).astype(int), np.floor((xhi - x0) / res).astype(int)
        ok = (r0 >= 0) & (r1 < raster.shape[0]) & (c0 >= 0) & (c1 < raster.shape[1])
        far = np.maximum(np.abs(px_lo), np.abs(px_lo + cell))
        fy = max(abs((half - i - 1) * cell), abs((half - i) * cell))
        ok &= np.hypot(far, fy) <= scope
        for j in np.flatnonzero(ok):
            block = raster[r0 : r1 + 1, c0[j] : c1[j] + 1]
            lower[i, j] = bool((block == FREE).all())
            upper[i, j] = not bool((block == OCCUPIED).all())
    return RasterShape(lower, upper, (-half * cell, half * cell), cell)


def run(duration: float = 240.0, seed: int = 3, period: float = 2.0, scope: float = 5.0,
        out: str | Path | None = None) -> dict:  # fmt: skip
    """Simulate, run Algorithm 6.1 to its fixpoint, draw the figure into ``out``; return the figures."""
    world = rock_world(seed)
    noise = NoiseConfig(speed=0.01, yaw_rate=0.002, heading=0.002, range=0.05)
    record, truth = loop_mission(world, LOOP, sonar_suite(), duration=duration, noise=noise, seed=seed)
    grid = Grid((-10.0, -10.0), (10.0, 10.0), (80, 80))
    tube, u_lo, u_hi, heading = mission_tube(record, truth[0, :2], truth[0, :2])
    step = int(round(period / 0.1))
    gates = np.arange(step, len(record), step)
    shapes = [double_sided_shape(world, truth[k, :2], scope) for k in gates]
    fams = [ShapeMeasurements(gates, shapes, eps=0.05), RangeMeasurements(record, heading)]
    t0 = time.perf_counter()
    res = explicit_slam(tube, u_lo, u_hi, fams, grid, ExplicitSlamConfig(max_iter=15))
    seconds = time.perf_counter() - t0
    inside = np.all((truth[:, :2] >= res.tube.gate_lo) & (truth[:, :2] <= res.tube.gate_hi), axis=1)
    codes = res.map.codes()
    raster = world.raster(CELL)[::-1]  # top row first, as the map (exact classes of the map's cells)
    area = CELL * CELL
    stats = {
        "seconds": seconds, "iterations": res.iterations, "consistent": res.consistent,
        "truth_in_tube": bool(inside.all()), "dead_reckoning_max_width": float(res.dead_reckoning.max()),
        "max_width": float(res.tube.widths().max()), "final_width": float(res.tube.widths()[-1]),
        "dead_reckoning_final_width": float(res.dead_reckoning[-1]),
        "clear_area": float((codes == CLEAR).sum() * area), "dark_area": float((codes == DARK).sum() * area),
        "penumbra_area": float((codes == PENUMBRA).sum() * area),
        "clear_sound": bool((raster[codes == CLEAR] == FREE).all()),
        "dark_sound": bool((raster[codes == DARK] == OCCUPIED).all()),
        "shapes": len(shapes), "result": res,
    }  # fmt: skip
    if out is not None:
        stats["figure"] = str(draw(res, world, truth, grid, out))
    return stats


def draw(res: ExplicitSlamResult, world: World, truth: np.ndarray, grid: Grid, out: str | Path) -> Path:
    """Tube vs dead reckoning; thick map (clear red, penumbra orange, dark blue) over the rocks; widths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection

    from digslam.observer.paving.draw import draw_grid

    fig, (a, b, c) = plt.subplots(1, 3, figsize=(19, 6.2))
    rings = [np.vstack([r, r[:1]]) for r in world.rings]
    k = np.arange(0, res.tube.T + 1, 20)
    lo, hi = res.tube.gate_lo[k], res.tube.gate_hi[k]
    quads = np.stack([lo, np.c_[hi[:, 0], lo[:, 1]], hi, np.c_[lo[:, 0], hi[:, 1]]], axis=1)
    a.add_collection(PolyCollection(quads, facecolors="none", edgecolors="tab:blue", linewidths=0.4))
    a.plot(truth[:, 0], truth[:, 1], "k", lw=0.6)
    a.set_title(f"tube (every 2 s), {res.iterations} passes of Algorithm 6.1")
    codes = res.map.codes()
    status = np.where(codes == CLEAR, 1, np.where(codes == DARK, -1, 0))
    draw_grid(status, grid.extent, ax=b, thick=True)
    b.set_title("thick map [M]: clear $M^-$ red, penumbra orange, dark blue")
    for ax in (a, b):
        for r in rings:
            ax.plot(r[:, 0], r[:, 1], "k", lw=0.8)
        ax.set_xlim(-10, 10)
        ax.set_ylim(-10, 10)
        ax.set_aspect("equal")
    t = res.tube.t
    c.plot(t, res.dead_reckoning, "r", label="dead reckoning")
    c.plot(t, res.tube.widths(), "k", label="Algorithm 6.1")
    c.set_xlabel("t (s)")
    c.set_ylabel("max gate width (m)")
    c.legend()
    fig.tight_layout()
    return save_figure(fig, out, "alg6_1_explicit_slam.png", dpi=110)


def main(argv: list[str] | None = None) -> dict:
    args = parser(__doc__.splitlines()[0], duration=240.0, seed=3).parse_args(argv)
    st = run(args.duration, args.seed, out=args.out)
    print(f"Algorithm 6.1: {st['iterations']} passes in {st['seconds']:.1f} s, "
          f"consistent={st['consistent']}, truth in tube: {st['truth_in_tube']}")  # fmt: skip
    print(f"max width {st['max_width']:.3f} m (dead reckoning {st['dead_reckoning_max_width']:.3f} m); final "
          f"{st['final_width']:.3f} m (dead reckoning {st['dead_reckoning_final_width']:.3f} m)")  # fmt: skip
    print(f"map: clear {st['clear_area']:.1f} m², penumbra {st['penumbra_area']:.1f} m², dark "
          f"{st['dark_area']:.1f} m² (clear cells all free: {st['clear_sound']}, dark all rock: "
          f"{st['dark_sound']}); figure {st.get('figure')}")  # fmt: skip
    return st


if __name__ == "__main__":
    main()
