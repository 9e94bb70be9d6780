"""§6.3.2 (Table 6.1, Figures 6.5–6.8): bathymetric inter-temporal shape SLAM (Algorithm 6.2).

An AUV at 2 m/s surveys a synthetic seabed (a seeded sum of Gaussian bumps): first a tie line along
``x = 0``, then a lawnmower of legs along ``x`` that all cross it. Its DVL gives the body-frame speed
vector and its INS the heading every 0.1 s, with errors bounded by 0.02 m/s (per component) and 0.05°.
Every 25 s the last 30 s of soundings (a swath of radius ``R`` around the track) make a local DEM on a
lattice of ``cell``-metre pixels, in the robot frame at ``x(t_i)`` (the thesis's hypothesis: no drift
inside the window, so the DEM is exact relative to the true ``x(t_i)``); a sounding error bound ``δ`` plus
the relief inside each pixel (a Taylor bound: gradient at the centre, curvature bound over the pixel) bound
``|z(m) - z_measured|`` over each pixel. The level set ``z <= h`` (``h`` the median depth) gives one
double-sided thick shape per DEM (§6.2.3.1). Algorithm 6.2 then registers every pair whose scopes may
overlap (Eq. 6.14) and propagates with ``C_-`` and ``C_d/dt``.

The thesis (Table 6.1) reports ``w([p12])`` going from 25.04 to 16.02 after one registration (``w``: the
diameter of the box, e.g. ``√(23.0² + 9.9²) = 25.04``) for ``t1 = 4 min 15 s``, ``t2 = 26 min 30 s``; here
``t1``, ``t2`` are the well-overlapping pair closest to those times. Simulation margins: the bounds given to
the observer are the noise bounds plus ``1e-9`` (the float rounding of the simulated measurements).

Usage: ``python examples/ex6_3_bathymetric_slam.py [--out DIR] [--duration S] [--seed N] [--bounds]``.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
from _common import parser, save_figure

from digslam.observer.core.boxes import width_euclid
from digslam.observer.slam.shape_registration import ThickImage, level_thick_image, register_translation
from digslam.observer.slam.shape_slam import ShapeSlamConfig, ShapeSlamResult, ctc_minus, shape_slam
from digslam.observer.tube.tube import Tube, body_velocity, ctc_deriv

DT, SPEED, V_ERR, PSI_ERR = 0.1, 2.0, 0.02, np.deg2rad(0.05)
PERIOD, WINDOW = 25.0, 30.0
PUBLISHED = (25.04, 16.02)
THESIS_T = (255.0, 1590.0, 2400.0)  # t1, t2 and the mission length (40 min)
MARGIN = 1e-9


def seabed(seed: int, n: int = 400, half: float = 400.0) -> dict[str, np.ndarray]:
    """Bumps ``z(m) = -30 + Σ A_k exp(-|m - c_k|² / 2σ_k²)`` (seeded)."""
    rng = np.random.default_rng(seed)
    return {"c": rng.uniform(-half, half, (n, 2)), "s": rng.uniform(10.0, 30.0, n),
            "a": rng.uniform(1.0, 4.0, n) * rng.choice([-1.0, 1.0], n)}  # fmt: skip


def elevation(f: dict, m: np.ndarray) -> np.ndarray:
    """``z`` at points ``m`` (…, 2)."""
    d2 = ((m[..., None, :] - f["c"]) ** 2).sum(-1)
    return -30.0 + (f["a"] * np.exp(-d2 / (2 * f["s"] ** 2))).sum(-1)


def pixel_variation(f: dict, c: np.ndarray, cell: float) -> np.ndarray:
    """Bound of ``|z(m) - z(c)|`` over the square pixels of side ``cell`` centred at ``c`` (N, 2).

    Taylor: ``|z(m) - z(c)| <= |∇z(c)|₁ e/2 + sup‖H‖ |m - c|²/2`` with ``|m - c|² <= e²/2``; for one bump
    ``‖H_k(m)‖ <= |A|/σ² · e^{-u} max(1, |2u - 1|)``, ``u = r²/2σ²``, which is at most ``|A|/σ²`` and
    decreases for ``u >= 3/2``: bounded with the smallest ``r`` over the pixel. Floats: relative slack.
    """
    d = c[:, None, :] - f["c"][None]
    s2 = f["s"][None] ** 2
    e = f["a"][None] * np.exp(-(d**2).sum(-1) / (2 * s2))
    grad = np.abs((e[..., None] * d / s2[..., None]).sum(1))
    near = np.clip(f["c"][None], c[:, None] - cell / 2, c[:, None] + cell / 2) - f["c"][None]
    u = (near**2).sum(-1) / (2 * s2)
    hess = np.abs(f["a"])[None] / s2 * np.where(u < 1.5, 1.0, np.exp(-u) * (2 * u - 1))
    return (grad.sum(1) * cell / 2 + hess.sum(1) * cell**2 / 4) * (1 + 1e-6)


def survey(leg: float, spacing: float, legs: int) -> np.ndarray:
    """Waypoints: the tie line ``x = 0`` northwards, then ``legs`` legs along ``x`` southwards."""
    y_top = (legs - 1) * spacing / 2
    pts = [(0.0, -y_top - 50.0), (0.0, y_top + 50.0), (-leg / 2, y_top)]
    for k in range(legs):
        y, xs = y_top - k * spacing, (-leg / 2, leg / 2) if k % 2 == 0 else (leg / 2, -leg / 2)
        pts += [(xs[0], y), (xs[1], y)]
    return np.array(pts)


def trajectory(wp: np.ndarray, duration: float | None) -> tuple[np.ndarray, np.ndarray]:
    """Positions at the gates and headings per slice along the waypoints at ``SPEED`` (``duration``
    None: the whole survey)."""
    seg = np.diff(wp, axis=0)
    lens = np.hypot(seg[:, 0], seg[:, 1])
    n = int(lens.sum() / SPEED / DT) if duration is None else int(round(duration / DT))
    s = np.minimum(np.arange(n) * DT * SPEED, lens.sum() - 1e-6)  # arc length at each slice start
    k = np.searchsorted(np.cumsum(lens), s, side="right")
    psi = np.arctan2(seg[k, 1], seg[k, 0])
    x = np.zeros((n + 1, 2))
    x[0] = wp[0]
    x[1:] = wp[0] + np.cumsum(DT * SPEED * np.stack([np.cos(psi), np.sin(psi)], 1), axis=0)
    return x, psi


def simulate(duration: float | None = None, seed: int = 0, bounds: bool = False, cell: float = 2.0,
             swath: float = 30.0, delta: float = 0.1, legs: int = 10, leg: float = 350.0,
             spacing: float = 50.0) -> dict[str, Any]:  # fmt: skip
    """The mission: truth, bounded inputs, local maps. ``bounds``: every noise exactly at its bound."""
    rng = np.random.default_rng(seed + 1)
    f = seabed(seed)
    x, psi = trajectory(survey(leg, spacing, legs), duration)
    n = psi.size

    def noise(b: float, shape: Any) -> np.ndarray:
        return b * (rng.choice([-1.0, 1.0], shape) if bounds else rng.uniform(-1, 1, shape))

    v_meas = np.array([SPEED, 0.0]) + noise(V_ERR, (n, 2))  # DVL, body frame
    psi_meas = psi + noise(PSI_ERR, n)
    vb, pb = V_ERR + MARGIN, PSI_ERR + MARGIN
    u_lo, u_hi = body_velocity(v_meas - vb, v_meas + vb, psi_meas - pb, psi_meas + pb)
    # re-run the truth with the true body speed (SPEED, 0) is x itself; maps every PERIOD s
    gates = np.arange(int(round(PERIOD / DT)), n + 1, int(round(PERIOD / DT)))
    h = float(np.median(elevation(f, np.random.default_rng(seed).uniform(-300, 300, (4000, 2)))))
    shapes = [local_map(f, x, k, cell, swath, delta, h, rng, bounds) for k in gates]
    return {"t": np.arange(n + 1) * DT, "x": x, "u": (u_lo, u_hi), "gates": gates, "shapes": shapes,
            "field": f, "level": h, "cell": cell, "delta": delta}  # fmt: skip


def local_map(f: dict, x: np.ndarray, k: int, cell: float, swath: float, delta: float, h: float,
              rng: np.random.Generator, bounds: bool) -> ThickImage:  # fmt: skip
    """The DEM of the last ``WINDOW`` s around gate ``k``, thresholded at ``z <= h`` (robot frame)."""
    track = x[max(0, k - int(WINDOW / DT)) : k + 1 : 10] - x[k]
    c0 = int(np.floor((track[:, 0].min() - swath) / cell)) - 1
    c1 = int(np.ceil((track[:, 0].max() + swath) / cell)) + 1
    r0 = int(np.ceil((track[:, 1].max() + swath) / cell)) + 1  # top edge (lattice index)
    r1 = int(np.floor((track[:, 1].min() - swath) / cell)) - 1
    cx = (np.arange(c0, c1) + 0.5) * cell
    cy = (r0 - np.arange(r0 - r1) - 0.5) * cell
    gx, gy = np.meshgrid(cx, cy)
    centres = np.stack([gx, gy], -1).reshape(-1, 2)
    d2 = ((centres[:, None, :] - track[None]) ** 2).sum(-1).min(1)
    scope = (d2 <= swath**2).reshape(gx.shape)
    lo, hi = centres[scope.ravel()] - cell / 2 + x[k], centres[scope.ravel()] + cell / 2 + x[k]
    # bumps farther than 6σ from the map are left out of the computed DEM; their summed value over the
    # map (at most |A| e^{-d²/2σ²}, d the distance from the bump to the map) is added to the error bound
    d = np.hypot(*np.moveaxis(np.clip(f["c"], lo.min(0), hi.max(0)) - f["c"], -1, 0))
    near = d <= 6 * f["s"]
    fn = {key: v[near] for key, v in f.items()}
    far_a, far_d, far_s = np.abs(f["a"][~near]), d[~near], f["s"][~near]
    tail = (far_a * np.exp(-(far_d**2) / (2 * far_s**2))).sum() * (1 + 1e-6)
    z = np.full(gx.shape, np.nan)
    err = np.zeros(gx.shape)
    m = int(scope.sum())
    nz = delta * (rng.choice([-1.0, 1.0], m) if bounds else rng.uniform(-1, 1, m))
    z[scope] = elevation(fn, centres[scope.ravel()] + x[k]) + nz
    err[scope] = delta + pixel_variation(fn, centres[scope.ravel()] + x[k], cell) + tail + MARGIN
    return level_thick_image(z, err, h, cell, (c0, r0), scope)


def table_pair(sim: dict, dr: Tube) -> tuple[int, int]:
    """The pair of Table 6.1: near the thesis's ``t1 = 4 min 15 s``, ``t2 = 26 min 30 s`` of its 40-minute
    mission (scaled to this one; ``|Δt1| + |Δt2|`` within 15 % of the mission), the one whose true scope
    hulls overlap most (at least 30 % of the smaller; else the closest such pair)."""
    g, xs = sim["gates"], sim["x"][sim["gates"]]
    boxes = [s.scope_box() for s in sim["shapes"]]
    lo, hi = np.array([b[0] for b in boxes]) + xs, np.array([b[1] for b in boxes]) + xs
    i, j = np.triu_indices(len(g), 1)
    ov = np.clip(np.minimum(hi[i], hi[j]) - np.maximum(lo[i], lo[j]), 0, None).prod(1)
    area = (hi - lo).prod(1)
    ratio = ov / np.minimum(area[i], area[j])
    t, scale = sim["t"][g], sim["t"][-1] / THESIS_T[2]  # the thesis's times, scaled to the mission
    cost = np.abs(t[i] - scale * THESIS_T[0]) + np.abs(t[j] - scale * THESIS_T[1])
    near = np.flatnonzero((ratio >= 0.3) & (cost <= 0.15 * sim["t"][-1]))
    k = near[np.argmax(ratio[near])] if near.size else np.argmin(np.where(ratio >= 0.3, cost, np.inf))
    return int(i[k]), int(j[k])


def run(duration: float | None = None, seed: int = 0, bounds: bool = False, out: str | Path | None = None,
        eps_p: float = 1.0, max_passes: int = 6, min_dt: float = 100.0, **sim_kw: Any) -> dict:  # fmt: skip
    """Simulate, run Algorithm 6.2, print Table 6.1's figures, draw Fig. 6.7–6.8 into ``out``."""
    sim = simulate(duration, seed, bounds, **sim_kw)
    t, g = sim["t"], sim["gates"]
    x0 = Tube.entire(t, 2)
    x0.gate_lo[0], x0.gate_hi[0] = sim["x"][0], sim["x"][0]
    dr = ctc_deriv(x0, *sim["u"])
    # Table 6.1: one registration and C_- on the dead-reckoning tube
    i, j = table_pair(sim, dr)
    xi, xj = (dr.gate_lo[g[[i]]], dr.gate_hi[g[[i]]]), (dr.gate_lo[g[[j]]], dr.gate_hi[g[[j]]])
    _, _, p_before = ctc_minus(xi, xj, (np.full((1, 2), -np.inf), np.full((1, 2), np.inf)))
    box = [(p_before[0][0, d], p_before[1][0, d]) for d in range(2)]
    reg = register_translation(sim["shapes"][j], sim["shapes"][i], box, eps_p)
    xi2, xj2, p_after = ctc_minus(xi, xj, (reg[0][None], reg[1][None]))
    p_true = sim["x"][g[j]] - sim["x"][g[i]]
    cfg = ShapeSlamConfig(max_passes=max_passes, eps_p=eps_p, min_dt=min_dt)
    res: ShapeSlamResult = shape_slam(x0, *sim["u"], g, sim["shapes"], cfg)
    inside = res.tube.contains(t, sim["x"])
    stats = {
        "t1": float(t[g[i]]), "t2": float(t[g[j]]), "x1": xi, "x2_before": xj, "x2_after": xj2,
        "p_before": p_before, "p_after": p_after, "p_true": p_true,
        "w_before": float(width_euclid(*p_before)[0]), "w_after": float(width_euclid(*p_after)[0]),
        "p_contains_truth": bool(((p_after[0][0] <= p_true) & (p_true <= p_after[1][0])).all()),
        "dr_width": dr.widths(), "slam_width": res.tube.widths(), "inside": bool(inside.all()),
        "passes": res.passes, "registrations": res.registrations, "tested": int(res.tested.sum()),
        "pairs": int(res.pairs.shape[0]), "seconds": res.seconds, "consistent": res.consistent,
        "result": res, "sim": sim, "dead_reckoning": dr,
    }  # fmt: skip
    if out is not None:
        stats["figure"] = str(draw(stats, out))
    return stats


