"""Guaranteed explored zone of a simulated survey (thesis App. B, §B.5, Figures B.2, B.7, B.8).

A robot runs a lawnmower survey in dead reckoning: its position is known only inside a box that grows
with the distance run (the tube). Three pictures:

* (B.8) patch exploration: a disk of radius in ``[r_lo, r_hi]`` seen at each of ``m`` times
  (:func:`~digslam.observer.slam.explored.explored_disks_grid`);
* (B.7) sweep exploration: a side-scan segment perpendicular to the path, sensed continuously
  (:func:`~digslam.observer.slam.explored_sweep.explored_sweep_grid`, Theorem B.1 over runs of gates);
* (B.2) two candidate trajectories whose opposite sonar pies cross: the cross intersection is clear
  once the hypotheses are joined (Eq. B.7), and not with the hull tube.

Clear red, penumbra orange, dark blue; white cells are undetermined. The true trajectory (dotted)
is used only to check the result.

Usage: ``python examples/b5_explored_zone.py [--out DIR] [--m M]``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, report, save_figure

from digslam.observer.record.grid import Grid
from digslam.observer.slam.explored import explored_disks_grid, explored_hypotheses
from digslam.observer.slam.explored_sweep import explored_sectors_grid, explored_sweep_grid, sweep_gates
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA

FRAME = ((-12.0, -12.0), (12.0, 12.0))


def survey(m: int, seed: int = 0) -> dict:
    """Nominal lawnmower path (5 lanes, semicircle turns of radius 2) sampled at ``m`` arc lengths, a
    smooth true drift inside the tube ``nominal ± e(s)``, ``e(s) = 0.05 + 0.008 s``, and headings."""
    pts = []
    for k in range(5):
        y, sgn = -8.0 + 4 * k, 1.0 if k % 2 == 0 else -1.0
        pts.append(np.stack([np.linspace(-8 * sgn, 8 * sgn, 400), np.full(400, y)], 1))
        if k < 4:
            a = np.linspace(-np.pi / 2, np.pi / 2, 200) * sgn
            pts.append(np.stack([8 * sgn + 2 * np.cos(a) * sgn, y + 2 + 2 * np.sin(a) * sgn], 1))
    poly = np.concatenate(pts)
    arc = np.r_[0, np.cumsum(np.hypot(*np.diff(poly, axis=0).T))]
    s = np.linspace(0, arc[-1], m)
    nom = np.stack([np.interp(s, arc, poly[:, 0]), np.interp(s, arc, poly[:, 1])], 1)
    d = np.gradient(nom, s, axis=0)
    psi = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    rng = np.random.default_rng(seed)
    e = 0.05 + 0.008 * s
    w, ph = rng.uniform(0.05, 0.2, 2), rng.uniform(0, 2 * np.pi, 2)
    drift = e[:, None] * np.stack([np.sin(w[0] * s + ph[0]), np.cos(w[1] * s + ph[1])], 1)
    return {"s": s, "nominal": nom, "true": nom + drift, "e": e, "psi": psi}


def _stats(st: np.ndarray, grid: Grid) -> dict:
    a = grid.cell_size[0] * grid.cell_size[1]
    codes = (("clear", CLEAR), ("penumbra", PENUMBRA), ("dark", DARK))
    return {k: float((st == c).sum() * a) for k, c in codes}


def fig_b2() -> dict:
    """Two exact candidate trajectories (a, b) at times t1, t2 with sonar pies (Figure B.2)."""
    g = Grid((-3.0, -3.0), (3.0, 3.0), (120, 120))
    # hypothesis a sees from below at t1 and to the far left at t2; b from the far right at t1 and above at t2
    pos = {"a": np.array([[0.0, -1.2], [-2.5, 2.5]]), "b": np.array([[2.5, -2.5], [0.0, 1.2]])}
    psi = {"a": np.array([np.pi / 2, np.pi]), "b": np.array([0.0, -np.pi / 2])}
    gam, r = np.pi / 5, 2.0
    st = {h: explored_sectors_grid(g, pos[h], pos[h], psi[h], psi[h], 0.0, gam, r, r) for h in "ab"}
    joined = explored_hypotheses([st["a"], st["b"]])
    lo, hi = np.minimum(pos["a"], pos["b"]), np.maximum(pos["a"], pos["b"])
    hull = explored_sectors_grid(g, lo, hi, np.minimum(psi["a"], psi["b"]), np.maximum(psi["a"], psi["b"]),
                                 0.0, gam, r, r)  # fmt: skip
    return {
        "grid": g,
        "a": st["a"],
        "b": st["b"],
        "joined": joined,
        "hull": hull,
        "cross_clear_cells": int((joined == CLEAR).sum()),
        "hull_clear_cells": int((hull == CLEAR).sum()),
    }


def run(m: int = 12000, out: str | Path | None = None, sweep_m: int = 1500, cells: int = 480) -> dict:
    """Classify the survey (``cells`` x ``cells`` grid for the disks, half that for the sweep) and the
    Figure B.2 case; draw into ``out``."""
    sv = survey(m)
    g = Grid(*FRAME, (cells, cells))
    lo, hi = sv["nominal"] - sv["e"][:, None], sv["nominal"] + sv["e"][:, None]
    t0 = time.perf_counter()
    disks = explored_disks_grid(g, lo, hi, 2.0, 2.2)
    t_disks = time.perf_counter() - t0
    sw = survey(sweep_m)
    gs = Grid(*FRAME, (cells // 2, cells // 2))
    slo, shi = sw["nominal"] - sw["e"][:, None], sw["nominal"] + sw["e"][:, None]
    epsi = 0.02 + 0.0005 * sw["s"]
    ds = sw["s"][1] - sw["s"][0]
    # bounds of the model (dt = 1 per sample): |ẋ| <= 1.5 ds + drift rate, |ψ̇| <= ds / 2 (turn radius 2)
    g_lo, g_hi, gp_lo, gp_hi = sweep_gates(slo, shi, sw["psi"] - epsi, sw["psi"] + epsi,
                                           v_max=1.5 * ds + 0.01 * ds, w_max=0.75 * ds, dt=1.0)  # fmt: skip
    t0 = time.perf_counter()
    sweep = explored_sweep_grid(gs, slo, shi, sw["psi"] - epsi, sw["psi"] + epsi, -2.2, 2.2,
                                g_lo, g_hi, gp_lo, gp_hi)  # fmt: skip
    t_sweep = time.perf_counter() - t0
    b2 = fig_b2()
    res = {"m": m, "disks_seconds": t_disks, "disks": _stats(disks, g), "sweep_m": sweep_m,
           "sweep_seconds": t_sweep, "sweep": _stats(sweep, gs),
           "b2_cross_clear_cells": b2["cross_clear_cells"], "b2_hull_clear_cells": b2["hull_clear_cells"],
           "final_tube_halfwidth": float(sv["e"][-1])}  # fmt: skip
    if out is not None:
        from digslam.observer.paving.draw import draw_grid, new_figure

        fig, axes = new_figure(2, 1, size=6.0)
        panels = ((axes[0], disks, g, sv, "patch (disks), cf. Fig. B.8"),
                  (axes[1], sweep, gs, sw, "sweep (side scan), cf. Fig. B.7"))  # fmt: skip
        for ax, st, gr, data, title in panels:
            draw_grid(st, gr.extent, ax=ax, thick=True, penumbra=int(PENUMBRA),
                      colors={1: "#e41a1c", 2: "#ff8c00", -1: "#08306b", 0: "#ffffff"})  # fmt: skip
            ax.plot(*data["nominal"].T, "k-", lw=0.5)
            ax.plot(*data["true"].T, "w:", lw=0.8)
            ax.set_title(title)
        res["figure"] = str(save_figure(fig, out, "b5_explored_zone.png"))
        fig, axes = new_figure(4, 1, size=3.5)
        titles = ("trajectory a", "trajectory b", "a or b (Eq. B.7)", "hull tube")
        for ax, key, title in zip(axes, ("a", "b", "joined", "hull"), titles):
            draw_grid(b2[key], b2["grid"].extent, ax=ax, thick=True, penumbra=int(PENUMBRA),
                      colors={1: "#e41a1c", 2: "#ff8c00", -1: "#08306b", 0: "#ffffff"})  # fmt: skip
            ax.set_title(title)
        res["figure_b2"] = str(save_figure(fig, out, "b5_fig_b2.png"))
    return res


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__)
    ap.add_argument("--m", type=int, default=12000, help="sensing times of the patch survey (default 12000)")
    a = ap.parse_args(argv)
    r = run(a.m, a.out)
    report(r)
    return r


if __name__ == "__main__":
    main()
