"""Example 5.5 (thesis §5.5.4, Algorithm 5.1, Figures 5.10–5.11): shape registration and carving.

One ellipse ``A`` (frame ``A``: centre ``(1, 1)``, semi-axes ``(2, 1)``, axis at ``0.4`` rad) is seen from
two poses linked by ``f_p(x) = (p₁, 0) + R(p₂) x`` (Eq. 5.63), ``p* = (2.8, -1)``: ``B = f_{p*}(A)``.
Each view is a ternary image (as in Example 5.1) of pixels of side ``1/32``: white pixels are proved
inside the ellipse (``X⁻``), white and grey pixels meet it (``X⁺``), black ones are proved outside.
The views are partial: view ``A`` does not see the cap ``x₁ > 1 + 1.2`` of its frame, view ``B`` the
cap ``y₁ < c_B,1 - 1.2`` of its own; there only a coarse prior is known, the ellipse lying between the
scaled ellipses ``0.8 A`` and ``1.25 A`` (same centre). Every pixel is classified with an outward
enclosure of the ellipse's quadratic form (for ``B`` through ``f_{p*}⁻¹`` with outward-rounded ``cos 1``,
``sin 1``), so ``A⁻ ⊂ A ⊂ A⁺`` and ``B⁻ ⊂ B ⊂ B⁺`` hold exactly.

SRAC (Algorithm 5.1) then contracts ``[p]₀ = [0, 4] × [-2, 2]`` with Prop. 5.4 / Remark 5.7 and carves
``[A] ⊓ f_[p]⁻¹([B])``, ``[B] ⊓ f_[p]([A])`` (Prop. 5.1–5.3). The thesis publishes
``[p] = [2.65113, 2.90901] × [-1.14117, -0.95238]``.

At the default ``eps = 0.01`` this gives ``[2.68124, 2.86759] × [-1.03643, -0.95094]`` (widths 0.186 and
0.085 against the published 0.258 and 0.189) in about 40 s of one core (the paving of ``[p]``: every
``p`` box is a projection over the images); ``--eps 0.2`` runs in about 6 s with a wider ``[p]``.

Usage: ``python examples/ex5_5_srac.py [--out DIR] [--eps EPS] [--draw-eps W]``.
"""

from __future__ import annotations

import functools
import time
from pathlib import Path
from typing import Any

import numpy as np
from _common import parser, save_figure

from digslam.observer import Function, Interval, SepImage, cos, sin
from digslam.observer.core import trig
from digslam.observer.thick.carving import SRACResult, srac
from digslam.observer.thick.sep import ThickSep

P_STAR = (2.8, -1.0)
P0 = [(0.0, 4.0), (-2.0, 2.0)]
PUBLISHED = ((2.65113, 2.90901), (-1.14117, -0.95238))
CENTER, AXES, ANGLE = (1.0, 1.0), (2.0, 1.0), 0.4
PIXEL, CUT, PRIOR = 1.0 / 32, 1.2, (0.8, 1.25)
FRAME_A = ((-2.0, 4.0), (-1.5, 3.5))
FRAME_B = ((1.25, 7.25), (-2.75, 2.25))  # around c_B ≈ (4.18, -0.30)


def q_a(x: Any) -> Any:
    """``q(x) = |M (x - c)|²``: the ellipse ``A`` is ``q <= 1`` (frame ``A``); floats define it exactly."""
    c, s = np.cos(ANGLE), np.sin(ANGLE)
    u, v = x[0] - CENTER[0], x[1] - CENTER[1]
    return ((c * u + s * v) / AXES[0]) ** 2 + ((c * v - s * u) / AXES[1]) ** 2


def q_b(y: Any) -> Any:
    """``q(f_{p*}⁻¹(y))`` with ``f_{p*}⁻¹(y) = R(1)(y - (2.8, 0))``, ``cos 1`` and ``sin 1`` enclosed."""
    one = (np.array([1.0]), np.array([1.0]))
    (c0, c1), (s0, s1) = trig.cos(one), trig.sin(one)
    c, s = Interval(c0[0], c1[0]), Interval(s0[0], s1[0])
    u, v = y[0] - P_STAR[0], y[1]
    return q_a([c * u - s * v, s * u + c * v])


