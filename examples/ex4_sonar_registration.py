"""§4.2.3 (Figure 4.3): simulating a sonar reading as a shape-registration problem.

A robot at ``(0, 0)`` in the map ``M = {x | x₁ < 5 or x₂ < 3}`` (Eq. 4.21) emits in the cone
``π/4 ± π/24``. The returned distance is ``d = sup D`` with ``D = {d | f(S₁, d) ⊂ M}`` (Eq. 4.24–4.25),
``f(x, d) = d·x`` and ``S₁`` the unit pie of Eq. 4.23. ``D`` is paved with the registration separator
``~proj_d{(S_S₁ × S_R) ∩ f⁻¹(~S_M)}`` (Eq. 4.16); then ``sup D⁻ <= d <= sup D⁺``.

Exact value: the pie of radius ``d`` reaches ``~M = {x₁ >= 5, x₂ >= 3}`` first through its lower ray
(angle ``5π/24``, where ``5 / cos θ >= 3 / sin θ``), so ``d = 5 / cos(5π/24) ≈ 6.302362``.
The thesis publishes ``d ∈ [6.2988, 6.3085]``.

Usage: ``python examples/ex4_sonar_registration.py [--out DIR] [--eps EPS]``; writes
``DIR/ex4_sonar_registration.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer import Box, Interval, IntervalArray, SepBox, pave
from digslam.observer.core import rounding, trig
from digslam.observer.sets.registration import scaling, sep_cone, sep_inclusion

#: the thesis's enclosure (Eq. 4.26)
PUBLISHED = (6.2988, 6.3085)
FRAME = Box([(0, 10)])


def exact_distance() -> tuple[float, float]:
    """An outward-rounded float enclosure of ``5 / cos(5π/24)``."""
    t = (np.array([rounding.mul_down(np.float64(5 / 24), rounding.PI_DOWN)]),
         np.array([rounding.mul_up(np.float64(5 / 24), rounding.PI_UP)]))  # fmt: skip
    # 5/24 is not a float: widen its product by one more ulp each way
    t = (rounding.next_down(t[0]), rounding.next_up(t[1]))
    c = trig.cos(t)
    return float(rounding.div_down(np.float64(5.0), c[1][0])), float(
        rounding.div_up(np.float64(5.0), c[0][0])
    )


def exact_distance_str(digits: int = 20) -> str:
    """``5 / cos(5π/24)`` to ``digits`` significant digits (mpmath when installed)."""
    try:
        import mpmath
    except ImportError:  # pragma: no cover
        return repr(5 / np.cos(5 * np.pi / 24))
    mpmath.mp.dps = digits + 5
    return mpmath.nstr(5 / mpmath.cos(5 * mpmath.pi / 24), digits)


def separators(eps: float):
    """``(S_S₁, S_M, S_D)``: the unit pie, the map and the registration separator for ``D``."""
    s1 = sep_cone((0.0, 1.0), Interval.pi() * 0.25, Interval.pi() / 24)
    s_m = ~SepBox(IntervalArray([5.0, 3.0], [np.inf, np.inf]))  # M = ~{x₁ >= 5 and x₂ >= 3}
    s_d = sep_inclusion(s1, s_m, scaling(), [(0.0, 1.0), (0.0, 1.0)], eps)
    return s1, s_m, s_d


def run(eps: float = 1e-5, out: str | Path | None = None) -> dict:
    """Pave ``D`` over ``[0, 10]`` at ``eps`` (also the projection's splitting width)."""
    _, _, s_d = separators(eps)
    t0 = time.perf_counter()
    p = pave(FRAME, s_d, eps)
    seconds = time.perf_counter() - t0
    d_lo = float(p.inner[1].max())
    d_hi = float(max(d_lo, p.boundary[1].max() if p.boundary[0].size else -np.inf))
    exact = exact_distance()
    res = {
        "eps": eps,
        "seconds": seconds,
        "d": (d_lo, d_hi),
        "width": d_hi - d_lo,
        "exact": exact,
        "exact_str": exact_distance_str(),
        "published": PUBLISHED,
        "published_width": PUBLISHED[1] - PUBLISHED[0],
        "contains_exact": d_lo <= exact[0] and exact[1] <= d_hi,
        "tighter_than_published": PUBLISHED[0] <= d_lo and d_hi <= PUBLISHED[1],
        "bisections": p.bisections,
        "separator_calls": s_d.proj.calls,
        "pairs": s_d.proj.pairs,
        "paving": p,
    }
    if out is not None:
        res["png"] = draw(res, out)
    return res


def draw(res: dict, out: str | Path) -> Path:
    from digslam.observer.paving.draw import new_figure

    fig, ax = new_figure(size=5.0)
    ax.fill([5, 12, 12, 5], [3, 3, 12, 12], hatch="//", facecolor="none", edgecolor="k", linewidth=0.5)
    for r, color, label in ((1.0, "0.6", "S₁"), (res["d"][0], "r", f"d⁻ = {res['d'][0]:.6f}")):
        th = np.linspace(5 * np.pi / 24, 7 * np.pi / 24, 50)
        ax.fill(np.r_[0, r * np.cos(th)], np.r_[0, r * np.sin(th)], color=color, alpha=0.5, label=label)
    ax.set_xlim(-0.5, 8)
    ax.set_ylim(-0.5, 8)
    ax.set_aspect("equal")
    ax.legend(loc="upper left")
    ax.set_title(f"§4.2.3: d ∈ [{res['d'][0]:.6f}, {res['d'][1]:.6f}] (thesis [6.2988, 6.3085])")
    return save_figure(fig, out, "ex4_sonar_registration.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=1e-5, eps_help="paver and projection precision (default 1e-5)")
    args = ap.parse_args(argv)
    r = run(args.eps, args.out)
    print(
        f"§4.2.3 sonar registration at eps={r['eps']:g} ({r['seconds']:.2f} s, {r['bisections']} bisections, "
        f"{r['separator_calls']} batched separator calls on {r['pairs']} (box, split) pairs)"
    )
    print(
        f"  d ∈ [{r['d'][0]:.7f}, {r['d'][1]:.7f}] (width {r['width']:.2e}); "
        f"exact 5/cos(5π/24) = {r['exact_str']}"
    )
    print(
        f"  published [{PUBLISHED[0]}, {PUBLISHED[1]}] (width {r['published_width']:.4f}); contains exact: "
        f"{r['contains_exact']}, inside the published interval: {r['tighter_than_published']}; "
        f"wrote {r['png']}"
    )
    return r


if __name__ == "__main__":
    main()
