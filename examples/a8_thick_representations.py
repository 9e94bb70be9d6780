"""Figure A.8 (thesis §A.5, test-case 1): classical, subset–supset and lower–upper thick intervals.

Test-case 1 (thick translation of the thick disk ``[D(0, 1), D(0, 2)]`` by ``[v] = [0.7, 1.3] ×
[−0.02, 0.02]``, frame ``[−2, 4]²``, ``ε = 0.1``) paved three ways, as in Figure A.8:

* left: classical Sivia (Algorithm A.1), which never proves the penumbra;
* centre: ThickSivia on the subset–supset representation (Eqs. A.13–A.15,
  :func:`~digslam.observer.thick.subset.thick_sivia_subset_supset`): while a box is wider than
  ``[v]`` (0.04 across ``x₂``) the subset bound of ``⟦f⟧([x])`` is empty and the penumbra cannot be
  proved, so undetermined boxes remain inside it;
* right: ThickSivia on lower–upper bounds (Algorithm A.2, :func:`~digslam.observer.thick.sivia.thick_sivia`).

The thesis times the three figures at 2.1 s, 0.21 s and 0.19 s (drawing included, i5-2520M).

``rule_variants`` is the study of the gap between the project's bisection counts and the thesis' table
(issue 22, item 4b): it re-paves test-case 1 with the bisection rules the thesis' code could have used
(ibex's ``LargestFirst`` cut at 0.45 of the side or 0.49 as codac, a stop on the Euclidean diameter
instead of ``w∞``). None multiplies the counts by the constant 1.40 of the thesis (see ``main``'s output
and the tests).

Usage: ``python examples/a8_thick_representations.py [--out DIR] [--eps EPS] [--rules]``; writes
``DIR/a8_thick_representations.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA
from digslam.observer.thick.function import ThickFunction
from digslam.observer.thick.sivia import ThickInverse, thick_sivia
from digslam.observer.thick.subset import thick_sivia_subset_supset

V_LO, V_HI = [0.7, -0.02], [1.3, 0.02]
FRAME = ([-2.0, -2.0], [4.0, 4.0])
Y_MINUS, Y_PLUS = [0.0, 1.0], [0.0, 4.0]  # squared radii: ‖x − v‖² ∈ [0, 1] (Y⁻), ∈ [0, 4] (Y⁺)
#: seconds per figure of Fig. A.8 in the thesis (drawing included)
THESIS_SECONDS = {"classical": 2.1, "subset_supset": 0.21, "lower_upper": 0.19}
#: thesis table of test-case 1, "our method" (lower-upper) bisections
THESIS_BISECTIONS = {0.5: 159, 0.1: 783, 0.05: 1623, 0.01: 13383, 0.005: 26823, 0.001: 107443}
LABELS = {"classical": "classical intervals", "subset_supset": "subset-supset thick intervals",
          "lower_upper": "lower-upper thick intervals"}  # fmt: skip


def thick_disk() -> ThickFunction:
    """``⟦f⟧`` of ``x ↦ ‖x − v‖²``, ``v ∈ [v]`` (exact ranges of ``f⁻``, ``f⁺`` on boxes)."""
    return ThickFunction.sqdist([V_LO], [V_HI])


def solve(kind: str, eps: float):  # noqa: ANN201
    """Pave test-case 1 with one representation; returns ``(ThickPaving, seconds)``."""
    t = time.perf_counter()
    if kind == "subset_supset":
        p = thick_sivia_subset_supset(FRAME, thick_disk(), Y_MINUS, Y_PLUS, eps=eps)
    else:
        p = thick_sivia(FRAME, thick_disk(), Y_MINUS, Y_PLUS, eps=eps, penumbra=kind == "lower_upper")
    return p, time.perf_counter() - t


def run(eps: float = 0.1, out: str | Path | None = None) -> dict:
    """The three pavings of Figure A.8 at ``eps``, their bisections, times and areas."""
    res: dict = {"eps": eps, "pavings": {}}
    for kind in ("classical", "subset_supset", "lower_upper"):
        p, s = solve(kind, eps)
        res["pavings"][kind] = p
        res[kind] = {"bisections": p.bisections, "seconds": s, "clear_area": p.clear_area,
                     "penumbra_area": p.penumbra_area, "dark_area": p.dark_area,
                     "boundary_area": p.boundary_area, "thesis_seconds": THESIS_SECONDS[kind]}  # fmt: skip
    if out is not None:
        res["png"] = draw(res, out)
    return res


def draw(res: dict, out: str | Path) -> Path:
    from digslam.observer.paving.draw import new_figure

    fig, axes = new_figure(ncols=3, size=4.5)
    for ax, kind in zip(axes, ("classical", "subset_supset", "lower_upper"), strict=True):
        r = res[kind]
        title = (f"{LABELS[kind]}\n{r['bisections']} bisections, {r['seconds'] * 1e3:.1f} ms, "
                 f"undet. {r['boundary_area']:.2f}")  # fmt: skip
        res["pavings"][kind].draw(ax, FRAME, title)
    fig.suptitle(f"Fig. A.8: test-case 1 (thick translation), ε = {res['eps']:g}")
    return save_figure(fig, out, "a8_thick_representations.png")


def _split(box: np.ndarray, n: int, ratio: float) -> np.ndarray:
    """Cut rows ``[lo | hi]`` across their (first) widest side at ``ratio`` of it."""
    w = box[:, n:] - box[:, :n]
    k = np.argmax(w, axis=1)
    rows = np.arange(box.shape[0])
    a, b = box[rows, k], box[rows, n + k]
    cut = np.minimum(np.maximum(a + ratio * (b - a), a), b)
    left, right = box.copy(), box.copy()
    left[rows, n + k] = cut
    right[rows, k] = cut
    return np.concatenate([left, right])


def bisections_with_rule(eps: float, ratio: float = 0.5, size: str = "inf") -> int:
    """ThickSivia's bisections on test-case 1 with another bisection rule (the study of item 4b).

    ``ratio``: where the widest side is cut; ``size``: ``"inf"`` stops when ``w∞ ≤ ε`` (Algorithm A.2,
    the project's rule), ``"euclid"`` when the Euclidean diameter ``‖w‖₂ ≤ ε``.
    """
    test = ThickInverse(thick_disk(), Y_MINUS, Y_PLUS)
    box = np.array([FRAME[0] + FRAME[1]], dtype=np.float64)
    n, count = 2, 0
    while box.shape[0]:
        st = test.classify(box[:, :n], box[:, n:])
        box = box[(st != CLEAR) & (st != DARK) & (st != PENUMBRA)]
        w = box[:, n:] - box[:, :n]
        big = (w.max(axis=1) if size == "inf" else np.sqrt((w * w).sum(axis=1))) > eps
        box = box[big]
        count += box.shape[0]
        box = _split(box, n, ratio)
    return count


#: the rules tried for item 4b: name -> (ratio, size)
RULES = {"widest side, midpoint, w∞ ≤ ε (project)": (0.5, "inf"),
         "cut at 0.45 (ibex LargestFirst)": (0.45, "inf"), "cut at 0.49 (codac)": (0.49, "inf"),
         "Euclidean diameter ≤ ε": (0.5, "euclid")}  # fmt: skip


def rule_variants(eps_list: tuple[float, ...] = (0.5, 0.1, 0.05, 0.01, 0.005)) -> dict:
    """Bisections of every rule in :data:`RULES` at each ``ε``, with their ratio to the thesis' count."""
    out = {}
    for name, (ratio, size) in RULES.items():
        counts = {e: bisections_with_rule(e, ratio, size) for e in eps_list}
        out[name] = {e: (c, c / THESIS_BISECTIONS[e]) for e, c in counts.items()}
    return out


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.1, eps_help="paver precision ε (default 0.1, as Fig. A.8)")
    ap.add_argument("--rules", action="store_true", help="also run the bisection-rule study (item 4b)")
    args = ap.parse_args(argv)
    r = run(args.eps, args.out)
    print(f"Figure A.8 at eps={r['eps']:g}:")
    for kind in ("classical", "subset_supset", "lower_upper"):
        v = r[kind]
        print(f"  {LABELS[kind]:30s}: {v['bisections']:5d} bisections, {v['seconds'] * 1e3:6.1f} ms "
              f"(thesis figure {v['thesis_seconds']} s), penumbra {v['penumbra_area']:.3f}, "
              f"undetermined {v['boundary_area']:.3f}")  # fmt: skip
    if args.rules:
        print("bisection rules against the thesis' table (count, count / thesis):")
        for name, row in rule_variants().items():
            print(f"  {name:42s} " + "  ".join(f"{e:g}: {c} ({q:.2f})" for e, (c, q) in row.items()))
    print(f"wrote {r['png']}")
    return r


if __name__ == "__main__":
    main()