def center_b() -> np.ndarray:
    """``c_B = f_{p*}(c_A)`` (floats, used only to place the unseen cap of view ``B``)."""
    c, s = np.cos(P_STAR[1]), np.sin(P_STAR[1])
    return np.array([P_STAR[0] + c * CENTER[0] - s * CENTER[1], s * CENTER[0] + c * CENTER[1]])


def ternary_image(q: Any, frame: Any, hidden: Any) -> tuple[np.ndarray, np.ndarray, tuple[float, float]]:
    """``(lower, upper, origin)``: pixels proved in the set, pixels that may meet it, top-left corner.

    ``[q]`` is enclosed on every pixel, then on the ``4 x 4`` sub-pixels of the pixels it leaves
    undecided: a pixel is inside ``q <= r²`` when ``max [q] <= r²`` on all its pieces, outside when
    ``min [q] > r²`` on all.
    """
    (x0, x1), (y0, y1) = frame
    nx, ny, k = round((x1 - x0) / PIXEL), round((y1 - y0) / PIXEL), 4
    fq = Function(q, n=2)
    hid = hidden(x0 + (np.arange(nx)[None, :] + 0.5) * PIXEL) & np.ones((ny, 1), bool)
    r_in = np.where(hid, PRIOR[0] ** 2, 1.0).ravel()  # 0.8² and 1.25² are rounded: the prior is these floats
    r_out = np.where(hid, PRIOR[1] ** 2, 1.0).ravel()

    def enclose(i: np.ndarray, j: np.ndarray, d: float) -> tuple[np.ndarray, np.ndarray]:
        lo = np.stack([x0 + j * d, y1 - (i + 1) * d], axis=1)  # exact: dyadic grid
        v = fq.eval((lo, lo + d))
        return v.lo, v.hi

    i, j = (a.ravel() for a in np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij"))
    qlo, qhi = enclose(i, j, PIXEL)
    open_ = np.flatnonzero(~(qhi <= r_in) & ~(qlo > r_out))  # undecided pixels: subdivide them
    a, b = (x.ravel() for x in np.meshgrid(np.arange(k), np.arange(k), indexing="ij"))
    si, sj = (i[open_, None] * k + a).ravel(), (j[open_, None] * k + b).ravel()
    slo, shi = enclose(si, sj, PIXEL / k)
    qlo[open_] = slo.reshape(-1, k * k).min(axis=1)
    qhi[open_] = shi.reshape(-1, k * k).max(axis=1)
    qlo, qhi, r_in, r_out = (x.reshape(ny, nx) for x in (qlo, qhi, r_in, r_out))
    return qhi <= r_in, ~(qlo > r_out), (x0, y1)


@functools.lru_cache(maxsize=1)
def thick_views() -> dict[str, Any]:
    """The two ternary images and their thick separators ``[A]``, ``[B]`` (Example 5.1), cached."""
    la, ua, oa = ternary_image(q_a, FRAME_A, lambda x: x > CENTER[0] + CUT)
    cb = center_b()
    lb, ub, ob = ternary_image(q_b, FRAME_B, lambda x: x < cb[0] - CUT)
    px = (PIXEL, PIXEL)
    a = ThickSep(SepImage(la, oa, px), SepImage(ua, oa, px))
    b = ThickSep(SepImage(lb, ob, px), SepImage(ub, ob, px))
    return {"a": a, "b": b, "images": (la, ua, oa, lb, ub, ob),
            "box_a": _bbox(la, oa), "box_b": _bbox(lb, ob)}  # fmt: skip


def _bbox(img: np.ndarray, origin: tuple[float, float]) -> list[tuple[float, float]]:
    r, c = np.nonzero(img)
    return [(origin[0] + c.min() * PIXEL, origin[0] + (c.max() + 1) * PIXEL),
            (origin[1] - (r.max() + 1) * PIXEL, origin[1] - r.min() * PIXEL)]  # fmt: skip


def f(a: Any, p: Any) -> tuple[Any, Any]:
    """``f_p(a) = (p₁, 0) + R(p₂) a`` (Eq. 5.63)."""
    c, s = cos(p[1]), sin(p[1])
    return p[0] + c * a[0] - s * a[1], s * a[0] + c * a[1]


def f_inv(b: Any, p: Any) -> tuple[Any, Any]:
    """``f_p⁻¹(b) = R(-p₂)(b - (p₁, 0))``."""
    c, s = cos(p[1]), sin(p[1])
    u = b[0] - p[0]
    return c * u + s * b[1], c * b[1] - s * u


f.q = f_inv.q = 2  # type: ignore[attr-defined]


def run(eps: float = 0.01, out: str | Path | None = None, draw_eps: float = 0.1,
        max_splits: int = 256) -> dict:  # fmt: skip
    """SRAC at paving width ``eps`` over ``[p]`` (projections over the images at ``4 eps``)."""
    views = thick_views()
    t0 = time.perf_counter()
    r: SRACResult = srac(f, f_inv, P0, views["a"], views["b"], views["box_a"], views["box_b"], eps=4 * eps,
                         eps_p=eps, eps_carve=0.05, presplit=6, max_splits=max_splits)  # fmt: skip
    seconds = time.perf_counter() - t0
    p = [(float(lo), float(hi)) for lo, hi in zip(*r.p)]
    res = {"eps": eps, "p": p, "seconds": seconds, "published": PUBLISHED, "empty": r.empty,
           "contains_p_star": all(lo <= v <= hi for (lo, hi), v in zip(p, P_STAR)),
           "width": [hi - lo for lo, hi in p], "published_width": [hi - lo for lo, hi in PUBLISHED],
           "result": r, "views": views}  # fmt: skip
    res["no_wider_than_published"] = all(w <= pw for w, pw in zip(res["width"], res["published_width"]))
    if out is not None:
        res["figure"] = str(draw(res, out, draw_eps))
    return res


def draw(res: dict, out: str | Path, draw_eps: float) -> Path:
    """Figure 5.10: (a) ``[A]``, (b) ``[B]``, (c) carved ``[A]``, (d) carved ``[B]``; Fig. 5.11 inset box."""
    from digslam.observer.paving.draw import (
        BOUNDARY_COLOR,
        CLEAR_COLOR,
        DARK_COLOR,
        PENUMBRA_COLOR,
        draw_boxes,
        new_figure,
    )
    from digslam.observer.thick.paver import thick_pave

    v, r = res["views"], res["result"]
    fig, axes = new_figure(2, 2, size=4.5)
    panels = ((v["a"], FRAME_A, "(a) [A]"), (v["b"], FRAME_B, "(b) [B]"),
              (r.a, FRAME_A, "(c) carved [A]"), (r.b, FRAME_B, "(d) carved [B]"))  # fmt: skip
    for ax, (ts, frame, title) in zip(axes.ravel(), panels):
        pv = thick_pave(([frame[0][0], frame[1][0]], [frame[0][1], frame[1][1]]), ts, draw_eps)
        for boxes, col in ((pv.clear, CLEAR_COLOR), (pv.penumbra, PENUMBRA_COLOR), (pv.dark, DARK_COLOR),
                           (pv.boundary, BOUNDARY_COLOR)):  # fmt: skip
            draw_boxes(boxes[0], boxes[1], ax=ax, color=col, linewidth=0.05)
        ax.set_xlim(*frame[0]), ax.set_ylim(*frame[1]), ax.set_aspect("equal")
        ax.set_title(title)
    (p1, p2) = res["p"]
    fig.suptitle(f"SRAC: [p] = [{p1[0]:.5f}, {p1[1]:.5f}] x [{p2[0]:.5f}, {p2[1]:.5f}]  (p* = {P_STAR})")
    return save_figure(fig, out, "ex5_5_srac.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.01, eps_help="paving width of [p] (default 0.01)")
    ap.add_argument("--draw-eps", type=float, default=0.1, help="paving width of the drawn thick sets")
    a = ap.parse_args(argv)
    r = run(a.eps, a.out, a.draw_eps)
    (p1, p2), ((q1, q2)) = r["p"], r["published"]
    print(f"Ex. 5.5 SRAC at eps={a.eps:g}: {r['seconds']:.1f} s")
    print(
        f"  [p] = [{p1[0]:.5f}, {p1[1]:.5f}] x [{p2[0]:.5f}, {p2[1]:.5f}] (widths {r['width'][0]:.5f}, "
        f"{r['width'][1]:.5f}); contains p* = {P_STAR}: {r['contains_p_star']}"
    )
    print(
        f"  published [{q1[0]}, {q1[1]}] x [{q2[0]}, {q2[1]}] (widths {r['published_width'][0]:.5f}, "
        f"{r['published_width'][1]:.5f}); no wider: {r['no_wider_than_published']}"
    )
    print(f"  wrote {r.get('figure')}")
    return r


if __name__ == "__main__":
    main()
