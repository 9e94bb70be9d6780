"""Example 2.7 (thesis §2.4.3, Eq. 2.60, Figure 2.12): paving a ring with a contractor vs a separator.

X = {x : (x1 - 2)² + (x2 - 2.5)² ∈ [1, 1.5²]}, a ring of area 5π/4. Left: the paver driven by the
forward-backward contractor ``C_X`` alone, i.e. the complement-less separator ``{identity, C_X}``
(:class:`ContractorOnly`): nothing is ever proved inside, so the whole ring stays undetermined and is
bisected down to ε. Right: the separator ``{~C_X, C_X}`` (:class:`SepInverse`), whose undetermined
boxes only cover the two circles (a 1-d accumulation set).

Usage: ``python examples/ex2_7_ring.py [--out DIR] [--eps EPS]``; writes ``DIR/ex2_7_ring.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer import Box, CtcFwdBwd, Function, Interval, Sep, SepInverse, pave

CENTRE = (2.0, 2.5)
RADII = (1.0, 1.5)
FRAME = Box([(-1, 5), (-0.5, 5.5)])
EXACT_AREA = float(np.pi * (RADII[1] ** 2 - RADII[0] ** 2))  # 5π/4


def ring_function() -> Function:
    cx, cy = CENTRE
    return Function(lambda x: (x[0] - cx) ** 2 + (x[1] - cy) ** 2)


class ContractorOnly(Sep):
    """The complement-less separator ``{identity, C}``: ``x_in`` is the box itself, ``x_out = C([x])``.

    With it the paver only removes what the contractor proves outside (Figure 2.12, left).
    """

    def __init__(self, ctc) -> None:
        self.ctc, self.n = ctc, ctc.n

    def separate(self, lo: np.ndarray, hi: np.ndarray):
        return (lo.copy(), hi.copy()), self.ctc.contract(lo, hi)


def run(eps: float = 0.05, out: str | Path | None = None) -> dict:
    """Pave the ring both ways at ``eps``; draw Figure 2.12 into ``out`` when given."""
    y = Interval(RADII[0] ** 2, RADII[1] ** 2)
    t0 = time.perf_counter()
    pc = pave(FRAME, ContractorOnly(CtcFwdBwd(ring_function(), y)), eps)
    t1 = time.perf_counter()
    ps = pave(FRAME, SepInverse(ring_function(), y), eps)
    t2 = time.perf_counter()
    res = {
        "eps": eps,
        "exact_area": EXACT_AREA,
        "contractor": {"inner_area": pc.inner_area, "boundary_area": pc.boundary_area,
                       "outer_area": pc.outer_area, "n_boxes": len(pc.boundary[0]) + len(pc.outer[0]),
                       "bisections": pc.bisections, "seconds": t1 - t0},
        "separator": {"inner_area": ps.inner_area, "boundary_area": ps.boundary_area,
                      "outer_area": ps.outer_area,
                      "n_boxes": len(ps.inner[0]) + len(ps.boundary[0]) + len(ps.outer[0]),
                      "bisections": ps.bisections, "seconds": t2 - t1},
        "pavings": (pc, ps),
    }  # fmt: skip
    if out is not None:
        res["png"] = draw(pc, ps, out)
    return res


def draw(pc, ps, out: str | Path) -> Path:
    from digslam.observer.paving.draw import draw_paving, new_figure

    fig, (a, b) = new_figure(ncols=2, size=5)
    draw_paving(
        pc,
        a,
        frame=FRAME,
        linewidth=0.1,
        title=f"contractor: undetermined {pc.boundary_area:.3f}, {pc.bisections} bisections",
    )
    draw_paving(
        ps,
        b,
        frame=FRAME,
        linewidth=0.1,
        title=f"separator: undetermined {ps.boundary_area:.3f}, {ps.bisections} bisections",
    )
    fig.suptitle(f"Ex. 2.7: ring (x1-2)² + (x2-2.5)² ∈ [1, 1.5²], ε = {ps.eps:g}")
    return save_figure(fig, out, "ex2_7_ring.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.05)
    args = ap.parse_args(argv)
    r = run(args.eps, args.out)
    print(f"Example 2.7 at eps={r['eps']:g}: exact ring area 5π/4 = {r['exact_area']:.4f}")
    for k in ("contractor", "separator"):
        v = r[k]
        print(
            f"  {k:10s}: inner {v['inner_area']:.4f}, undetermined {v['boundary_area']:.4f}, "
            f"outer {v['outer_area']:.4f}, {v['bisections']} bisections, {v['seconds']:.2f} s"
        )
    ratio = r["contractor"]["boundary_area"] / r["separator"]["boundary_area"]
    print(f"  the separator's undetermined area is {ratio:.1f}x smaller; wrote {r['png']}")
    return r


if __name__ == "__main__":
    main()
