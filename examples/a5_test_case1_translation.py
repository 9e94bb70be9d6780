"""Test-case 1 of thesis §A.5 (Figure A.8 and its table): thick translation of a thick disk.

``⟦Y⟧ = [Y⁻, Y⁺]`` with ``Y⁻``, ``Y⁺`` the disks of centre ``(0, 0)`` and radii ``r⁻ = 1``, ``r⁺ = 2``;
``[f](x) = x − [v]`` with ``[v] = [0.7, 1.3] × [−0.02, 0.02]``; frame ``[−2, 4] × [−2, 4]``. Pointwise
``X⁻ = {x | x − [v] ⊂ Y⁻} = Y⁻ ⊖ [v]`` and ``X⁺ = {x | (x − [v]) ∩ Y⁺ ≠ ∅} = Y⁺ ⊕ [v]`` (Remark A.4).
Since ``Yᵢ`` are disks, the tests are written on the squared norm: ``‖x − v‖² ∈ [0, 1]`` for
``Y⁻`` and ``∈ [0, 4]`` for ``Y⁺``, with the exact thick inclusion of ``x ↦ ‖x − v‖²``, ``v ∈ [v]``
(:meth:`ThickFunction.sqdist`). The classical method (Algorithm A.1) uses the same enclosures without
the penumbra test.

Usage: ``python examples/a5_test_case1_translation.py [--out DIR] [--eps EPS] [--classical-min-eps E]``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from digslam.observer.thick_function import ThickFunction
from digslam.observer.thick_paver import ThickPaving
from digslam.observer.thick_sivia import thick_sivia

V_LO, V_HI = [0.7, -0.02], [1.3, 0.02]
R_MINUS, R_PLUS = 1.0, 2.0
FRAME = ([-2.0, -2.0], [4.0, 4.0])
EPS_TABLE = (0.5, 0.1, 0.05, 0.01, 0.005, 0.001)
#: thesis table of test-case 1: eps -> (classical bisections, our-method bisections)
THESIS = {0.5: (195, 159), 0.1: (2215, 783), 0.05: (8043, 1623), 0.01: (470407, 13383),
          0.005: (1867707, 26823), 0.001: (29722487, 107443)}  # fmt: skip


def thick_disk() -> ThickFunction:
    """``⟦f⟧`` of ``x ↦ ‖x − v‖²``, ``v ∈ [v]`` (exact ranges of ``f⁻``, ``f⁺`` on boxes)."""
    return ThickFunction.sqdist([V_LO], [V_HI])


def solve(eps: float, penumbra: bool = True) -> tuple[ThickPaving, float]:
    """ThickSivia (or classical Sivia when ``penumbra=False``) at ``eps``; returns the paving and seconds."""
    f = thick_disk()
    t = time.perf_counter()
    p = thick_sivia(FRAME, f, [0.0, R_MINUS**2], [0.0, R_PLUS**2], eps=eps, penumbra=penumbra)
    return p, time.perf_counter() - t


def run(eps: float = 0.1, out: str | Path | None = None, classical_min_eps: float = 0.01,
        table: tuple[float, ...] = EPS_TABLE) -> dict:  # fmt: skip
    """Bisection table over ``table`` (classical only for ``eps >= classical_min_eps``) and Fig. A.8."""
    rows = []
    for e in table:
        p, s = solve(e)
        row = {
            "eps": e,
            "ours": p.bisections,
            "ours_s": s,
            "thesis_ours": THESIS.get(e, (None, None))[1],
            "thesis_classical": THESIS.get(e, (None, None))[0],
            "classical": None,
            "classical_s": None,
        }
        if e >= classical_min_eps:
            pc, sc = solve(e, penumbra=False)
            row["classical"], row["classical_s"] = pc.bisections, sc
        rows.append(row)
    p, _ = solve(eps)
    pc, _ = solve(eps, penumbra=False)
    res = {"eps": eps, "table": rows, "clear_area": p.clear_area, "penumbra_area": p.penumbra_area,
           "dark_area": p.dark_area, "boundary_area": p.boundary_area, "bisections": p.bisections,
           "classical_bisections": pc.bisections, "classical_boundary_area": pc.boundary_area}  # fmt: skip
    if out is not None:
        from digslam.observer.draw import new_figure, save_figure

        fig, axes = new_figure(2, 1, size=4.5)
        pc.draw(axes[0], FRAME, f"classical intervals (ε = {eps})")
        p.draw(axes[1], FRAME, f"thick intervals, ThickSivia (ε = {eps})")
        res["figure"] = str(save_figure(fig, Path(out) / "a5_test_case1_translation.png"))
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", default="out")
    ap.add_argument("--eps", type=float, default=0.1)
    ap.add_argument(
        "--classical-min-eps",
        type=float,
        default=0.005,
        help="the classical method is run only down to this eps (0.001 needs ~30M bisections)",
    )
    a = ap.parse_args()
    r = run(a.eps, a.out, a.classical_min_eps)
    print(f"{'eps':>6} | {'classical':>10} {'thesis':>10} | {'ours':>8} {'thesis':>8} | "
          f"{'ours s':>7} {'class. s':>8}")  # fmt: skip
    for row in r["table"]:
        cl = "-" if row["classical"] is None else str(row["classical"])
        cs = "-" if row["classical_s"] is None else f"{row['classical_s']:.3f}"
        print(f"{row['eps']:6g} | {cl:>10} {row['thesis_classical']:>10} | {row['ours']:>8} "
              f"{row['thesis_ours']:>8} | {row['ours_s']:7.4f} {cs:>8}")  # fmt: skip
    print({k: v for k, v in r.items() if k != "table"})


if __name__ == "__main__":
    main()
