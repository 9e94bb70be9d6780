"""§3.4.3, Figure 3.12, Tables 3.2–3.3: initial localization among 280 indistinguishable landmarks.

The thesis's data set is not public, so the test-case is simulated (seeded): 280 point landmarks
uniform in a 210 m × 130 m rectangle, an AUV at about 1 m/s on a small pattern (two 50 m legs and
two half-turns, 180 s), a forward-looking sonar (range 10–70 m, aperture ±30°) pinging every 3 s, and 90
(ping, landmark) detections drawn among the pairs in the sonar pie. The robot starts anywhere
(``p(0) ∈ ℝ²``). Errors follow Table 3.2: initial heading ±10°, body speed ±0.05 m/s, gyro
±0.001°/s, range ±1 % (``ρ_true ∈ ρ_meas·[0.99, 1.01]``), bearing ±1°. With ``noise="bounds"``
every error sits exactly on its bound (random sign). Each data interval is widened by ``1e-9`` (times
the magnitude of the value) to absorb the simulator's own float error, nothing more.

:func:`~digslam.observer.slam.landmarks.localize` iterates Eq. 3.70 to the fixpoint and prints Table 3.3:
per iteration, the min / max number of landmarks in the ``[m_i]`` and the number of unique
associations. The figure shows the scenario (Fig. 3.12), the final tube and the widths of the
position gates along the mission for several iterations (Fig. 3.13).

Usage: ``python examples/ex3_12_initial_localization.py [--out DIR] [--seed S] [--noise uniform|bounds]``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, save_figure

from digslam.observer.slam.landmarks import Localization, localize

N_LANDMARKS, MAP_LO, MAP_HI = 280, (-150.0, -80.0), (60.0, 50.0)
DT, SUB, DURATION, PING = 1.0, 10, 180, 3
RANGE, APERTURE, N_DETECTIONS = (10.0, 70.0), np.deg2rad(30.0), 90
PSI0_ERR, SPEED_ERR, GYRO_ERR = np.deg2rad(10.0), 0.05, np.deg2rad(0.001)
RANGE_REL, BEARING_ERR = 0.01, np.deg2rad(1.0)
MARGIN = 1e-9
SEED = 1  # the scenario of the figure (convergence depends on the draw; soundness never does)
START, PSI_START = np.array([-90.0, -40.0]), 0.0


def _yaw_rate() -> np.ndarray:
    """Planned yaw rate per slice: a leg east, a half-turn left (40 s), a leg west, a half-turn right."""
    w = np.zeros(DURATION)
    leg = (DURATION - 80) // 2
    w[leg : leg + 40] = np.pi / 40
    w[2 * leg + 40 : 2 * leg + 80] = -np.pi / 40
    return w


def _noise(rng: np.random.Generator, shape: tuple[int, ...] | int, bound: float, mode: str) -> np.ndarray:
    if mode == "bounds":
        return bound * rng.choice([-1.0, 1.0], size=shape)
    return rng.uniform(-bound, bound, size=shape)


def _interval(meas: np.ndarray, bound: float | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    pad = MARGIN * (np.abs(meas) + bound + 1.0)
    return meas - bound - pad, meas + bound + pad


def simulate(seed: int = 0, noise: str = "uniform") -> dict:
    """Truth, map and interval data (every interval holds the true value)."""
    if noise not in ("uniform", "bounds"):
        raise ValueError(f"noise: expected 'uniform' or 'bounds', got {noise!r}")
    rng = np.random.default_rng(seed)
    lm = rng.uniform(MAP_LO, MAP_HI, size=(N_LANDMARKS, 2))
    t = np.arange(DURATION + 1) * DT
    w = _yaw_rate()
    v = np.stack([1.0 + 0.1 * np.sin(0.05 * t[:-1]), 0.03 * np.cos(0.02 * t[:-1])], axis=1)
    psi = np.concatenate([[PSI_START], PSI_START + np.cumsum(w * DT)])
    x = np.empty((DURATION * SUB + 1, 2))  # truth at SUB sub-steps per slice, heading at sub-step middles
    x[0] = START
    h = DT / SUB
    for k in range(DURATION):
        a = psi[k] + w[k] * h * (np.arange(SUB) + 0.5)
        c, s = np.cos(a), np.sin(a)
        d = h * np.stack([c * v[k, 0] - s * v[k, 1], s * v[k, 0] + c * v[k, 1]], axis=1)
        x[k * SUB + 1 : (k + 1) * SUB + 1] = x[k * SUB] + np.cumsum(d, axis=0)
    gates = x[::SUB]
    # sonar: every (ping, landmark) pair in the pie, then N_DETECTIONS of them at random
    pings = np.arange(0, DURATION + 1, PING)
    d = lm[None, :, :] - gates[pings][:, None, :]
    rng_true = np.hypot(d[..., 0], d[..., 1])
    brg_true = np.angle(np.exp(1j * (np.arctan2(d[..., 1], d[..., 0]) - psi[pings][:, None])))
    pie = (rng_true >= RANGE[0]) & (rng_true <= RANGE[1]) & (np.abs(brg_true) <= APERTURE)
    pi_, li_ = np.nonzero(pie)
    pick = np.sort(rng.choice(pi_.size, size=min(N_DETECTIONS, pi_.size), replace=False))
    pi_, li_ = pi_[pick], li_[pick]
    k = pings[pi_]
    e_r = _noise(rng, k.size, RANGE_REL, noise)
    rho_meas = rng_true[pi_, li_] / (1 + e_r)  # so that ρ_true = ρ_meas·(1 + e), |e| <= 1 %
    phi_meas = brg_true[pi_, li_] + _noise(rng, k.size, BEARING_ERR, noise)
    v_meas = v + _noise(rng, v.shape, SPEED_ERR, noise)
    w_meas = w + _noise(rng, w.shape, GYRO_ERR, noise)
    psi0_meas = psi[0] + _noise(rng, 1, PSI0_ERR, noise)[0]
    return {
        "t": t, "landmarks": lm, "x": x, "gates": gates, "psi": psi, "k": k, "true_landmark": li_,
        "v": _interval(v_meas, SPEED_ERR), "omega": _interval(w_meas, GYRO_ERR),
        "psi0": _interval(np.array([psi0_meas]), PSI0_ERR), "rho": _interval(rho_meas, RANGE_REL * rho_meas),
        "phi": _interval(phi_meas, BEARING_ERR),
    }  # fmt: skip


def solve(data: dict, max_iter: int = 50, disjunctive: bool = True) -> Localization:
    return localize(data["t"], data["v"], data["omega"], data["psi0"], data["k"], data["rho"], data["phi"],
                    data["landmarks"], max_iter=max_iter, disjunctive=disjunctive)  # fmt: skip


def run(
    eps: float = 0.0,
    out: str | Path | None = None,
    seed: int = SEED,
    noise: str = "uniform",
    max_iter: int = 50,
    disjunctive: bool = True,
) -> dict:
    """Simulate, localize, check against the truth; ``eps`` is unused (no paving)."""
    data = simulate(seed, noise)
    t0 = time.perf_counter()
    res = solve(data, max_iter, disjunctive)
    seconds = time.perf_counter() - t0
    assoc = res.associations
    ts = np.linspace(0.0, data["t"][-1], data["x"].shape[0])
    inside = res.position.contains(ts, data["x"])
    head_in = res.heading.contains(data["t"], data["psi"])
    out_d = {
        "data": data, "result": res, "seconds": seconds, "truth_inside": bool(inside.all()),
        "heading_inside": bool(head_in.all()), "unique": int((assoc >= 0).sum()),
        "wrong": int(((assoc >= 0) & (assoc != data["true_landmark"])).sum()),
        "full_association_at": res.full_association_at, "iterations": len(res.history),
    }  # fmt: skip
    if out is not None:
        out_d["png"] = draw(out_d, out)
    return out_d


def draw(r: dict, out: str | Path) -> Path:
    from matplotlib.patches import Rectangle, Wedge

    from digslam.observer.paving.draw import new_figure

    d, res = r["data"], r["result"]
    fig, (a, b) = new_figure(ncols=2, size=6)
    a.plot(*d["landmarks"].T, "k.", ms=3, label=f"{len(d['landmarks'])} landmarks")
    a.plot(*d["x"].T, "b-", lw=1, label="true trajectory")
    a.plot(*d["x"][0], "ro", label="start")
    p, m = d["gates"][d["k"]], d["landmarks"][d["true_landmark"]]
    a.plot(*m.T, "g.", ms=6, label="detected landmarks")
    for pi, mi in zip(p, m, strict=True):
        a.plot([pi[0], mi[0]], [pi[1], mi[1]], "r-", lw=0.4)
    kq = d["k"][len(d["k"]) // 2]
    th = np.rad2deg(d["psi"][kq] + np.array([-APERTURE, APERTURE]))
    a.add_patch(Wedge(d["gates"][kq], RANGE[1], th[0], th[1], width=RANGE[1] - RANGE[0], alpha=0.3))
    pos = res.position
    for k in range(0, pos.T + 1, 5):
        lo, hi = pos.gate_lo[k], pos.gate_hi[k]
        a.add_patch(Rectangle(lo, *(hi - lo), fill=False, ec="orange", lw=0.5))
    a.set_aspect("equal")
    a.legend(fontsize=7, loc="upper right")
    a.set_title(f"Fig. 3.12: scenario and final tube ({r['iterations']} iterations)")
    for h, wid in zip(res.history, res.width_history, strict=True):
        if h.iteration % 3 == 1:
            b.semilogy(d["t"], wid, lw=0.8, label=f"iteration {h.iteration}")
    b.semilogy(d["t"], pos.widths(), "k-", lw=2, label="final")
    b.set_xlabel("t (s)")
    b.set_ylabel("w([p](t)) (m)")
    b.set_title("Fig. 3.13: width of the position tube")
    b.legend(fontsize=7)
    return save_figure(fig, out, "ex3_12_initial_localization.png")


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__, seed=SEED)
    ap.add_argument("--noise", default="uniform", choices=["uniform", "bounds"])
    args = ap.parse_args(argv)
    r = run(out=args.out, seed=args.seed, noise=args.noise)
    print(f"{len(r['data']['landmarks'])} landmarks, {len(r['data']['k'])} detections")
    print(f"{'iteration':>9} {'time (s)':>9} {'min |[m]|':>10} {'max |[m]|':>10} {'unique':>7} "
          f"{'max w(p)':>10}")  # fmt: skip
    for h in r["result"].history:
        print(f"{h.iteration:9d} {h.seconds:9.3f} {h.min_candidates:10d} {h.max_candidates:10d} "
              f"{h.unique:7d} {h.max_width:10.2f}")  # fmt: skip
    print(f"truth inside tube: {r['truth_inside']}, heading inside: {r['heading_inside']}; unique "
          f"associations {r['unique']}, wrong {r['wrong']}; full association at iteration "
          f"{r['full_association_at']}; {r['seconds']:.2f} s; wrote {r.get('png')}")  # fmt: skip
    return r


if __name__ == "__main__":
    main()
