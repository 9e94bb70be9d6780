"""Example 2.8 (thesis §2.4.4, Theorem 2.1, Figure 2.13): inverting a polygon separator by a rotation.

``M`` is a non-convex polygon (a "C" shape) with its boundary-based separator :class:`SepPolygon`
(§2.5.1). The rotation ``R = R_{π/4}`` about the origin gives ``R(M) = {x | R⁻¹ x ∈ M}``, so
``SepInverse(R⁻¹, S_M)`` is a separator for ``R(M)`` (Theorem 2.1); ``R(M) ∩ ~M`` is then
``SepInverse(R⁻¹, S_M) & ~S_M`` (Figure 2.13 c). ``cos π/4 = sin π/4`` enter ``R⁻¹`` as a two-float
interval enclosing the real value, so the pavings are guaranteed for the exact rotation.

Usage: ``python examples/ex2_8_rotated_polygon.py [--out DIR] [--eps EPS]``; writes
``DIR/ex2_8_rotated_polygon.png`` (panels a, b, c).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer import Box, Function, Interval, SepInverse, SepPolygon, pave

#: the non-convex polygon M (Figure 2.13 a): a "C" open towards +x
M = np.array([(-2.5, -2.0), (2.5, -2.0), (2.5, -0.8), (-1.0, -0.8), (-1.0, 0.8), (2.5, 0.8), (2.5, 2.0),
              (-2.5, 2.0)])  # fmt: skip
ANGLE = np.pi / 4
FRAME = Box([(-4, 4), (-4, 4)])


def _cos_sin_pi_4() -> Interval:
    """A two-float interval enclosing cos(π/4) = sin(π/4) = √2/2."""
    c = np.sqrt(0.5)
    return Interval(np.nextafter(c, 0.0), np.nextafter(c, 1.0))


def rotation_inverse() -> Function:
    """``R⁻¹ = R_{-π/4}``: ``x ↦ (c x1 + s x2, -s x1 + c x2)`` with ``c = s`` enclosing √2/2."""
    c = s = _cos_sin_pi_4()
    # the Expr goes first: ``Interval * Expr`` is not supported by IntervalArray.__mul__
    return Function(lambda x: (x[0] * c + x[1] * s, x[1] * c - x[0] * s))


def separators():
    """``(S_M, S_R(M), S_R(M) ∩ ~S_M)``."""
    s_m = SepPolygon(M)
    s_rm = SepInverse(rotation_inverse(), s_m)
    return s_m, s_rm, s_rm & ~s_m


def point_in_polygon(pts: np.ndarray, poly: np.ndarray = M) -> np.ndarray:
    """Even-odd point-in-polygon test (floats) for ``(N, 2)`` points."""
    a, b = poly, np.roll(poly, -1, axis=0)
    x, y = pts[:, 0, None], pts[:, 1, None]
    crosses = (a[:, 1] > y) != (b[:, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xi = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    return (crosses & (x < xi)).sum(axis=1) % 2 == 1


def distance_to_boundary(pts: np.ndarray, poly: np.ndarray = M) -> np.ndarray:
    """Euclidean distance of ``(N, 2)`` points to the polygon's edges."""
    a, b = poly[None], np.roll(poly, -1, axis=0)[None]
    p = pts[:, None]
    d = b - a
    t = np.clip(((p - a) * d).sum(-1) / (d * d).sum(-1), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * d), axis=-1).min(axis=1)


def rotate(pts: np.ndarray, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.column_stack([c * pts[:, 0] - s * pts[:, 1], s * pts[:, 0] + c * pts[:, 1]])


def polygon_area(poly: np.ndarray) -> float:
    x, y = poly[:, 0], poly[:, 1]
    return float(abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2)


def in_rm_minus_m(pts: np.ndarray) -> np.ndarray:
    """Exact-geometry membership in ``R(M) \\ M`` (points near a boundary are decided by float rounding)."""
    return point_in_polygon(rotate(pts, -ANGLE)) & ~point_in_polygon(pts)


def monte_carlo_area(n: int = 400_000, seed: int = 0) -> tuple[float, float]:
    """Area of ``R(M) \\ M`` by Monte Carlo over the frame: ``(estimate, standard error)``."""
    rng = np.random.default_rng(seed)
    pts = rng.uniform(FRAME.lo, FRAME.hi, size=(n, 2))
    frac = in_rm_minus_m(pts).mean()
    a = float(np.prod(FRAME.hi - FRAME.lo))
    return a * frac, a * float(np.sqrt(frac * (1 - frac) / n))


def run(eps: float = 0.02, out: str | Path | None = None) -> dict:
    """Pave M, R(M) and R(M) ∩ ~M at ``eps``; draw Figure 2.13 into ``out`` when given."""
    t0 = time.perf_counter()
    pavings = [pave(FRAME, s, eps) for s in separators()]
    seconds = time.perf_counter() - t0
    mc, mc_err = monte_carlo_area()
    res = {
        "eps": eps,
        "seconds": seconds,
        "polygon_area": polygon_area(M),
        "mc_area": mc,
        "mc_stderr": mc_err,
        "pavings": pavings,
    }
    for name, p in zip(("M", "RM", "RM_minus_M"), pavings, strict=True):
        res[name] = {
            "inner_area": p.inner_area,
            "boundary_area": p.boundary_area,
            "n_inner": len(p.inner[0]),
            "n_boundary": len(p.boundary[0]),
            "bisections": p.bisections,
        }
    if out is not None:
        res["png"] = draw(pavings, out)
    return res


def draw(pavings, out: str | Path) -> Path:
    from digslam.observer.paving.draw import draw_paving, draw_polygon, new_figure

    fig, axes = new_figure(ncols=3, size=4.5)
    titles = ("(a) M", "(b) R_π/4(M)", "(c) R_π/4(M) ∩ ~M")
    for ax, p, t in zip(axes, pavings, titles, strict=True):
        draw_paving(p, ax, frame=FRAME, linewidth=0.05, title=t)
        draw_polygon(M, ax, edgecolor="k", linewidth=0.8)
        draw_polygon(rotate(M, ANGLE), ax, edgecolor="w", linewidth=0.8, linestyle="--")
    fig.suptitle(f"Ex. 2.8: inversion of a polygon separator by a rotation, ε = {pavings[0].eps:g}")
    return save_figure(fig, out, "ex2_8_rotated_polygon.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.02)
    args = ap.parse_args(argv)
    r = run(args.eps, args.out)
    print(
        f"Example 2.8 at eps={r['eps']:g} ({r['seconds']:.2f} s): "
        f"area(M) = area(R(M)) = {r['polygon_area']:.4f}"
    )
    for name in ("M", "RM", "RM_minus_M"):
        v = r[name]
        print(
            f"  {name:10s}: inner {v['inner_area']:.4f}, undetermined {v['boundary_area']:.4f} "
            f"({v['n_inner']} inner, {v['n_boundary']} boundary boxes, {v['bisections']} bisections)"
        )
    print(f"  area(R(M) \\ M) by Monte Carlo: {r['mc_area']:.4f} ± {r['mc_stderr']:.4f}; wrote {r['png']}")
    return r


if __name__ == "__main__":
    main()
