"""Paver benchmark: Ex. 2.7 (ring) and Ex. 2.6 (three rings) at ε = 0.1, 0.01, 0.001, ours vs codac 2.

codac runs in a subprocess (importing it switches this process to upward rounding). The last line is
``ratio_vs_codac=<our time / codac time>``, the worst case over the runs. Both cut boxes at 0.49 of their
largest side (codac's default; ``--ratio 0.5`` for the thesis's midpoint), so the pavings are comparable
box for box: the ring's are identical. ``--kappa K`` paves ours with ``cut="grid", max_volume=K ε²``
instead (see :func:`pave`). ``--quick``: ε = 0.05 only, one repeat (a smoke run).

Before the comparison, the costs behind three choices of the library (issue #37), ours only:

* ``qinter_exact_over_relaxed``: time of paving the points in 5 of 8 rings with :class:`SepQInter`'s
  exact box q-intersection (the default) over the coordinate-wise one (``exact=False``), and the
  boundary areas of both (``qinter_exact_area``, ``qinter_relaxed_area``);
* ``sepproj_fixpoint_call_over_once``: one :class:`SepProj` call with ``fixpoint=True`` over one without,
  on codac's three SepProj boxes; ``sepproj_fixpoint_pave_over_once``: the same ratio for paving the
  projection over [-2, 2]² at ε = 0.1 (the default stays off while it costs 2× or more);
* ``parabolas_subsets_*`` / ``parabolas_boxes_*``: codac's ParabolasExample paved at 0.01 with one pass of
  HC4, HC4 to a fixpoint and the centred form: connected subsets (codac: 1) and boundary boxes.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _peer import codac

from digslam.observer import Box, CtcFwdBwd, Function, Interval, SepInverse, SepQInter, pave, sqr
from digslam.observer.sets import CtcFixPoint, SepCtcPair, SepProj


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


def _best(fn, repeat: int) -> float:  # noqa: ANN001
    fn()  # warm-up (numba kernels)
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def _parabolas():  # noqa: ANN202
    """codac's ParabolasExample: the difference of two Bézier patches, and its domain."""
    pts_p = (((0, 0, 0), (1, 0, 1), (2, 0, 0)), ((0, 2, 0), (1, 2, 1), (2, 2, 0)))
    pts_q = (((0, 0, 0.55), (0, 1, -0.45), (0, 2, 0.55)), ((2, 0, 0.55), (2, 1, -0.45), (2, 2, 0.55)))

    def patch(u, v, pts):  # noqa: ANN001, ANN202
        bez = [
            [sqr(1 - u) * r[0][k] + 2 * u * (1 - u) * r[1][k] + sqr(u) * r[2][k] for k in range(3)]
            for r in pts
        ]
        return [(1 - v) * bez[0][k] + v * bez[1][k] for k in range(3)]

    f = Function(lambda a: [p - q for p, q in zip(patch(a[0], a[1], pts_p), patch(a[2], a[3], pts_q))], n=4)
    return f, Box([(0, 1), (0, 1), (0.05, 0.18), (0.05, 0.18)])


def library_choices(repeat: int) -> None:
    """Print the key lines of the module docstring's second list."""
    rng = np.random.default_rng(3)
    rings = [ring(a, b, (2.0, 3.0)) for a, b in rng.uniform(-2, 2, (8, 2))]
    frame = Box([(-6, 6), (-6, 6)])
    res = {}
    for exact in (True, False):
        sep = SepQInter(rings, 3, exact=exact)
        res[exact] = (
            _best(lambda sep=sep: pave(frame, sep, 0.02), repeat),
            pave(frame, sep, 0.02).boundary_area,
        )
    print(f"qinter_exact_over_relaxed={res[True][0] / res[False][0]:.3f} qinter_exact_area={res[True][1]:.5f} "
          f"qinter_relaxed_area={res[False][1]:.5f}")  # fmt: skip
    shell = SepInverse(Function(lambda x: 2 * sqr(x[0]) + x[0] * x[1] + x[0] * x[2] + sqr(x[1]) + sqr(x[2]), n=3),
                       Interval(0.7, 1))  # fmt: skip
    boxes = [
        Box([(0.2, 0.4), (0.0, 1.0)]),
        Box([(-0.4, -0.2), (0.95, 1.5)]),
        Box([(0.65, 0.65), (-0.5, -0.4)]),
    ]
    call, paving = {}, {}
    for fixpoint in (True, False):
        sp = SepProj(shell, [0, 1], Box([(0.1, 0.2)]), eps=1e-3, fixpoint=fixpoint)
        call[fixpoint] = _best(lambda sp=sp: [sp(b) for b in boxes], 3 * repeat)
        sp = SepProj(shell, [0, 1], Box([(0.1, 0.2)]), eps=1e-2, fixpoint=fixpoint)
        paving[fixpoint] = _best(lambda sp=sp: pave(Box([(-2, 2), (-2, 2)]), sp, 0.1), repeat)
    print(f"sepproj_fixpoint_call_over_once={call[True] / call[False]:.3f} "
          f"sepproj_fixpoint_pave_over_once={paving[True] / paving[False]:.3f}")  # fmt: skip
    f, x0 = _parabolas()
    zero = Box([(0, 0)] * 3)
    line = []
    for tag, ctc in (("natural", CtcFwdBwd(f, zero)), ("fixpoint", CtcFixPoint(CtcFwdBwd(f, zero), ratio=1e-3)),
                     ("centred", CtcFwdBwd(f, zero, centred=True))):  # fmt: skip
        p = pave(x0, SepCtcPair(None, ctc), 0.01, ratio=0.49)
        line.append(
            f"parabolas_subsets_{tag}={len(p.connected_subsets())} parabolas_boxes_{tag}={len(p.boundary[0])}"
        )
    print(" ".join(line))


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
    library_choices(args.repeat)
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
