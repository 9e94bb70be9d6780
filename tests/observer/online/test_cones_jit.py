"""The directional impact contractor (:mod:`digslam.observer.online.cones_jit`) against independent oracles.

* :func:`box_in_cone` must be rigorous: never False when some ``c ∈ C``, ``g ∈ G`` have ``|g - c| <= r``
  and the direction of ``g - c`` within ``half`` of ``mid`` (mod 2π). Two oracles, neither using the
  module's helpers: an exact one on the difference box ``D = G - C`` (high-precision :mod:`mpmath`: the
  sector meets ``D`` iff the nearest point of ``D`` lies in it, or one of the sector's bounding rays enters
  ``D`` within ``r`` — the sector cut into convex pieces of at most π/2), and dense sampling of the points
  of ``C`` and ``G`` (each pair it flags is confirmed exactly before it counts). ``g = c`` (touching boxes)
  counts as a pair in every direction.
* :func:`cone_cell_ok` against the same exact oracle, cell by cell (and the outside of the frame).
* :func:`contract_cones` keeps the true position: random worlds of rectangles, the true nearest obstacle
  distance in each cone computed exactly (the nearest point of each convex obstacle, or the entry of a
  cone's bounding ray; the outside of the frame is four half-planes), checked against dense ray casting;
  ``free`` is an inner approximation of the free space. With ``q = 1`` one cone's reading is a wrong
  interval. The contractor does cut: a robot between two walls seen by two opposite cones.
  Contradictory readings (no position meets them all) must not make the contraction loop forever.
* Through the filter: on the synthetic square room, the true position stays in the box at every step with
  the cones, and the boxes lie inside those without them and are narrower on the whole run.
"""

from __future__ import annotations

import math
import subprocess
import sys

import mpmath
import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from digslam.observer.online.cones_jit import (
    MIN_SLICE,
    box_feasible,
    box_in_cone,
    cone_cell_ok,
    contract_cones,
)
from digslam.observer.online.window import grid_frame
from digslam.observer.record.grid import Grid

TWO_PI = 2.0 * math.pi


# ===================================================================== exact oracle of box_in_cone
def _mpf(v: float) -> mpmath.mpf:
    return mpmath.mpf(float(v))


def exact_pair_exists(c: tuple, g: tuple, r: float, mid: float, half: float) -> bool:
    """Whether some ``c ∈ C``, ``g ∈ G`` have ``|g - c| <= r`` and ``g - c`` in the directions ``mid ± half``
    (``g = c`` counts), decided in high precision on ``D = G - C`` (the real numbers of the float inputs)."""
    with mpmath.workprec(1200):  # float differences exact, trigonometry far below any float's ulp
        cx0, cy0, cx1, cy1 = (_mpf(v) for v in c)
        gx0, gy0, gx1, gy1 = (_mpf(v) for v in g)
        lx, hx, ly, hy = gx0 - cx1, gx1 - cx0, gy0 - cy1, gy1 - cy0
        rr = _mpf(r)
        if rr < 0:
            return False
        if lx <= 0 <= hx and ly <= 0 <= hy:
            return True  # g = c
        nx, ny = min(max(mpmath.mpf(0), lx), hx), min(max(mpmath.mpf(0), ly), hy)  # nearest point of D
        if nx * nx + ny * ny > rr * rr:
            return False  # no point of D within r
        h = _mpf(half)
        if h >= mpmath.pi:
            return True
        m = _mpf(mid)
        pieces = max(1, int(mpmath.ceil(2 * h / (mpmath.pi / 2))))
        step = 2 * h / pieces
        tn = mpmath.atan2(ny, nx)
        for k in range(pieces):
            a = m - h + k * step
            b = a + step
            # the nearest point of D in the (convex) piece [a, b]
            if (tn - a) % (2 * mpmath.pi) <= b - a:
                return True
            # else the minimum over D ∩ piece lies on one of its bounding rays
            for th in (a, b):
                if _ray_entry_mp(mpmath.cos(th), mpmath.sin(th), lx, ly, hx, hy) <= rr:
                    return True
        return False


def _ray_entry_mp(ux, uy, lx, ly, hx, hy):
    """The parameter at which the ray ``t·u`` (``t >= 0``) enters the box (``inf`` when it misses)."""
    t0, t1 = mpmath.mpf(0), mpmath.inf
    for u, lo, hi in ((ux, lx, hx), (uy, ly, hy)):
        if u == 0:
            if not lo <= 0 <= hi:
                return mpmath.inf
            continue
        a, b = lo / u, hi / u
        if a > b:
            a, b = b, a
        t0, t1 = max(t0, a), min(t1, b)
    return t0 if t0 <= t1 else mpmath.inf


def _exact_pair(c: np.ndarray, g: np.ndarray, r: float, mid: float, half: float) -> bool:
    """The exact test of one pair of points (``g = c`` counts)."""
    with mpmath.workprec(1200):
        dx, dy = _mpf(g[0]) - _mpf(c[0]), _mpf(g[1]) - _mpf(c[1])
        if dx == 0 and dy == 0:
            return r >= 0
        if dx * dx + dy * dy > _mpf(r) ** 2:
            return False
        diff = (mpmath.atan2(dy, dx) - _mpf(mid) + mpmath.pi) % (2 * mpmath.pi) - mpmath.pi
        return abs(diff) <= _mpf(half)


