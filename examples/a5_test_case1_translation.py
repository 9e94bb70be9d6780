"""Test-case 1 of thesis §A.5 (Figure A.8 and its table): thick translation of a thick disk.

``⟦Y⟧ = [Y⁻, Y⁺]`` with ``Y⁻``, ``Y⁺`` the disks of centre ``(0, 0)`` and radii ``r⁻ = 1``, ``r⁺ = 2``;
``[f](x) = x − [v]`` with ``[v] = [0.7, 1.3] × [−0.02, 0.02]``; frame ``[−2, 4] × [−2, 4]``. Pointwise
``X⁻ = {x | x − [v] ⊂ Y⁻} = Y⁻ ⊖ [v]`` and ``X⁺ = {x | (x − [v]) ∩ Y⁺ ≠ ∅} = Y⁺ ⊕ [v]`` (Remark A.4).
Since ``Yᵢ`` are disks, the tests are written on the squared norm: ``‖x − v‖² ∈ [0, 1]`` for
``Y⁻`` and ``∈ [0, 4]`` for ``Y⁺``, with the exact thick inclusion of ``x ↦ ‖x − v‖²``, ``v ∈ [v]``
(:meth:`ThickFunction.sqdist`). The classical method (Algorithm A.1) uses the same enclosures without
the penumbra test.

Why the thesis' counts are higher (issue 22, item 5). The project's counts are 0.712× the thesis' at
every ``ε ≤ 0.05`` (119/565/1161/9539/19109/76517 against 159/783/1623/13383/26823/107443) because
the exact test above leaves only the boxes that straddle ``∂X⁻`` or ``∂X⁺``. Remark A.2 says that in
the test cases ``Y⁺`` "is made with boxes": the thesis' code (pyibex ``ThickTranslateInPaving``)
tests the translated box against a precomputed paving of ``⟦Y⟧``, whose own band of undetermined
boxes widens the band of ``⟦X⟧``. :class:`PavedDiskTest` (opt-in: ``run(..., y_paving=r)``,
``--y-paving R``) redoes the tests against a paving of ``⟦Y⟧`` at ``ε_Y = r·ε`` over a square frame,
with the sound bounds: ``Y⁻`` by its inner boxes, ``Y⁺`` by its outer boxes, and the penumbra proved
only from boxes proved inside ``Y⁺`` and proved outside ``Y⁻``. Bisections (count / thesis):

========================  ============  ============  =============  ==============  ==============
Y paving                  ε = 0.5       ε = 0.1       ε = 0.05       ε = 0.01        ε = 0.005
========================  ============  ============  =============  ==============  ==============
none (exact, default)     119 (0.748)   565 (0.722)   1161 (0.715)   9539 (0.713)    19109 (0.712)
[−2, 4]², ε_Y = ε         174 (1.094)   859 (1.097)   1926 (1.187)   14321 (1.070)   29118 (1.086)
[−2, 4]², ε_Y = ε/2       149 (0.937)   765 (0.977)   1525 (0.940)   12106 (0.905)   24335 (0.907)
[−2, 2]², ε_Y = ε         167 (1.050)   782 (0.999)   1534 (0.945)   16076 (1.201)   32613 (1.216)
[−2, 2]², ε_Y = ε/2       160 (1.006)   667 (0.852)   1452 (0.895)   12971 (0.969)   26032 (0.971)
[−3, 3]², ε_Y = ε         163 (1.025)   873 (1.115)   1934 (1.192)   15237 (1.139)   30855 (1.150)
[−3, 3]², ε_Y = ε/2       147 (0.925)   764 (0.976)   1509 (0.930)   12562 (0.939)   23219 (0.866)
[−2.5, 2.5]², ε_Y = ε     164 (1.031)   842 (1.075)   1598 (0.985)   16896 (1.262)   35857 (1.337)
[−2, 2]², ε_Y = ε/16      129           583           1187           (slow)          (slow)
========================  ============  ============  =============  ==============  ==============

A paving of ``⟦Y⟧`` at ``ε_Y ∈ [ε/2, ε]`` thus gives counts of the thesis' size (0.85× to 1.34×), and
the paving over the outer frame ``[−2, 4]²`` brackets the thesis' count at every ``ε`` (``ε_Y = ε/2``
below it, ``ε_Y = ε`` above; at ``ε = 0.001``, ``ε_Y = ε`` gives 113453, 1.056×), while a fine
paving (``ε/16``) falls back to the exact counts. But no variant reproduces the thesis within a
few percent at every ``ε``: each fluctuates by ±10 % with the way its grid meets the circles, where
the thesis/project ratio is constant to 0.5 % (0.7153, 0.7128, 0.7124, 0.7122 for ``ε ≤ 0.05``).
So a paved ``⟦Y⟧`` explains the size of the gap but, as modelled here, not the thesis' figures; a
constant ratio points to a rule that scales with the boxes of ``⟦X⟧`` alone (the exact pyibex test,
``ThickPaving::Intersect`` with its projection heuristics, and the thesis' ``Y`` frame are not known).

Usage: ``python examples/a5_test_case1_translation.py [--out DIR] [--eps EPS] [--classical-min-eps E]
[--y-paving R]``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, report, save_figure

from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA
from digslam.observer.thick.function import ThickFunction
from digslam.observer.thick.paver import ThickPaving, thick_pave
from digslam.observer.thick.sivia import thick_sivia

V_LO, V_HI = [0.7, -0.02], [1.3, 0.02]
R_MINUS, R_PLUS = 1.0, 2.0
FRAME = ([-2.0, -2.0], [4.0, 4.0])
EPS_TABLE = (0.5, 0.1, 0.05, 0.01, 0.005, 0.001)
#: thesis table of test-case 1: eps -> (classical bisections, our-method bisections)
THESIS = {0.5: (195, 159), 0.1: (2215, 783), 0.05: (8043, 1623), 0.01: (470407, 13383),
          0.005: (1867707, 26823), 0.001: (29722487, 107443)}  # fmt: skip


def thick_disk() -> ThickFunction:
    """``⟦f⟧`` of ``x ↦ ‖x − v‖²``, ``v ∈ [v]`` (exact ranges of ``f⁻``, ``f⁺`` on boxes)."""
    return ThickFunction.sqdist([V_LO], [V_HI])


def solve(eps: float, penumbra: bool = True) -> tuple[ThickPaving, float]:
    """ThickSivia (or classical Sivia when ``penumbra=False``) at ``eps``; returns the paving and seconds."""
    f = thick_disk()
    t = time.perf_counter()
    p = thick_sivia(FRAME, f, [0.0, R_MINUS**2], [0.0, R_PLUS**2], eps=eps, penumbra=penumbra)
    return p, time.perf_counter() - t


def _cum(mask: np.ndarray) -> np.ndarray:
    """Summed-area table of a 2-d mask, padded with a zero row and column."""
    c = np.zeros((mask.shape[0] + 1, mask.shape[1] + 1), np.int32)
    c[1:, 1:] = mask.cumsum(0, dtype=np.int32).cumsum(1, dtype=np.int32)
    return c


def _rect(c: np.ndarray, i1: np.ndarray, j1: np.ndarray, i2: np.ndarray, j2: np.ndarray) -> np.ndarray:
    """Number of marked cells in ``[i1, j1) × [i2, j2)`` from the summed-area table ``c``."""
    return c[j1, j2] - c[i1, j2] - c[j1, i2] + c[i1, i2]


class PavedDiskTest:
    """Opt-in test of Test-case 1 against a paving of ``⟦Y⟧`` (Remark A.2), for :func:`thick_pave`.

    ``⟦Y⟧ = [D(0, 1), D(0, 2)]`` is paved over the square ``y_frame`` by midpoint bisection of the widest
    side down to ``w∞ ≤ y_eps``. Its finest level is the grid of squares of side ``s`` (the frame's width
    halved until ``≤ y_eps``), and its leaves that meet a circle are exactly the grid cells that meet it
    (every ancestor of a box that straddles a circle straddles it), so the grid with exact labels is that
    paving; the lattice is extended past the frame, where the labels are known. For a box ``[x]``:

    * clear: every cell that meets ``[x] − [v]`` is inside ``Y⁻`` (inner boxes of ``Y⁻``);
    * dark: every cell that meets ``[x] − [v]`` is outside ``Y⁺`` (outer boxes of ``Y⁺``);
    * penumbra: for every ``x ∈ [x]``, ``x − [v]`` meets a cell inside ``Y⁺`` and a cell outside ``Y⁻``.
      The cells met by ``x − [v]`` contain ``L = ⌈w([v])/s⌉`` consecutive cells from the one that holds
      ``x − v⁺``, so it suffices that every such window of ``L₁ × L₂`` cells, for the cells met by
      ``[x] − v⁺``, holds one (sound, and exact but for the first window).

    Index bounds are widened by ``1e-9`` cell against rounding. Not a library test: the study of the
    thesis' bisection counts (see the module docstring).
    """

    n = 2

    def __init__(self, y_eps: float, y_frame: tuple[float, float] = (-2.0, 4.0)) -> None:
        o, w = float(y_frame[0]), float(y_frame[1] - y_frame[0])
        if not (w > 0 and y_eps > 0):
            raise ValueError(f"y_frame, y_eps: expected a proper frame and y_eps > 0, got {y_frame}, {y_eps}")
        s = w
        while s > y_eps:
            s /= 2
        self.s, self.o = s, o
        vlo, vhi = np.asarray(V_LO), np.asarray(V_HI)
        lo_y = min(FRAME[0]) - float(vhi.max()) - 2 * s  # every [x] − [v] for [x] in FRAME
        hi_y = max(FRAME[1]) - float(vlo.min()) + 2 * s
        self.i0 = int(np.floor((lo_y - o) / s))
        nc = int(np.ceil((hi_y - o) / s)) - self.i0
        e = o + s * np.arange(self.i0, self.i0 + nc + 1)
        a, b = e[:-1], e[1:]
        mn = np.where(a > 0, a, np.where(b < 0, b, 0.0)) ** 2
        mx = np.maximum(a * a, b * b)
        dmin, dmax = mn[:, None] + mn[None, :], mx[:, None] + mx[None, :]  # squared distance range
        self.c_in_lower, self.c_out_upper = _cum(dmax <= R_MINUS**2), _cum(dmin >= R_PLUS**2)
        self.L = [int(np.ceil((vhi[d] - vlo[d]) / s)) for d in range(2)]
        ii = np.arange(nc)
        j1, j2 = np.minimum(ii + self.L[0], nc), np.minimum(ii + self.L[1], nc)
        # window maps: the L₁ × L₂ window from cell (i, j) holds a cell inside Y⁺ / outside Y⁻
        self.c_win_upper = _cum(_rect(_cum(dmax <= R_PLUS**2), ii[:, None], j1[:, None], ii, j2) > 0)
        self.c_win_lower = _cum(_rect(_cum(dmin >= R_MINUS**2), ii[:, None], j1[:, None], ii, j2) > 0)

    def _first(self, a: np.ndarray) -> np.ndarray:
        return np.floor((a - self.o) / self.s - 1e-9).astype(np.int64) - self.i0

    def _last(self, b: np.ndarray) -> np.ndarray:
        return np.ceil((b - self.o) / self.s + 1e-9).astype(np.int64) - self.i0

    def classify(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """``int8`` codes (:data:`CLEAR`, :data:`DARK`, :data:`PENUMBRA`, ``0``) of boxes ``[lo, hi]``."""
        vlo, vhi = np.asarray(V_LO), np.asarray(V_HI)
        a1, b1 = self._first(lo[:, 0] - vhi[0]), self._last(hi[:, 0] - vlo[0])
        a2, b2 = self._first(lo[:, 1] - vhi[1]), self._last(hi[:, 1] - vlo[1])
        size = (b1 - a1) * (b2 - a2)
        clear = _rect(self.c_in_lower, a1, b1, a2, b2) == size
        dark = _rect(self.c_out_upper, a1, b1, a2, b2) == size
        f1, l1 = self._first(lo[:, 0] - vhi[0]), self._last(hi[:, 0] - vhi[0])
        f2, l2 = self._first(lo[:, 1] - vhi[1]), self._last(hi[:, 1] - vhi[1])
        nw = (l1 - f1) * (l2 - f2)
        meets = _rect(self.c_win_upper, f1, l1, f2, l2) == nw
        pen = meets & (_rect(self.c_win_lower, f1, l1, f2, l2) == nw)
        st = np.where(pen, PENUMBRA, 0).astype(np.int8)
        st[dark] = DARK
        st[clear] = CLEAR
        return st


def solve_paved(eps: float, y_paving: float = 1.0,
                y_frame: tuple[float, float] = (-2.0, 4.0)) -> tuple[ThickPaving, float]:  # fmt: skip
    """ThickSivia at ``eps`` against the paving of ``⟦Y⟧`` at ``ε_Y = y_paving·eps`` over ``y_frame²``
    (:class:`PavedDiskTest`); returns the paving and seconds (paving of ``⟦Y⟧`` included)."""
    t = time.perf_counter()
    p = thick_pave(FRAME, PavedDiskTest(y_paving * eps, y_frame), eps)
    return p, time.perf_counter() - t


def run(eps: float = 0.1, out: str | Path | None = None, classical_min_eps: float = 0.01,
        table: tuple[float, ...] = EPS_TABLE, y_paving: float | None = None) -> dict:  # fmt: skip
    """Bisection table over ``table`` (classical only for ``eps >= classical_min_eps``) and Fig. A.8.

    ``y_paving`` (opt-in, default ``None``): also count ThickSivia's bisections against the paving of
    ``⟦Y⟧`` at ``ε_Y = y_paving·ε`` over ``[−2, 4]²`` (:func:`solve_paved`), as rows ``paved``, ``paved_s``.
    """
    rows = []
    for e in table:
        p, s = solve(e)
        row = {
            "eps": e,
            "ours": p.bisections,
            "ours_s": s,
            "thesis_ours": THESIS.get(e, (None, None))[1],
            "thesis_classical": THESIS.get(e, (None, None))[0],
            "classical": None,
            "classical_s": None,
        }
        if e >= classical_min_eps:
            pc, sc = solve(e, penumbra=False)
            row["classical"], row["classical_s"] = pc.bisections, sc
        if y_paving is not None:
            pp, sp = solve_paved(e, y_paving)
            row["paved"], row["paved_s"] = pp.bisections, sp
        rows.append(row)
    p, _ = solve(eps)
    pc, _ = solve(eps, penumbra=False)
    res = {"eps": eps, "table": rows, "clear_area": p.clear_area, "penumbra_area": p.penumbra_area,
           "dark_area": p.dark_area, "boundary_area": p.boundary_area, "bisections": p.bisections,
           "classical_bisections": pc.bisections, "classical_boundary_area": pc.boundary_area}  # fmt: skip
    if out is not None:
        from digslam.observer.paving.draw import new_figure

        fig, axes = new_figure(2, 1, size=4.5)
        pc.draw(axes[0], FRAME, f"classical intervals (ε = {eps})")
        p.draw(axes[1], FRAME, f"thick intervals, ThickSivia (ε = {eps})")
        res["figure"] = str(save_figure(fig, out, "a5_test_case1_translation.png"))
    return res


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.1)
    ap.add_argument(
        "--classical-min-eps",
        type=float,
        default=0.005,
        help="the classical method is run only down to this eps (0.001 needs ~30M bisections)",
    )
    ap.add_argument(
        "--y-paving",
        type=float,
        default=None,
        metavar="R",
        help="also test against a paving of ⟦Y⟧ at ε_Y = R·ε (the thesis' Remark A.2)",
    )
    a = ap.parse_args(argv)
    r = run(a.eps, a.out, a.classical_min_eps, y_paving=a.y_paving)
    print(f"{'eps':>6} | {'classical':>10} {'thesis':>10} | {'ours':>8} {'thesis':>8} | "
          f"{'ours s':>7} {'class. s':>8}")  # fmt: skip
    for row in r["table"]:
        cl = "-" if row["classical"] is None else str(row["classical"])
        cs = "-" if row["classical_s"] is None else f"{row['classical_s']:.3f}"
        print(f"{row['eps']:6g} | {cl:>10} {row['thesis_classical']:>10} | {row['ours']:>8} "
              f"{row['thesis_ours']:>8} | {row['ours_s']:7.4f} {cs:>8}"
              + (f" | paved Y: {row['paved']}" if "paved" in row else ""))  # fmt: skip
    report(r, skip=("table",))
    return r


if __name__ == "__main__":
    main()
