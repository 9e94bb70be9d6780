"""The premise of the guarantee, checked: every recorded interval contains the independently recomputed truth.

:mod:`premise` recomputes the motion exactly (mpmath, 200 bits, from ``truth.pieces`` under the unicycle;
``Fraction`` and mpmath from ``truth.states`` under pymunk) and the ranges by brute-force cone geometry from
``world.edges``; these tests run it, under both dynamics, over hostile action sequences (tiny, subnormal,
huge-but-valid and sign-alternating yaw actions), zero noise bounds, the adversarial noise model and robots
pressed against walls, and check that the checker itself catches corrupted records.
"""

from __future__ import annotations

import copy
import math

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from premise import PremiseChecker, PremiseViolation, arc_exact, check_episode, cone_distances, mpf

from digslam.envs.explore.env import ExploreEnv

ZERO = {"speed": 0.0, "yaw_rate": 0.0, "heading": 0.0, "range": 0.0}
NOISES = {
    "uniform": {},
    "zero": ZERO,
    "adversarial": {"model": "adversarial"},
    "adversarial-zero": {**ZERO, "model": "adversarial"},
}
YAWS = (
    0.0,
    1e-12,
    -1e-12,
    2e-12,
    1e-9,
    -1e-9,
    5e-324,
    -5e-324,
    2.2e-308,
    -2.2e-308,
    1e-6,
    1e-3,
    1.0,
    -1.0,
    1.0 + 5e-7,
    -1.0 - 5e-7,
)  # the last two: inside the accepted tolerance, clipped to +-1
SPEEDS = (0.0, 1.0, -1.0, 0.5, 1e-12, 5e-324, 1.0 + 5e-7)
FAST = settings(max_examples=10, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])  # fmt: skip
_ENVS: dict[tuple[str, str, str], ExploreEnv] = {}


def _env(world: str, noise: str, dynamics: str = "pymunk") -> ExploreEnv:
    key = (world, noise, dynamics)
    if key not in _ENVS:
        _ENVS[key] = ExploreEnv(world=world, noise=NOISES[noise], n_obstacles=12, dynamics=dynamics)
    return _ENVS[key]


def _action() -> st.SearchStrategy:
    v = st.one_of(st.sampled_from(SPEEDS), st.floats(-1.0, 1.0))
    w = st.one_of(st.sampled_from(YAWS), st.floats(-1.0, 1.0))
    return st.tuples(v, w)


@st.composite
def _actions(draw: st.DrawFn, n_max: int = 10) -> list[tuple[float, float]]:
    """A short action sequence; sometimes a run of sign-alternating tiny yaws at full speed."""
    acts = draw(st.lists(_action(), min_size=1, max_size=n_max))
    if draw(st.booleans()):
        y = draw(st.sampled_from(YAWS[1:10]))
        acts += [(1.0, y if k % 2 == 0 else -y) for k in range(draw(st.integers(2, 6)))]
    return acts


# --- the checker's pieces against closed forms -------------------------------------------------------------
def test_exact_arc_closed_forms() -> None:
    x, y = arc_exact(mpf(0.0), mpf(0.0), 0.0, 1.0, 2.0, 0.0)  # straight
    assert x == 2 and y == 0
    with mpmath.workprec(200):
        tau = float(2 * mpmath.pi)
        x, y = arc_exact(mpf(1.0), mpf(2.0), 0.0, 1.0, tau, tau)  # a full circle of radius 1: back home
        assert abs(x - 1) < 1e-15 and abs(y - 2) < 1e-15
        x, y = arc_exact(mpf(0.0), mpf(0.0), 0.0, 1.0, 1.0, 1e-300)  # tiny turn: the chord is the path
        assert abs(x - 1) < mpmath.mpf(10) ** -100 and abs(y - 5e-301) < mpmath.mpf(10) ** -310


def test_cone_distances_closed_forms() -> None:
    from premise import ExactPose

    edges = np.array([[2.0, -1.0, 2.0, 1.0], [-3.0, 5.0, 3.0, 5.0]])
    pose = ExactPose(mpf(0.0), mpf(0.0), 0.0)
    alpha = np.array([0.0, math.pi, 0.0, 0.5, math.pi / 2])
    gamma = np.array([0.1, 0.3, math.pi, 0.1, 0.01])
    d = cone_distances(pose, alpha, gamma, edges, np.full(5, 10.0))
    with mpmath.workprec(200):
        assert d[0] == 2 and d[1] == mpmath.inf and d[2] == 2 and d[4] == 5
        # direction 0.5 +- 0.1: the wall x = 2 is met first by the lower boundary ray at angle 0.4
        assert abs(d[3] - 2 / mpmath.cos(mpmath.mpf(0.5) - mpmath.mpf(0.1))) < mpmath.mpf(10) ** -50


# --- property tests over hostile actions -------------------------------------------------------------------
@pytest.mark.parametrize("dynamics", ["pymunk", "unicycle"])
@FAST
@given(world=st.sampled_from(["room", "rocks"]), noise=st.sampled_from(sorted(NOISES)),
       seed=st.integers(960000, 960999), actions=_actions())  # fmt: skip
@example(
    world="room", noise="adversarial", seed=960000, actions=[(5e-324, 0.0)]
)  # a subnormal speed: it once
@example(world="rocks", noise="zero", seed=960201, actions=[(1.0, 2e-12)] * 3)  # broke the simulator's bound
def test_premise_holds_for_hostile_actions(
    world: str, noise: str, seed: int, actions: list, dynamics: str
) -> None:
    env = _env(world, noise, dynamics)
    chk = check_episode(env, seed, actions, radius=env.config.robot_radius)
    assert chk.k == len(actions)