def _box_points(x0: float, y0: float, x1: float, y1: float, k: int) -> np.ndarray:
    xs = np.unique(np.concatenate([np.linspace(x0, x1, k), [x0, x1]]))
    ys = np.unique(np.concatenate([np.linspace(y0, y1, k), [y0, y1]]))
    X, Y = np.meshgrid(xs, ys)
    return np.column_stack([X.ravel(), Y.ravel()])


def sampled_pair(c: tuple, g: tuple, r: float, mid: float, half: float, k: int = 21) -> tuple | None:
    """Dense sampling of ``C × G``: a pair flagged in floats and confirmed by :func:`_exact_pair`, or None."""
    pc, pg = _box_points(*c, k), _box_points(*g, k)
    d = pg[None, :, :] - pc[:, None, :]
    dist = np.hypot(d[..., 0], d[..., 1])
    ang = np.abs(np.remainder(np.arctan2(d[..., 1], d[..., 0]) - mid + math.pi, TWO_PI) - math.pi)
    ok = (dist <= r * (1 + 1e-12)) & ((ang <= half + 1e-12) | (dist == 0))
    if not ok.any():
        return None
    slack = np.where(ok, np.minimum(r - dist, half - ang), -np.inf)
    for flat in np.argsort(slack, axis=None)[::-1][:8]:  # the most interior candidates first
        i, j = np.unravel_index(flat, slack.shape)
        if not ok[i, j]:
            break
        if _exact_pair(pc[i], pg[j], r, mid, half):
            return tuple(pc[i]), tuple(pg[j])
    return None


# --------------------------------------------------------------------------- the oracle itself
def test_exact_oracle_on_hand_cases() -> None:
    """The oracle of the oracle: a few cases decided by hand."""
    pt = (0.0, 0.0, 0.0, 0.0)
    assert exact_pair_exists(pt, (1.0, 0.0, 1.0, 0.0), 1.0, 0.0, 0.0)  # straight ahead, just in range
    assert not exact_pair_exists(pt, (1.0, 0.0, 1.0, 0.0), 0.999, 0.0, 0.0)  # out of range
    assert not exact_pair_exists(pt, (1.0, 0.0, 1.0, 0.0), 2.0, math.pi, 3.0)  # behind (π ± 3 misses 0)
    assert exact_pair_exists(pt, (1.0, 0.0, 1.0, 0.0), 2.0, math.pi, 3.2)
    assert not exact_pair_exists(pt, (-1.0, 0.0, -1.0, 0.0), 2.0, 7.0, 1.0)  # 7 ≡ 0.717: π is 2.42 away
    assert exact_pair_exists(pt, (-1.0, 0.0, -1.0, 0.0), 2.0, 7.0, 2.5)
    # D = [1, 2] × [-1, 1] spans the directions ±π/4, nearest point (1, 0)
    assert not exact_pair_exists(pt, (1.0, -1.0, 2.0, 1.0), 100.0, 0.9, 0.1)  # [0.8, 1.0] misses ±π/4
    assert not exact_pair_exists(pt, (1.0, -1.0, 2.0, 1.0), 1.3, 0.8, 0.1)  # the ray at 0.7 enters at 1.307
    assert exact_pair_exists(pt, (1.0, -1.0, 2.0, 1.0), 1.31, 0.8, 0.1)
    # D = [1, 2]²: its nearest point (1, 1), at √2 and π/4, is in the wedge
    assert not exact_pair_exists(pt, (1.0, 1.0, 2.0, 2.0), 1.41, math.pi / 4, 0.01)
    assert exact_pair_exists(pt, (1.0, 1.0, 2.0, 2.0), 1.415, math.pi / 4, 0.01)
    # a wide wedge [0.5, 3.5] (cut into pieces): the nearest point (1, 0) outside, the ray at 0.5 enters at 1.1395
    assert exact_pair_exists(pt, (1.0, -1.0, 2.0, 1.0), 1.14, 2.0, 1.5)
    assert not exact_pair_exists(pt, (1.0, -1.0, 2.0, 1.0), 1.139, 2.0, 1.5)
    assert not exact_pair_exists(pt, (1.0, -1.0, 2.0, 1.0), 1.2, math.pi, 2.0)
    # touching boxes and equal points
    assert exact_pair_exists((0.0, 0.0, 1.0, 1.0), (1.0, 0.0, 2.0, 1.0), 0.0, -2.0, 0.0)
    assert exact_pair_exists(pt, pt, 0.0, 1.0, 0.0)


