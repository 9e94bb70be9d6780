"""Static map-based laser localization with outliers (thesis §2.6.2, Eq. 2.84–2.86, Figures 2.23–2.24).

The map ``M`` is the free space of a non-convex room with a pillar (a polygon with a hole, separator
:class:`SepPolygon`). A robot at an unknown position ``x`` (known heading ``θ = 0``) measures 56 ranges
``d_i ∈ [d̃_i - 0.1, d̃_i + 0.1]`` in directions ``α_i`` (exact ray casting against the map's edges, plus
uniform errors of amplitude ``--error``, 0.05 m by default, inside the ±0.1 m bound the observer assumes);
15 of them are outliers (random wrong values). With ``u_i = (cos α_i, sin α_i)``,
``a_i = x + d_i⁻ u_i`` and ``b_i = x + d_i⁺ u_i``, measurement ``i`` gives (Eq. 2.84–2.85)

    X_i = f_i⁻⁻¹(M) ∩ f_i⁺⁻¹(~M),     S_i = f_i⁻⁻¹(S_M) ∩ f_i⁺⁻¹(~S_M),

and the position is in the q-relaxed intersection of the ``X_i`` with ``q = 15`` (Eq. 2.86).

Soundness. ``a_i ∈ M`` always holds for a correct measurement (the ray is free up to the true range),
but ``b_i ∉ M`` needs the obstacle hit to be at least ``d_i⁺ - d_i`` (up to 0.2 m) thick along the ray: a
ray grazing a corner can leave the obstacle and re-enter the free space before ``b_i``. The default
(``sound=True``) therefore widens the outer part only: ``S_i = f_i⁻⁻¹(S_M) ∩ (f_i⁺⁻¹(~S_M) ∪ S_i^∂)``
where ``S_i^∂`` is the (inner-less) separator ``{identity, C}`` of
``{x | ∃ r ∈ [d_i⁻, d_i⁺], x + r u_i ∈ ∂M}``,
``C`` the forward-backward contractor of ``x + r u_i`` with ``r`` an interval constant into the polygon
boundary contractor. Every correct measurement's set then contains the true position unconditionally
(the segment ``[a_i, b_i]`` meets ``∂M`` at the true impact), while the inner approximation is the
thesis's. ``sound=False`` runs Eq. 2.85 as written.

Usage: ``python examples/localization_laser.py [--out DIR] [--eps EPS] [--seed S] [--thesis]``;
writes ``DIR/localization_laser.png`` (Figures 2.23 and 2.24 side by side).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer import (
    Box,
    CtcPolygonBoundary,
    Function,
    Interval,
    Sep,
    SepInverse,
    SepPolygon,
    SepQInter,
    pave,
)

#: the room (outer ring, non-convex) and a pillar (hole); the free space M lies between them
ROOM = np.array([(0.0, 0.0), (10.0, 0.0), (10.0, 5.0), (7.0, 5.0), (7.0, 8.0), (3.5, 8.0), (3.5, 6.5),
                 (2.0, 6.5), (2.0, 8.0), (0.0, 8.0)])  # fmt: skip
PILLAR = np.array([(4.0, 2.5), (5.5, 2.5), (5.5, 4.0), (4.0, 4.0)])
RINGS = [ROOM, PILLAR]
TRUTH = np.array([2.3, 2.1])
N_MEAS, N_OUTLIERS, NOISE = 56, 15, 0.1
#: amplitude of the simulated range errors (uniform), inside the guaranteed bound NOISE
ERROR = 0.05
FRAME = Box([(0.0, 10.0), (0.0, 8.0)])


def edges(rings: list[np.ndarray] = RINGS) -> tuple[np.ndarray, np.ndarray]:
    """All polygon edges as ``(a, b)`` arrays ``(E, 2)``."""
    return np.concatenate(rings), np.concatenate([np.roll(r, -1, axis=0) for r in rings])


def ray_cast(p: np.ndarray, alpha: np.ndarray, rings: list[np.ndarray] = RINGS) -> np.ndarray:
    """Exact range (float) from ``p`` to the nearest edge in each direction ``alpha`` (``inf`` if none)."""
    a, b = edges(rings)
    u = np.column_stack([np.cos(alpha), np.sin(alpha)])[:, None]  # (K, 1, 2)
    e = (b - a)[None]  # (1, E, 2)
    w = (a - p)[None]

    def cross(v, z):
        return v[..., 0] * z[..., 1] - v[..., 1] * z[..., 0]

    den = cross(u, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = cross(w, e) / den  # along the ray
        s = cross(w, u) / den  # along the edge
    ok = (den != 0) & (t > 0) & (s >= 0) & (s <= 1)
    return np.where(ok, t, np.inf).min(axis=1)


def point_in_map(pts: np.ndarray, rings: list[np.ndarray] = RINGS) -> np.ndarray:
    """Even-odd point test (floats) for the free space M."""
    a, b = edges(rings)
    x, y = pts[:, 0, None], pts[:, 1, None]
    crosses = (a[:, 1] > y) != (b[:, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xi = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    return (crosses & (x < xi)).sum(axis=1) % 2 == 1


def simulate(seed: int = 1, truth: np.ndarray = TRUTH, error: float = ERROR) -> dict:
    """56 directions, exact ranges, uniform errors in ±``error`` (≤ 0.1, the bound the observer uses) and
    15 outliers (wrong by more than 0.5 m)."""
    if not 0 <= error < NOISE:
        raise ValueError(f"error: must lie in [0, {NOISE}), got {error}")
    rng = np.random.default_rng(seed)
    alpha = 2 * np.pi * np.arange(N_MEAS) / N_MEAS
    d_true = ray_cast(truth, alpha)
    d = d_true + rng.uniform(-error, error, N_MEAS)
    outliers = np.sort(rng.choice(N_MEAS, N_OUTLIERS, replace=False))
    for k in outliers:
        while True:  # a wrong value: short returns (people, clutter) or long ones (glass, reflections)
            v = rng.uniform(0.3, 12.0)
            if abs(v - d_true[k]) > 0.5:
                d[k] = v
                break
    return {
        "alpha": alpha,
        "d_true": d_true,
        "d": d,
        "d_lo": d - NOISE,
        "d_hi": d + NOISE,
        "outliers": outliers,
    }


class SepNoInner(Sep):
    """The complement-less separator ``{identity, C}`` of a contractor: nothing is proved inside."""

    def __init__(self, ctc) -> None:
        self.ctc, self.n = ctc, ctc.n

    def separate(self, lo: np.ndarray, hi: np.ndarray):
        return (lo.copy(), hi.copy()), self.ctc.contract(lo, hi)


def _translate(r, c: float, s: float) -> Function:
    """``x ↦ x + r (c, s)``; ``r`` a number or an Interval constant."""
    return Function(lambda x: (x[0] + r * c, x[1] + r * s))


def measurement_separators(meas: dict, sound: bool = True) -> list[Sep]:
    """``S_i`` for every measurement (Eq. 2.85, widened outward when ``sound``)."""
    s_m = SepPolygon(RINGS)
    boundary = SepNoInner(CtcPolygonBoundary(RINGS))
    seps = []
    for al, lo, hi in zip(meas["alpha"], meas["d_lo"], meas["d_hi"], strict=True):
        c, s = float(np.cos(al)), float(np.sin(al))
        near = SepInverse(_translate(float(lo), c, s), s_m)  # a_i ∈ M
        far = SepInverse(_translate(float(hi), c, s), ~s_m)  # b_i ∉ M
        if sound:
            far = far | SepInverse(_translate(Interval(lo, hi), c, s), boundary)
        seps.append(near & far)
    return seps


def run(
    eps: float = 0.01, out: str | Path | None = None, seed: int = 1, sound: bool = True, error: float = ERROR
) -> dict:
    """Simulate, pave the q-relaxed intersection at ``eps``; draw Figures 2.23–2.24 into ``out``."""
    meas = simulate(seed, error=error)
    inl = np.setdiff1d(np.arange(N_MEAS), meas["outliers"])
    u = np.column_stack([np.cos(meas["alpha"]), np.sin(meas["alpha"])])
    a_pts = TRUTH + meas["d_lo"][:, None] * u
    b_pts = TRUTH + meas["d_hi"][:, None] * u
    thesis_ok = point_in_map(a_pts) & ~point_in_map(b_pts)  # truth ∈ X_i of Eq. 2.84 (point test)
    sep = SepQInter(measurement_separators(meas, sound), q=N_OUTLIERS)
    t0 = time.perf_counter()
    p = pave(FRAME, sep, eps)
    seconds = time.perf_counter() - t0
    xp_lo = np.concatenate([p.inner[0], p.boundary[0]])
    xp_hi = np.concatenate([p.inner[1], p.boundary[1]])
    in_xplus = bool(((xp_lo <= TRUTH) & (TRUTH <= xp_hi)).all(axis=1).any())
    hull = (xp_lo.min(axis=0), xp_hi.max(axis=0)) if len(xp_lo) else (np.full(2, np.nan), np.full(2, np.nan))
    res = {
        "eps": eps, "seed": seed, "sound": sound, "truth": TRUTH.copy(), "measurements": meas,
        "inliers_consistent_eq_2_84": int(thesis_ok[inl].sum()), "n_inliers": len(inl),
        "inner_area": p.inner_area, "boundary_area": p.boundary_area, "n_inner": len(p.inner[0]),
        "n_boundary": len(p.boundary[0]), "bisections": p.bisections, "truth_in_outer": in_xplus,
        "hull_lo": hull[0], "hull_hi": hull[1], "seconds": seconds, "paving": p,
    }  # fmt: skip
    if out is not None:
        res["png"] = draw(p, meas, out)
    return res


def draw(p, meas: dict, out: str | Path) -> Path:
    from digslam.observer.paving.draw import draw_boxes, draw_polygon, new_figure

    fig, (a, b) = new_figure(ncols=2, size=6)
    for ax in (a, b):
        draw_polygon(ROOM, ax, edgecolor="k", facecolor="0.85", linewidth=1.5, zorder=0)
        draw_polygon(PILLAR, ax, edgecolor="k", facecolor="w", linewidth=1.5, zorder=0)
        ax.set_aspect("equal")
        ax.set_xlim(-0.5, 10.5)
        ax.set_ylim(-0.5, 8.5)
    u = np.column_stack([np.cos(meas["alpha"]), np.sin(meas["alpha"])])
    outl = np.zeros(N_MEAS, dtype=bool)
    outl[meas["outliers"]] = True
    for k in range(N_MEAS):
        end = TRUTH + meas["d"][k] * u[k]
        style = dict(color="r", linestyle="--", linewidth=0.8) if outl[k] else dict(color="b", linewidth=0.6)
        a.plot([TRUTH[0], end[0]], [TRUTH[1], end[1]], **style)
        seg = TRUTH + np.outer([meas["d_lo"][k], meas["d_hi"][k]], u[k])
        a.plot(seg[:, 0], seg[:, 1], "-", color="k" if not outl[k] else "r", linewidth=2.0)
    a.plot(*TRUTH, "ko", markersize=6)
    a.set_title(f"Fig. 2.23: {N_MEAS} ranges ±{NOISE} m, {N_OUTLIERS} outliers (dashed)")
    if len(p.boundary[0]):
        draw_boxes(*p.boundary, b, color="0.65", edgecolor="none", autoscale=False)
    if len(p.inner[0]):
        draw_boxes(*p.inner, b, color="0.2", edgecolor="none", autoscale=False)
    b.plot(*TRUTH, "o", markerfacecolor="none", markeredgecolor="k", markersize=10)
    # inset: zoom on the solution set
    if len(p.boundary[0]) or len(p.inner[0]):
        lo = np.concatenate([p.inner[0], p.boundary[0]]).min(axis=0)
        hi = np.concatenate([p.inner[1], p.boundary[1]]).max(axis=0)
        pad = 0.25 * max(hi - lo) + 0.05
        ins = b.inset_axes([0.67, 0.6, 0.31, 0.37])  # over the empty corner outside the room
        if len(p.boundary[0]):
            draw_boxes(*p.boundary, ins, color="0.65", edgecolor="k", linewidth=0.1, autoscale=False)
        if len(p.inner[0]):
            draw_boxes(*p.inner, ins, color="0.2", edgecolor="k", linewidth=0.1, autoscale=False)
        ins.plot(*TRUTH, "o", markerfacecolor="none", markeredgecolor="r", markersize=8)
        ins.set_xlim(lo[0] - pad, hi[0] + pad)
        ins.set_ylim(lo[1] - pad, hi[1] + pad)
        ins.set_aspect("equal")
        ins.tick_params(labelsize=6)
    b.set_title(f"Fig. 2.24: q = {N_OUTLIERS}, ε = {p.eps:g}: X⁻ dark, ΔX light")
    return save_figure(fig, out, "localization_laser.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.01, seed=1)
    ap.add_argument(
        "--error",
        type=float,
        default=ERROR,
        help=f"amplitude of the simulated range errors, below the bound {NOISE} (default {ERROR})",
    )
    ap.add_argument("--thesis", action="store_true", help="Eq. 2.85 as written (no outward widening)")
    args = ap.parse_args(argv)
    r = run(args.eps, args.out, args.seed, sound=not args.thesis, error=args.error)
    print(
        f"Laser localization at eps={r['eps']:g} "
        f"(seed {r['seed']}, {'sound' if r['sound'] else 'Eq. 2.85'}): "
        f"{r['seconds']:.2f} s, {r['bisections']} bisections"
    )
    print(
        f"  {N_MEAS} ranges, outliers at {r['measurements']['outliers'].tolist()}; "
        f"{r['inliers_consistent_eq_2_84']}/{r['n_inliers']} inliers satisfy Eq. 2.84 at the truth"
    )
    print(
        f"  inner area {r['inner_area']:.5f} ({r['n_inner']} boxes), undetermined {r['boundary_area']:.5f} "
        f"({r['n_boundary']} boxes)"
    )
    print(
        f"  X+ hull [{r['hull_lo'][0]:.3f}, {r['hull_hi'][0]:.3f}] x "
        f"[{r['hull_lo'][1]:.3f}, {r['hull_hi'][1]:.3f}]; "
        f"truth {r['truth'].tolist()} in X+: {r['truth_in_outer']}"
    )
    print(f"  wrote {r['png']}")
    return r


if __name__ == "__main__":
    main()
