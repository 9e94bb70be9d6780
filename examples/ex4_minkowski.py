"""Minkowski difference and sum separators (thesis §4.3, Ex. 4.1 / Figure 4.4, Ex. 4.2 / Figure 4.5).

* Ex. 4.1: ``B ⊖ A`` for the disk ``B`` of radius 5 and the ``4 × 2`` rectangle ``A`` (both centred at
  the origin), paved with ``S_B ⊖ S_A`` (Prop. 4.1, Eq. 4.28). Closed form: ``A`` is the hull of its
  corners ``c_k`` and ``B`` is convex, so ``B ⊖ A = ∩_k (B - c_k)``, four disks of radius 5.
* Ex. 4.2: ``A ⊕ B`` for a triangle ``A`` (a :class:`SepPolygon`) and a square ``B`` (a :class:`SepBox`),
  paved with ``S_A ⊕ S_B = ~(~S_B ⊖ -S_A)`` (Prop. 4.2, Eq. 4.31). Closed form: the sum of two convex
  polygons is the convex hull of the vertex sums.

Both pavings are checked against the closed forms by point membership (points of inner boxes are in
the set, points of outer boxes are not) and by area (``inner <= exact <= inner + undetermined``).

Usage: ``python examples/ex4_minkowski.py [--out DIR] [--eps EPS]``; writes ``DIR/ex4_minkowski_diff.png``
(Figure 4.4) and ``DIR/ex4_minkowski_sum.png`` (Figure 4.5).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer import Box, Function, Interval, SepBox, SepInverse, SepPolygon, pave
from digslam.observer.sets.minkowski import SepMinkowskiDiff, SepMinkowskiSum

RADIUS = 5.0
RECT = np.array([(-2.0, -1.0), (2.0, -1.0), (2.0, 1.0), (-2.0, 1.0)])  # A of Ex. 4.1, 4 × 2
TRIANGLE = np.array([(0.0, 0.0), (3.0, 0.0), (1.0, 2.0)])  # A of Ex. 4.2
SQUARE = np.array([(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)])  # B of Ex. 4.2
FRAME_DIFF = Box([(-6, 6), (-6, 6)])
FRAME_SUM = Box([(-3, 6), (-3, 5)])


def sep_diff(eps_proj: float) -> SepMinkowskiDiff:
    """``S_B ⊖ S_A`` of Ex. 4.1 (the disk's separator uses ``|x|² <= 25``, no lower bound)."""
    disk = SepInverse(Function(lambda x: x[0] ** 2 + x[1] ** 2), Interval(-np.inf, RADIUS**2))
    rect = SepBox(Box([(-2, 2), (-1, 1)]))
    return SepMinkowskiDiff(disk, rect, [(-2, 2), (-1, 1)], eps_proj)


def sep_sum(eps_proj: float) -> SepMinkowskiSum:
    """``S_A ⊕ S_B`` of Ex. 4.2."""
    a_box = np.stack([TRIANGLE.min(axis=0), TRIANGLE.max(axis=0)], axis=1)
    return SepMinkowskiSum(SepPolygon(TRIANGLE), SepBox(Box([(-1, 1), (-1, 1)])), a_box, eps_proj)


def in_diff(pts: np.ndarray) -> np.ndarray:
    """Exact membership in ``B ⊖ A`` (Ex. 4.1): every corner of ``p + A`` in the disk."""
    return (np.linalg.norm(pts[:, None, :] + RECT[None], axis=2) <= RADIUS).all(axis=1)


def diff_margin(pts: np.ndarray) -> np.ndarray:
    """``max_k |p + c_k| - 5``: negative inside ``B ⊖ A``, its absolute value bounds the distance scale."""
    return np.linalg.norm(pts[:, None, :] + RECT[None], axis=2).max(axis=1) - RADIUS


def diff_area(n: int = 200_001) -> float:
    """Area of ``B ⊖ A`` = ∩ of the disks ``|p + c_k| <= 5``, by integrating its vertical chords."""
    x = np.linspace(-RADIUS, RADIUS, n)
    ylo, yhi = np.full(n, -np.inf), np.full(n, np.inf)
    for cx, cy in RECT:
        h = np.sqrt(np.clip(RADIUS**2 - (x + cx) ** 2, 0.0, None))
        ylo, yhi = np.maximum(ylo, -cy - h), np.minimum(yhi, -cy + h)
    return float(np.trapezoid(np.clip(yhi - ylo, 0.0, None), x))


def _cross(u: np.ndarray, v: np.ndarray) -> float:
    return float(u[0] * v[1] - u[1] * v[0])


def convex_hull(pts: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull (Andrew's monotone chain)."""
    pts = np.unique(pts, axis=0)

    def half(points: np.ndarray) -> list:
        h: list = []
        for p in points:
            while len(h) >= 2 and _cross(h[-1] - h[-2], p - h[-2]) <= 0:
                h.pop()
            h.append(p)
        return h

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def sum_polygon() -> np.ndarray:
    """``A ⊕ B`` of Ex. 4.2 in closed form: the hull of the vertex sums."""
    return convex_hull((TRIANGLE[:, None, :] + SQUARE[None]).reshape(-1, 2))


def sum_margin(pts: np.ndarray, poly: np.ndarray | None = None) -> np.ndarray:
    """Signed distance-like margin to the convex polygon: ``max_k`` of the outward edge offsets."""
    poly = sum_polygon() if poly is None else poly
    a, b = poly, np.roll(poly, -1, axis=0)
    e = b - a
    nrm = np.stack([e[:, 1], -e[:, 0]], axis=1) / np.linalg.norm(e, axis=1)[:, None]  # outward (ccw ring)
    return ((pts[:, None, :] - a[None]) * nrm[None]).sum(axis=2).max(axis=1)


def in_sum(pts: np.ndarray) -> np.ndarray:
    """Exact membership in ``A ⊕ B`` (closed convex polygon)."""
    return sum_margin(pts) <= 0


def polygon_area(poly: np.ndarray) -> float:
    x, y = poly[:, 0], poly[:, 1]
    return float(abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2)


def sample_boxes(lo: np.ndarray, hi: np.ndarray, per_box: int, rng: np.random.Generator) -> np.ndarray:
    """``per_box`` uniform points in each box (flat boxes skipped)."""
    keep = (hi > lo).all(axis=1)
    lo, hi = lo[keep], hi[keep]
    u = rng.random((lo.shape[0], per_box, lo.shape[1]))
    return (lo[:, None] + u * (hi - lo)[:, None]).reshape(-1, lo.shape[1])


def check(p, member, seed: int = 0) -> dict:
    """Point-membership soundness: points of inner boxes in the set, of outer boxes not."""
    rng = np.random.default_rng(seed)
    pin, pout = sample_boxes(*p.inner, 4, rng), sample_boxes(*p.outer, 4, rng)
    return {"inner_points": len(pin), "inner_violations": int((~member(pin)).sum()),
            "outer_points": len(pout), "outer_violations": int(member(pout).sum())}  # fmt: skip


def run(eps: float = 0.05, out: str | Path | None = None, eps_proj: float | None = None) -> dict:
    """Pave Ex. 4.1 and Ex. 4.2 at ``eps`` (projection splits down to ``eps_proj``, default ``eps``)."""
    eps_proj = eps if eps_proj is None else eps_proj
    res: dict = {"eps": eps, "eps_proj": eps_proj}
    for key, sep, frame, member, area in (
        ("diff", sep_diff(eps_proj), FRAME_DIFF, in_diff, diff_area()),
        ("sum", sep_sum(eps_proj), FRAME_SUM, in_sum, polygon_area(sum_polygon())),
    ):
        t0 = time.perf_counter()
        p = pave(frame, sep, eps)
        res[key] = {
            "seconds": time.perf_counter() - t0,
            "paving": p,
            "exact_area": area,
            "inner_area": p.inner_area,
            "boundary_area": p.boundary_area,
            "bisections": p.bisections,
            "separator_calls": sep.proj.calls,
            "pairs": sep.proj.pairs,
            **check(p, member),
        }
    if out is not None:
        res["png"] = draw(res, out)
    return res


def draw(res: dict, out: str | Path) -> list[Path]:
    from digslam.observer.paving.draw import draw_paving, draw_polygon, new_figure

    paths = []
    fig, ax = new_figure(size=5.5)
    draw_paving(res["diff"]["paving"], ax, frame=FRAME_DIFF, linewidth=0.05)
    th = np.linspace(0, 2 * np.pi, 200)
    ax.plot(RADIUS * np.cos(th), RADIUS * np.sin(th), "k", linewidth=1.0)
    draw_polygon(RECT, ax, edgecolor="g", linewidth=1.2)
    ax.set_title(f"Fig. 4.4: disk(5) ⊖ rectangle 4×2, ε = {res['eps']:g}")
    paths.append(save_figure(fig, out, "ex4_minkowski_diff.png"))
    fig, ax = new_figure(size=5.5)
    draw_paving(res["sum"]["paving"], ax, frame=FRAME_SUM, linewidth=0.05)
    draw_polygon(TRIANGLE, ax, edgecolor="g", linewidth=1.2)
    draw_polygon(SQUARE, ax, edgecolor="m", linewidth=1.2)
    draw_polygon(sum_polygon(), ax, edgecolor="k", linewidth=0.8, linestyle="--")
    ax.set_title(f"Fig. 4.5: triangle ⊕ square, ε = {res['eps']:g}")
    paths.append(save_figure(fig, out, "ex4_minkowski_sum.png"))
    return paths


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.05)
    args = ap.parse_args(argv)
    r = run(args.eps, args.out)
    for key, name in (("diff", "Ex. 4.1 disk ⊖ rectangle"), ("sum", "Ex. 4.2 triangle ⊕ square")):
        v = r[key]
        print(f"{name} at eps={r['eps']:g} ({v['seconds']:.2f} s, {v['bisections']} bisections, "
              f"{v['separator_calls']} calls on {v['pairs']} pairs): inner {v['inner_area']:.4f} <= exact "
              f"{v['exact_area']:.4f} <= inner + undetermined {v['inner_area'] + v['boundary_area']:.4f}; "
              f"violations {v['inner_violations']}/{v['inner_points']} inner, "
              f"{v['outer_violations']}/{v['outer_points']} outer")  # fmt: skip
    print(f"wrote {', '.join(map(str, r['png']))}")
    return r


if __name__ == "__main__":
    main()
