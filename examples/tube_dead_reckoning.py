"""Guaranteed dead reckoning of a unicycle in a tube, contracted by a few position fixes (§2.5.4, §6.4.2).

``ẋ = v (cos ψ, sin ψ)`` (Eq. 6.23) measured every 0.1 s for 20 minutes with the errors of §6.4.2:
speed ``± 0.001 m/s``, heading ``± 0.001 rad`` (compass) and yaw rate ``± 0.001 rad/s`` (gyro). The heading
tube fuses compass and gyro (:func:`heading_from_compass`), :func:`unicycle_velocity` gives the velocity
boxes on its slices, :func:`dead_reckoning` integrates them, then position fixes ``± 0.5 m`` at 5, 10 and
15 minutes are propagated to the whole trajectory by :func:`ctc_deriv`. The bounds on each slice are
built to hold the true signals (noise ``± 0.0005`` plus the signal's variation over 0.1 s), so the true
trajectory is guaranteed inside; the script checks it on a fine time grid.

Usage: ``python examples/tube_dead_reckoning.py [--out DIR] [--minutes M]``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _common import parser, report, save_figure

from digslam.observer.tube.tube import (
    ctc_deriv,
    dead_reckoning,
    heading_from_compass,
    heading_from_gyro,
    unicycle_velocity,
)

DT = 0.1
ERR_SPEED, ERR_HEADING, ERR_RATE = 0.001, 0.001, 0.001  # §6.4.2
FIX_RADIUS = 0.5


def speed(t: np.ndarray) -> np.ndarray:
    return 1.0 + 0.1 * np.sin(0.02 * t)  # |v'| <= 0.002: varies by <= 0.0002 over a slice


def yaw_rate(t: np.ndarray) -> np.ndarray:
    return 0.02 * np.sin(0.01 * t) + 0.01 * np.cos(0.003 * t)  # |ω'| <= 0.00023


def heading(t: np.ndarray) -> np.ndarray:
    return 2.0 * (1.0 - np.cos(0.01 * t)) + (0.01 / 0.003) * np.sin(0.003 * t)  # ∫ ω


def true_positions(t: np.ndarray, sub: int = 10) -> tuple[np.ndarray, np.ndarray]:
    """Positions on a ``sub``-times finer grid (trapezoid rule: error ~1e-7 m, far below the widths)."""
    fine = np.linspace(t[0], t[-1], (t.size - 1) * sub + 1)
    v, psi = speed(fine), heading(fine)
    h = np.diff(fine)
    x = np.concatenate([[0.0], np.cumsum((v[1:] * np.cos(psi[1:]) + v[:-1] * np.cos(psi[:-1])) / 2 * h)])
    y = np.concatenate([[0.0], np.cumsum((v[1:] * np.sin(psi[1:]) + v[:-1] * np.sin(psi[:-1])) / 2 * h)])
    return fine, np.stack([x, y], axis=1)


def run(out: str | Path | None = None, minutes: float = 20.0, seed: int = 0) -> dict:
    """Build the tubes, print and return their widths; draw the figure into ``out``."""
    rng = np.random.default_rng(seed)
    T = int(round(minutes * 60 / DT))
    t = np.arange(T + 1) * DT
    noise = lambda size: rng.uniform(-0.0005, 0.0005, size)  # noqa: E731
    # slice k: measurement at t_k; its error bound covers the noise and the signal's drift over the slice
    v_meas, w_meas = speed(t[:-1]) + noise(T), yaw_rate(t[:-1]) + noise(T)
    psi_meas = heading(t) + noise(T + 1)
    w_lo, w_hi = w_meas - ERR_RATE, w_meas + ERR_RATE
    t0 = time.perf_counter()
    psi = heading_from_compass(t, psi_meas - ERR_HEADING, psi_meas + ERR_HEADING, w_lo, w_hi)
    v_lo, v_hi = v_meas - ERR_SPEED, v_meas + ERR_SPEED
    u_lo, u_hi = unicycle_velocity(v_lo, v_hi, psi.slice_lo[:, 0], psi.slice_hi[:, 0])
    x = dead_reckoning(t, [0.0, 0.0], [0.0, 0.0], u_lo, u_hi)
    t1 = time.perf_counter()
    fine, pos = true_positions(t)
    fix_idx = [k for k in (int(T * f) for f in (0.25, 0.5, 0.75)) if 0 < k < T]
    z = x.copy()
    for k in fix_idx:  # a fix ± 0.5 m holding the true position, off-centre
        centre = pos[k * 10] + rng.uniform(-0.4, 0.4, 2) * FIX_RADIUS
        z.gate_lo[k] = np.maximum(z.gate_lo[k], centre - FIX_RADIUS)
        z.gate_hi[k] = np.minimum(z.gate_hi[k], centre + FIX_RADIUS)
    t2 = time.perf_counter()
    y = ctc_deriv(z, u_lo, u_hi)
    t3 = time.perf_counter()
    gyro_only = heading_from_gyro(t, 0.0, 0.0, w_lo, w_hi)
    res = {
        "T": T,
        "heading_width_max": float(psi.widths().max()),
        "heading_width_mean": float(psi.widths().mean()),
        "heading_width_gyro_only_final": float(gyro_only.widths()[-1]),
        "dead_reckoning_width_final": float(x.widths()[-1]),
        "dead_reckoning_width_at_fixes": [float(x.widths()[k]) for k in fix_idx],
        "contracted_width_max": float(y.widths().max()),
        "contracted_width_final": float(y.widths()[-1]),
        "contracted_width_mean": float(y.widths().mean()),
        "seconds_build": t1 - t0,
        "seconds_ctc_deriv": t3 - t2,
        "truth_inside": bool(
            x.contains(fine, pos).all()
            and y.contains(fine, pos).all()
            and psi.contains(fine, heading(fine)).all()
        ),  # fmt: skip
    }
    if out is not None:
        from digslam.observer.paving.draw import (
            BOUNDARY_COLOR,
            INSIDE_COLOR,
            draw_boxes,
            new_figure,
        )

        fig, (ax0, axz, ax1) = new_figure(3, 1, size=4.5)
        fx = pos[np.array(fix_idx) * 10]
        kz = fix_idx[len(fix_idx) // 2]  # zoom: 10 s around the middle fix
        zoom = slice(max(0, kz - 50), min(T, kz + 50))
        for ax, sl, title in ((ax0, slice(None), "(a) tube [x](·)"), (axz, zoom, "(b) zoom on a fix")):
            draw_boxes(x.slice_lo[sl], x.slice_hi[sl], ax=ax, color=BOUNDARY_COLOR, edgecolor=BOUNDARY_COLOR,
                       linewidth=0.5, label="dead reckoning")  # fmt: skip
            draw_boxes(y.slice_lo[sl], y.slice_hi[sl], ax=ax, color=INSIDE_COLOR, edgecolor=INSIDE_COLOR,
                       linewidth=0.5, label="with fixes")  # fmt: skip
            ax.plot(pos[:, 0], pos[:, 1], "k", linewidth=0.5, label="true path")
            ax.plot(fx[:, 0], fx[:, 1], "b+", label="fixes")
            ax.set_aspect("equal"), ax.set_title(title)
        lo, hi = x.slice_lo[zoom].min(axis=0), x.slice_hi[zoom].max(axis=0)
        axz.set_xlim(lo[0], hi[0]), axz.set_ylim(lo[1], hi[1]), ax0.legend(loc="best", fontsize=7)
        ax1.plot(t / 60, x.widths(), color=BOUNDARY_COLOR, label="dead reckoning")
        ax1.plot(t / 60, y.widths(), color=INSIDE_COLOR, label="with fixes")
        ax1.set_xlabel("time (min)"), ax1.set_ylabel("max gate width (m)"), ax1.legend(fontsize=7)
        ax1.set_title("(c) widths")
        res["figure"] = str(save_figure(fig, out, "tube_dead_reckoning.png"))
    return res


def main(argv: list[str] | None = None) -> dict:
    ap = parser(__doc__)
    ap.add_argument("--minutes", type=float, default=20.0, help="mission length in min (default 20)")
    a = ap.parse_args(argv)
    r = run(a.out, a.minutes)
    report(r)
    return r


if __name__ == "__main__":
    main()
