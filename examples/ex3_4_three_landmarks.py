"""§3.4.1.2, Table 3.1, Figure 3.7: localization from three landmarks (range and bearing to each).

``X = ∩ᵢ g_{mᵢ} ∘ π([yᵢ])`` (Eq. 3.57) with the separator ``∩ᵢ g_{mᵢ} ∘ S_{π⁻¹}^{[yᵢ]}`` (Eq. 3.58).
The paving uses the minimal polar separators; the dashed box is the first outer box of the
forward-backward separator (``SepInverse`` of range and atan2), the solid one ours: ours is never
larger. Bearings are in the world frame, in degrees in the table.

Usage: ``python examples/ex3_4_three_landmarks.py [--out DIR] [--eps EPS]``; writes
``DIR/ex3_4_three_landmarks.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer import Box, SepInter, pave
from digslam.observer.polar.sep import SepLandmark, sep_landmark_fwdbwd

#: Table 3.1: landmark position, range [m], bearing [deg]
TABLE = [((6.0, 12.0), (11.0, 12.0), (14.0, 100.0)),
         ((-2.0, -5.0), (8.0, 10.0), (-147.0, -75.0)),
         ((-3.0, 10.0), (5.0, 7.0), (63.0, 150.0))]  # fmt: skip
FRAME = Box([(-10, 10), (-10, 10)])


def separators(kind: str) -> SepInter:
    make = SepLandmark if kind == "polar" else sep_landmark_fwdbwd
    return SepInter(*(make(m, r, np.deg2rad(b)) for m, r, b in TABLE))


def run(eps: float = 0.05, out: str | Path | None = None) -> dict:
    """First outer boxes of both separators, then the paving with ours (and with forward-backward)."""
    res: dict = {"eps": eps, "pavings": {}}
    for kind in ("polar", "fwdbwd"):
        sep = separators(kind)
        _, xout = sep(FRAME)
        t = time.perf_counter()
        p = pave(FRAME, sep, eps)
        res[kind] = {"first_outer_box": (xout.lo.tolist(), xout.hi.tolist()),
                     "first_outer_area": float(np.prod(xout.hi - xout.lo)), "inner_area": p.inner_area,
                     "boundary_area": p.boundary_area, "bisections": p.bisections,
                     "seconds": time.perf_counter() - t}  # fmt: skip
        res["pavings"][kind] = p
    if out is not None:
        res["png"] = draw(res, out)
    return res


def draw(res: dict, out: str | Path) -> Path:
    from digslam.observer.paving.draw import draw_paving, new_figure

    fig, ax = new_figure(size=6)
    p = res["pavings"]["polar"]
    draw_paving(
        p,
        ax,
        frame=FRAME,
        linewidth=0.1,
        title=f"minimal polar separators: {p.bisections} bisections, ε = {res['eps']:g}",
    )
    for kind, style in (("polar", "k-"), ("fwdbwd", "w--")):
        (a, b), (c, d) = res[kind]["first_outer_box"]
        ax.plot([a, c, c, a, a], [b, b, d, d, b], style, lw=1.5, label=f"first outer box, {kind}")
    ax.legend(loc="lower left", fontsize=7)
    return save_figure(fig, out, "ex3_4_three_landmarks.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.01)
    args = ap.parse_args(argv)
    r = run(args.eps, args.out)
    print(f"§3.4.1.2 (Table 3.1) at eps={r['eps']:g}")
    for k in ("polar", "fwdbwd"):
        v = r[k]
        lo, hi = v["first_outer_box"]
        print(
            f"  {k:7s}: first outer box [{lo[0]:.3f}, {hi[0]:.3f}]×[{lo[1]:.3f}, {hi[1]:.3f}] "
            f"(area {v['first_outer_area']:.3f}); inner {v['inner_area']:.4f}, undetermined "
            f"{v['boundary_area']:.4f}, {v['bisections']} bisections, {v['seconds']:.2f} s"
        )
    print(f"  wrote {r['png']}")
    return r


if __name__ == "__main__":
    main()
