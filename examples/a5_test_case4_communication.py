"""Test-case 4 of thesis §A.5 (Eq. A.47–A.49, Table A.3, Figure A.11): communication area.

Four marks ``m(i) ∈ [m](i)`` (Table A.3, ``±0.5`` on each coordinate); the robot at ``x`` surely
communicates with mark ``i`` within 10 m and surely not beyond 20 m: ``⟦X⟧ = [f]⁻¹([Y⁻, Y⁺])`` with
``[fᵢ](x) = ‖x − [m](i)‖`` (Eq. A.49), ``Y⁻ = [0, 10]^4`` and ``Y⁺ = [0, 20]^4`` (Eq. A.48), written
on squared distances (``[0, 100]^4``, ``[0, 400]^4``) with the exact thick inclusion
:meth:`ThickFunction.sqdist`. The thesis gives neither ``ε`` nor the frame: ``[−20, 20]²`` contains
``X⁺`` (within 20.71 of every mark box) and ``ε = 0.1`` is used. Reference areas come from a fine
point grid with the exact point bounds ``f⁻(x) = d(x, [m])``, ``f⁺(x) = max over the box corners``.

Usage: ``python examples/a5_test_case4_communication.py [--out DIR] [--eps EPS]``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, report, save_figure

from digslam.observer.thick.function import ThickFunction
from digslam.observer.thick.sivia import thick_sivia

MARKS = np.array([[1.0, 3.0], [10.0, -1.0], [10.0, 6.0], [-2.0, -5.0]])  # Table A.3
M_LO, M_HI = MARKS - 0.5, MARKS + 0.5
Y_MINUS, Y_PLUS = [[0.0, 10.0**2]] * 4, [[0.0, 20.0**2]] * 4
FRAME = ([-20.0, -20.0], [20.0, 20.0])


def point_bounds(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact ``(f⁻(x), f⁺(x))`` of the squared distances, ``(P, 4)`` each, for points ``(P, 2)``."""
    d = np.maximum(np.maximum(M_LO[None] - x[:, None], x[:, None] - M_HI[None]), 0.0)
    far = np.maximum(np.abs(x[:, None] - M_LO[None]), np.abs(x[:, None] - M_HI[None]))
    return (d**2).sum(axis=-1), (far**2).sum(axis=-1)


def grid_areas(n: int = 1200) -> dict:
    """Areas of ``X⁻`` and ``X⁺`` estimated on an ``n × n`` grid of cell centres of the frame."""
    g = FRAME[0][0] + (np.arange(n) + 0.5) * (FRAME[1][0] - FRAME[0][0]) / n
    pts = np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)
    lo, hi = point_bounds(pts)
    cell = ((FRAME[1][0] - FRAME[0][0]) / n) ** 2
    return {
        "lower": float((hi <= 100.0).all(axis=1).sum() * cell),
        "upper": float((lo <= 400.0).all(axis=1).sum() * cell),
    }


def run(eps: float = 0.1, out: str | Path | None = None, grid: int = 1200) -> dict:
    """ThickSivia on the communication area (thesis: < 0.3 s), the classical paving for comparison and
    the ``grid × grid`` estimates of the areas of ``X⁻``, ``X⁺``."""
    f = ThickFunction.sqdist(M_LO, M_HI)
    t = time.perf_counter()
    p = thick_sivia(FRAME, f, Y_MINUS, Y_PLUS, eps=eps)
    s = time.perf_counter() - t
    pc = thick_sivia(FRAME, f, Y_MINUS, Y_PLUS, eps=eps, penumbra=False)
    ga = grid_areas(grid)
    res = {"eps": eps, "seconds": s, "bisections": p.bisections, "boxes": p.n_boxes,
           "clear_area": p.clear_area, "penumbra_area": p.penumbra_area, "dark_area": p.dark_area,
           "boundary_area": p.boundary_area, "classical_bisections": pc.bisections,
           "grid_lower_area": ga["lower"], "grid_upper_area": ga["upper"]}  # fmt: skip
    if out is not None:
        from digslam.observer.paving.draw import draw_boxes, new_figure

        fig, ax = new_figure(1, 1, size=5.0)
        p.draw(ax, FRAME, f"communication area, ε = {eps}")
        draw_boxes(M_LO, M_HI, ax=ax, color="k", autoscale=False, zorder=3)
        res["figure"] = str(save_figure(fig, out, "a5_test_case4_communication.png"))
    return res


def main(argv: list[str] | None = None) -> dict:
    a = parser(__doc__, eps=0.1).parse_args(argv)
    r = run(a.eps, a.out)
    report(r)
    return r


if __name__ == "__main__":
    main()