def test_exact_oracle_agrees_with_sampling() -> None:
    """Whatever dense sampling confirms, the exact oracle finds (and it finds some)."""
    rng = np.random.default_rng(7)
    found = 0
    for _ in range(300):
        c0, g0 = rng.uniform(-2, 2, 2), rng.uniform(-2, 2, 2)
        cw, gw = rng.uniform(0, 1, 2), rng.uniform(0, 1, 2)
        c, g = (*c0, *(c0 + cw)), (*g0, *(g0 + gw))
        r, mid, half = rng.uniform(0, 4), rng.uniform(-7, 7), rng.uniform(0, 3.5)
        if sampled_pair(c, g, r, mid, half, 9) is not None:
            found += 1
            assert exact_pair_exists(c, g, r, mid, half)
    assert found > 50


# ===================================================================== box_in_cone is rigorous
def _fl(lo: float, hi: float):
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


COORD = st.one_of(_fl(-3, 3), st.integers(-30, 30).map(lambda k: k / 10), _fl(-1e3, 1e3))
WIDTH = st.one_of(st.just(0.0), _fl(0, 1e-9), _fl(0, 2.5), st.integers(0, 20).map(lambda k: k / 10))
HALF = st.one_of(
    st.just(0.0),
    _fl(0, 1e-6),
    _fl(0, math.pi),
    st.sampled_from([0.1, 0.5, math.pi / 2, math.pi - 1e-7]),
    _fl(math.pi, 5.0),
)
R = st.one_of(st.just(0.0), _fl(0, 1e-6), _fl(0, 10), st.just(1e6))
MID = st.one_of(_fl(-math.pi, math.pi), _fl(-50, 50), st.sampled_from([7.0, -7.0, math.pi, -math.pi, 100.0]))


def _nudge(v: float, ulps: int) -> float:
    """``v`` moved by ``ulps`` floats (towards +inf when positive)."""
    for _ in range(abs(ulps)):
        v = float(np.nextafter(v, math.inf if ulps > 0 else -math.inf))
    return v


@st.composite
def box_pairs(draw):
    """``(C, G, n)``: independent, touching, a few ulps apart, or overlapping boxes (points included); ``n``
    the direction from ``C`` to ``G`` across the side they share (None for independent boxes)."""
    x0, y0 = draw(COORD), draw(COORD)
    c = (x0, y0, x0 + draw(WIDTH), y0 + draw(WIDTH))
    mode = draw(st.sampled_from(["free", "near", "touch", "gap", "overlap"]))
    gw, gh = draw(WIDTH), draw(WIDTH)
    if mode == "free":
        gx, gy = draw(COORD), draw(COORD)
        return c, (gx, gy, gx + gw, gy + gh), None
    if mode == "near":
        gx, gy = c[0] + draw(_fl(-3, 3)), c[1] + draw(_fl(-3, 3))
        return c, (gx, gy, gx + gw, gy + gh), None
    # G beside one side of C (its edge 0, a few ulps out or in), anywhere along that side
    gap = {"touch": 0, "gap": draw(st.integers(1, 3)), "overlap": -draw(st.integers(1, 3))}[mode]
    side, off = draw(st.integers(0, 3)), draw(_fl(-3, 3))
    if draw(st.booleans()):  # flat: both boxes of zero thickness across the shared side (segments, points)
        if side < 2:
            c, gw = (c[0], c[1], c[0], c[3]), 0.0
        else:
            c, gh = (c[0], c[1], c[2], c[1]), 0.0
    if side == 0:  # right of C
        gx0 = _nudge(c[2], gap)
        return c, (gx0, c[1] + off, gx0 + gw, c[1] + off + gh), 0.0
    if side == 1:  # left of C
        gx1 = _nudge(c[0], -gap)
        return c, (gx1 - gw, c[1] + off, gx1, c[1] + off + gh), math.pi
    if side == 2:  # above C
        gy0 = _nudge(c[3], gap)
        return c, (c[0] + off, gy0, c[0] + off + gw, gy0 + gh), math.pi / 2
    gy1 = _nudge(c[1], -gap)  # below C
    return c, (c[0] + off, gy1 - gh, c[0] + off + gw, gy1), -math.pi / 2


@st.composite
def aimed(draw, c, g):
    """``(r, mid, half)`` aimed at a pair of points of ``C × G``: the range and the angle on the edge."""

    def coord(lo: float, hi: float) -> float:  # an end (often) or a point between
        if draw(st.booleans()):
            return draw(st.sampled_from([lo, hi]))
        return min(lo + draw(_fl(0, 1)) * (hi - lo), hi)

    pc = coord(c[0], c[2]), coord(c[1], c[3])
    pg = coord(g[0], g[2]), coord(g[1], g[3])
    dx, dy = pg[0] - pc[0], pg[1] - pc[1]
    r = math.hypot(dx, dy) * draw(st.sampled_from([1.0, 1.0 + 1e-15, 1.0 + 1e-9, 1.5]))
    half = draw(HALF)
    s = draw(st.one_of(st.sampled_from([-1.0, -1.0 + 1e-12, 0.0, 1.0 - 1e-12, 1.0]), _fl(-1, 1)))
    mid = math.atan2(dy, dx) + s * half + TWO_PI * draw(st.integers(-3, 3))
    return r, mid, half


