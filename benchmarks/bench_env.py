"""Steps per second of ``digslam/Explore-v0`` (exact cones) against a pymunk ray-casting reference loop.

Both run the same 30-rock world, 8 sonar cones plus the omnidirectional sensor, dt = 0.1 s with 4 substeps
and the same random actions, and both move the robot with pymunk (the env's default dynamics: the same
space, bodies and joints). The reference steps the space and casts 5 rays per cone with
``Space.segment_query_first`` and gets the omni range from ``Space.point_query_nearest``; it has no noise,
no record, no reward. Ours also checks the premise after every substep, bounds the body-frame velocity and
yaw rate over the step, and computes the exact cone distances, the noisy intervals, the mission record, the
ground truth and the coverage reward, and is stepped through ``gym.make``'s wrappers (order enforcing,
passive env checker; the reference has none), so the ratio is conservative; the unwrapped rate is printed
too. The same env with the exact unicycle dynamics (``dynamics="unicycle"``) is timed beside it (keys
ending in ``_unicycle``). All are timed warm (one untimed run of each first, which also loads the compiled
kernels), the repeats alternating between them.

Real buildings: the observed env (``digslam/DigCoverage-v0``) on ``world="floorplan"`` levels (windows of
the shipped KTH plans, whose traced walls have more edges than a rooms level) and on ``world="rooms"``
levels, otherwise the same settings, runs the same actions on the same seeds (a new level every
:data:`LEVEL_STEPS` steps, the levels of ``bench_observer.py``), the two alternating in chunks of
:data:`CHUNK` steps so that a load spike lands on both; ``floorplan_over_rooms`` is the floorplan step rate
over the rooms one (median of the repeats; the issue's bound: at least 0.7), ``floorplan_over_rooms_unicycle``
the same with the unicycle dynamics.

Usage: ``python benchmarks/bench_env.py [--steps N] [--repeats R] [--quick]`` (``--quick``: 100 steps, one
repeat). The last line is
``ratio_vs_raycast=<ours / reference>`` (median of the repeats, wall-clock time).
"""

from __future__ import annotations

import argparse
import math
import time

import gymnasium as gym
import numpy as np
import pymunk

import digslam.envs  # noqa: F401  (registers the environments)
from digslam.envs.sim.robot import RobotSim

RAYS_PER_CONE = 5
#: Steps per level of the floorplan/rooms comparison (resets, untimed, with the seeds 0, LEVEL_STEPS, ...).
LEVEL_STEPS = 500
#: Steps per chunk of the floorplan/rooms alternation.
CHUNK = 100


def make_ours(dynamics: str = "pymunk") -> gym.Env:
    """The benchmarked environment: the rock field of 30 obstacles, 8 cones + omni."""
    # start at the origin (carved free by the generator), as before procedural starts: the same world, start
    # and actions from run to run and release to release
    return gym.make("digslam/Explore-v0", world="rocks", n_obstacles=30, n_sonars=8, omni=True, dt=0.1,
                    substeps=4, dynamics=dynamics, start_rule="origin")  # fmt: skip


def run_ours(env: gym.Env, actions: np.ndarray) -> float:
    """Wall time of ``len(actions)`` env steps."""
    env.reset(seed=0)
    t0 = time.perf_counter()
    for a in actions:
        env.step(a)
    return time.perf_counter() - t0


