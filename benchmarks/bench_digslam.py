"""Offline Dig-SLAM: its time on the §6.4.2 scenario, and its certified coverage against the online filter's.

1. The thesis's room of Fig. 6.10, a 20-minute loop sampled every 0.1 s (12,001 samples), errors
   0.001 m/s, 0.001 rad, 0.001 rad/s and 0.01 m, a 400×400 grid of 5 cm cells over [-10, 10]², run by
   ``dig_slam`` (the fixpoint of the filter's contractors) and by ``thesis_dig_slam`` (Algorithm 6.3 as
   written). The thesis reports 4 iterations in under 40 s (its predecessor, Jaulin 2011: about 90 s).
2. Frontier episodes of ``--steps`` steps on the first ``--levels`` test levels of each generator (room,
   rocks, caves, rooms; the environment's own grid, start box and filter settings). Per episode, the
   offline certified coverage (``dig_slam`` on the episode's record) over the online filter's on the same
   record, both counted on the certifiable reachable free cells, and the widest box of each tube. Every
   offline box is checked to contain the true position.

There is no peer library to run: the figures are ours, the thesis's are quoted.

Usage: ``python benchmarks/bench_digslam.py [--duration S] [--repeats R] [--levels N] [--steps K] [--quick]``
(``--quick``: a 60 s mission timed once, one 300-step level per generator). The last lines are
``seconds=`` (median time of ``dig_slam`` on the mission, generation excluded), ``dig_slam_over_thesis=``
(that median over the median time of ``thesis_dig_slam`` on the same mission, both timed in turn in the same
run; goal <= 1), ``offline_over_online_coverage=`` (mean ratio over the episodes), ``..._min=`` and
``..._rooms=``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from digslam.agents.baselines.registry import make_baseline
from digslam.agents.evaluation.evaluate import make_env
from digslam.agents.evaluation.suite import GENERATORS, SUITE_KWARGS
from digslam.envs.sim.generators import ThesisRoom
from digslam.envs.sim.missions import loop_mission
from digslam.envs.splits import seeds
from digslam.observer.online.smoother import dig_slam
from digslam.observer.record.grid import Grid
from digslam.observer.record.mission import MissionRecord
from digslam.observer.slam.digslam import DigSlamConfig, thesis_dig_slam


def thesis_scenario(duration: float, repeats: int) -> tuple[float, float]:
    """Part 1: print both algorithms' figures; return the median time of ``dig_slam`` and the ratio of the
    medians of ``dig_slam`` and ``thesis_dig_slam``, both timed ``repeats`` times in turn in this run (after
    a warm-up call of each on the first 10 s, which loads the compiled kernels)."""
    world = ThesisRoom().generate(0)
    record, truth = loop_mission(world, duration=duration, seed=0)
    grid = Grid.from_cell_size((-10.0, -10.0), (10.0, 10.0), 0.05)
    x0 = truth[0, :2]
    warm = record[: min(len(record), 101)]
    dig_slam(warm, grid, x0, x0)
    thesis_dig_slam(warm, grid, x0, x0)
    times, times_ref, res, ref = [], [], None, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = dig_slam(record, grid, x0, x0)
        t1 = time.perf_counter()
        ref = thesis_dig_slam(record, grid, x0, x0)
        times.append(t1 - t0)
        times_ref.append(time.perf_counter() - t1)
    assert res is not None and res.tube is not None and ref is not None and ref.tube is not None
    inside = bool(res.tube.contains(record.t, truth[:, :2]).all())
    print(f"samples: {len(record)}  truth in tube: {inside}")
    print(f"dead reckoning width: max {res.dead_reckoning.max():.3f} m, final {res.dead_reckoning[-1]:.3f} m")
    print(f"online filter: max width {res.online_widths.max():.3f} m (mean {res.online_widths.mean():.3f})")
    seconds, seconds_ref = float(np.median(times)), float(np.median(times_ref))
    for name, r, t in (("dig_slam", res, seconds), ("thesis_dig_slam", ref, seconds_ref)):
        w = r.tube.widths()
        print(f"{name}: {r.iterations} iterations, max width {w.max():.3f} m (mean {w.mean():.3f}), "
              f"dig zone {r.dig.free.sum() * 0.05**2:.1f} m², {t:.2f} s (median of {repeats})")  # fmt: skip
    return seconds, seconds / seconds_ref


def find_observer(env):  # type: ignore[no-untyped-def]
    """The DigCoverage wrapper inside a ``gym.make`` chain (it holds the filter)."""
    e = env
    while not hasattr(e, "filter"):
        e = e.env
    return e


def frontier_episode(generator: str, seed: int, steps: int) -> tuple[float, float, float, float, bool]:
    """Part 2, one episode: online and offline certified coverage, widest online and offline box, and
    whether every offline box holds the truth."""
    env_id, kw = GENERATORS[generator]
    env = make_env(env_id, steps, {**kw, **SUITE_KWARGS})
    agent = make_baseline("frontier", env)
    agent.reset()
    obs, info = env.reset(seed=seed)
    obsw = find_observer(env)
    p, b, g = info["truth"].pose[:2], obsw.obs_config.start_box, obsw.grid
    x0 = (np.maximum(p - b, np.array(g.lo)), np.minimum(p + b, np.array(g.hi)))
    recs, truth = [info["record"]], [info["truth"].pose[:2]]
    state = None
    for _ in range(steps):
        action, state = agent.predict(obs, state=state, deterministic=True)
        obs, _, terminated, truncated, info = env.step(np.clip(np.asarray(action, np.float32), -1.0, 1.0))
        recs.append(info["record"])
        truth.append(info["truth"].pose[:2])
        if terminated or truncated:
            break
    f, reach = obsw.filter, obsw.reachable
    n = max(int(reach.sum()), 1)
    online = float((f.clear_mask() & reach).sum()) / n if f.consistent else 0.0
    on = f.config
    cfg = DigSlamConfig(impacts=on.impacts, cones=on.cones, cone_every=on.cone_every, q=on.q)
    record = MissionRecord.stack(recs)
    res = dig_slam(record, g, *x0, cfg)
    env.close()
    if not res.consistent or res.tube is None:
        return (
            online,
            0.0,
            float(res.online_widths.max()) if res.online_widths is not None else np.nan,
            np.nan,
            False,
        )
    offline = float((res.clear_mask() & reach).sum()) / n
    inside = bool(res.tube.contains(record.t, np.array(truth)).all())
    return online, offline, float(res.online_widths.max()), float(res.tube.widths().max()), inside


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--duration", type=float, default=1200.0)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--levels", type=int, default=4, help="test levels per generator (default %(default)s)")
    p.add_argument("--steps", type=int, default=3000, help="steps per episode (default %(default)s)")
    p.add_argument("--quick", action="store_true", help="a smoke run: a 60 s mission, one short level each")
    a = p.parse_args()
    if a.quick:
        a.duration, a.repeats, a.levels, a.steps = 60.0, 1, 1, 300
    seconds, over_thesis = thesis_scenario(a.duration, a.repeats)
    ratios: dict[str, list[float]] = {}
    all_inside = True
    for gen in GENERATORS:
        for s in seeds("test", a.levels):
            t0 = time.perf_counter()
            on, off, w_on, w_off, inside = frontier_episode(gen, int(s), a.steps)
            all_inside &= inside
            ratios.setdefault(gen, []).append(off / on if on > 0 else 1.0)
            print(f"{gen} {s}: online {on:.4f}, offline {off:.4f} ({off / max(on, 1e-12):.4f}); widest box "
                  f"online {w_on:.3f} m, offline {w_off:.3f} m; truth inside: {inside}; "
                  f"{time.perf_counter() - t0:.1f} s")  # fmt: skip
    flat = [r for v in ratios.values() for r in v]
    print(f"truth_in_offline_tube={all_inside}")
    for gen, v in ratios.items():
        print(f"offline_over_online_coverage_{gen}={np.mean(v):.4f}")
    print(f"offline_over_online_coverage_min={min(flat):.4f}")
    print(f"seconds={seconds:.3f}")
    print(f"dig_slam_over_thesis={over_thesis:.3f}")
    print(f"offline_over_online_coverage={np.mean(flat):.4f}")


if __name__ == "__main__":
    main()
