"""Paver benchmark: Ex. 2.7 (ring) and Ex. 2.6 (three rings) at ε = 0.1, 0.01, 0.001, ours vs codac 2.

codac runs in a subprocess (importing it switches this process to upward rounding). The last line is
``ratio_vs_codac=<our time / codac time>``, the worst case over the runs. Both cut boxes at 0.49 of their
largest side (codac's default; ``--ratio 0.5`` for the thesis's midpoint), so the pavings are comparable
box for box: the ring's are identical. ``--kappa K`` paves ours with ``cut="grid", max_volume=K ε²``
instead (see :func:`pave`). ``--quick``: ε = 0.05 only, one repeat (a smoke run).
"""

from __future__ import annotations

import argparse
import time

from _peer import codac

from digslam.observer import Box, Function, Interval, SepInverse, pave


def ring(cx: float, cy: float, r: tuple[float, float]) -> SepInverse:
    return SepInverse(Function(lambda x: (x[0] - cx) ** 2 + (x[1] - cy) ** 2), Interval(r[0] ** 2, r[1] ** 2))


def problem(name: str):  # noqa: ANN201
    if name == "ring":  # Ex. 2.7, Eq. 2.60
        return Box([(-1, 5), (-0.5, 5.5)]), ring(2, 2.5, (1, 1.5))
    s1, s2, s3 = ring(1, 3, (3, 6)), ring(4, 2, (1, 5)), ring(-3, -3, (3, 4))  # Table 2.1
    return Box([(-10, 10), (-10, 10)]), (s1 & s2) | (s3 & ~s1)  # Eq. 2.56


def ours(name: str, eps: float, repeat: int, ratio: float, kappa: float | None = None) -> dict:
    x0, sep = problem(name)
    kw = {} if kappa is None else {"cut": "grid", "max_volume": kappa * eps**2}
    pave(x0, sep, 0.5, ratio=ratio)  # warm-up: numba compiles (or loads) its kernels on the first call
    best, p = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        p = pave(x0, sep, eps, ratio=ratio, **kw)
        best = min(best, time.perf_counter() - t)
    assert p is not None
    return {"seconds": best, "boundary_boxes": len(p.boundary[0]), "undetermined_area": p.boundary_area,
            "bisections": p.bisections}  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--eps", type=float, nargs="+", default=[0.1, 0.01, 0.001])
    ap.add_argument("--problems", nargs="+", default=["ring", "ex26"])
    ap.add_argument("--repeat", type=int, default=3, help="best of N for ours")
    ap.add_argument(
        "--ratio",
        type=float,
        default=0.49,
        help="bisection ratio (default 0.49, codac's own cut, so both pavers build the same tree)",
    )
    ap.add_argument("--kappa", type=float, default=None, help="ours with cut='grid', max_volume=kappa*eps**2")
    ap.add_argument("--quick", action="store_true", help="a smoke run: eps 0.05 only, one repeat")
    args = ap.parse_args()
    if args.quick:
        args.eps, args.repeat = [0.05], 1
    worst = 0.0
    print(f"{'problem':8} {'eps':>6} | {'ours s':>8} {'boxes':>7} {'undet.':>9} | "
          f"{'codac s':>8} {'boxes':>7} {'undet.':>9} | ratio")  # fmt: skip
    for name in args.problems:
        for eps in args.eps:
            a, c = ours(name, eps, args.repeat, args.ratio, args.kappa), codac("pave", name, eps)
            ratio = a["seconds"] / c["seconds"]
            worst = max(worst, ratio)
            print(f"{name:8} {eps:6g} | {a['seconds']:8.4f} {a['boundary_boxes']:7d} {a['undetermined_area']:9.5f} | "
                  f"{c['seconds']:8.4f} {c['boundary_boxes']:7d} {c['undetermined_area']:9.5f} | {ratio:.3f}")  # fmt: skip
    print(f"ratio_vs_codac={worst:.4f}")


if __name__ == "__main__":
    main()