def run_reference(env: gym.Env, actions: np.ndarray) -> float:
    """Wall time of the pymunk ray-casting loop on the same world and actions."""
    u = env.unwrapped
    env.reset(seed=0)
    cfg, suite = u.config, u.suite
    skin = 1.5 * cfg.max_speed * cfg.dt / cfg.substeps  # the env's collision skin
    sim = RobotSim(u.world, cfg.robot_radius, u.sim.pose, cfg.max_force, cfg.max_torque, skin)
    space, body = sim.space, sim.body
    filt = pymunk.ShapeFilter(group=1)
    sim.shape.filter = filt
    cones = [(a, g, r) for a, g, r in zip(suite.alpha, suite.gamma, suite.r_max, strict=True) if g < math.pi]
    offsets = [
        (a + g * (2 * k / (RAYS_PER_CONE - 1) - 1), r) for a, g, r in cones for k in range(RAYS_PER_CONE)
    ]
    omni_range = float(suite.r_max[suite.gamma >= math.pi][0])
    h = cfg.dt / cfg.substeps
    t0 = time.perf_counter()
    for a in actions:
        v, w = float(a[0]) * cfg.max_speed, float(a[1]) * cfg.max_yaw_rate
        for _ in range(cfg.substeps):
            th = body.angle
            sim.control.velocity = (v * math.cos(th), v * math.sin(th))
            sim.control.angular_velocity = w
            space.step(h)
        p, th = body.position, body.angle
        ranges = []
        for off, r in offsets:
            end = (p.x + r * math.cos(th + off), p.y + r * math.sin(th + off))
            hit = space.segment_query_first(p, end, 0.0, filt)
            ranges.append(hit.alpha * r if hit is not None else math.inf)
        nearest = space.point_query_nearest(p, omni_range, filt)
        ranges.append(nearest.distance if nearest is not None else math.inf)
    return time.perf_counter() - t0


def make_observed(world: str, dynamics: str = "pymunk") -> gym.Env:
    """The observed env on ``world`` levels (the defaults otherwise; no coverage target ends an episode)."""
    return gym.make("digslam/DigCoverage-v0", world=world, dynamics=dynamics, target=1.0,
                    max_episode_steps=LEVEL_STEPS + 1)  # fmt: skip


def run_levels(envs: list[gym.Env], actions: np.ndarray) -> list[float]:
    """Total wall time of each env over ``actions``: all reset with the same seed every :data:`LEVEL_STEPS`
    steps (untimed), the envs taking turns chunk by chunk (:data:`CHUNK` steps)."""
    times = [0.0] * len(envs)
    for start in range(0, len(actions), LEVEL_STEPS):
        for e in envs:
            e.reset(seed=start)
        block = actions[start : start + LEVEL_STEPS]
        for c in range(0, len(block), CHUNK):
            for i, e in enumerate(envs):
                t0 = time.perf_counter()
                for a in block[c : c + CHUNK]:
                    e.step(a)
                times[i] += time.perf_counter() - t0
    return times


