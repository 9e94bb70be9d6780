"""Polar benchmark: one-landmark localization (§3.4.1.1) at ε = 0.01 and 0.001, ours vs codac 2.

Landmark at the origin, frame ``[-6, 4]²``, range ``[4, 6]``, bearing ``[-π/12, π/4]``. Ours: the
minimal polar separator (:class:`SepLandmark`) and the forward-backward ``SepInverse``; codac 2 (in a
subprocess: importing it switches the process to upward rounding): ``SepInverse`` and ``SepPolarCart``.
Prints time, bisections and undetermined area for each. The last line is
``ratio_vs_codac=<our polar time / fastest codac time>``, the worst case over the ε.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _peer import codac

from digslam.observer import Box, pave
from digslam.observer.polar_sep import SepLandmark, sep_landmark_fwdbwd

FRAME = Box([(-6, 4), (-6, 4)])
ARGS = ((0.0, 0.0), (4.0, 6.0), (-np.pi / 12, np.pi / 4))


def ours(kind: str, eps: float, repeat: int) -> dict:
    sep = SepLandmark(*ARGS) if kind == "polar" else sep_landmark_fwdbwd(*ARGS)
    best, p = float("inf"), None
    pave(FRAME, sep, 0.1)  # warm-up: numba compiles (or loads from cache) before timing; codac is timed warm too
    for _ in range(repeat):
        t = time.perf_counter()
        p = pave(FRAME, sep, eps)
        best = min(best, time.perf_counter() - t)
    assert p is not None
    return {"seconds": best, "bisections": p.bisections, "undetermined_area": p.boundary_area,
            "inner_area": p.inner_area}  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--eps", type=float, nargs="+", default=[0.01, 0.001])
    ap.add_argument("--repeat", type=int, default=2, help="best of N for ours")
    args = ap.parse_args()
    worst = 0.0
    print(f"{'eps':>6} {'method':22} {'seconds':>8} {'bisections':>10} {'undetermined':>12} {'inner':>9}")
    for eps in args.eps:
        rows = {"ours polar (SepLandmark)": ours("polar", eps, args.repeat),
                "ours SepInverse": ours("fwdbwd", eps, args.repeat),
                "codac SepInverse": codac("polar", "inverse", eps),
                "codac SepPolarCart": codac("polar", "polar", eps)}  # fmt: skip
        for name, r in rows.items():
            print(
                f"{eps:6g} {name:22} {r['seconds']:8.4f} {r['bisections']:10d} {r['undetermined_area']:12.6f} "
                f"{r['inner_area']:9.5f}"
            )
        fastest = min(rows["codac SepInverse"]["seconds"], rows["codac SepPolarCart"]["seconds"])
        worst = max(worst, rows["ours polar (SepLandmark)"]["seconds"] / fastest)
    print(f"ratio_vs_codac={worst:.4f}")


if __name__ == "__main__":
    main()