@st.composite
def cone_cases(draw):
    c, g, normal = draw(box_pairs())
    how = draw(st.sampled_from(["aimed", "random", "across"]))
    if how == "aimed":
        r, mid, half = draw(aimed(c, g))
    elif how == "across" and normal is not None:  # the cone across the shared side, near its normal
        r, half = draw(R), draw(HALF)
        mid = normal + draw(_fl(-1.5, 1.5)) + TWO_PI * draw(st.integers(-2, 2))
    else:
        r, mid, half = draw(R), draw(MID), draw(HALF)
    return c, g, r, mid, half


def _check_box_in_cone(c, g, r, mid, half) -> None:
    got = box_in_cone(*c, *g, r, mid, half)
    if got:
        return
    assert not exact_pair_exists(c, g, r, mid, half), (
        f"box_in_cone(C={c}, G={g}, r={r!r}, mid={mid!r}, half={half!r}) is False but a pair exists"
    )
    pair = sampled_pair(c, g, r, mid, half)
    assert pair is None, f"box_in_cone(C={c}, G={g}, r={r!r}, mid={mid!r}, half={half!r}) False; pair {pair}"


@settings(max_examples=3000, deadline=None)
@given(cone_cases())
@example(((0.0, 0.0, 0.0, 0.0), (1.0, 0.0, 1.0, 0.0), 1.0, 0.0, 0.0))  # a ray onto a point, exactly in range
@example(((0.0, 0.0, 1.0, 1.0), (1.0, 1.0, 2.0, 2.0), 0.0, -2.0, 0.0))  # corners touching, r = 0
@example(((-1.0, 0.0, -1.0, 0.0), (-2.0, 0.0, -2.0, 0.0), 1.0, math.pi, 0.0))  # along -x (atan2 = ±π)
@example(((-1.0, 0.0, -1.0, 0.0), (-2.0, -0.0, -2.0, 0.0), 1.0, -math.pi, 0.0))
@example(((0.0, 0.0, 0.0, 0.0), (-1.0, -1e-300, -1.0, 1e-300), 1.0, math.pi, 0.0))
@example(((0.0, 0.0, 0.0, 0.0), (1.0, 0.0, 1.0, 0.0), 1.0, TWO_PI * 3, 0.0))  # mid = 6π
@example(((0.0, 0.0, 0.0, 0.0), (math.cos(7.0), math.sin(7.0), math.cos(7.0), math.sin(7.0)), 1.0 + 1e-15, 7.0,
          1e-12))  # fmt: skip
# G above, the cone down
@example(((0.0, 0.0, 1.0, 1.0), (0.5, 3.0, 0.5, 3.0), 2.0, -math.pi / 2 + TWO_PI * 3, 1.0))
@example(((0.0, 0.0, 0.0, 0.0), (1e6, 1e6, 1e6, 1e6), 1e7, math.pi / 4, 0.0))  # large r
@example(((0.0, 0.0, 0.0, 0.0), (1e-9, 0.0, 1e-9, 0.0), 1e-9, 0.0, 0.0))  # tiny r
def test_box_in_cone_never_false_on_a_real_pair(case) -> None:
    _check_box_in_cone(*case)


@st.composite
def nearly_touching_segments(draw):
    """A horizontal segment (or point) ``C`` and a segment ``G`` one to three ulps above (or below) it, both
    of zero or sub-ulp thickness, G straddling C's abscissae or not; the cone across, its range 1."""
    cy = draw(st.one_of(st.just(1.0), _fl(-3, 3), _fl(-100, 100)))
    cx0, cw = draw(_fl(-3, 3)), draw(st.one_of(st.just(0.0), _fl(0, 2)))
    up = draw(st.booleans())
    gy = _nudge(cy, draw(st.integers(1, 3)) * (1 if up else -1))
    gx0, gw = cx0 + draw(_fl(-3, 3)), draw(_fl(0, 5))
    gh = draw(st.sampled_from([0.0, 1e-16]))
    g = (gx0, gy, gx0 + gw, gy + gh) if up else (gx0, gy - gh, gx0 + gw, gy)
    mid = (1 if up else -1) * math.pi / 2 + draw(_fl(-1.5, 1.5)) + TWO_PI * draw(st.integers(-1, 1))
    return (cx0, cy, cx0 + cw, cy), g, 1.0, mid, draw(_fl(0, 0.5))


@settings(max_examples=500, deadline=None)
@given(nearly_touching_segments())
def test_box_in_cone_nearly_touching_segments(case) -> None:
    """Degenerate boxes a few ulps apart, the cone across the gap: the difference box is a thin segment just
    off the origin, whose directions span almost π (its far corners at ±π from one another)."""
    _check_box_in_cone(*case)


def test_box_in_cone_one_ulp_gap_regression() -> None:
    """A point under a wide segment one ulp above it, the cone straight up: ``g - c = (0, 2⁻⁵²)`` is a
    real pair (distance 2.2e-16, direction exactly π/2), so the answer must be True. The difference box's
    corner ``(-1, 2.2e-16)`` is at π - 2.2e-16, which rounds to π (float) and wraps to -π."""
    y = float(np.nextafter(1.0, 2.0))
    c, g = (0.0, 1.0, 0.0, 1.0), (-1.0, y, 5.0, y)
    assert exact_pair_exists(c, g, 1.0, math.pi / 2, 0.1)
    _check_box_in_cone(c, g, 1.0, math.pi / 2, 0.1)


