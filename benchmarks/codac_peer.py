"""codac 2 peer for the benchmarks, run in its own process (``python codac_peer.py TASK ARGS``).

Importing codac switches the whole process to upward rounding, which would corrupt numpy results in
the process that measures digslam: the benchmarks call this script with ``subprocess`` and read one
JSON line from its standard output.
"""

from __future__ import annotations

import json
import sys
import time


def _ring_function(codac, cx: float, cy: float):  # noqa: ANN001, ANN202
    x = codac.VectorVar(2)
    return codac.AnalyticFunction([x], codac.sqr(x[0] - cx) + codac.sqr(x[1] - cy))


def pave_task(name: str, eps: float) -> dict:
    """Pave Ex. 2.7 (``ring``) or Ex. 2.6 (``ex26``) with codac's ``pave`` and ``SepInverse``."""
    import codac

    if name == "ring":
        sep = codac.SepInverse(_ring_function(codac, 2.0, 2.5), codac.Interval(1, 2.25))
        x0 = codac.IntervalVector([[-1, 5], [-0.5, 5.5]])
    else:
        s1 = codac.SepInverse(_ring_function(codac, 1, 3), codac.Interval(9, 36))
        s2 = codac.SepInverse(_ring_function(codac, 4, 2), codac.Interval(1, 25))
        s3 = codac.SepInverse(_ring_function(codac, -3, -3), codac.Interval(9, 16))
        sep = (s1 & s2) | (s3 & ~s1)
        x0 = codac.IntervalVector([[-10, 10], [-10, 10]])
    t = time.perf_counter()
    p = codac.pave(x0, sep, eps)
    dt = time.perf_counter() - t
    bound = p.boxes(codac.PavingInOut.bound)
    inner = p.boxes(codac.PavingInOut.inner)
    return {
        "seconds": dt,
        "boundary_boxes": len(bound),
        "undetermined_area": sum(b.volume() for b in bound),
        "inner_area": sum(b.volume() for b in inner),
    }


def eval_task(n_boxes: int, seed: int) -> dict:
    """Natural inclusion and forward-backward contraction of the ring function, box after box."""
    import codac
    import numpy as np

    rng = np.random.default_rng(seed)
    c = rng.uniform(-1, 5, (n_boxes, 2))
    r = rng.uniform(0, 0.1, (n_boxes, 2))
    boxes = [codac.IntervalVector([[a - u, a + u], [b - v, b + v]]) for (a, b), (u, v) in zip(c, r)]
    f = _ring_function(codac, 2.0, 2.5)
    t = time.perf_counter()
    for b in boxes:
        f.eval(b)
    t_eval = time.perf_counter() - t
    ctc = codac.CtcInverse(f, codac.Interval(1, 2.25))
    t = time.perf_counter()
    for b in boxes:
        ctc.contract(b)
    t_ctc = time.perf_counter() - t
    return {"eval_seconds": t_eval, "ctc_seconds": t_ctc}


def polar_task(kind: str, eps: float) -> dict:
    """One-landmark localization (§3.4.1.1): landmark at the origin, range [4, 6], bearing [-π/12, π/4],
    frame [-6, 4]², paved with ``SepInverse`` of (range, atan2) (``inverse``) or ``SepPolarCart`` (``polar``)."""
    import math

    import codac

    x0 = codac.IntervalVector([[-6, 4], [-6, 4]])
    if kind == "inverse":
        x = codac.VectorVar(2)  # m - x = -x = π(ρ, θ)
        f = codac.AnalyticFunction([x], codac.vec(codac.sqrt(codac.sqr(x[0]) + codac.sqr(x[1])),
                                                  codac.atan2(-x[1], -x[0])))  # fmt: skip
        sep = codac.SepInverse(f, codac.IntervalVector([[4, 6], [-math.pi / 12, math.pi / 4]]))
    else:  # the pie of x = -π(ρ, θ): bearings shifted by π
        pie = codac.IntervalVector([[4, 6], [-math.pi / 12 + math.pi, math.pi / 4 + math.pi]])
        sep = codac.SepPolarCart(codac.SepWrapper_IntervalVector(pie))
    t = time.perf_counter()
    p = codac.pave(x0, sep, eps)
    dt = time.perf_counter() - t
    count = [0]

    def visit(node) -> bool:  # noqa: ANN001
        count[0] += 0 if node.is_leaf() else 1
        return True

    p.tree().visit(visit)
    bound = p.boxes(codac.PavingInOut.bound)
    inner = p.boxes(codac.PavingInOut.inner)
    return {
        "seconds": dt,
        "bisections": count[0],
        "boundary_boxes": len(bound),
        "undetermined_area": sum(b.volume() for b in bound),
        "inner_area": sum(b.volume() for b in inner),
    }


if __name__ == "__main__":
    task = sys.argv[1]
    if task == "pave":
        out = pave_task(sys.argv[2], float(sys.argv[3]))
    elif task == "eval":
        out = eval_task(int(sys.argv[2]), int(sys.argv[3]))
    elif task == "polar":
        out = polar_task(sys.argv[2], float(sys.argv[3]))
    else:
        raise SystemExit(f"codac_peer: unknown task {task!r} (pave or eval)")
    print(json.dumps(out))
