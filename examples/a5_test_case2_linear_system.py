"""Test-case 2 of thesis §A.5 (Eq. A.40, Figure A.9): tolerable and united solution sets.

``[A] x ∈ [b]`` with ``[A] = ([2, 4], [−2, 0]; [−1, 1], [2, 4])`` and ``[b] = [−1, 1] × [0, 2]``. The
thick function ``x ↦ [A] x`` (:meth:`ThickFunction.linear`) inverted on the thin set ``[b]`` gives the
thick set ``[X⁻, X⁺]`` whose lower bound is the tolerable solution set ``{x | [A] x ⊂ [b]}`` and whose
upper bound is the united solution set ``{x | ∃A ∈ [A], A x ∈ [b]}``. The exact areas are computed by
clipping, orthant by orthant, the polygons of the Oettli–Prager inequalities
``|A_c x − b_c| ≤ Δ|x| + δ`` (united) and ``|A_c x − b_c| + Δ|x| ≤ δ`` (tolerable).

Usage: ``python examples/a5_test_case2_linear_system.py [--out DIR] [--eps EPS]``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, report, save_figure

from digslam.observer.thick.function import ThickFunction
from digslam.observer.thick.sivia import thick_sivia

A_LO = np.array([[2.0, -2.0], [-1.0, 2.0]])
A_HI = np.array([[4.0, 0.0], [1.0, 4.0]])
B = np.array([[-1.0, 1.0], [0.0, 2.0]])
FRAME = ([-2.5, -2.0], [4.5, 4.0])  # contains X⁺ (checked by exact_sets: its bounding box)


def _clip(poly: np.ndarray, a: np.ndarray, c: float) -> np.ndarray:
    """Sutherland–Hodgman: keep the part of a convex polygon ``(k, 2)`` where ``a·x ≤ c``."""
    if len(poly) == 0:
        return poly
    s = poly @ a - c
    nxt, s_nxt = np.roll(poly, -1, axis=0), np.roll(s, -1)
    pts = []
    for p, q, sp, sq in zip(poly, nxt, s, s_nxt, strict=True):  # a few vertices, not boxes
        if sp <= 0:
            pts.append(p)
        if sp * sq < 0:
            pts.append(p + (q - p) * (sp / (sp - sq)))
    return np.array(pts).reshape(-1, 2)


def _area(poly: np.ndarray) -> float:
    if len(poly) < 3:
        return 0.0
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def exact_sets() -> dict:
    """Polygons (per orthant) of the tolerable and united solution sets and their areas."""
    ac, da = (A_LO + A_HI) / 2, (A_HI - A_LO) / 2
    bc, db = B.mean(axis=1), (B[:, 1] - B[:, 0]) / 2
    big = 100.0
    polys: dict[str, list[np.ndarray]] = {"tolerable": [], "united": []}
    for sx in (-1.0, 1.0):
        for sy in (-1.0, 1.0):
            ds = np.diag([sx, sy])
            for kind, sign in (("tolerable", 1.0), ("united", -1.0)):
                poly = np.array([[-big, -big], [big, -big], [big, big], [-big, big]])
                poly = _clip(_clip(poly, np.array([-sx, 0.0]), 0.0), np.array([0.0, -sy]), 0.0)
                for i in range(2):  # ±(A_c x − b_c) + sign·Δ|x| ≤ δ
                    for pm in (1.0, -1.0):
                        poly = _clip(poly, pm * ac[i] + sign * da[i] @ ds, db[i] + pm * bc[i])
                polys[kind].append(poly)
    out = {k: float(sum(_area(p) for p in v)) for k, v in polys.items()}
    pts = np.concatenate([p for p in polys["united"] if len(p)])
    out["united_bbox"] = (pts.min(axis=0).tolist(), pts.max(axis=0).tolist())
    out["polygons"] = polys
    return out


def thick_linear() -> ThickFunction:
    """``⟦f⟧`` of ``x ↦ A x``, ``A ∈ [A]`` (Eq. A.40)."""
    return ThickFunction.linear(A_LO, A_HI)


def run(eps: float = 0.01, out: str | Path | None = None) -> dict:
    """Pave ``[X⁻, X⁺]`` at ``eps`` (thesis: ε = 0.01, < 0.4 s) and compare with the exact areas."""
    f = thick_linear()
    t = time.perf_counter()
    p = thick_sivia(FRAME, f, B, eps=eps)
    s = time.perf_counter() - t
    pc = thick_sivia(FRAME, f, B, eps=eps, penumbra=False)
    ex = exact_sets()
    res = {"eps": eps, "seconds": s, "bisections": p.bisections, "boxes": p.n_boxes,
           "clear_area": p.clear_area, "penumbra_area": p.penumbra_area, "dark_area": p.dark_area,
           "boundary_area": p.boundary_area, "classical_bisections": pc.bisections,
           "tolerable_area": ex["tolerable"], "united_area": ex["united"],
           "united_bbox": ex["united_bbox"]}  # fmt: skip
    if out is not None:
        from digslam.observer.paving.draw import draw_polygon, new_figure

        fig, ax = new_figure(1, 1, size=5.0)
        p.draw(ax, FRAME, f"Eq. A.40: tolerable ⊂ united solution set, ε = {eps}")
        for poly in ex["polygons"]["tolerable"] + ex["polygons"]["united"]:
            if len(poly) >= 3:
                draw_polygon(poly, ax, edgecolor="w", linewidth=0.6)
        ax.axhline(0, color="w", lw=0.5), ax.axvline(0, color="w", lw=0.5)
        res["figure"] = str(save_figure(fig, out, "a5_test_case2_linear_system.png"))
    return res


def main(argv: list[str] | None = None) -> dict:
    a = parser(__doc__, eps=0.01).parse_args(argv)
    r = run(a.eps, a.out)
    report(r)
    return r


if __name__ == "__main__":
    main()
