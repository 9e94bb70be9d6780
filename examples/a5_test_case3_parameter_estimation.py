"""Test-case 3 of thesis §A.5 (Eq. A.41–A.46, Table A.2, Figure A.10): parameter estimation with
uncertain measurement times.

``y_m(x, t) = x₁ e^{−x₂ t}``; the times ``tᵢ ∈ [tᵢ]`` are uncertain and go into the thick function
``[fᵢ](x) = x₁ e^{−x₂ [tᵢ]}`` (Eq. A.43). ``t ↦ x₁ e^{−x₂ t}`` is monotone for every ``x``, so
``fᵢ⁻(x) = min(x₁e^{−x₂tᵢ⁻}, x₁e^{−x₂tᵢ⁺})`` and ``fᵢ⁺`` is the max (exact bounds). Inverting on the
box ``[y]`` (Eq. A.44) gives ``X⁻`` (Eq. A.45: every ``t ∈ [tᵢ]`` fits) and ``X⁺`` (Eq. A.46: some
``t`` fits). The thesis gives no frame: ``[2, 20] × [−2, 16]`` contains ``X⁺`` (``x₁ ≥ 4`` from
``y₁``; ``0 < x₂ ≤ ln 8 / 0.15`` and ``x₁ ≤ 8 e^{0.06 x₂}`` from ``y₁``, ``y₄``).

Usage: ``python examples/a5_test_case3_parameter_estimation.py [--out DIR] [--eps EPS]``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, report, save_figure

from digslam.observer import Function, exp
from digslam.observer.core import arith
from digslam.observer.thick.function import ThickFunction
from digslam.observer.thick.interval import ThickIntervalArray
from digslam.observer.thick.sivia import thick_sivia

T = np.array([[0.03, 0.06], [0.09, 0.12], [0.15, 0.18], [0.21, 0.24], [0.27, 0.30]])  # Table A.2
Y = np.array([[4.0, 8.0], [2.0, 6.0], [2.0, 5.0], [1.0, 3.0], [0.0, 2.0]])
FRAME = ([2.0, -2.0], [20.0, 16.0])
THESIS = {"eps": 0.1, "classical_boxes": 10337, "thick_boxes": 2744}


def thick_model() -> ThickFunction:
    """``⟦f⟧`` of Eq. A.43: ``[fᵢ⁻]`` and ``[fᵢ⁺]`` are the min and max of the inclusions of the two ends."""
    ends = Function(lambda x: [x[0] * exp(-x[1] * t) for t in T.ravel()], n=2)  # (t₁⁻, t₁⁺, t₂⁻, ...)

    def ev(lo: np.ndarray, hi: np.ndarray) -> ThickIntervalArray:
        e = ends.eval((lo, hi))
        a, b = (e.lo[:, 0::2], e.hi[:, 0::2]), (e.lo[:, 1::2], e.hi[:, 1::2])
        return ThickIntervalArray(*arith.minimum(a, b), *arith.maximum(a, b), check=False)

    return ThickFunction.from_evaluator(2, ev)


def run(eps: float = 0.1, out: str | Path | None = None) -> dict:
    """ThickSivia and classical Sivia at ``eps`` (thesis: ε = 0.1; 2744 vs 10337 boxes)."""
    f = thick_model()
    t = time.perf_counter()
    p = thick_sivia(FRAME, f, Y, eps=eps)
    s = time.perf_counter() - t
    t = time.perf_counter()
    pc = thick_sivia(FRAME, f, Y, eps=eps, penumbra=False)
    sc = time.perf_counter() - t
    res = {"eps": eps, "boxes": p.n_boxes, "bisections": p.bisections, "seconds": s,
           "classical_boxes": pc.n_boxes, "classical_seconds": sc, "clear_area": p.clear_area,
           "penumbra_area": p.penumbra_area, "dark_area": p.dark_area, "boundary_area": p.boundary_area,
           "classical_boundary_area": pc.boundary_area, "thesis": THESIS}  # fmt: skip
    if out is not None:
        from digslam.observer.paving.draw import new_figure

        fig, axes = new_figure(2, 1, size=4.5)
        pc.draw(axes[0], FRAME, f"classical: {pc.n_boxes} boxes")
        p.draw(axes[1], FRAME, f"ThickSivia: {p.n_boxes} boxes")
        for ax in axes:
            ax.set_xlabel("x₁"), ax.set_ylabel("x₂")
        res["figure"] = str(save_figure(fig, out, "a5_test_case3_parameter_estimation.png"))
    return res


def main(argv: list[str] | None = None) -> dict:
    a = parser(__doc__, eps=0.1).parse_args(argv)
    r = run(a.eps, a.out)
    report(r)
    return r


if __name__ == "__main__":
    main()
