"""Dig-SLAM on the §6.4.2 scenario (seeded), run to its fixpoint.

The thesis's room of Fig. 6.10, a 20-minute loop sampled every 0.1 s (12,001 samples), errors
0.001 m/s, 0.001 rad, 0.001 rad/s and 0.01 m, a 400×400 grid of 5 cm cells over [-10, 10]². The thesis
reports 4 iterations in under 40 s (its predecessor, Jaulin 2011: about 90 s). There is no peer library to
run: the figures are ours, the thesis's are quoted.

Usage: ``python benchmarks/bench_digslam.py [--duration S] [--repeats R] [--quick]`` (``--quick``: a 60 s
mission, timed once). The last line is
``seconds=<median time of dig_slam>`` (mission generation excluded).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from digslam.envs.sim.generators import ThesisRoom
from digslam.envs.sim.missions import loop_mission
from digslam.observer.slam.digslam import dig_slam
from digslam.observer.slam.grid import Grid


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--duration", type=float, default=1200.0)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--quick", action="store_true", help="a smoke run: a 60 s mission, timed once")
    a = p.parse_args()
    if a.quick:
        a.duration, a.repeats = 60.0, 1
    world = ThesisRoom().generate(0)
    record, truth = loop_mission(world, duration=a.duration, seed=0)
    grid = Grid.from_cell_size((-10.0, -10.0), (10.0, 10.0), 0.05)
    times = []
    for _ in range(a.repeats):
        t0 = time.perf_counter()
        res = dig_slam(record, grid, truth[0, :2], truth[0, :2])
        times.append(time.perf_counter() - t0)
    inside = np.all((truth[:, :2] >= res.tube.gate_lo) & (truth[:, :2] <= res.tube.gate_hi))
    print(f"samples: {len(record)}  iterations: {res.iterations}  truth in tube: {bool(inside)}")
    print(f"dead reckoning width: max {res.dead_reckoning.max():.3f} m, final {res.dead_reckoning[-1]:.3f} m")
    for i, w in enumerate(res.widths):
        print(
            f"iteration {i + 1}: max width before {w['before'].max():.3f} m, after impacts "
            f"{w['impacts'].max():.3f} m, after C_d/dt {w['deriv'].max():.3f} m (mean {w['deriv'].mean():.3f})"
        )
    print(f"dig zone: {res.dig.free.sum() * 0.05**2:.1f} m²; times: {', '.join(f'{t:.2f}' for t in times)} s")
    print(f"seconds={float(np.median(times)):.3f}")


if __name__ == "__main__":
    main()
