"""§3.4.1.1, Figure 3.6: localization from one landmark, minimal polar separator vs forward-backward.

The landmark is at the origin, the robot sees it at range ``[4, 6]`` and bearing ``[-π/12, π/4]``
(world frame); the feasible set ``X = {x | m - x ∈ π([y])}`` (Eq. 3.54) is a pie of area
``(6² - 4²)/2 · π/3 = 10π/3``, paved in ``X0 = [-6, 4]²``. Left: the minimal separator
``g_m ∘ S_{π⁻¹}`` (Eq. 3.56, :class:`SepLandmark`); right: ``SepInverse`` of
``x ↦ (|m - x|, atan2(m - x))``, the classical forward-backward separator.

The chapter's claim (the minimal separator needs fewer bisections) depends on where the paver cuts. The
figure uses the policy that fits a minimal separator, ``pave(..., cut="grid", max_volume=ε²/2)``: every
cut falls on one grid of cells just under ``ε``, and fat boundary boxes keep being cut. With the default
policy (each box cut at the middle of its widest side) the claim fails at small ``ε``: the minimal
separator contracts every box to the pie's exact hull, so boxes of arbitrary sizes are cut at their own
middles, the cuts of neighbouring boxes do not line up and more slivers straddle the two arcs and the two
rays than with forward-backward, whose looser boxes stay closer to the halving grid of ``X0``. Both counts
are printed (and returned under ``"default_cut"``).

Usage: ``python examples/ex3_4_one_landmark.py [--out DIR] [--eps EPS]``; writes
``DIR/ex3_4_one_landmark.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer import Box, pave
from digslam.observer.polar.sep import SepLandmark, sep_landmark_fwdbwd

LANDMARK = (0.0, 0.0)
RANGE = (4.0, 6.0)
BEARING = (-np.pi / 12, np.pi / 4)
FRAME = Box([(-6, 4), (-6, 4)])
EXACT_AREA = 0.5 * (RANGE[1] ** 2 - RANGE[0] ** 2) * (BEARING[1] - BEARING[0])


def _stats(p, first, seconds: float) -> dict:
    return {"inner_area": p.inner_area, "boundary_area": p.boundary_area, "outer_area": p.outer_area,
            "bisections": p.bisections, "seconds": seconds, "first_outer_box": first,
            "first_outer_area": float(np.prod(np.asarray(first[1]) - np.asarray(first[0])))}  # fmt: skip


def run(eps: float = 0.01, out: str | Path | None = None, default_cut: bool = True) -> dict:
    """Pave the pie with both separators at ``eps`` (grid policy); draw Figure 3.6 into ``out`` when given.

    With ``default_cut`` the bisections of the default policy (midpoint cuts) are measured too.
    """
    seps = {
        "polar": SepLandmark(LANDMARK, RANGE, BEARING),
        "fwdbwd": sep_landmark_fwdbwd(LANDMARK, RANGE, BEARING),
    }
    res: dict = {"eps": eps, "exact_area": EXACT_AREA, "pavings": {}}
    for name, sep in seps.items():
        _, xout = sep(FRAME)  # the first outer box, before any bisection
        t = time.perf_counter()
        p = pave(FRAME, sep, eps, cut="grid", max_volume=eps**2 / 2)
        res[name] = _stats(p, (xout.lo.tolist(), xout.hi.tolist()), time.perf_counter() - t)
        res["pavings"][name] = p
        if default_cut:
            res.setdefault("default_cut", {})[name] = pave(FRAME, sep, eps).bisections
    if out is not None:
        res["png"] = draw(res, out)
    return res


def draw(res: dict, out: str | Path) -> Path:
    from digslam.observer.paving.draw import draw_paving, new_figure

    fig, axes = new_figure(ncols=2, size=5)
    for ax, (name, label) in zip(axes, (("polar", "minimal polar separator"), ("fwdbwd", "forward-backward")),
                                 strict=True):  # fmt: skip
        p, r = res["pavings"][name], res[name]
        draw_paving(
            p,
            ax,
            frame=FRAME,
            linewidth=0.1,
            title=f"{label}\n{r['bisections']} bisections (grid cuts), undetermined {r['boundary_area']:.3f}",
        )
        (a, b), (c, d) = r["first_outer_box"]
        ax.plot([a, c, c, a, a], [b, b, d, d, b], "k--", lw=1.2)  # first outer box
    fig.suptitle(f"Fig. 3.6: one landmark, [y] = [4,6]×[-π/12, π/4], ε = {res['eps']:g}")
    return save_figure(fig, out, "ex3_4_one_landmark.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.01)
    args = ap.parse_args(argv)
    r = run(args.eps, args.out)
    print(f"§3.4.1.1 at eps={r['eps']:g}: exact area 10π/3 = {r['exact_area']:.4f}")
    for k in ("polar", "fwdbwd"):
        v = r[k]
        print(
            f"  {k:7s}: first outer box area {v['first_outer_area']:.3f}, inner {v['inner_area']:.4f}, "
            f"undetermined {v['boundary_area']:.4f}, {v['bisections']} bisections, {v['seconds']:.2f} s"
        )
    d = r["default_cut"]
    print(
        f"  policy cut='grid', max_volume=eps²/2: polar {r['polar']['bisections']} < forward-backward "
        f"{r['fwdbwd']['bisections']} bisections, as §3.4.1.1 claims"
    )
    print(
        f"  default midpoint cut: polar {d['polar']} vs forward-backward {d['fwdbwd']} bisections: "
        "likely because the minimal separator's exact hulls are cut at their own middles, so the cuts of "
        "neighbouring boxes do not line up and more slivers straddle the pie's arcs and rays"
    )
    print(f"  wrote {r['png']}")
    return r


if __name__ == "__main__":
    main()
