"""§3.4.2, Figure 3.10: underwater transit, box diameters, minimal polar vs forward-backward separator.

The VAMA data set is not public, so a transit is simulated: a ship at ``m = (0, 0)`` measures the
range and bearing to an AUV that follows waypoints at about 1.5 m/s (``dt = 0.5`` s, 100 s, one
acoustic fix per second by default). Sensor errors as in the thesis: range ±1 %, bearing ±2°, speed ±0.05 m/s,
heading ±1°. Every interval contains the true value.

Two observers, each run with the minimal separator ``g_m ∘ S_{π⁻¹}`` and with the forward-backward
``SepInverse`` (Eq. 3.63):

* ``ī = 0`` (Figure 3.10): ``[x_k] = S_out([-∞, ∞]²)`` for the fix at time ``k``, no bisection;
* dead reckoning: ``[x_k] = S_out([x_{k-1}] + dt·R([ψ])·[v])``, the box predicted with the interval
  heading and speed, then contracted by the fix (a box observer with memory).

Usage: ``python examples/ex3_10_transit.py [--out DIR] [--eps EPS]`` (``eps`` is unused: no paving);
writes ``DIR/ex3_10_transit.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer.core import arith as A
from digslam.observer.core import trig as T
from digslam.observer.core.boxes import width_euclid
from digslam.observer.polar.sep import SepLandmark, sep_landmark_fwdbwd

SHIP = (0.0, 0.0)
DT, DURATION, FIX_PERIOD = 0.5, 100.0, 1.0
WAYPOINTS = np.array([[40.0, -60.0], [90.0, -20.0], [100.0, 60.0], [40.0, 110.0]])
START = np.array([-20.0, -90.0])
SPEED = 1.5
RANGE_REL, BEARING_ERR = 0.01, np.deg2rad(2.0)
SPEED_ERR, HEADING_ERR = 0.05, np.deg2rad(1.0)


def simulate(seed: int = 0, fix_period: float = FIX_PERIOD) -> dict:
    """True trajectory and interval data: heading ψ, body speed (u, w), and range/bearing fixes."""
    rng = np.random.default_rng(seed)
    n = int(round(DURATION / DT))
    x = np.empty((n + 1, 2))
    x[0] = START
    psi, speed = np.empty(n), np.empty((n, 2))
    wp = 0
    for k in range(n):
        d = WAYPOINTS[wp] - x[k]
        if np.hypot(*d) < 5 and wp + 1 < len(WAYPOINTS):
            wp += 1
            d = WAYPOINTS[wp] - x[k]
        psi[k] = np.arctan2(d[1], d[0])
        speed[k] = (SPEED + 0.1 * np.sin(0.05 * k), 0.02 * np.cos(0.03 * k))
        c, s = np.cos(psi[k]), np.sin(psi[k])
        x[k + 1] = x[k] + DT * np.array(
            [c * speed[k, 0] - s * speed[k, 1], s * speed[k, 0] + c * speed[k, 1]]
        )
    # measurements: errors drawn inside half the bound, intervals of the full bound around them
    psi_m = psi + rng.uniform(-0.5, 0.5, n) * HEADING_ERR
    speed_m = speed + rng.uniform(-0.5, 0.5, (n, 2)) * SPEED_ERR
    fixes = np.arange(0, n + 1, max(1, int(round(fix_period / DT))))
    d = np.asarray(SHIP) - x[fixes]  # m - x = π(ρ, θ)  (Eq. 3.54)
    rho = np.hypot(d[:, 0], d[:, 1]) * (1 + rng.uniform(-0.5, 0.5, len(fixes)) * RANGE_REL)
    theta = np.arctan2(d[:, 1], d[:, 0]) + rng.uniform(-0.5, 0.5, len(fixes)) * BEARING_ERR
    return {"x": x, "psi_m": psi_m, "speed_m": speed_m, "fixes": fixes, "rho": rho, "theta": theta}


def fix_separator(kind: str, rho: float, theta: float):
    r = (rho * (1 - RANGE_REL), rho * (1 + RANGE_REL))
    t = (theta - BEARING_ERR, theta + BEARING_ERR)
    return SepLandmark(SHIP, r, t) if kind == "polar" else sep_landmark_fwdbwd(SHIP, r, t)


def predict(lo: np.ndarray, hi: np.ndarray, psi: float, speed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``[x] + dt·R([ψ])·[v]`` with outward rounding (Eq. 3.59)."""
    p = (np.array(psi - HEADING_ERR), np.array(psi + HEADING_ERR))
    u = (np.array(speed[0] - SPEED_ERR), np.array(speed[0] + SPEED_ERR))
    w = (np.array(speed[1] - SPEED_ERR), np.array(speed[1] + SPEED_ERR))
    c, s = T.cos(p), T.sin(p)
    dt = (np.array(DT), np.array(DT))
    dx = A.mul(dt, A.sub(A.mul(c, u), A.mul(s, w)))
    dy = A.mul(dt, A.add(A.mul(s, u), A.mul(c, w)))
    nx, ny = A.add((lo[:, 0], hi[:, 0]), dx), A.add((lo[:, 1], hi[:, 1]), dy)
    return np.stack([nx[0], ny[0]], 1), np.stack([nx[1], ny[1]], 1)