def draw(st: dict, out: str | Path) -> Path:
    """(a) truth, dead-reckoning and SLAM tube boxes every 20 s; (b) tube widths over time (Fig. 6.7–6.8)."""
    from matplotlib.patches import Rectangle

    from digslam.observer.paving.draw import new_figure

    sim, res, dr = st["sim"], st["result"], st["dead_reckoning"]
    fig, (ax, bx) = new_figure(2, 1, size=6.0)
    gx, gy = np.meshgrid(np.linspace(-300, 300, 200), np.linspace(-300, 300, 200))
    z = elevation(sim["field"], np.stack([gx, gy], -1))
    ax.imshow(z <= sim["level"], extent=(-300, 300, -300, 300), origin="lower", cmap="gray", alpha=0.5)
    for tube, col in ((dr, "tab:blue"), (res.tube, "tab:red")):
        for k in range(0, tube.t.size, 200):
            lo, hi = tube.gate_lo[k], tube.gate_hi[k]
            ax.add_patch(Rectangle(lo, *(hi - lo), fill=False, lw=0.4, ec=col))
    ax.plot(*sim["x"].T, "k", lw=0.6)
    ax.plot(*sim["x"][sim["gates"]].T, "y^", ms=3)
    ax.set_aspect("equal"), ax.set_title("truth, dead reckoning (blue), Alg. 6.2 (red)", fontsize=9)
    bx.plot(dr.t / 60, st["dr_width"], "tab:blue", label="dead reckoning")
    bx.plot(res.tube.t / 60, st["slam_width"], "tab:red", label="Algorithm 6.2")
    bx.set_xlabel("time (min)"), bx.set_ylabel("tube width (m)"), bx.legend()
    return save_figure(fig, out, "ex6_3_bathymetric_slam.png")


