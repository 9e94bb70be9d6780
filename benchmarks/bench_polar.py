"""Polar benchmark: one-landmark localization (§3.4.1.1) at ε = 0.01 and 0.001, ours vs codac 2.

Landmark at the origin, frame ``[-6, 4]²``, range ``[4, 6]``, bearing ``[-π/12, π/4]``.

* Ours: the minimal polar separator (:class:`SepLandmark`) and the forward-backward ``SepInverse``,
  both paved with the grid cut and ``max_volume = κ ε²`` (``--kappa``, 1/2 by default; see
  :func:`pave`), and the polar separator with the midpoint cut of Algorithm 2.1.
* codac 2, in a subprocess (importing it switches the process to upward rounding): ``SepInverse`` and
  ``SepPolarCart`` with its ``pave`` (cut at 0.49).

Prints time, bisections and undetermined area for each, then ours against codac's fewest bisections.
The last line is ``ratio_vs_codac=<our polar time / fastest codac time>``, the worst case over the ε.
``--quick``: ε = 0.05 only, one repeat (a smoke run).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _peer import codac

from digslam.observer import Box, pave
from digslam.observer.polar.sep import SepLandmark, sep_landmark_fwdbwd

FRAME = Box([(-6, 4), (-6, 4)])
ARGS = ((0.0, 0.0), (4.0, 6.0), (-np.pi / 12, np.pi / 4))


def ours(kind: str, eps: float, repeat: int, kappa: float | None = 0.5) -> dict:
    """Our paving; ``kappa`` None is the midpoint cut, else the grid cut with ``max_volume = κ ε²``."""
    sep = SepLandmark(*ARGS) if kind == "polar" else sep_landmark_fwdbwd(*ARGS)
    kw = {} if kappa is None else {"cut": "grid", "max_volume": kappa * eps**2}
    best, p = float("inf"), None
    pave(FRAME, sep, 0.1, **kw)  # warm-up: numba compiles (or loads) before timing; codac is timed warm too
    for _ in range(repeat):
        t = time.perf_counter()
        p = pave(FRAME, sep, eps, **kw)
        best = min(best, time.perf_counter() - t)
    assert p is not None
    return {"seconds": best, "bisections": p.bisections, "undetermined_area": p.boundary_area,
            "inner_area": p.inner_area}  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--eps", type=float, nargs="+", default=[0.01, 0.001])
    ap.add_argument("--repeat", type=int, default=2, help="best of N for ours")
    ap.add_argument("--kappa", type=float, default=0.5, help="grid cut with max_volume = kappa * eps**2")
    ap.add_argument("--quick", action="store_true", help="a smoke run: eps 0.05 only, one repeat")
    args = ap.parse_args()
    if args.quick:
        args.eps, args.repeat = [0.05], 1
    worst, summary = 0.0, []
    print(f"{'eps':>6} {'method':30} {'seconds':>8} {'bisections':>10} {'undetermined':>12} {'inner':>9}")
    for eps in args.eps:
        rows = {"ours polar, grid cut": ours("polar", eps, args.repeat, args.kappa),
                "ours polar, midpoint cut": ours("polar", eps, args.repeat, None),
                "ours SepInverse, grid cut": ours("fwdbwd", eps, args.repeat, args.kappa),
                "codac SepInverse": codac("polar", "inverse", eps),
                "codac SepPolarCart": codac("polar", "polar", eps)}  # fmt: skip
        for name, r in rows.items():
            print(
                f"{eps:6g} {name:30} {r['seconds']:8.4f} {r['bisections']:10d} {r['undetermined_area']:12.6f} "
                f"{r['inner_area']:9.5f}"
            )
        us = rows["ours polar, grid cut"]
        peer = min((rows["codac SepInverse"], rows["codac SepPolarCart"]), key=lambda r: r["bisections"])
        summary.append(f"eps={eps:g}: bisections {us['bisections']}/{peer['bisections']}, undetermined "
                       f"{us['undetermined_area']:.6f}/{peer['undetermined_area']:.6f}")  # fmt: skip
        fastest = min(rows["codac SepInverse"]["seconds"], rows["codac SepPolarCart"]["seconds"])
        worst = max(worst, us["seconds"] / fastest)
    print("ours polar, grid cut / codac's fewest bisections: " + "; ".join(summary))
    print(f"ratio_vs_codac={worst:.4f}")


if __name__ == "__main__":
    main()
