"""Steps per second of ``digslam/Explore-v0`` (raw) and ``digslam/DigCoverage-v0`` (with the observer).

Both run the default map (the thesis room) and sensors (8 sonar cones + the omnidirectional sensor, a
128 x 128 observer grid, a 64 x 64 map) under the same random forward-biased actions, reset every
``--episode`` steps. Besides the two step rates it reports the online filter's median and 99th-percentile
update time (``OnlineDigSlam.last_update_seconds``, the filter alone) and the rest of the wrapper's time
(map and state images, info sets).

Measurement: the two envs run the same actions, reset with the same seeds at the same steps (resets
excluded), after an untimed warm-up of 50 steps each. To keep a load spike on a shared machine from landing
on one env only, the timed steps alternate between them in chunks of ``--chunk`` steps (raw chunk, then
the same steps on the observed env, then the next chunk...); each env's time is the total over its chunks
and the overhead is the ratio of the two totals.

The observed env runs twice, with the filter's q-relaxed mode off (``q = 0``, the figures above) and at
``q = 1`` (at most one outlier among each step's readings, thesis §2.6.2: a cell is dug where two readings
prove it free), on the same actions and seeds, the three envs alternating chunk by chunk; the ``q = 1``
figures end in ``_q1``, and ``observed_q1_over_q0`` is the ratio of the observed step rates (the issue's
bound: at least 0.9).

A third observed env runs with smoothing at loop closures on (``OnlineConfig(loop_smoothing=0.3)``,
:data:`LOOP`), in the same alternation; its figures end in ``_loop`` (the issue's bounds: overhead at most
2.5, the 99th-percentile update under 20 ms), with its worst update (a pass) and the passes of its last
episode. Random actions seldom close a loop, so the frontier agent then drives the rooms' first test level
(3000 steps) with and without it: the ``loop_frontier_`` figures give its passes, its mean, 99th-percentile
and worst update and the certified coverage at the end, both ways.

The envs move the robot with pymunk, the default dynamics (the record then bounds a lateral velocity too,
and the filter's tube grows with it). The same pair (raw, observed at ``q = 0``) with the exact unicycle
dynamics runs afterwards on the same actions and seeds; its figures end in ``_unicycle``.

Real buildings: the observed env (``digslam/DigCoverage-v0``, ``q = 0``) on ``world="floorplan"`` levels
(windows of the shipped KTH plans, :class:`~digslam.envs.sim.generators.Floorplan`) and on ``world="rooms"``
levels, otherwise the same settings, run the same actions and seeds in alternating chunks as above (the
floorplan env's update times are read each step, the rooms env's are not: the ratio leans conservative);
``floorplan_over_rooms`` is the floorplan levels' step rate over the rooms levels' (the issue's bound: at
least 0.7), ``floorplan_edges_mean`` the mean number of edges of the floorplan levels timed (each sensor
reads the edges that its bounding-box pre-filter keeps).

Usage: ``python benchmarks/bench_observer.py [--steps N] [--episode K] [--chunk C] [--grid-cell S] [--quick]``
(``S``: the observer's cell side, m; 0.078125 for the grid twice as fine; ``--quick``: 200 steps in episodes of
100, a smoke run). Last line:
``observer_overhead=<raw steps per second / observed steps per second>`` (``q = 0``).
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import digslam.envs  # noqa: F401  (registers the environments)
from digslam.envs.stack import observer_of

#: The loop-closure smoothing of the ``_loop`` figures (:mod:`digslam.observer.online.history`).
LOOP = {"loop_smoothing": 0.3, "history": 4000}


def timed(env: gym.Env, actions: np.ndarray, probe: list[float] | None = None) -> float:
    """Wall time of ``env.step`` over ``actions``; filter update times appended to ``probe``."""
    if probe is None:
        t0 = time.perf_counter()
        for a in actions:
            env.step(a)
        return time.perf_counter() - t0
    f = observer_of(env).filter
    t0 = time.perf_counter()
    for a in actions:
        env.step(a)
        probe.append(f.last_update_seconds)
    return time.perf_counter() - t0


def run_pair(raw: gym.Env, obs: gym.Env | list[gym.Env], actions: np.ndarray, episode: int, chunk: int,
             probe: list[float] | list[list[float]]) -> tuple[float, ...]:  # fmt: skip
    """Total step times of ``raw`` and ``obs`` (one env, or several with one probe list each) over
    ``actions``, reset every ``episode`` steps (untimed), alternating chunks of ``chunk`` steps."""
    envs = obs if isinstance(obs, list) else [obs]
    probes: list[list[float]] = probe if isinstance(obs, list) else [probe]  # type: ignore[assignment]
    t_raw, t_obs = 0.0, [0.0] * len(envs)
    for start in range(0, len(actions), episode):
        raw.reset(seed=start)
        for e in envs:
            e.reset(seed=start)
        block = actions[start : start + episode]
        for c in range(0, len(block), chunk):
            t_raw += timed(raw, block[c : c + chunk])
            for i, e in enumerate(envs):
                t_obs[i] += timed(e, block[c : c + chunk], probes[i])
    return (t_raw, *t_obs)


def loop_on_frontier(steps: int) -> tuple[int, np.ndarray, float, float]:
    """The frontier agent on the rooms' first test level, the filter with loop smoothing (:data:`LOOP`): the
    passes, every update time, and the certified coverage at the end without and with it."""
    from digslam.agents.baselines.registry import make_baseline
    from digslam.envs.splits import seeds

    out = []
    for online in ({}, LOOP):
        env = gym.make(
            "digslam/DigCoverage-v0", world="rooms", max_episode_steps=steps, target=1.0, online=online
        )
        agent = make_baseline("frontier", env)
        agent.reset()
        o, info = env.reset(seed=int(seeds("test", 1)[0]))
        f, times = observer_of(env).filter, []
        for _ in range(steps):
            a, _ = agent.predict(o, deterministic=True)
            o, _, term, trunc, info = env.step(np.clip(np.asarray(a, np.float32), -1.0, 1.0))
            times.append(f.last_update_seconds)
            if term or trunc:
                break
        out.append(
            (f.history.passes if f.history is not None else 0, np.array(times), info["certified_coverage"])
        )
        env.close()
    return out[1][0], out[1][1], out[0][2], out[1][2]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--episode", type=int, default=500)
    parser.add_argument("--chunk", type=int, default=100)
    parser.add_argument(
        "--grid-cell", type=float, default=None, help="observer cell side (m); default: the env's"
    )
    parser.add_argument("--quick", action="store_true", help="a smoke run: 200 steps, episodes of 100")
    args = parser.parse_args()
    if args.quick:
        args.steps, args.episode, args.chunk = 200, 100, 50
    rng = np.random.default_rng(0)
    actions = np.column_stack([rng.uniform(0.2, 1.0, args.steps), rng.uniform(-1, 1, args.steps)])
    actions = actions.astype(np.float32)
    steps = args.episode + 1
    cell = {} if args.grid_cell is None else {"grid_cell": args.grid_cell}
    raw = gym.make("digslam/Explore-v0", max_episode_steps=steps)
    obs = gym.make("digslam/DigCoverage-v0", max_episode_steps=steps, target=1.0, **cell)
    obs1 = gym.make("digslam/DigCoverage-v0", max_episode_steps=steps, target=1.0, q=1, **cell)
    obs_l = gym.make("digslam/DigCoverage-v0", max_episode_steps=steps, target=1.0, online=LOOP, **cell)
    run_pair(raw, [obs, obs1, obs_l], actions[:50], 50, 50, [[], [], []])  # warm-up
    probes: list[list[float]] = [[], [], []]
    t_raw, t_obs, t_obs1, t_obs_l = run_pair(
        raw, [obs, obs1, obs_l], actions, args.episode, args.chunk, probes
    )
    up, up1, up_l = (np.array(p) for p in probes)
    raw_sps, obs_sps, obs1_sps = args.steps / t_raw, args.steps / t_obs, args.steps / t_obs1
    obs_l_sps = args.steps / t_obs_l
    raw_u = gym.make("digslam/Explore-v0", max_episode_steps=steps, dynamics="unicycle")
    obs_u = gym.make(
        "digslam/DigCoverage-v0", max_episode_steps=steps, target=1.0, dynamics="unicycle", **cell
    )
    run_pair(raw_u, [obs_u], actions[:50], 50, 50, [[]])  # warm-up
    probe_u: list[list[float]] = [[]]
    t_raw_u, t_obs_u = run_pair(raw_u, [obs_u], actions, args.episode, args.chunk, probe_u)
    up_u = np.array(probe_u[0])
    raw_sps_u, obs_sps_u = args.steps / t_raw_u, args.steps / t_obs_u
    rooms, plan = (
        gym.make("digslam/DigCoverage-v0", world=w, max_episode_steps=steps, target=1.0, **cell)
        for w in ("rooms", "floorplan")
    )
    run_pair(rooms, [plan], actions[:50], 50, 50, [[]])  # warm-up
    probe_f: list[list[float]] = [[]]
    t_rooms, t_plan = run_pair(rooms, [plan], actions, args.episode, args.chunk, probe_f)
    plan_edges = []  # the floorplan levels timed (resets with the same seeds give the same levels)
    for start in range(0, args.steps, args.episode):
        plan.reset(seed=start)
        plan_edges.append(len(plan.unwrapped.world.edges))
    layer = observer_of(obs)
    print(f"grid={layer.grid.shape} map={layer.obs_config.map_size} sensors={raw.unwrapped.suite.n}")
    print(f"raw_steps_per_s={raw_sps:.0f}")
    print(f"observed_steps_per_s_q1={obs1_sps:.0f}")
    print(f"observer_update_median_ms_q1={1e3 * np.median(up1):.3f}")
    print(f"observer_update_p99_ms_q1={1e3 * np.percentile(up1, 99):.3f}")
    print(f"wrapper_other_ms_per_step_q1={1e3 * (t_obs1 - t_raw - up1.sum()) / args.steps:.3f}")
    print(f"observer_overhead_q1={raw_sps / obs1_sps:.3f}")
    print(f"observed_q1_over_q0={obs1_sps / obs_sps:.3f}")
    print(f"observed_steps_per_s_loop={obs_l_sps:.0f}")
    print(f"observer_update_p99_ms_loop={1e3 * np.percentile(up_l, 99):.3f}")
    print(f"observer_update_max_ms_loop={1e3 * up_l.max():.3f}")
    print(f"loop_passes_last_episode={observer_of(obs_l).filter.history.passes}")
    print(f"observer_overhead_loop={raw_sps / obs_l_sps:.3f}")
    passes, up_f, cov0, cov1 = loop_on_frontier(300 if args.quick else 3000)
    print(f"loop_frontier_passes={passes}")
    print(f"loop_frontier_update_mean_ms={1e3 * up_f.mean():.3f}")
    print(f"loop_frontier_update_p99_ms={1e3 * np.percentile(up_f, 99):.3f}")
    print(f"loop_frontier_update_max_ms={1e3 * up_f.max():.3f}")
    print(f"loop_frontier_certified={cov1:.4f} (without loop smoothing: {cov0:.4f})")
    print(f"raw_steps_per_s_unicycle={raw_sps_u:.0f}")
    print(f"observed_steps_per_s_unicycle={obs_sps_u:.0f}")
    print(f"observer_update_median_ms_unicycle={1e3 * np.median(up_u):.3f}")
    print(f"observer_overhead_unicycle={raw_sps_u / obs_sps_u:.3f}")
    print(f"observed_steps_per_s_rooms={args.steps / t_rooms:.0f}")
    print(f"observed_steps_per_s_floorplan={args.steps / t_plan:.0f}")
    print(f"observer_update_median_ms_floorplan={1e3 * np.median(probe_f[0]):.3f}")
    n_rooms = len(rooms.unwrapped.world.edges)
    print(f"floorplan_edges_mean={np.mean(plan_edges):.0f}  (max {max(plan_edges)}; rooms level: {n_rooms})")
    print(f"floorplan_over_rooms={t_rooms / t_plan:.3f}")
    print(f"observed_steps_per_s={obs_sps:.0f}")
    print(f"observer_update_median_ms={1e3 * np.median(up):.3f}")
    print(f"observer_update_p99_ms={1e3 * np.percentile(up, 99):.3f}")
    print(f"wrapper_other_ms_per_step={1e3 * (t_obs - t_raw - up.sum()) / args.steps:.3f}")
    print(f"observer_overhead={raw_sps / obs_sps:.3f}")


if __name__ == "__main__":
    main()