def test_box_in_cone_is_not_trivially_true() -> None:
    """Clear misses are rejected (so that the properties above are not met by ``return True``)."""
    pt = (0.0, 0.0, 0.0, 0.0)
    assert not box_in_cone(*pt, 2.0, 0.0, 3.0, 1.0, 1.9, 0.0, 1.0)  # too far
    assert not box_in_cone(*pt, 2.0, -0.5, 3.0, 0.5, 5.0, math.pi, 0.5)  # behind
    assert not box_in_cone(*pt, 2.0, -0.5, 3.0, 0.5, 5.0, 7.0 + math.pi, 0.5)  # behind, mid wrapped
    above = (0.0, 0.0, 1.0, 1.0, 0.0, 3.0, 1.0, 4.0, 10.0)  # G above C
    assert not box_in_cone(*above, -math.pi / 2, 1.0)  # the cone down
    assert box_in_cone(*above, -math.pi / 2 + TWO_PI * 5, 3.0)  # wide enough to reach up


# ===================================================================== cone_cell_ok against the exact oracle
@settings(max_examples=1000, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([(12, 12), (10, 16)]), st.booleans())
def test_cone_cell_ok_never_misses(seed: int, shape: tuple, aim: bool) -> None:
    """Whenever a not-free cell, or a point outside the frame, has a point in the cone from a point of
    ``C``, :func:`cone_cell_ok` says so. ``aim``: the cone's range and one of its edges (or its axis) put
    exactly on a corner or an edge point of a not-free cell, from a corner or an edge point of ``C``."""
    rng = np.random.default_rng(seed)
    grid = Grid((-1.0, 0.5), (2.0, 3.5), shape)
    xs, ys, nys = grid_frame(grid)[:3]
    free = rng.random(shape) < rng.choice([0.6, 0.9, 0.98, 1.0])
    x0, y0 = rng.uniform(-1.5, 2.5), rng.uniform(0.0, 4.0)
    if rng.random() < 0.3:  # a box edge on a cell bound
        x0 = float(xs[rng.integers(xs.size)])
    c = (x0, y0, x0 + rng.choice([0.0, rng.uniform(0, 0.6)]), y0 + rng.choice([0.0, rng.uniform(0, 0.6)]))
    halves = [0.0, rng.uniform(0, 1.5), math.pi / 2 - 2e-6, math.pi / 2, rng.uniform(1.5, 3.1)]
    half = float(halves[rng.integers(len(halves))])
    r, mid = rng.uniform(0.0, 2.0), rng.uniform(-8, 8)
    rows, cols = np.nonzero(~free)
    if aim and rows.size:
        k = rng.integers(rows.size)
        i, j = rows[k], cols[k]
        pick = lambda lo, hi: float(rng.choice([lo, hi, lo + rng.random() * (hi - lo)]))  # noqa: E731
        pc = pick(c[0], c[2]), pick(c[1], c[3])
        pg = pick(xs[j], xs[j + 1]), pick(ys[i + 1], ys[i])
        dx, dy = pg[0] - pc[0], pg[1] - pc[1]
        r = math.hypot(dx, dy) * float(rng.choice([1.0, 1.0 + 1e-15, 1.0 + 1e-12]))
        mid = (
            math.atan2(dy, dx)
            + float(rng.choice([-1.0, 0.0, 1.0])) * half
            + TWO_PI * int(rng.integers(-2, 3))
        )
    if cone_cell_ok(free, xs, ys, nys, *c, r, mid, half):
        return
    for i, j in zip(rows, cols):
        cell = (xs[j], ys[i + 1], xs[j + 1], ys[i])
        assert not exact_pair_exists(c, cell, r, mid, half), f"misses cell {(i, j)}: C={c} r={r} {mid} {half}"
    big = 1e3  # the outside of the frame: four closed half-planes (cut far away)
    fx0, fx1, fy0, fy1 = xs[0], xs[-1], ys[-1], ys[0]
    for o in ((-big, -big, fx0, big), (fx1, -big, big, big), (-big, -big, big, fy0), (-big, fy1, big, big)):
        assert not exact_pair_exists(c, o, r, mid, half), f"misses the outside {o}: C={c} r={r} {mid} {half}"


# ===================================================================== worlds: contract_cones keeps the truth
FRAME = 4.0  # the frame is [lo, lo + 4]²


def _ray_entry(px, py, ux, uy, a0, b0, a1, b1) -> float:
    """Distance along the unit ray ``p + t·u`` to the closed box (``inf`` when missed)."""
    t0, t1 = 0.0, math.inf
    for p, u, lo, hi in ((px, ux, a0, a1), (py, uy, b0, b1)):
        if u == 0.0:
            if not lo <= p <= hi:
                return math.inf
            continue
        a, b = (lo - p) / u, (hi - p) / u
        if a > b:
            a, b = b, a
        t0, t1 = max(t0, a), min(t1, b)
    return t0 if t0 <= t1 else math.inf


