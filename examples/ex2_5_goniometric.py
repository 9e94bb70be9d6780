"""Example 2.5 (thesis §2.4.1.3, Eqs. 2.42–2.45, Figures 2.7–2.8): goniometric localization from two beacons.

The robot measures the bearings ``θ₁ = 45°`` and ``θ₂ = 120°`` (angle of ``mᵢ − x`` with the x-axis),
each within ``Δθ = 3°``. Each beacon gives (Eq. 2.43)
``Xᵢ = {x | ∃θᵢ ∈ [θᵢ], (m¹ᵢ − x₁) sin θᵢ − (m²ᵢ − x₂) cos θᵢ = 0}`` and ``X = X₁ ∩ X₂`` (Eq. 2.44).

The thesis gives ``[x₀] = [−4, 6]²`` but not the beacons (they are only drawn in Figure 2.7): we put the
robot at ``x* = (1, 1)``, ``m₁ = x* + 4√2 (cos 45°, sin 45°) = (5, 5)`` and
``m₂ = x* + 4 (cos 120°, sin 120°) = (−1, 1 + 2√3)``, both inside ``[x₀]``.

* Figure 2.8a–c: ``Cᵢ`` is the forward-backward contractor of Eq. 2.43 (``θᵢ`` enters as an interval
  constant), ``C = C₂ ∘ C₁`` (Eq. 2.45), iterated to its fixpoint ``C^∞``; the boxes after ``C₁``, after
  ``C₂`` and after each pass are returned and drawn.
* Figure 2.8d: the paver driven by ``C^∞`` alone (the complement-less separator ``{identity, C^∞}``):
  nothing is proved inside, so the whole set is covered by undetermined boxes of width ``ε``.
* The reformulation of Chapter 3 (promised at the end of §2.4.1.3): each ``Xᵢ`` as the cone
  ``{x | mᵢ − x ∈ π([0, ∞) × [θᵢ])}`` and its minimal separator (:class:`SepLandmark`), whose
  intersection proves an inner approximation.

``X`` is the quadrilateral cut by the four rays ``θᵢ ± Δθ`` around ``x*`` (the double cones of Eq. 2.43
meet nowhere else in ``[x₀]``); its exact vertices and area are computed by clipping, to check the
pavings against.

Usage: ``python examples/ex2_5_goniometric.py [--out DIR] [--eps EPS]``; writes ``DIR/ex2_5_goniometric.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer import Box, CtcFwdBwd, Function, Interval, Sep, SepInter, cos, pave, sin
from digslam.observer.polar.sep import SepLandmark

FRAME = Box([(-4, 6), (-4, 6)])
TRUE_POSITION = (1.0, 1.0)
BEARINGS_DEG = (45.0, 120.0)
DELTA_DEG = 3.0
BEACONS = ((5.0, 5.0), (-1.0, 1.0 + 2.0 * np.sqrt(3.0)))


def bearing_interval(i: int) -> tuple[float, float]:
    """``[θᵢ] = [θᵢ − Δθ, θᵢ + Δθ]`` in radians."""
    return float(np.deg2rad(BEARINGS_DEG[i] - DELTA_DEG)), float(np.deg2rad(BEARINGS_DEG[i] + DELTA_DEG))


def ctc_beacon(i: int) -> CtcFwdBwd:
    """``Cᵢ``: forward-backward contractor of ``(m¹ᵢ − x₁) sin θ − (m²ᵢ − x₂) cos θ = 0``, ``θ ∈ [θᵢ]``
    (Eqs. 2.42–2.43)."""
    (a, b), th = BEACONS[i], Interval(*bearing_interval(i))
    s, c = sin(th), cos(th)  # two uncertain constants (each its own node of the Function, even if equal)
    return CtcFwdBwd(Function(lambda x: (a - x[0]) * s - (b - x[1]) * c), Interval(0.0, 0.0))


class ContractorOnly(Sep):
    """The complement-less separator ``{identity, C}``: nothing is ever proved inside (Figure 2.8d)."""

    def __init__(self, ctc) -> None:  # noqa: ANN001
        self.ctc, self.n = ctc, ctc.n

    def separate(self, lo: np.ndarray, hi: np.ndarray):  # noqa: ANN201
        return (lo.copy(), hi.copy()), self.ctc.contract(lo, hi)


class CtcFix:
    """``C^∞ = C ∘ C ∘ …`` with ``C = C₂ ∘ C₁`` (Eq. 2.45), iterated until no bound moves by more than
    ``tol`` (the boxes only shrink, so this terminates)."""

    n = 2

    def __init__(self, tol: float = 1e-9, max_iter: int = 200) -> None:
        self.c1, self.c2, self.tol, self.max_iter = ctc_beacon(0), ctc_beacon(1), tol, max_iter

    def contract(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        for _ in range(self.max_iter):
            nlo, nhi = self.c2.contract(*self.c1.contract(lo, hi))
            with np.errstate(invalid="ignore"):
                moved = np.nan_to_num(np.abs(nlo - lo) + np.abs(nhi - hi), nan=0.0, posinf=0.0)
            lo, hi = nlo, nhi
            if not (moved > self.tol).any():
                break
        return lo, hi


def propagation(max_iter: int = 50, tol: float = 1e-9) -> list[dict]:
    """Figure 2.8a–c: the boxes after ``C₁`` and ``C₂`` at each pass of ``C``, from ``[x₀]`` to the
    fixpoint."""
    c1, c2 = ctc_beacon(0), ctc_beacon(1)
    lo, hi = FRAME.lo[None].copy(), FRAME.hi[None].copy()
    steps = []
    for k in range(max_iter):
        alo, ahi = c1.contract(lo, hi)
        blo, bhi = c2.contract(alo, ahi)
        steps.append({"pass": k + 1, "after_c1": (alo[0].tolist(), ahi[0].tolist()),
                      "after_c2": (blo[0].tolist(), bhi[0].tolist())})  # fmt: skip
        moved = float(np.abs(blo - lo).max() + np.abs(bhi - hi).max())
        lo, hi = blo, bhi
        if moved <= tol:
            break
    return steps


def exact_set() -> np.ndarray:
    """Vertices of ``X ∩ [x₀]`` (counter-clockwise): ``[x₀]`` clipped by the four half-planes of the cones
    ``mᵢ − x ∈ π([0, ∞) × [θᵢ])`` (apertures 6° < π: ``det(u(θᵢ⁻), mᵢ − x) ≥ 0 ≥ det(u(θᵢ⁺), mᵢ − x)``)."""
    (x0, y0), (x1, y1) = FRAME.lo, FRAME.hi
    poly = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)
    for i in range(2):
        m = np.asarray(BEACONS[i])
        for t, sign in zip(bearing_interval(i), (1.0, -1.0), strict=True):
            u = np.array([np.cos(t), np.sin(t)])

            def g(p: np.ndarray, u: np.ndarray = u, m: np.ndarray = m, sign: float = sign) -> np.ndarray:
                d = m - p
                return sign * (u[0] * d[..., 1] - u[1] * d[..., 0])  # >= 0 inside

            out = []
            for k in range(len(poly)):
                p, q = poly[k], poly[(k + 1) % len(poly)]
                gp, gq = g(p), g(q)
                if gp >= 0:
                    out.append(p)
                if (gp >= 0) != (gq >= 0):
                    out.append(p + gp / (gp - gq) * (q - p))
            poly = np.array(out)
    return poly


def polygon_area(v: np.ndarray) -> float:
    x, y = v[:, 0], v[:, 1]
    return float(0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _stats(p, seconds: float) -> dict:  # noqa: ANN001
    lo = np.concatenate([p.inner[0], p.boundary[0]])
    hi = np.concatenate([p.inner[1], p.boundary[1]])
    hull = (lo.min(axis=0).tolist(), hi.max(axis=0).tolist())
    return {"bisections": p.bisections, "seconds": seconds, "inner_area": p.inner_area,
            "boundary_area": p.boundary_area, "hull": hull}  # fmt: skip


def run(eps: float = 0.05, out: str | Path | None = None) -> dict:
    """Propagation, contractor paving and separator paving at ``eps``; Figures 2.7–2.8 into ``out``."""
    verts = exact_set()
    res: dict = {"eps": eps, "exact_vertices": verts, "exact_area": polygon_area(verts),
                 "exact_hull": (verts.min(axis=0).tolist(), verts.max(axis=0).tolist()),
                 "propagation": propagation(), "pavings": {}}  # fmt: skip
    t = time.perf_counter()
    pc = pave(FRAME, ContractorOnly(CtcFix()), eps)
    res["contractor"] = _stats(pc, time.perf_counter() - t)
    sep = SepInter(*(SepLandmark(BEACONS[i], (0.0, np.inf), bearing_interval(i)) for i in range(2)))
    t = time.perf_counter()
    ps = pave(FRAME, sep, eps)
    res["separator"] = _stats(ps, time.perf_counter() - t)
    res["pavings"] = {"contractor": pc, "separator": ps}
    res["fixpoint"] = res["propagation"][-1]["after_c2"]
    if out is not None:
        res["png"] = draw(res, out)
    return res


def draw(res: dict, out: str | Path) -> Path:
    from digslam.observer.paving.draw import draw_paving, new_figure

    fig, axes = new_figure(ncols=3, size=4.5)
    ax = axes[0]
    (x0, y0), (x1, y1) = FRAME.lo, FRAME.hi
    for i, col in ((0, "tab:blue"), (1, "tab:cyan")):  # the double cones X_i of Eq. 2.43 (Figure 2.7)
        m = np.asarray(BEACONS[i])
        for t in bearing_interval(i):
            d = 20 * np.array([np.cos(t), np.sin(t)])
            ax.plot([m[0] - d[0], m[0] + d[0]], [m[1] - d[1], m[1] + d[1]], color=col, lw=0.8)
        ax.plot(*m, "ks")
        ax.annotate(f"m{i + 1}", m, textcoords="offset points", xytext=(4, 4))
    colors = ["orange", "gold", "red"]
    for k, s in enumerate(res["propagation"]):
        (a, b), (c, d) = s["after_c2"]
        col = colors[min(k, 2)]
        lab = f"C pass {s['pass']}" if k < 2 else ("C passes ≥ 3" if k == 2 else None)
        ax.plot([a, c, c, a, a], [b, b, d, d, b], color=col, lw=1.2, label=lab)
    v = res["exact_vertices"]
    ax.fill(v[:, 0], v[:, 1], color="0.3")
    ax.plot(*TRUE_POSITION, "k.")
    ax.set_xlim(x0, x1), ax.set_ylim(y0, y1), ax.set_aspect("equal")
    ax.set_title(f"Fig. 2.7–2.8a–c: C∞ from [x0] ({len(res['propagation'])} passes)")
    ax.legend(fontsize=7, loc="lower right")
    view = Box([(-0.5, 2.5), (-0.5, 2.5)])
    for ax, name, label in ((axes[1], "contractor", "Fig. 2.8d: paving with C∞ only"),
                            (axes[2], "separator", "cones, minimal separators (Ch. 3)")):  # fmt: skip
        r = res[name]
        draw_paving(res["pavings"][name], ax, frame=view, linewidth=0.1,
                    title=f"{label}\n{r['bisections']} bisections, inner {r['inner_area']:.3f}, "
                          f"undet. {r['boundary_area']:.3f}")  # fmt: skip
        ax.fill(v[:, 0], v[:, 1], fill=False, edgecolor="k", lw=0.8)
        ax.plot(*TRUE_POSITION, "k+")
    fig.suptitle(f"Ex. 2.5: bearings 45° and 120° ± 3°, [x0] = [-4, 6]², ε = {res['eps']:g}; "
                 f"exact area {res['exact_area']:.4f}")  # fmt: skip
    return save_figure(fig, out, "ex2_5_goniometric.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.05)
    args = ap.parse_args(argv)
    r = run(args.eps, args.out)
    print(f"Example 2.5 at eps={r['eps']:g}: X is a quadrilateral of area {r['exact_area']:.4f}, hull "
          f"{np.round(r['exact_hull'], 4).tolist()}")  # fmt: skip
    for s in r["propagation"][:3]:
        print(f"  pass {s['pass']}: after C1 {np.round(s['after_c1'], 3).tolist()}, "
              f"after C2 {np.round(s['after_c2'], 3).tolist()}")  # fmt: skip
    print(f"  fixpoint after {len(r['propagation'])} passes: {np.round(r['fixpoint'], 4).tolist()}")
    for k in ("contractor", "separator"):
        v = r[k]
        print(f"  {k:10s}: {v['bisections']} bisections, inner {v['inner_area']:.4f}, undetermined "
              f"{v['boundary_area']:.4f}, {v['seconds']:.2f} s")  # fmt: skip
    print(f"  wrote {r['png']}")
    return r


if __name__ == "__main__":
    main()
