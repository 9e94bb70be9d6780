"""The simulator's truth against exact arithmetic: the one arc (envs/sim/arc_jit.py), the robot's accumulated pose
error, and the rigorous range bounds of the record (envs/geometry_jit.sector_bounds_kernel).

The references are computed here in mpmath at 200 bits, with their own formulas: the exact arc of a piece,
and the exact sector distance from the true apex (nearest point of each edge inside the cone: endpoints and
foot inside it, and crossings of the boundary rays).
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from digslam.envs.sim.arc_jit import advance, arc_bounded, exact_duration, yaw_rate_bounds
from digslam.envs.sim.geometry_jit import edge_boxes, sector_bounds_kernel
from digslam.envs.sim.robot import RobotSim
from digslam.envs.sim.world import World

mp.mp.prec = 200

TINY_W = [
    0.0,
    5e-324,
    -5e-324,
    2.2e-308,
    1e-300,
    1e-15,
    2e-12,
    -2e-12,
    1e-9,
    1e-6,
    1e-3,
    0.5,
    -1.5,
    3.0,
    50.0,
]


def exact_piece(x: mp.mpf, y: mp.mpf, th0: float, th1: float, v: float, tau: float) -> tuple[mp.mpf, mp.mpf]:
    """The exact end of a piece: heading linear from th0 to th1 (floats, exact), speed v for tau s."""
    d = mp.mpf(th1) - mp.mpf(th0)
    s = mp.mpf(1) if d == 0 else mp.sin(d / 2) / (d / 2)
    m = mp.mpf(th0) + d / 2
    a = mp.mpf(v) * mp.mpf(tau)
    return x + a * s * mp.cos(m), y + a * s * mp.sin(m)


def exact_yaw(th0: float, th1: float, tau: float) -> mp.mpf:
    return (mp.mpf(th1) - mp.mpf(th0)) / mp.mpf(tau)


@settings(max_examples=300, deadline=None)
@given(
    x=st.floats(-20, 20),
    y=st.floats(-20, 20),
    th=st.one_of(st.floats(-4, 4), st.floats(-3000, 3000)),
    v=st.one_of(st.sampled_from([0.0, 5e-324, 1e-300, 1e-12, -2.0]), st.floats(-3, 3)),
    w=st.one_of(st.sampled_from(TINY_W), st.floats(-60, 60), st.floats(-1e-6, 1e-6)),
    tau=st.sampled_from([0.1, 0.025, 0.05, 1e-3, 7.0]),
)
def test_arc_error_bound_holds_against_200_bits(x, y, th, v, w, tau) -> None:
    x1, y1, th1, err = advance(x, y, th, v, w, tau)
    ex, ey = exact_piece(mp.mpf(x), mp.mpf(y), th, th1, v, tau)
    assert abs(mp.mpf(x1) - ex) <= err and abs(mp.mpf(y1) - ey) <= err
    assert err <= 1e-12 * max(1.0, abs(v) * tau) * (1 + abs(th) / 100)  # and the bound is tight enough
    lo, hi = yaw_rate_bounds(th, th1, tau)
    assert lo <= exact_yaw(th, th1, tau) <= hi


@pytest.mark.parametrize("w", [2e-12, 1e-9, 1e-6, 1e-3])
def test_small_yaw_rates_no_longer_cancel(w: float) -> None:
    """The issue's figures: the classic form erred by about 1e-16 v/|w| (1.1e-4 m at 2e-12)."""
    (x1, y1, th1), err = arc_bounded(np.array([3.0, -2.0, 0.7]), 1.0, w, 0.1)
    ex, ey = exact_piece(mp.mpf(3.0), mp.mpf(-2.0), 0.7, th1, 1.0, 0.1)
    assert max(abs(mp.mpf(x1) - ex), abs(mp.mpf(y1) - ey)) < 2e-15 and err < 1e-14


def test_exact_duration() -> None:
    t = 0.0
    for _ in range(5000):  # the env's clock: consecutive float times are an exact float apart
        t1 = t + 0.1
        tau = exact_duration(t, t1)
        assert mp.mpf(t1) - mp.mpf(t) == mp.mpf(tau)
        t = t1
    with pytest.raises(ValueError, match="exact positive float duration"):
        exact_duration(1e17, 1e17)


def _room() -> World:
    frame = np.array([(-5.0, -5.0), (5.0, -5.0), (5.0, 5.0), (-5.0, 5.0)])
    rock = np.array([(1.0, -1.0), (2.0, -0.5), (1.5, 1.0)])
    return World((-5, -5, 5, 5), [frame, rock])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_robot_pose_error_bounds_the_exact_chain(seed: int) -> None:
    """Hostile actions (tiny, subnormal, sign-alternating yaw rates, full speed into walls) over a long
    episode: the accumulated bound covers the distance between the simulator's pose and the exact chain."""
    rng = np.random.default_rng(seed)
    world = _room()
    sim = RobotSim(world, 0.2, np.array([-3.0, 0.5, 0.3]), dynamics="unicycle")
    ex, ey = mp.mpf(-3.0), mp.mpf(0.5)
    th_prev = sim.pose[2]
    t = 0.0
    for k in range(600):
        w = float(rng.choice(TINY_W)) * (-1) ** k * float(rng.choice([1.0, 0.0]) if k % 7 else 1.0)
        v = float(rng.choice([2.0, -2.0, 1e-12, 5e-324, 0.0, rng.uniform(-2, 2)]))
        t1 = t + 0.1
        sim.step(v, min(max(w, -3.0), 3.0), exact_duration(t, t1), 4)
        t = t1
        total = mp.mpf(0)
        for vp, tau, th_end in sim.pieces:
            if tau > 0:
                ex, ey = exact_piece(ex, ey, th_prev, th_end, vp, tau)
                lo, hi = sim.yaw_hull
                assert lo <= exact_yaw(th_prev, th_end, tau) <= hi
                assert sim.speed_hull[0] <= vp <= sim.speed_hull[1]
            th_prev = float(th_end)
            total += mp.mpf(tau)
        assert total == mp.mpf(0.1) or total == mp.mpf(t) - mp.mpf(t - 0.1) or total > 0
        p = sim.pose
        assert p[2] == th_prev  # the stored heading is the true heading
        assert max(abs(mp.mpf(p[0]) - ex), abs(mp.mpf(p[1]) - ey)) <= sim.pose_error
    assert sim.pose_error < 1e-11