def true_cone_distance(p, obstacles, th: float, gamma: float) -> float:
    """Exact distance from ``p`` to the nearest obstacle point in the wedge ``th ± gamma`` (``gamma < π/2``):
    for each convex obstacle, its nearest point if in the wedge, else the entry of a bounding ray."""
    best = math.inf
    for a0, b0, a1, b1 in obstacles:
        nx, ny = min(max(p[0], a0), a1), min(max(p[1], b0), b1)
        vx, vy = nx - p[0], ny - p[1]
        if abs(math.remainder(math.atan2(vy, vx) - th, TWO_PI)) <= gamma:
            best = min(best, math.hypot(vx, vy))
        else:
            for t in (th - gamma, th + gamma):
                best = min(best, _ray_entry(p[0], p[1], math.cos(t), math.sin(t), a0, b0, a1, b1))
    return best


def sampled_cone_distance(p, obstacles, th: float, gamma: float, n: int = 121) -> float:
    """Dense ray casting: the nearest hit over ``n`` rays of the cone (an upper bound of the truth)."""
    return min(_ray_entry(p[0], p[1], math.cos(t), math.sin(t), *o)
               for t in np.linspace(th - gamma, th + gamma, n) for o in obstacles)  # fmt: skip


def make_world(seed: int, shape: tuple, lo: tuple, n_rect: int, n_cone: int, q_outlier: bool = False):
    """A random world, the truth, the readings and the boxes (None when no free spot was found)."""
    rng = np.random.default_rng(seed)
    grid = Grid(lo, (lo[0] + FRAME, lo[1] + FRAME), shape)
    xs, ys = grid.xs, grid.ys
    fx0, fx1, fy0, fy1 = xs[0], xs[-1], ys[-1], ys[0]
    aligned = rng.random() < 0.4
    rects = []
    for _ in range(n_rect):
        if aligned:  # on cell bounds
            i0, j0 = rng.integers(0, xs.size), rng.integers(0, ys.size)
            i1, j1 = min(i0 + rng.integers(1, 12), xs.size - 1), min(j0 + rng.integers(1, 12), ys.size - 1)
            a0, a1, b0, b1 = xs[i0], xs[i1], ys[j1], ys[j0]  # (a segment on the last bound)
        else:
            a0, b0 = rng.uniform(fx0 - 0.5, fx1), rng.uniform(fy0 - 0.5, fy1)
            a1, b1 = a0 + rng.uniform(0.02, 1.5), b0 + rng.uniform(0.02, 1.5)
        rects.append((float(a0), float(b0), float(a1), float(b1)))

    def blocked(x, y):
        return any(a0 <= x <= a1 and b0 <= y <= b1 for a0, b0, a1, b1 in rects)

    for _ in range(200):
        px, py = rng.uniform(fx0, fx1), rng.uniform(fy0, fy1)
        u = rng.random()
        if u < 0.15 and rects:  # just beside an obstacle
            a0, b0, a1, b1 = rects[rng.integers(len(rects))]
            px = (
                a0 - rng.choice([1e-12, 1e-6, 1e-3]) if rng.random() < 0.5 else a1 + rng.choice([1e-12, 1e-3])
            )
        elif u < 0.3:  # on a cell bound
            px = float(xs[rng.integers(1, xs.size - 1)])
        if fx0 < px < fx1 and not blocked(px, py):
            break
    else:
        return None
    p = (float(px), float(py))
    inf = math.inf
    obstacles = rects + [
        (-inf, -inf, fx0, inf),
        (fx1, -inf, inf, inf),
        (-inf, -inf, inf, fy0),
        (-inf, fy1, inf, inf),
    ]

    psi = float(
        rng.uniform(-math.pi, math.pi) + (TWO_PI * rng.integers(-2, 3) if rng.random() < 0.2 else 0.0)
    )
    psi_lo = psi - float(rng.choice([0.0, rng.uniform(0, 0.3)]))
    psi_hi = psi + float(rng.choice([0.0, rng.uniform(0, 0.3)]))
    alpha = rng.uniform(-math.pi, math.pi, n_cone)
    quarter = rng.random(n_cone) < 0.3
    alpha[quarter] = rng.integers(-1, 3, quarter.sum()) * math.pi / 2
    gamma = np.where(rng.random(n_cone) < 0.2, 0.5, rng.uniform(1e-3, 0.5, n_cone))
    r_max = float(rng.choice([2.0, 5.0, 8.0]))
    ranges, no_echo, dist = np.empty((n_cone, 2)), np.zeros(n_cone, bool), np.empty(n_cone)
    for k in range(n_cone):
        th = psi + alpha[k]
        d = true_cone_distance(p, obstacles, th, gamma[k])
        assert d <= sampled_cone_distance(p, obstacles, th, gamma[k]) * (1 + 1e-12) + 1e-12  # oracle sanity
        dist[k] = d
        noise_lo, noise_hi = (float(rng.choice([0.0, rng.uniform(0, 0.1)])) for _ in range(2))
        if d > r_max:
            ranges[k], no_echo[k] = (r_max, inf), True
        else:
            ranges[k] = max(d - noise_lo, 0.0), d * (1 + 1e-12) + noise_hi
    if q_outlier:
        k = int(rng.integers(n_cone))
        a = float(rng.uniform(0, 3))
        ranges[k] = (a, a + float(rng.choice([0.0, rng.uniform(0, 0.5)])))
        no_echo[k] = rng.random() < 0.2

    # M⁻: cells whose closed extent meets no closed obstacle, within R of p, and a random subset of those
    R, keep = float(rng.choice([0.5, 1.5, 3.0, 10.0])), float(rng.choice([1.0, 0.8]))
    cx0, cx1 = xs[:-1][None, :], xs[1:][None, :]
    cy0, cy1 = ys[1:][:, None], ys[:-1][:, None]
    free = np.ones(shape, bool)
    for a0, b0, a1, b1 in rects:
        free &= (cx1 < a0) | (cx0 > a1) | (cy1 < b0) | (cy0 > b1)
    far2 = (
        np.maximum(abs(cx0 - p[0]), abs(cx1 - p[0])) ** 2 + np.maximum(abs(cy0 - p[1]), abs(cy1 - p[1])) ** 2
    )
    free &= far2 <= R * R  # the farthest corner within R
    free &= rng.random(shape) < keep

    box = [p[0] - rng.choice([0.0, rng.uniform(0, 1.5)]), p[1] - rng.choice([0.0, rng.uniform(0, 1.5)]),
           p[0] + rng.choice([0.0, rng.uniform(0, 1.5)]), p[1] + rng.choice([0.0, rng.uniform(0, 1.5)])]  # fmt: skip
    return dict(grid=grid, free=free, p=p, psi=psi, psi_lo=psi_lo, psi_hi=psi_hi, alpha=alpha, gamma=gamma,
                ranges=ranges, no_echo=no_echo, box=[float(v) for v in box], rects=rects, dist=dist)  # fmt: skip


