"""Example 2.6 (thesis §2.4.2, Eq. 2.55–2.57, Figure 2.10): X = (X1 ∩ X2) ∪ (X3 \\ X1) with three rings.

The rings of Table 2.1 (centre, radius interval) each get a forward-backward separator
``S_i = {C_i, ~C_i}`` (:class:`SepInverse` of ``(x - c)² + (y - c)²`` into ``[r⁻², r⁺²]``); the separator
algebra gives ``S = (S1 & S2) | (S3 - S1)`` (Eq. 2.56), paved over ``[-10, 10]²`` (Algorithm 2.1).

Usage: ``python examples/ex2_6_three_rings.py [--out DIR] [--eps EPS]``; writes ``DIR/ex2_6_three_rings.png``
and prints the areas, checked against the exact area of X (midpoint-rule quadrature on a fine grid).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer import Box, Function, Interval, SepInverse, pave

#: Table 2.1: centre and radius interval of the rings c1, c2, c3
RINGS = (((1.0, 3.0), (3.0, 6.0)), ((4.0, 2.0), (1.0, 5.0)), ((-3.0, -3.0), (3.0, 4.0)))
FRAME = Box([(-10, 10), (-10, 10)])
RING_COLORS = ("white", "red", "cyan")  # Figure 2.10: c1 white, c2 red, c3 cyan


def sep_ring(centre: tuple[float, float], radius: tuple[float, float]) -> SepInverse:
    """Separator of the ring ``{x : ‖x - c‖ ∈ [r⁻, r⁺]}`` by forward-backward propagation."""
    cx, cy = centre
    f = Function(lambda x: (x[0] - cx) ** 2 + (x[1] - cy) ** 2)
    return SepInverse(f, Interval(radius[0] ** 2, radius[1] ** 2))


def separator():
    """``S = (S1 ∩ S2) ∪ (S3 ∩ ~S1)`` (Eq. 2.56)."""
    s1, s2, s3 = (sep_ring(c, r) for c, r in RINGS)
    return (s1 & s2) | (s3 - s1)


def in_set(pts: np.ndarray) -> np.ndarray:
    """Exact point membership in X (Eq. 2.55), for ``(N, 2)`` points."""
    inside = []
    for (cx, cy), (r1, r2) in RINGS:
        d2 = (pts[:, 0] - cx) ** 2 + (pts[:, 1] - cy) ** 2
        inside.append((d2 >= r1**2) & (d2 <= r2**2))
    x1, x2, x3 = inside
    return (x1 & x2) | (x3 & ~x1)


def exact_area(n: int = 4000) -> float:
    """Area of X by the midpoint rule on an ``n x n`` grid over the frame (error well under 1e-2)."""
    lo, hi = FRAME.lo, FRAME.hi
    h = (hi - lo) / n
    xs = lo[0] + h[0] * (np.arange(n) + 0.5)
    count = 0
    for j in range(n):  # row by row: O(n) memory
        y = lo[1] + h[1] * (j + 0.5)
        count += int(in_set(np.column_stack([xs, np.full(n, y)])).sum())
    return float(count * h[0] * h[1])


def run(eps: float = 0.05, out: str | Path | None = None, exact_n: int = 2000) -> dict:
    """Pave X at ``eps``; draw Figure 2.10 into ``out`` (a folder) when given. Returns the numbers."""
    t0 = time.perf_counter()
    p = pave(FRAME, separator(), eps)
    seconds = time.perf_counter() - t0
    res = {
        "eps": eps,
        "inner_area": p.inner_area,
        "boundary_area": p.boundary_area,
        "outer_area": p.outer_area,
        "frame_area": float(np.prod(FRAME.hi - FRAME.lo)),
        "exact_area": exact_area(exact_n),
        "ring_areas": [float(np.pi * (r2**2 - r1**2)) for _, (r1, r2) in RINGS],
        "n_inner": len(p.inner[0]),
        "n_outer": len(p.outer[0]),
        "n_boundary": len(p.boundary[0]),
        "bisections": p.bisections,
        "seconds": seconds,
        "paving": p,
    }
    if out is not None:
        res["png"] = draw(p, out)
    return res


def draw(p, out: str | Path) -> Path:
    from matplotlib.patches import Circle

    from digslam.observer.paving.draw import draw_paving, new_figure

    fig, ax = new_figure(size=7)
    draw_paving(p, ax, frame=FRAME, linewidth=0.1)
    for ((cx, cy), radii), color in zip(RINGS, RING_COLORS, strict=True):
        for r in radii:
            ax.add_patch(Circle((cx, cy), r, fill=False, edgecolor=color, linewidth=1.2, zorder=4))
    ax.set_title(f"Ex. 2.6: X = (X1 ∩ X2) ∪ (X3 \\ X1), ε = {p.eps:g}")
    return save_figure(fig, out, "ex2_6_three_rings.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.05)
    args = ap.parse_args(argv)
    r = run(args.eps, args.out, exact_n=4000)
    print(
        f"Example 2.6 at eps={r['eps']:g}: {r['n_inner']} inner, {r['n_outer']} outer, "
        f"{r['n_boundary']} boundary boxes, {r['bisections']} bisections, {r['seconds']:.2f} s"
    )
    print("  ring areas pi(r2^2 - r1^2): " + ", ".join(f"{a:.4f}" for a in r["ring_areas"]))
    print(
        f"  area(X-) = {r['inner_area']:.4f} <= area(X) = {r['exact_area']:.4f} (quadrature) "
        f"<= area(X+) = {r['inner_area'] + r['boundary_area']:.4f}; undetermined {r['boundary_area']:.4f}"
    )
    print(f"  wrote {r['png']}")
    return r


if __name__ == "__main__":
    main()
