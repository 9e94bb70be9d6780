"""Interval core benchmark: the ring function of Ex. 2.7 on 10⁶ boxes, natural inclusion function and
forward-backward contractor, ours (one batch) vs codac 2 (box by box, in a subprocess because importing
codac switches the process to upward rounding). Last line: ``ratio_vs_codac=<ours / codac>``. ``--quick``:
10,000 boxes (a smoke run).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _peer import codac

from digslam.observer import CtcFwdBwd, Function, Interval


def boxes(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)  # the same boxes as codac_peer.eval_task
    c = rng.uniform(-1, 5, (n, 2))
    r = rng.uniform(0, 0.1, (n, 2))
    return c - r, c + r


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--boxes", type=int, default=1_000_000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true", help="a smoke run: 10,000 boxes")
    args = ap.parse_args()
    if args.quick:
        args.boxes = 10_000
    lo, hi = boxes(args.boxes, args.seed)
    f = Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2)
    ctc = CtcFwdBwd(f, Interval(1, 2.25))
    t = time.perf_counter()
    f.eval((lo, hi))
    t_eval = time.perf_counter() - t
    t = time.perf_counter()
    ctc.contract(lo, hi)
    t_ctc = time.perf_counter() - t
    c = codac("eval", args.boxes, args.seed)
    ours, theirs = t_eval + t_ctc, c["eval_seconds"] + c["ctc_seconds"]
    print(f"{args.boxes} boxes   natural inclusion: ours {t_eval:.3f} s, codac {c['eval_seconds']:.3f} s")
    print(f"{args.boxes} boxes   forward-backward:  ours {t_ctc:.3f} s, codac {c['ctc_seconds']:.3f} s")
    print(f"ratio_vs_codac={ours / theirs:.4f}")


if __name__ == "__main__":
    main()