def _contract(w: dict, q: int) -> tuple:
    return contract_cones(w["free"], grid_frame(w["grid"]), *w["box"], w["psi_lo"], w["psi_hi"], w["alpha"],
                          w["gamma"], w["ranges"], w["no_echo"], q)  # fmt: skip


def _assert_keeps_truth(w: dict, q: int, seed: int) -> tuple:
    x0, y0, x1, y1 = out = _contract(w, q)
    (px, py), f = w["p"], grid_frame(w["grid"])
    info = f"seed={seed} q={q} p={w['p']} box={w['box']} -> {out}; psi={w['psi_lo']}..{w['psi_hi']}"
    assert x0 <= px <= x1 and y0 <= py <= y1, "the true position was dropped: " + info
    assert box_feasible(w["free"], f.xs, f.ys, f.nys, px, py, px, py, w["psi_lo"], w["psi_hi"], w["alpha"],
                        w["gamma"], w["ranges"], w["no_echo"], q), "the true position fails: " + info  # fmt: skip
    return out


WORLD = st.tuples(
    st.integers(0, 2**32 - 1),
    st.sampled_from([(40, 40), (40, 32), (25, 40)]),
    st.sampled_from([(0.0, 0.0), (-2.0, -1.5), (0.3, 10.7)]),
    st.integers(0, 6),
    st.integers(1, 6),
)


@settings(max_examples=600, deadline=None)
@given(WORLD)
def test_contract_cones_keeps_the_true_position(world) -> None:
    seed, shape, lo, n_rect, n_cone = world
    w = make_world(seed, shape, lo, n_rect, n_cone)
    assume(w is not None)
    _assert_keeps_truth(w, 0, seed)
    _assert_keeps_truth(w, 1, seed)  # a looser claim is sound too


@settings(max_examples=600, deadline=None)
@given(WORLD)
def test_contract_cones_q1_survives_one_outlier(world) -> None:
    seed, shape, lo, n_rect, n_cone = world
    w = make_world(seed, shape, lo, n_rect, n_cone, q_outlier=True)
    assume(w is not None)
    _assert_keeps_truth(w, 1, seed)


def test_contract_cones_worlds_sweep_is_not_vacuous() -> None:
    """Over fixed random worlds the truth is always kept, and the boxes are often cut."""
    cut = tried = 0
    for seed in range(300):
        w = make_world(seed, (40, 40), (0.0, 0.0), seed % 5 + 1, 4)
        if w is None:
            continue
        tried += 1
        out = _assert_keeps_truth(w, 0, seed)
        cut += any(abs(a - b) > 0 for a, b in zip(out, w["box"]))
    assert tried > 250
    assert cut > 0.1 * tried, (cut, tried)  # 52 of 300 when written


def test_contract_cones_doctest_example_bound() -> None:
    """The module's example: a wall at x = 3 seen at [0.99, 1.01] along +x: x >= 1.99, found to within the
    last slice tried (under 2·MIN_SLICE)."""
    g = grid_frame(Grid((0.0, 0.0), (4.0, 4.0), (40, 40)))
    free = np.ones((40, 40), bool)
    free[:, 30:] = False
    ranges = np.array([[0.99, 1.01], [np.inf, np.inf]])
    x0, y0, x1, y1 = contract_cones(free, g, 1.0, 1.0, 2.5, 2.5, 0.0, 0.0, np.array([0.0, np.pi]),
                                    np.array([0.1, 0.1]), ranges, np.array([False, True]), 0)  # fmt: skip
    assert 1.99 - 2 * MIN_SLICE <= x0 <= 1.99 and (y0, x1, y1) == (1.0, 2.5, 2.5)