def sensing_only(env: gym.Env, n: int) -> tuple[float, float]:
    """Sensor calls per second at ``n`` free poses: exact cones vs the reference ray fan (no physics)."""
    u = env.unwrapped
    env.reset(seed=0)
    world, suite, space = u.world, u.suite, u.sim.space
    filt = pymunk.ShapeFilter(group=1)
    u.sim.shape.filter = filt
    rng = np.random.default_rng(1)
    poses = [world.sample_free_pose(rng, 0.3) for _ in range(n)]
    cones = [(a, g, r) for a, g, r in zip(suite.alpha, suite.gamma, suite.r_max, strict=True) if g < math.pi]
    offsets = [
        (a + g * (2 * k / (RAYS_PER_CONE - 1) - 1), r) for a, g, r in cones for k in range(RAYS_PER_CONE)
    ]
    t0 = time.perf_counter()
    for p in poses:
        suite.true_ranges(world, p)
    t1 = time.perf_counter()
    for x, y, th in poses:
        for off, r in offsets:
            space.segment_query_first(
                (x, y), (x + r * math.cos(th + off), y + r * math.sin(th + off)), 0.0, filt
            )
        space.point_query_nearest((x, y), 5.0, filt)
    t2 = time.perf_counter()
    return n / (t1 - t0), n / (t2 - t1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="a smoke run: 100 steps, one repeat")
    args = parser.parse_args()
    if args.quick:
        args.steps, args.repeats = 100, 1
    env, uni = make_ours(), make_ours("unicycle")
    rng = np.random.default_rng(0)
    actions = np.column_stack([rng.uniform(0.3, 1.0, args.steps), rng.uniform(-1, 1, args.steps)])
    actions = actions.astype(np.float32)
    env.reset(seed=0)
    n_edges = len(env.unwrapped.world.edges)
    # Warm-up, untimed: loads the compiled kernels (numba's on-disk cache) and lets gymnasium's passive env
    # checker see its first step; then both loops run warm, on the same world and actions.
    run_ours(env, actions[:50])
    run_ours(uni, actions[:50])
    run_reference(env, actions[:50])
    env.unwrapped.suite.true_ranges(env.unwrapped.world, env.unwrapped.sim.pose)  # sensing_only's kernel
    levels = [make_observed(w, d) for d in ("pymunk", "unicycle") for w in ("rooms", "floorplan")]
    run_levels(levels, actions[:50])
    ours, ref, raw, ours_u, raw_u, plan, plan_u = [], [], [], [], [], [], []
    for _ in range(args.repeats):
        ours.append(args.steps / run_ours(env, actions))
        ours_u.append(args.steps / run_ours(uni, actions))
        ref.append(args.steps / run_reference(env, actions))
        raw.append(args.steps / run_ours(env.unwrapped, actions))
        raw_u.append(args.steps / run_ours(uni.unwrapped, actions))
        t_rooms, t_plan, t_rooms_u, t_plan_u = run_levels(levels, actions)
        plan.append(t_rooms / t_plan)
        plan_u.append(t_rooms_u / t_plan_u)
    plan_edges = []  # the floorplan levels timed (the same seeds give the same levels)
    for start in range(0, args.steps, LEVEL_STEPS):
        levels[1].reset(seed=start)
        plan_edges.append(len(levels[1].unwrapped.world.edges))
    o, r, o_u = float(np.median(ours)), float(np.median(ref)), float(np.median(ours_u))
    s_ours, s_ref = sensing_only(env, args.steps)
    print(
        f"world: rocks, 30 obstacles, {n_edges} edges; 8 cones + omni; dt=0.1 s, 4 substeps; "
        f"{args.steps} steps"
    )
    print(
        f"ours_steps_per_s={o:.0f}  (exact cones, noise, record, truth, coverage reward; gym.make wrappers)"
    )
    print(
        f"ours_unwrapped_steps_per_s={float(np.median(raw)):.0f}  (the same env without gym.make's wrappers)"
    )
    print(f"ours_steps_per_s_unicycle={o_u:.0f}  ours_unwrapped_steps_per_s_unicycle={float(np.median(raw_u)):.0f}"
          "  (exact unicycle dynamics)")  # fmt: skip
    print(f"hard_stops={env.unwrapped.sim.stops}  (premise guard, last episode)")
    print(
        f"reference_steps_per_s={r:.0f}  "
        f"(pymunk, {RAYS_PER_CONE} rays/cone segment_query_first + omni nearest)"
    )
    print(
        f"sensing_only: exact_cones_per_s={s_ours:.0f} ray_fan_per_s={s_ref:.0f} ratio={s_ours / s_ref:.3f}"
    )
    print(f"ratio_vs_raycast_unicycle={o_u / r:.3f}")
    print(
        f"floorplan levels: {len(plan_edges)}, edges mean {np.mean(plan_edges):.0f} max {max(plan_edges)}; "
        f"rooms levels: {len(levels[0].unwrapped.world.edges)} edges; observed env (DigCoverage-v0)"
    )
    print(f"floorplan_over_rooms_unicycle={float(np.median(plan_u)):.3f}")
    print(f"floorplan_over_rooms={float(np.median(plan)):.3f}")
    print(f"ratio_vs_raycast={o / r:.3f}")


if __name__ == "__main__":
    main()