@pytest.mark.parametrize("dynamics", ["pymunk", "unicycle"])
@FAST
@given(seed=st.integers(960000, 960999), yaw=st.sampled_from(YAWS), n=st.integers(3, 12))
def test_premise_holds_for_constant_tiny_yaws(seed: int, yaw: float, n: int, dynamics: str) -> None:
    check_episode(_env("rocks", "adversarial-zero", dynamics), seed, [(1.0, yaw)] * n)


def _facing_nearest_wall(env: ExploreEnv, seed: int) -> tuple[float, float, float]:
    """The reset pose of ``seed``, turned to face the nearest obstacle point."""
    env.reset(seed=seed)
    x, y, _ = env.sim.pose
    e = env.world.edges
    d = e[:, 2:] - e[:, :2]
    t = np.clip(((np.array([x, y]) - e[:, :2]) * d).sum(1) / np.maximum((d * d).sum(1), 1e-300), 0, 1)
    p = e[:, :2] + t[:, None] * d
    k = int(np.argmin(np.hypot(p[:, 0] - x, p[:, 1] - y)))
    return float(x), float(y), math.atan2(p[k, 1] - y, p[k, 0] - x)


@pytest.mark.parametrize("dynamics", ["unicycle", "pymunk"])
@pytest.mark.parametrize("world,noise", [("room", "zero"), ("rocks", "adversarial"), ("rooms", "uniform")])
def test_premise_holds_against_a_wall(world: str, noise: str, dynamics: str) -> None:
    """Drive full speed into the nearest wall for many steps (unicycle: blocked pieces, reduced speeds;
    pymunk: contacts, the disc kept off the wall), then keep pressing with tiny and sign-alternating yaw
    actions."""
    probe = ExploreEnv(world=world, n_obstacles=12, dynamics=dynamics)
    start = _facing_nearest_wall(probe, 960300)
    env = ExploreEnv(world=world, n_obstacles=12, noise=NOISES[noise], start=start, dynamics=dynamics)
    acts = [(1.0, 0.0)] * 70 + [(1.0, 2e-12), (1.0, -2e-12), (1.0, 5e-324), (1.0, 1e-9), (-1.0, 1e-12)] * 3
    chk = check_episode(env, 960300, acts, dense=False, radius=env.config.robot_radius)
    assert chk.k == len(acts)
    assert env.sim.bumps >= 1  # it did hit the wall
    if dynamics == "pymunk":
        assert chk.substeps == 4 * len(acts) and len(chk.paths) == len(acts)
        assert env.sim.stops <= 2  # the skin keeps pymunk's contacts off the disc
        return
    seg = np.array(chk.pieces)
    blocked = (seg[:, 1, 1] > 0) & (seg[:, 1, 0] != seg[:, 0, 0])
    assert blocked.sum() >= 10  # many steps ran a reduced-speed (or stopped) second piece


# --- the checker catches corrupted records -----------------------------------------------------------------
def _one_step(noise: str = "zero", dynamics: str = "pymunk") -> tuple[ExploreEnv, dict, dict]:
    env = ExploreEnv(world="rocks", n_obstacles=12, noise=NOISES[noise], dynamics=dynamics)
    _, info0 = env.reset(seed=960400)
    _, _, _, _, info1 = env.step(np.array([1.0, 0.3]))
    return env, info0, info1


@pytest.mark.parametrize("dynamics", ["unicycle", "pymunk"])
@pytest.mark.parametrize("what", ["range", "no_echo", "heading", "speed", "yaw", "lateral", "pose", "tau"])
def test_the_checker_catches_a_corrupted_record(what: str, dynamics: str) -> None:
    env, info0, info1 = _one_step(dynamics=dynamics)
    rec, truth = copy.deepcopy(info1["record"]), copy.deepcopy(info1["truth"])
    echo = np.nonzero(~rec.no_echo)[0]
    if what == "range":
        rec.range[echo[0]] += 0.05
    elif what == "no_echo":
        s = echo[0]
        rec.no_echo[s], rec.range[s] = True, (rec.r_max[s], np.inf)
    elif what == "heading":
        rec.heading += 2e-9
    elif what == "speed":
        rec.speed[:] = (rec.speed[1] + 1e-12, rec.speed[1] + 1.0)
    elif what == "yaw":
        rec.yaw_rate[:] = (rec.yaw_rate[1] + 1e-12, rec.yaw_rate[1] + 1.0)
    elif what == "lateral":  # pymunk: a 1 m/s turn makes the lateral hull about +-0.0125 m/s wide
        rec.lateral[:] = (rec.lateral[1] + 1e-12, rec.lateral[1] + 1.0)
    elif what == "pose":
        truth.pose[0] += 1e-9
    elif dynamics == "pymunk":
        truth.taus[0] += 1e-3
    else:
        truth.pieces[0, 1] += 1e-3
    chk = PremiseChecker(env.world.edges)
    chk.reset(info0["record"], info0["truth"])
    with pytest.raises(PremiseViolation):
        chk.step(rec, truth)
    chk = PremiseChecker(env.world.edges)  # the untouched data pass
    chk.reset(info0["record"], info0["truth"])
    chk.step(info1["record"], info1["truth"])