# ===================================================================== it does contract: between two walls
def test_two_opposite_cones_pin_the_position_between_walls() -> None:
    grid = Grid((0.0, 0.0), (4.0, 4.0), (40, 40))
    g = grid_frame(grid)
    free = np.zeros((40, 40), bool)
    free[:, 10:30] = True  # walls x <= 1 and x >= 3, the corridor between dug
    p = (2.0, 2.0)
    alpha, gamma = np.array([0.0, math.pi]), np.array([0.2, 0.2])
    ranges = np.array([[0.99, 1.01], [0.99, 1.01]])
    no_echo = np.zeros(2, bool)
    box = (1.2, 1.5, 2.8, 2.5)
    x0, y0, x1, y1 = contract_cones(free, g, *box, -0.05, 0.05, alpha, gamma, ranges, no_echo, 0)
    assert x0 <= p[0] <= x1 and y0 <= p[1] <= y1
    assert x1 - x0 < 0.1 < box[2] - box[0], (x0, x1)  # both sides cut: 3 - 1.01 <= x <= 1 + 1.01
    assert (y0, y1) == (box[1], box[3])  # nothing along y
    # one cone alone bounds one side only
    one = contract_cones(free, g, *box, -0.05, 0.05, alpha, gamma, ranges, np.array([False, True]), 0)
    assert one[0] > box[0] + 0.5 and one[2] == box[2]
    # q = 1: either reading may be the outlier, nothing is cut
    assert contract_cones(free, g, *box, -0.05, 0.05, alpha, gamma, ranges, no_echo, 1) == box


CONTRADICTION = """
import math, numpy as np
from digslam.observer.online.cones_jit import contract_cones
from digslam.observer.online.window import grid_frame
from digslam.observer.record.grid import Grid
g = grid_frame(Grid((0.0, 0.0), (4.0, 4.0), (40, 40)))
free = np.zeros((40, 40), bool)
free[:, 10:30] = True
bad = np.array([[0.2, 0.3], [0.2, 0.3]])  # walls within 0.3 m both ahead and behind: impossible here
print(repr(contract_cones(free, g, 1.2, 1.5, 2.8, 2.5, -0.05, 0.05, np.array([0.0, math.pi]),
                          np.array([0.2, 0.2]), bad, np.zeros(2, bool), 0)))
"""


def test_contradictory_readings_terminate() -> None:
    """Two readings that no position of the box meets together (the whole box meets each from a different
    point): the contraction must end (an empty box, or any sub-box). Run in a subprocess: a hang would
    otherwise freeze the test session."""
    try:
        out = subprocess.run(
            [sys.executable, "-c", CONTRADICTION], capture_output=True, text=True, timeout=15
        )
    except subprocess.TimeoutExpired:
        pytest.fail("contract_cones did not return within 15 s on contradictory readings (an endless loop)")
    assert out.returncode == 0, out.stderr
    x0, y0, x1, y1 = eval(out.stdout, {"inf": math.inf})
    assert x0 == math.inf or (1.2 <= x0 <= x1 <= 2.8 and 1.5 <= y0 <= y1 <= 2.5), (x0, y0, x1, y1)


# ===================================================================== through the filter
@pytest.mark.parametrize("seed", [0, 3])
def test_filter_with_cones_keeps_the_truth_and_is_tighter(seed: int) -> None:
    """The synthetic square room (exact ranges, noise bound 0.05): with the cones the true position stays in
    the box at every step, the boxes are inside those without the cones at every step (observed on these
    runs; each stage is monotone but the shaving is not strictly so) and narrower on the whole run."""
    from qrelaxed_data import GRID, square_room_records

    from digslam.observer.online.observer import OnlineConfig, OnlineDigSlam

    recs, poses = square_room_records(seed, 150, 0.05)
    boxes = {}
    for cones in (True, False):
        f = OnlineDigSlam(GRID, OnlineConfig(cones=cones))
        f.reset([0.0, 0.0], [0.0, 0.0], recs[0])
        boxes[cones] = []
        for k, r in enumerate(recs[1:], 1):
            f.update(r)
            assert f.consistent
            assert np.all(f.pose_lo <= poses[k, :2]) and np.all(poses[k, :2] <= f.pose_hi), (cones, k)
            boxes[cones].append((f.pose_lo.copy(), f.pose_hi.copy()))
    for k, ((lo, hi), (lo0, hi0)) in enumerate(zip(boxes[True], boxes[False]), 1):
        assert np.all(lo0 <= lo) and np.all(hi <= hi0), (k, lo, hi, lo0, hi0)
    width = {c: sum(float(np.sum(hi - lo)) for lo, hi in b) for c, b in boxes.items()}
    assert width[True] < 0.99 * width[False], width
