"""pymunk moves the robot, and the guarantee still holds (issue #23).

The truth of a pymunk step is the piecewise-linear path through the substep states read back from pymunk
(:mod:`digslam.envs.sim.dynamics_jit`). These tests recompute it independently, in exact arithmetic from the
stored floats (:mod:`premise`: ``Fraction`` velocities and yaw rates, the body-frame velocity's extremes over
each substep's heading range in mpmath, segment-to-edge distances in ``Fraction``), and check that every
record bounds it and that the robot's disc never overlaps an obstacle, over random and hostile policies
(ramming, spinning in corners, sliding along walls, full-speed reversals, extreme actions) on every world
generator; plus the kernels alone against exact references, a thin wall at high speed, and the hard-stop
counter under ramming.
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from premise import (
    PREC,
    PremiseChecker,
    check_episode,
    mean_velocity_exact,
    segment_distance2,
    velocity_extremes,
)

from digslam.envs import ExploreEnv, World
from digslam.envs.sim.dynamics_jit import (
    free_radius,
    step_bounds,
    step_bounds_free,
    substep_clear,
    substep_times,
)
from digslam.envs.sim.geometry_jit import edge_boxes
from digslam.envs.sim.robot import RobotSim

WORLDS = ("room", "rocks", "caves", "rooms")
POLICIES = ("random", "ram", "spin", "slide", "reverse", "extreme")
FAST = settings(max_examples=60, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow])  # fmt: skip
_ENVS: dict[tuple[str, str], ExploreEnv] = {}


def _env(world: str, noise: str = "uniform") -> ExploreEnv:
    key = (world, noise)
    if key not in _ENVS:
        nz = {"model": "adversarial"} if noise == "adversarial" else {}
        _ENVS[key] = ExploreEnv(world=world, n_obstacles=12, noise=nz, dynamics="pymunk")
    return _ENVS[key]


# --- the substep durations ---------------------------------------------------------------------------------
@FAST
@given(dt=st.one_of(st.floats(2.0**-1000, 1e6), st.sampled_from([0.1, 0.05, 1.0 / 3, 1e-300, 2.0**-1000])),
       n=st.integers(1, 64))  # fmt: skip
def test_substep_durations_are_exact_and_sum_to_dt(dt: float, n: int) -> None:
    taus = substep_times(dt, n)
    s = [Fraction(j * dt / n) for j in range(n)] + [Fraction(dt)]
    assert len(taus) == n and all(t > 0 for t in taus)
    assert [Fraction(float(t)) for t in taus] == [s[j + 1] - s[j] for j in range(n)]  # exact differences
    assert sum(Fraction(float(t)) for t in taus) == Fraction(dt)


def test_substep_durations_refuse_underflow() -> None:
    with pytest.raises(ValueError, match="dt"):
        substep_times(5e-324, 4)
    with pytest.raises(ValueError, match="substeps"):
        substep_times(0.1, 0)


# --- the bounds kernel against the exact extremes ----------------------------------------------------------
_ANGLES = st.one_of(
    st.floats(-10.0, 10.0),
    st.sampled_from([0.0, math.pi / 2, math.pi, -math.pi / 2, 1e6, -1e6 + 0.3, 5e-324, 2.0**-1000]),
)
_DELTAS = st.one_of(st.floats(-0.5, 0.5), st.sampled_from([0.0, 5e-324, -5e-324, 1e-300, 1e-12, 3.5, -7.0]))
_MOVES = st.one_of(st.floats(-1.0, 1.0), st.sampled_from([0.0, 5e-324, 1e-300, -1e-12, 40.0]))


@FAST
@given(x=st.floats(-1e3, 1e3), y=st.floats(-1e3, 1e3), a=_ANGLES,
       moves=st.lists(st.tuples(_MOVES, _MOVES, _DELTAS), min_size=1, max_size=6),
       dt=st.sampled_from([0.1, 0.025, 1e-3, 1.0 / 3]))  # fmt: skip
def test_step_bounds_contain_the_exact_body_velocity(x: float, y: float, a: float, moves: list,
                                                     dt: float) -> None:  # fmt: skip
    taus = substep_times(dt, len(moves))
    states = [(x, y, a)]
    for dx, dy, da in moves:
        px, py, pa = states[-1]
        states.append((px + dx, py + dy, pa + da))
    states_a = np.array(states)
    out = np.empty((5, 2))
    step_bounds(states_a, taus, out)
    for j in range(len(moves)):
        tau = Fraction(float(taus[j]))
        (x0, y0, a0), (x1, y1, a1) = states_a[j], states_a[j + 1]
        ux, uy = (Fraction(x1) - Fraction(x0)) / tau, (Fraction(y1) - Fraction(y0)) / tau
        assert Fraction(out[2, 0]) <= (Fraction(a1) - Fraction(a0)) / tau <= Fraction(out[2, 1])
        l1, h1, l2, h2 = velocity_extremes(ux, uy, float(a0), float(a1))
        with mpmath.workprec(PREC):
            assert mpmath.mpf(out[0, 0]) <= l1 and h1 <= mpmath.mpf(out[0, 1]), (j, l1, h1, out[0])
            assert mpmath.mpf(out[1, 0]) <= l2 and h2 <= mpmath.mpf(out[1, 1]), (j, l2, h2, out[1])
    m1, m2 = mean_velocity_exact(states_a, taus)  # the odometry increment, at 200 bits
    with mpmath.workprec(PREC):
        for lo_hi, m in ((out[3], m1), (out[4], m2)):
            assert mpmath.mpf(lo_hi[0]) <= m <= mpmath.mpf(lo_hi[1]), (m, lo_hi)


def test_the_mean_velocity_stays_tight_when_the_velocity_changes_within_the_step() -> None:
    """From rest to full speed within one step (inertia): the hull spans [0, 1] m/s, the increment does
    not widen."""
    taus = substep_times(0.1, 4)
    xs = np.cumsum([0.0, 0.0, 0.02, 0.025, 0.025])
    out = np.empty((5, 2))
    step_bounds(np.column_stack([xs, np.zeros(5), np.zeros(5)]), taus, out)
    assert out[0, 1] - out[0, 0] > 0.99  # the hull: from 0 to 1 m/s
    assert out[3, 0] <= 0.7 <= out[3, 1] and out[3, 1] - out[3, 0] < 1e-14
    assert out[4, 0] <= 0.0 <= out[4, 1] and out[4, 1] - out[4, 0] < 1e-300  # no sideways motion


def test_step_bounds_are_tight_for_straight_motion_and_exact_at_rest() -> None:
    taus = substep_times(0.1, 4)
    straight = np.array([[0.025 * j, 0.0, 0.0] for j in range(5)])
    out = np.empty((5, 2))
    step_bounds(straight, taus, out)
    assert out[0, 0] <= 1.0 <= out[0, 1] and out[0, 1] - out[0, 0] < 1e-14
    assert out[1].tolist() == [0.0, 0.0] and out[2].tolist() == [0.0, 0.0]
    step_bounds(np.tile([1.0, 2.0, 3.0], (5, 1)), taus, out)
    assert out.tolist() == [[0.0, 0.0]] * 5
    with pytest.raises(ValueError, match="out"):
        step_bounds(straight, taus, np.empty((3, 2)))


# --- the premise guard against exact geometry --------------------------------------------------------------
@settings(max_examples=300, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(p=st.tuples(st.floats(-1, 1), st.floats(-1, 1)), d=st.tuples(st.floats(-0.6, 0.6), st.floats(-0.6, 0.6)),
       e=st.tuples(*[st.floats(-1.5, 1.5)] * 4), thin=st.booleans())  # fmt: skip
def test_substep_clear_is_sound_and_tight(p: tuple, d: tuple, e: tuple, thin: bool) -> None:
    edges = np.array([e, (e[0], e[1], e[0] + 1e-3, e[1])] if thin else [e], dtype=np.float64)
    x1, y1 = p[0] + d[0], p[1] + d[1]
    ok = substep_clear(p[0], p[1], x1, y1, 0.2, edges, edge_boxes(edges))
    dist2 = min(segment_distance2((p[0], p[1]), (x1, y1), (k[0], k[1]), (k[2], k[3])) for k in edges)
    r2 = Fraction(0.2) ** 2
    if ok:
        assert dist2 >= r2
    else:  # refused only within a hair of the radius
        assert dist2 < (Fraction(0.2) + Fraction(1, 10**9)) ** 2


@settings(max_examples=300, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(p=st.tuples(st.floats(-2, 2), st.floats(-2, 2)), e=st.lists(st.tuples(*[st.floats(-2, 2)] * 4), min_size=1,
       max_size=4), reach=st.sampled_from([0.05, 1.0, 10.0]))  # fmt: skip
def test_free_radius_is_sound(p: tuple, e: list, reach: float) -> None:
    """The guard's fast path: the disc of radius 0.2 anywhere within ``free_radius`` of ``p`` keeps off every
    edge (exact: ``dist(p, edges) >= 0.2 + rho``)."""
    edges = np.array(e, dtype=np.float64)
    rho = free_radius(p[0], p[1], 0.2, reach, edges, edge_boxes(edges))
    assert rho <= reach
    if rho > 0:
        d2 = min(segment_distance2(p, p, k[:2], k[2:]) for k in edges)
        assert d2 >= (Fraction(0.2) + Fraction(rho)) ** 2


def test_substep_clear_catches_tunnelling_through_a_thin_wall() -> None:
    sliver = np.array([[2.0, -3.0, 2.0, 3.0], [2.001, -3.0, 2.001, 3.0]])
    bbox = edge_boxes(sliver)
    assert not substep_clear(1.0, 0.0, 3.0, 0.0, 0.2, sliver, bbox)  # jumps clean through
    assert not substep_clear(1.5, 0.3, 2.6, -0.4, 0.2, sliver, bbox)
    assert substep_clear(1.0, 0.0, 1.79, 0.0, 0.2, sliver, bbox)


# --- the robot in the env: every substep of every step inside its record ----------------------------------
def _policy(name: str, rng: np.random.Generator, k: int) -> tuple[float, float]:
    if name == "random":
        return float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1))
    if name == "ram":  # full speed ahead, a new heading now and then
        return 1.0, (0.0 if k % 40 < 30 else 1.0)
    if name == "spin":  # pressing into whatever is ahead while spinning both ways
        return 1.0, (1.0 if (k // 15) % 2 else -1.0)
    if name == "slide":  # mostly straight, a slight constant turn: grazes and slides along walls
        return 1.0, 0.05
    if name == "reverse":  # full-speed reversals every step, with a turn
        return (1.0 if k % 2 else -1.0), (0.7 if k % 6 < 3 else -0.7)
    extreme = [(1.0, 5e-324), (-1.0, -5e-324), (1e-300, 1.0), (1.0 + 5e-7, -1.0 - 5e-7), (5e-324, 5e-324),
               (-1.0, 1.0), (1.0, 2.2e-308), (0.0, 0.0)]  # fmt: skip
    return extreme[k % len(extreme)]


@pytest.mark.parametrize("world", WORLDS)
@pytest.mark.parametrize("policy", POLICIES)
def test_every_substep_lies_inside_the_record(world: str, policy: str) -> None:
    env = _env(world, "adversarial" if policy in ("ram", "extreme") else "uniform")
    rng = np.random.default_rng(10 * WORLDS.index(world) + POLICIES.index(policy))
    acts = [_policy(policy, rng, k) for k in range(120)]
    chk = check_episode(env, 970000 + WORLDS.index(world), acts, dense=False, ranges=False,
                        radius=env.config.robot_radius)  # fmt: skip
    assert chk.k == len(acts) and chk.substeps == 4 * len(acts)
    assert env.sim.stops <= 2  # hard stops are rare: the collision skin keeps pymunk off the walls


@pytest.mark.parametrize("world", WORLDS)
def test_premise_with_ranges_holds_for_pymunk(world: str) -> None:
    env = _env(world, "adversarial")
    rng = np.random.default_rng(3)
    acts = [(1.0, 0.0)] * 25 + [tuple(rng.uniform(-1, 1, 2)) for _ in range(10)]
    check_episode(env, 970100, acts, dense=False, radius=env.config.robot_radius)


def test_ramming_rarely_needs_a_hard_stop() -> None:
    stops, steps, bumps = 0, 0, 0
    for world in WORLDS:
        env = _env(world)
        env.reset(seed=970200)
        for k in range(300):
            env.step(np.array([1.0, 0.0 if k % 60 < 45 else 1.0]))
        stops, steps, bumps = stops + env.sim.stops, steps + 300, bumps + env.sim.bumps
    assert bumps >= 4  # it did hit walls
    assert stops <= 0.01 * steps * 4, stops  # at most 1 % of the substeps


def test_thin_wall_at_high_speed_is_never_crossed() -> None:
    frame = np.array([(-5.0, -5.0), (5.0, -5.0), (5.0, 5.0), (-5.0, 5.0)])
    sliver = np.array([(2.0, -3.0), (2.001, -3.0), (2.001, 3.0), (2.0, 3.0)])  # 1 mm thick wall
    world = World((-5, -5, 5, 5), [frame, sliver])
    chk = PremiseChecker(world.edges, radius=0.2, ranges=False)
    for speed, skin, force in ((5.0, 5.0 * 0.1 / 4 * 1.5, 200.0), (5.0, 0.0, 200.0), (40.0, 0.0, 1e5)):
        sim = RobotSim(world, 0.2, np.array([0.0, 0.0, 0.0]), max_force=force, skin=skin, dynamics="pymunk")
        for _ in range(60):
            sim.step(speed, 0.0, 0.1, 4)
            assert sim.pose[0] <= 2.0 - 0.2
            chk.check_path(sim.states, sim.taus)  # exact clearance of every substep segment
        assert sim.bumps >= 1
        if skin == 0.0:  # without a skin pymunk lets the disc in (or through): the guard stops it
            assert sim.stops >= 1


def test_walls_make_the_robot_slide() -> None:
    """Driving into a wall at 30 degrees: the wall turns the motion sideways (a lateral velocity the record
    bounds), which no unicycle with the recorded heading explains."""
    frame = np.array([(-5.0, -5.0), (5.0, -5.0), (5.0, 5.0), (-5.0, 5.0)])
    world = World((-5, -5, 5, 5), [frame])
    sim = RobotSim(world, 0.2, np.array([3.5, 0.0, math.radians(30)]), skin=0.0375, dynamics="pymunk")
    lat = []
    for _ in range(30):
        sim.step(1.0, 0.0, 0.1, 4)
        lat.append(sim.lateral_hull)
    assert max(hi for _, hi in lat) > 0.1  # slid along the wall (to the left of its heading)
    assert sim.pose[0] <= 5.0 - 0.2 and sim.pose[1] > 0.5


def test_the_checker_catches_a_disc_overlap_and_a_bad_velocity() -> None:
    from premise import PremiseViolation

    wall = np.array([[1.0, -1.0, 1.0, 1.0]])
    chk = PremiseChecker(wall, radius=0.2, ranges=False)
    taus = substep_times(0.1, 2)
    chk.check_path(np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [0.79, 0.0, 0.0]]), taus)  # 0.21 m off: fine
    with pytest.raises(PremiseViolation, match="overlaps"):
        chk.check_path(np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.81, 0.0, 0.0]]), taus)
    with pytest.raises(PremiseViolation, match="overlaps"):  # jumps through the wall between two states
        chk.check_path(np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [1.5, 0.0, 0.0]]), taus)

    class Rec:  # a record whose lateral interval misses a sideways step
        speed, lateral, yaw_rate = np.array([-1.0, 20.0]), np.array([-0.01, 0.01]), np.array([-1.0, 1.0])

    with pytest.raises(PremiseViolation, match="lateral"):
        chk.check_path(np.array([[0.0, 0.0, 0.0], [0.0, 0.05, 0.0], [0.0, 0.05, 0.0]]), taus, Rec())


# --- the same work, less overhead ----------------------------------------------------------------------------
def test_step_bounds_free_is_step_bounds_then_free_radius() -> None:
    """The simulator's one call after a step: the hulls of :func:`step_bounds` and the :func:`free_radius` of
    the step's end, bit for bit."""
    env = _env("rocks")
    env.reset(seed=0)
    assert env.world is not None
    edges, bbox = env.world.edges, env.world.bbox
    rng = np.random.default_rng(3)
    for _ in range(50):
        start = np.array([rng.uniform(-8, 8), rng.uniform(-8, 8), 0.0])
        states = start + np.cumsum(rng.normal(0.0, 0.05, (5, 3)), axis=0)
        taus = substep_times(0.1, 4)
        a, b = np.empty((5, 2)), np.empty((5, 2))
        step_bounds(states, taus, a)
        rho = free_radius(states[-1, 0], states[-1, 1], 0.2, 1.0, edges, bbox)
        assert step_bounds_free(states, taus, b, 0.2, 1.0, edges, bbox) == rho
        assert np.array_equal(a, b)