def run(
    eps: float = 0.0, out: str | Path | None = None, seed: int = 0, fix_period: float = FIX_PERIOD
) -> dict:
    """Diameters of ``[x_k]`` for both separators and both observers; ``eps`` is unused."""
    data = simulate(seed, fix_period)
    x, fixes = data["x"], data["fixes"]
    t_fix = fixes * DT
    res: dict = {"t": t_fix, "data": data}
    full = (np.full((1, 2), -np.inf), np.full((1, 2), np.inf))
    for kind in ("polar", "fwdbwd"):
        t0 = time.perf_counter()
        seps = [fix_separator(kind, r, t) for r, t in zip(data["rho"], data["theta"], strict=True)]
        memoryless = [s.separate(*full)[1] for s in seps]
        diam0 = np.array([width_euclid(*b)[0] for b in memoryless])
        sound0 = all(((b[0] <= x[k]) & (x[k] <= b[1])).all() for b, k in zip(memoryless, fixes, strict=True))
        lo, hi = memoryless[0]
        diam, sound, j = [float(width_euclid(lo, hi)[0])], True, 1
        for k in range(1, len(x)):
            lo, hi = predict(lo, hi, data["psi_m"][k - 1], data["speed_m"][k - 1])
            if j < len(fixes) and k == fixes[j]:
                lo, hi = seps[j].separate(lo, hi)[1]
                diam.append(float(width_euclid(lo, hi)[0]))
                sound &= bool(((lo <= x[k]) & (x[k] <= hi)).all())
                j += 1
        res[kind] = {
            "diameter_i0": diam0,
            "diameter_dr": np.array(diam),
            "contains_truth": bool(sound0 and sound),
            "seconds": time.perf_counter() - t0,
        }
    res["ratio_i0"] = res["fwdbwd"]["diameter_i0"] / res["polar"]["diameter_i0"]
    res["ratio_dr"] = res["fwdbwd"]["diameter_dr"] / res["polar"]["diameter_dr"]
    if out is not None:
        res["png"] = draw(res, out)
    return res


def draw(res: dict, out: str | Path) -> Path:
    from digslam.observer.paving.draw import new_figure

    fig, (a, b) = new_figure(ncols=2, size=5)
    x = res["data"]["x"]
    a.plot(x[:, 0], x[:, 1], "k-", lw=1, label="true transit")
    a.plot(*SHIP, "r^", label="ship m")
    a.plot(*WAYPOINTS.T, "bo", ms=3, label="waypoints")
    a.set_aspect("equal")
    a.legend(fontsize=7)
    a.set_title("simulated transit (Figure 3.9)")
    t = res["t"]
    b.plot(t, res["polar"]["diameter_i0"], "b-", label="minimal polar, ī = 0")
    b.plot(t, res["fwdbwd"]["diameter_i0"], "g-", label="forward-backward, ī = 0")
    b.plot(t, res["polar"]["diameter_dr"], "b:", label="minimal polar, dead reckoning")
    b.plot(t, res["fwdbwd"]["diameter_dr"], "g:", label="forward-backward, dead reckoning")
    b.set_xlabel("t (s)")
    b.set_ylabel("diameter of [x_k] (m)")
    b.legend(fontsize=7)
    b.set_title("Figure 3.10: box diameters")
    return save_figure(fig, out, "ex3_10_transit.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, eps=0.0, eps_help="unused (no paving); kept for a uniform interface")
    args = ap.parse_args(argv)
    r = run(args.eps, args.out)
    for key, label in (("i0", "ī = 0"), ("dr", "dead reckoning")):
        p, f = r["polar"][f"diameter_{key}"], r["fwdbwd"][f"diameter_{key}"]
        ratio = r[f"ratio_{key}"]
        print(
            f"{label:15s}: mean diameter polar {p.mean():.3f} m, fwd-bwd {f.mean():.3f} m; fwd-bwd / polar "
            f"min {ratio.min():.3f}, mean {ratio.mean():.3f}, max {ratio.max():.3f} "
            f"(at t = {r['t'][int(np.argmax(ratio))]:.0f} s)"
        )
    print(
        f"truth kept: polar {r['polar']['contains_truth']}, fwd-bwd {r['fwdbwd']['contains_truth']}; "
        f"wrote {r['png']}"
    )
    return r


if __name__ == "__main__":
    main()
