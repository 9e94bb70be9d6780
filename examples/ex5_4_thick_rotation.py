"""Example 5.4 (thesis §5.4.3, Eq. 5.39–5.42, Figure 5.7): uncertain inversion of a rotation.

``[X] = {x | R_θ x ∈ [y]}`` for ``θ ∈ [π/6, π/3]`` and ``[y] = [0, 3] × [4, 5]``: ``X⁻`` holds the
``x`` sent into ``[y]`` by every ``θ`` (Eq. 5.40), ``X⁺`` by some ``θ`` (Eq. 5.41). Three pictures:
(a) sampling of ``θ`` (``R_{-θ}[y]`` drawn with transparency); (b) the classical thick paver with
``θ`` kept as an interval (no penumbra proved, pessimism); (c) the thick paver with projections.

Usage: ``python examples/ex5_4_thick_rotation.py [--out DIR] [--eps EPS]``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, report, save_figure

from digslam.observer import Box, cos, sin
from digslam.observer.thick.inversion import thick_inverse_classical, thick_inverse_proj
from digslam.observer.thick.paver import ThickPaving, thick_pave

THETA = (np.pi / 6, np.pi / 3)
Y = Box([(0, 3), (4, 5)])
FRAME = Box([(0, 7), (-1, 6)])


def rotation(z: object) -> list:
    """``R_θ x`` with ``z = (x₁, x₂, θ)``."""
    return [cos(z[2]) * z[0] - sin(z[2]) * z[1], sin(z[2]) * z[0] + cos(z[2]) * z[1]]


def _stats(p: ThickPaving, seconds: float) -> dict:
    return {"clear_area": p.clear_area, "penumbra_area": p.penumbra_area, "dark_area": p.dark_area,
            "boundary_area": p.boundary_area, "bisections": p.bisections, "seconds": seconds}  # fmt: skip


def run(eps: float = 0.05, out: str | Path | None = None) -> dict:
    """Pave ``[X]`` classically and with projections at ``eps``; draw Figure 5.7 into ``out``."""
    theta = Box([THETA])
    t0 = time.perf_counter()
    pc = thick_pave(FRAME, thick_inverse_classical(rotation, Y, Y, theta, n=2), eps)
    t1 = time.perf_counter()
    pp = thick_pave(FRAME, thick_inverse_proj(rotation, Y, Y, theta, n=2, eps=eps / 4), eps)
    t2 = time.perf_counter()
    # exact areas: X⁻ = ∩ R_{-θ}[y] , X⁺ = ∪ R_{-θ}[y] estimated on a fine point grid
    gx, gy = np.meshgrid(np.linspace(0, 7, 701), np.linspace(-1, 6, 701))
    ths = np.linspace(*THETA, 181)[:, None, None]
    u, v = np.cos(ths) * gx - np.sin(ths) * gy, np.sin(ths) * gx + np.cos(ths) * gy
    inside = (u >= 0) & (u <= 3) & (v >= 4) & (v <= 5)
    cell = (7 / 700) ** 2
    res = {"eps": eps, "classical": _stats(pc, t1 - t0), "projection": _stats(pp, t2 - t1),
           "sampled_lower_area": float(inside.all(0).sum() * cell),
           "sampled_upper_area": float(inside.any(0).sum() * cell)}  # fmt: skip
    if out is not None:
        from digslam.observer.paving.draw import (
            CLEAR_COLOR,
            DARK_COLOR,
            PENUMBRA_COLOR,
            draw_boxes,
            new_figure,
        )

        fig, axes = new_figure(3, 1, size=4.0)
        corners = np.array([[0, 4], [3, 4], [3, 5], [0, 5], [0, 4]], float)
        for th in np.linspace(*THETA, 40):  # a few drawing calls, not per-box work
            c, s = np.cos(-th), np.sin(-th)
            pts = corners @ np.array([[c, s], [-s, c]])
            axes[0].fill(pts[:, 0], pts[:, 1], color=CLEAR_COLOR, alpha=0.05)
        axes[0].set_title("(a) sampling")
        for ax, p, title in ((axes[1], pc, "(b) classical"), (axes[2], pp, "(c) projection")):
            for b, col in ((p.clear, CLEAR_COLOR), (p.penumbra, PENUMBRA_COLOR), (p.dark, DARK_COLOR),
                           (p.boundary, "#ffd700")):  # fmt: skip
                draw_boxes(b[0], b[1], ax=ax, color=col, linewidth=0.1)
            ax.set_title(title)
        for ax in axes:
            ax.set_xlim(0, 7), ax.set_ylim(-1, 6), ax.set_aspect("equal")
        res["figure"] = str(save_figure(fig, out, "ex5_4_thick_rotation.png"))
    return res


def main(argv: list[str] | None = None) -> dict:
    a = parser(__doc__, out=".", eps=0.05).parse_args(argv)
    r = run(a.eps, a.out)
    report(r)
    return r


if __name__ == "__main__":
    main()