def _fmt(b: Any) -> str:
    return " x ".join(f"[{lo:.1f}, {hi:.1f}]" for lo, hi in zip(np.ravel(b[0]), np.ravel(b[1])))


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, duration=2340.0, seed=0)
    ap.add_argument("--bounds", action="store_true", help="every noise exactly at its bound")
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    st = run(a.duration, a.seed, a.bounds, a.out)
    print(
        f"§6.3.2 bathymetric shape SLAM: {len(st['sim']['gates'])} local maps, {st['pairs']} pairs, "
        f"{st['tested']} kept by the pre-test, {st['registrations']} registrations, {st['passes']} passes, "
        f"{st['seconds']:.1f} s (total {time.perf_counter() - t0:.1f} s)"
    )
    print(f"Table 6.1: t1 = {st['t1']:.0f} s, t2 = {st['t2']:.0f} s")
    print(
        f"  [x](t1) = {_fmt(st['x1'])}; [x](t2) before {_fmt(st['x2_before'])}, after {_fmt(st['x2_after'])}"
    )
    print(
        f"  [p12] before {_fmt(st['p_before'])}, after {_fmt(st['p_after'])} (true {st['p_true'].round(2)},"
        f" kept: {st['p_contains_truth']})"
    )
    print(
        f"  w([p12]) = {st['w_before']:.2f} -> {st['w_after']:.2f}  (thesis {PUBLISHED[0]} -> {PUBLISHED[1]})"
    )
    print(
        f"tube width: dead reckoning max {st['dr_width'].max():.1f} m (final {st['dr_width'][-1]:.1f}), "
        f"shape SLAM max {st['slam_width'].max():.1f} m (final {st['slam_width'][-1]:.1f}); "
        f"truth inside: {st['inside']}"
    )
    print(f"  wrote {st.get('figure')}")
    return st


if __name__ == "__main__":
    main()
