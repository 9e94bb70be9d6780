"""Initial-localization benchmark (thesis §3.4.3, Table 3.3): 280 landmarks, 90 range-bearing detections.

Runs the scenario of ``examples/ex3_12_initial_localization.py`` (seeded) to the fixpoint of Eq. 3.70,
prints the per-iteration table (time, min / max candidates per detection, unique associations) and
the checks against the truth. The thesis reports 12 iterations at 2.4 s each (under a minute); the
last line is ``seconds=<total time of localize>`` (goal: under 10 s). ``--quick`` stops after 2 iterations
(a smoke run).
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _example() -> ModuleType:
    """``examples/ex3_12_initial_localization.py`` as a module, with ``examples/`` on ``sys.path`` as when it
    runs as a script, so that its ``from _common import ...`` finds the examples' shared helper
    ``examples/_common.py`` (as ``tests/example_loader.py`` does)."""
    if str(EXAMPLES) not in sys.path:
        sys.path.append(str(EXAMPLES))
    name = "_bench_ex3_12"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / "ex3_12_initial_localization.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


def main(argv: list[str] | None = None) -> float:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seed", type=int, default=None)
    ap.add_argument("--hull-only", action="store_true", help="the thesis's hull contractor only")
    ap.add_argument("--quick", action="store_true", help="a smoke run: the first 2 iterations only")
    args = ap.parse_args(argv)
    ex = _example()
    seed = ex.SEED if args.seed is None else args.seed
    r = ex.run(seed=seed, disjunctive=not args.hull_only, max_iter=2 if args.quick else 50)
    print(f"{'iteration':>9} {'time (s)':>9} {'min':>5} {'max':>5} {'unique':>7} {'max w(p) m':>11}")
    for h in r["result"].history:
        print(f"{h.iteration:9d} {h.seconds:9.3f} {h.min_candidates:5d} {h.max_candidates:5d} "
              f"{h.unique:7d} {h.max_width:11.2f}")  # fmt: skip
    print(f"detections={len(r['data']['k'])} unique={r['unique']} wrong={r['wrong']} "
          f"truth_inside={r['truth_inside']} full_association_at={r['full_association_at']} "
          f"iterations={r['iterations']}")  # fmt: skip
    print(f"seconds={r['seconds']:.3f}")
    return r["seconds"]


if __name__ == "__main__":
    main()