# --- range bounds against an exact sector distance ----------------------------------------------------------
def exact_sector(ax: mp.mpf, ay: mp.mpf, heading: mp.mpf, gamma: float, edges: np.ndarray) -> mp.mpf:
    """Distance from the apex to the nearest edge point inside the closed cone, in mpmath."""
    best = mp.inf
    ux, uy = mp.cos(heading), mp.sin(heading)
    cg = mp.cos(mp.mpf(gamma))
    whole = gamma >= math.pi
    for e in edges:
        x0, y0, x1, y1 = (mp.mpf(float(c)) for c in e)
        a = (x0 - ax, y0 - ay)
        d = (x1 - x0, y1 - y0)
        pts = [a, (a[0] + d[0], a[1] + d[1])]
        dd = d[0] ** 2 + d[1] ** 2
        if dd > 0:
            t = min(max(-(a[0] * d[0] + a[1] * d[1]) / dd, mp.mpf(0)), mp.mpf(1))
            pts.append((a[0] + t * d[0], a[1] + t * d[1]))
        for px, py in pts:
            n = mp.sqrt(px * px + py * py)
            if whole or ux * px + uy * py >= n * cg:
                best = min(best, n)
        if whole:
            continue
        for b in (heading - gamma, heading + gamma):
            wx, wy = mp.cos(b), mp.sin(b)
            den = wx * d[1] - wy * d[0]
            if den == 0:
                continue
            r = (a[0] * d[1] - a[1] * d[0]) / den
            sp = (wy * a[0] - wx * a[1]) / den
            if r >= 0 and 0 <= sp <= 1:
                best = min(best, r)
    return best


def hostile_edges(rng: np.random.Generator, x: float, y: float, th: float, alpha: np.ndarray,
                  gamma: np.ndarray) -> np.ndarray:  # fmt: skip
    """Random edges, plus vertices and edges placed (in float) on the cones' boundary rays and along them."""
    out = []
    for _ in range(int(rng.integers(1, 6))):
        a = rng.uniform(-4, 4, 2) + [x, y]
        out.append([*a, *(a + rng.uniform(-2, 2, 2))])
    for s in range(len(alpha)):
        for side in (-1, 1):
            b = th + alpha[s] + side * gamma[s]
            r = rng.uniform(0.3, 4)
            p = np.array([x + r * math.cos(b), y + r * math.sin(b)])
            kind = rng.integers(3)
            if kind == 0:  # a vertex on the ray, the edge going outward
                q = p + rng.uniform(0.2, 1) * np.array([math.cos(b + side), math.sin(b + side)])
            elif kind == 1:  # an edge along the ray
                q = p + rng.uniform(0.2, 1) * np.array([math.cos(b), math.sin(b)])
            else:  # an edge crossing the ray at a grazing angle
                q = p + rng.uniform(0.2, 1) * np.array([math.cos(b + side * 1e-9), math.sin(b + side * 1e-9)])
            out.append([*p, *q])
    return np.array(out, dtype=np.float64)


@pytest.mark.parametrize("perr", [0.0, 1e-15, 1e-12])
def test_range_bounds_contain_the_exact_distance(perr: float) -> None:
    rng = np.random.default_rng(int(perr * 1e15) + 7)
    widths = []
    for _ in range(120):
        x, y = rng.uniform(-3, 3, 2)
        th = float(rng.choice([rng.uniform(-4, 4), rng.uniform(-500, 500)]))
        S = int(rng.integers(1, 5))
        alpha = rng.uniform(-math.pi, math.pi, S)
        gamma = rng.choice([1e-3, 0.13, 0.5, 1.7, 3.0, math.pi], S)
        edges = hostile_edges(rng, x, y, th, alpha, gamma)
        out = np.empty((S, 2))
        sector_bounds_kernel(x, y, th, alpha, gamma, edges, edge_boxes(edges), 10.0, perr, out)
        lo, hi = out[:, 0], out[:, 1]
        # the truth: any apex within perr (corners of the error square and the centre)
        for dx, dy in [(0, 0), (1, 1), (1, -1), (-1, 1), (-1, -1)]:
            ax, ay = mp.mpf(x) + dx * mp.mpf(perr), mp.mpf(y) + dy * mp.mpf(perr)
            for s in range(S):
                d = exact_sector(ax, ay, mp.mpf(th) + mp.mpf(float(alpha[s])), float(gamma[s]), edges)
                d_cap = min(
                    d, mp.mpf(10.0)
                )  # beyond the pre-filter's reach only "no nearer than reach" holds
                assert lo[s] <= d_cap, (x, y, th, alpha[s], gamma[s], lo[s], d)
                assert d <= hi[s], (x, y, th, alpha[s], gamma[s], hi[s], d)
                if math.isfinite(hi[s]):
                    widths.append(hi[s] - lo[s])
    assert np.median(widths) < 1e-9  # rigorous, and still tight almost everywhere
