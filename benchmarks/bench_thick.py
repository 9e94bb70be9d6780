"""ThickSivia benchmark: test-case 1 of thesis §A.5 (thick translation of a thick disk) at ε = 0.01, 0.001.

Ours: :func:`digslam.observer.thick.sivia.thick_sivia` with the closed-form thick disk
(:meth:`ThickFunction.sqdist`), frame ``[−2, 4]²``. codac 1.5.6 (``ThickPaving`` with ``ThickDisk``)
cannot be installed here, so its figures are the reference ones measured on this machine:
0.034 s / 9,543 bisections at ε = 0.01 and 0.279 s / 76,521 bisections at ε = 0.001. The times are
medians of ``--repeat`` runs (wall clock; the CPU time is printed too, the machine being shared). The last line is ``ratio_vs_codac1=<our time / 0.279>`` at ε = 0.001
(goal: ≤ 0.2 with at most 76,521 bisections). ``--quick``: one run per ε (a smoke run).
"""

from __future__ import annotations

import argparse
import statistics
import time

from digslam.observer.thick.function import ThickFunction
from digslam.observer.thick.sivia import thick_sivia

FRAME = ([-2.0, -2.0], [4.0, 4.0])
#: codac 1.5.6 reference on this machine: eps -> (seconds, bisections)
CODAC1 = {0.01: (0.034, 9543), 0.001: (0.279, 76521)}
#: thesis table (i5-2520M, pyIbex): eps -> (seconds, bisections) of "our method"
THESIS = {0.01: (0.1779, 13383), 0.001: (6.1724, 107443)}


def ours(eps: float, repeat: int) -> tuple[float, float, int]:
    """Median wall time, median CPU time and bisection count of ThickSivia on test-case 1."""
    wall, cpu, bis = [], [], -1
    for _ in range(repeat):
        f = ThickFunction.sqdist([[0.7, -0.02]], [[1.3, 0.02]])
        t, c = time.perf_counter(), time.process_time()
        p = thick_sivia(FRAME, f, [0.0, 1.0], [0.0, 4.0], eps=eps)
        wall.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
        bis = p.bisections
    return statistics.median(wall), statistics.median(cpu), bis


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=7, help="median of N runs")
    ap.add_argument("--quick", action="store_true", help="a smoke run: one run per eps")
    args = ap.parse_args()
    if args.quick:
        args.repeat = 1
    ours(0.01, 1)  # warm-up (imports, caches)
    print(
        f"{'eps':>6} | {'ours s':>8} {'cpu s':>8} {'bisect.':>8} | {'codac1 s':>8} {'bisect.':>8} | "
        f"{'thesis s':>8} {'bisect.':>8} | ratio"
    )
    ratio = float("nan")
    for eps in (0.01, 0.001):
        s, c, b = ours(eps, args.repeat)
        cs, cb = CODAC1[eps]
        ts, tb = THESIS[eps]
        print(f"{eps:6g} | {s:8.4f} {c:8.4f} {b:8d} | {cs:8.3f} {cb:8d} | {ts:8.4f} {tb:8d} | {s / cs:.3f}")
        ratio = s / cs
    print("(ratio: median wall-clock time; the CPU-time column shows the share lost to other processes)")
    print(f"ratio_vs_codac1={ratio:.4f}")


if __name__ == "__main__":
    main()