def test_substeps_calling_chipmunk_directly_match_space_step() -> None:
    """The substeps call chipmunk's step directly while the space's queues are empty; a queued body sends
    them through ``Space.step``. Both give the same states, bit for bit, contacts and bumps included."""
    frame = np.array([(-5.0, -5.0), (5.0, -5.0), (5.0, 5.0), (-5.0, 5.0)])
    world = World((-5, -5, 5, 5), [frame])
    pose = np.array([3.5, 0.0, math.radians(30)])
    direct, wrapped = (RobotSim(world, 0.2, pose, skin=0.0375, dynamics="pymunk") for _ in range(2))
    rng = np.random.default_rng(5)
    for v, w in zip(rng.uniform(-0.5, 1.5, 80), rng.uniform(-2.0, 2.0, 80), strict=True):
        wrapped.space._bodies_to_check.add(wrapped.body)  # pymunk checks its mass: Space.step it is
        assert direct.step(v, w, 0.1, 4) == wrapped.step(v, w, 0.1, 4)
        assert np.array_equal(direct.states, wrapped.states) and np.array_equal(direct.hulls, wrapped.hulls)
        ends = [(sim.speed, sim.lateral, sim.yaw_rate, sim.speed_hull) for sim in (direct, wrapped)]
        assert ends[0] == ends[1]
    assert direct.bumps == wrapped.bumps >= 1 and direct.stops == wrapped.stops
