"""``digslam certify`` on a simulated mission (issue #47's benchmark).

A 30-minute mission in a 60 m x 60 m building (:class:`~digslam.envs.sim.generators.RoomsCorridors` at half-width
30 m, a 5 x 5 grid of rooms off corridors), odometry at 50 Hz, a 360-beam laser (20 m) at 10 Hz with a 13 ms
phase, a compass (:func:`digslam.envs.sim.logs.simulate_log`; noise bounds 0.005 m/s, 0.001 rad/s, 0.005 rad,
0.02 m: without a compass the dead-reckoning frame of a 30-minute mission spans kilometres), written as an MCAP bag with its bounds file,
then certified (:func:`digslam.agents.cli.certify.certify`, offline ``dig_slam`` without the cross-check).
Prints ``key=value`` lines:

* ``certify_realtime_factor``: mission seconds per wall second, the bounds file's default beam subsampling
  (``beams = 37``), reading the bag included;
* ``certify_realtime_factor_all_beams``: the same with all 360 beams kept (and the 37 merged readings, without
  which the pose boxes are never contracted and grow with the mission: 0 m² certified);
* ``online_realtime_factor``: the online filter alone over the read records (37 beams);
* ``certify_peak_mb``: the process's peak resident memory (simulation included).

``--quick``: a 60 s mission (a few seconds; compilation aside). ``--minutes`` sets the length.
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from digslam.envs.sim.generators import RoomsCorridors
from digslam.envs.sim.logs import LaserSpec, SimNoise, simulate_log


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a 60 s mission")
    ap.add_argument("--minutes", type=float, default=30.0, help="mission length (default %(default)s)")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    from digslam.agents.cli.certify import certify, read
    from digslam.agents.cli.certify_run import frame_grid, run_online

    duration = 60.0 if args.quick else 60.0 * args.minutes
    world = RoomsCorridors(size=30.0, grid=5).generate(args.seed)
    laser = LaserSpec(beams=360, fov=2 * np.pi * 359 / 360, range_max=20.0, rate=10.0, phase=0.013)
    t = time.perf_counter()
    noise = SimNoise(speed=0.005, yaw_rate=0.001, heading=0.005, range=(0.02, 0.0))
    log = simulate_log(world, duration=duration, odom_rate=50.0, laser=laser, compass=True, noise=noise,
                       seed=args.seed, speed=0.8)  # fmt: skip
    print(f"simulated {duration:.0f} s ({len(log.streams.scans[0])} scans) in {time.perf_counter() - t:.1f} s",
          file=sys.stderr)  # fmt: skip
    out: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        log.write(d / "mission", "mcap")
        (d / "bounds.toml").write_text(log.bounds(beams=37) + "merge = 37\n")  # the [[ranges]] table is last
        for key, beams in (("certify_realtime_factor", None), ("certify_realtime_factor_all_beams", 360)):
            t = time.perf_counter()
            s = certify(d / "mission", d / "bounds.toml", d / f"out{beams}", beams=beams, cross_check=False)
            wall = time.perf_counter() - t
            if s["failure"] is not None:
                print(f"certify failed: {s['failure']['message']}", file=sys.stderr)
                return 1
            out[key] = duration / wall
        rlog = read(d / "mission", d / "bounds.toml")
        grid = frame_grid(rlog.records, rlog.x0_lo, rlog.x0_hi, rlog.max_range, rlog.bounds.map.resolution)
        t = time.perf_counter()
        run_online(rlog.records, grid, rlog.x0_lo, rlog.x0_hi, rlog.q)
        out["online_realtime_factor"] = duration / (time.perf_counter() - t)
    out["certify_peak_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    for k, v in out.items():
        print(f"{k}={v:.4g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
