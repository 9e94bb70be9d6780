"""Minimal polar contractor and polar separators (thesis §3.2.3, §3.3, Eq. 3.22–3.34, 3.46–3.56).

Minimality is checked against a dense sampling of ``Π ∩ [p]``: the sides of the ``(ρ, θ)`` rectangle
and the pre-images of the four box edges (each parametrised by θ and by ρ), which pass through every
vertex where a face of ``⟦Π ∩ [p]⟧`` is reached. Soundness uses exact-enough points: a box is built
around the image of a random ``(ρ, θ)`` and must keep it.
"""

from __future__ import annotations

import numpy as np
import pytest
from polar_boxes import random_boxes

from digslam.observer import Box, Function, SepInverse, pave
from digslam.observer.polar.ctc import CtcPolar
from digslam.observer.polar.sep import (
    SepCtcPreimage,
    SepLandmark,
    SepPi,
    SepPiInv,
    SepPolarXY,
    complement_boxes,
)
from digslam.observer.sets.separators import check_separation

CTC = CtcPolar()


def sampled_hull(lo: np.ndarray, hi: np.ndarray, n: int = 20000):
    """Hull of sampled points of ``Π ∩ [p]`` (None when no sample falls inside)."""
    (xl, yl, rl, tl), (xh, yh, rh, th) = lo, hi
    rs, ts = np.linspace(rl, rh, n), np.linspace(tl, th, n)
    pts = [np.stack([np.full(n, r), ts], 1) for r in (rl, rh)] + [
        np.stack([rs, np.full(n, t)], 1) for t in (tl, th)
    ]
    pts.append(np.stack(np.meshgrid(np.linspace(rl, rh, 40), np.linspace(tl, th, 40)), -1).reshape(-1, 2))
    ks = np.arange(np.floor((tl - 4) / (2 * np.pi)), np.ceil((th + 4) / (2 * np.pi)) + 1)
    rr = rs[rs != 0]
    for a, fn, inv in (
        (xl, np.cos, np.arccos),
        (xh, np.cos, np.arccos),
        (yl, np.sin, np.arcsin),
        (yh, np.sin, np.arcsin),
    ):
        with np.errstate(all="ignore"):
            pts.append(np.stack([a / fn(ts), ts], 1))
            base = inv(np.clip(a / rr, -1, 1))
        for an in (base, -base) if fn is np.cos else (base, np.pi - base):
            pts += [np.stack([rr, an + 2 * np.pi * k], 1) for k in ks]
    p = np.concatenate(pts)
    p = p[np.isfinite(p).all(1)]
    r, t = p[:, 0], p[:, 1]
    x, y = r * np.cos(t), r * np.sin(t)
    tol = 1e-9 * (1 + np.abs(x) + np.abs(y))
    keep = (r >= rl) & (r <= rh) & (t >= tl) & (t <= th) & (x >= xl - tol) & (x <= xh + tol)
    keep &= (y >= yl - tol) & (y <= yh + tol)
    q = np.stack([np.clip(x, xl, xh), np.clip(y, yl, yh), r, t], 1)[keep]
    if rl <= 0 <= rh and xl <= 0 <= xh and yl <= 0 <= yh:
        q = np.concatenate([q, [[0, 0, 0, tl], [0, 0, 0, th]]])
    return (q.min(0), q.max(0)) if len(q) else None


@pytest.mark.parametrize("seed", [0])
def test_contractor_minimal_and_sound_on_random_boxes(seed: int) -> None:
    """Each face of the contracted box touches Π (within the sampling step) and no sample is lost."""
    lo, hi = random_boxes(np.random.default_rng(seed), 120)
    rlo, rhi = CTC.contract(lo, hi)
    for i in range(len(lo)):
        h = sampled_hull(lo[i], hi[i])
        if h is None:  # nothing sampled: the box may still touch Π at a point; only check the result is small
            continue
        assert not (rlo[i] > rhi[i]).any(), f"box {i} emptied but holds solutions"
        scale = 1e-9 * (1 + np.abs(h[0]) + np.abs(h[1]))
        assert (rlo[i] <= h[0] + scale).all() and (rhi[i] >= h[1] - scale).all(), f"box {i} lost a solution"
        assert np.allclose(rlo[i], h[0], atol=2e-3) and np.allclose(rhi[i], h[1], atol=2e-3), (
            f"box {i} not minimal: {rlo[i]}, {rhi[i]} vs sampled {h}"
        )


def test_contractor_keeps_exact_points() -> None:
    """Random (ρ, θ) and their images, in boxes built around them (any θ width, ρ of any sign)."""
    rng = np.random.default_rng(3)
    n = 4000
    r, t = rng.uniform(-6, 6, n), rng.uniform(-40, 40, n)
    x, y = r * np.cos(t), r * np.sin(t)  # rounding error ~1e-15: boxes are at least 1e-9 wide
    p = np.c_[x, y, r, t]
    lo = p - rng.uniform(1e-9, 3, (n, 4)) * (rng.random((n, 4)) < 0.8)
    hi = p + rng.uniform(1e-9, 3, (n, 4)) * (rng.random((n, 4)) < 0.8)
    lo, hi = lo - 1e-9, hi + 1e-9
    rlo, rhi = CTC.contract(lo, hi)
    assert ((rlo <= p) & (p <= rhi)).all()


def test_contractor_special_cases() -> None:
    c = CTC
    # θ wider than 2π: θ contracts to the first and last consistent representative
    lo, hi = c.contract(np.array([[1.0, 1.0, 0.0, -10.0]]), np.array([[2.0, 2.0, 10.0, 10.0]]))
    assert np.allclose(lo, [1, 1, np.sqrt(2), np.arctan(0.5) - 2 * np.pi])
    assert np.allclose(hi, [2, 2, np.sqrt(8), np.arctan(2) + 2 * np.pi])
    # a box on the ±π cut
    lo, hi = c.contract(np.array([[-3.0, -0.5, 0.0, 3.0]]), np.array([[-2.0, 0.5, 9.0, 3.3]]))
    assert np.isclose(lo[0, 3], 3.0) and np.isclose(hi[0, 3], 3.3) and np.isclose(lo[0, 1], -3 * np.tan(3.3))
    # origin inside: θ is free, ρ down to 0
    lo, hi = c.contract(np.array([[-1.0, -1.0, -0.5, 0.1]]), np.array([[1.0, 1.0, 5.0, 0.2]]))
    assert lo[0, 2] == -0.5 and lo[0, 3] == 0.1 and hi[0, 3] == 0.2 and hi[0, 0] == 1.0
    # infeasible: the ring misses the box
    lo, hi = c.contract(np.array([[3.0, 3.0, 0.0, -1.0]]), np.array([[4.0, 4.0, 1.0, 1.0]]))
    assert (lo > hi).all()
    # unbounded θ is kept, unbounded box clipped by the range
    lo, hi = c.contract(
        np.array([[-np.inf, -np.inf, 1.0, -np.inf]]), np.array([[np.inf, np.inf, 2.0, np.inf]])
    )
    assert lo.tolist() == [[-2, -2, 1, -np.inf]] and hi.tolist() == [[2, 2, 2, np.inf]]
    # point boxes, ray angle exact
    t = np.pi / 3
    lo, hi = c.contract(np.array([[-5.0, -5.0, 2.0, t]]), np.array([[5.0, 5.0, 2.0, t]]))
    assert lo[0, 3] == t == hi[0, 3] and np.isclose(lo[0, 0], 1.0) and np.isclose(hi[0, 1], np.sqrt(3))
    with pytest.raises(ValueError, match="dimension 3"):
        c(Box([(0, 1), (0, 1), (0, 1)]))


def test_tighter_than_forward_backward() -> None:
    """The forward-backward contractor of the same equations never gives a smaller box."""
    from digslam.observer import CtcFwdBwd, cos, sin

    fb = CtcFwdBwd(Function(lambda p: (p[0] - p[2] * cos(p[3]), p[1] - p[2] * sin(p[3]))), (0.0, 0.0))
    lo, hi = random_boxes(np.random.default_rng(5), 400)
    lo[:, 2] = np.maximum(lo[:, 2], 0)
    a, b = CTC.contract(lo, hi), fb.contract(lo, hi)
    ok = ~(b[0] > b[1]).any(1)
    assert ((a[0][ok] >= b[0][ok] - 1e-12) | (a[0][ok] > a[1][ok])).all()
    assert ((a[1][ok] <= b[1][ok] + 1e-12) | (a[0][ok] > a[1][ok])).all()
    assert (
        (a[1] - a[0])[ok & ~(a[0] > a[1]).any(1)] < (b[1] - b[0])[ok & ~(a[0] > a[1]).any(1)] - 1e-6
    ).any()


def random_xy(rng: np.random.Generator, n: int, span: float = 8.0, width: float = 2.0):
    c, w = rng.uniform(-span, span, (n, 2)), rng.uniform(0, width, (n, 2))
    return c - w, c + w


def test_pie_separator_invariant_and_points() -> None:
    rng = np.random.default_rng(7)
    s = SepPiInv((2.1, 4.0), (np.pi / 12, 3 * np.pi / 4))  # Figure 3.5
    lo, hi = random_xy(rng, 3000, 5, 1.5)
    xin, xout = s.separate(lo, hi)
    assert not check_separation(xin, xout, lo, hi).any()
    # points: outside the pie are never removed from x_in, inside never from x_out
    pts = rng.uniform(lo, hi)
    r, t = np.hypot(pts[:, 0], pts[:, 1]), np.arctan2(pts[:, 1], pts[:, 0])
    inside = (r >= 2.1) & (r <= 4.0) & (t >= np.pi / 12) & (t <= 3 * np.pi / 4)
    in_out = ((xout[0] <= pts) & (pts <= xout[1])).all(1)
    in_in = ((xin[0] <= pts) & (pts <= xin[1])).all(1)
    assert in_out[inside].all() and in_in[~inside].all()
    assert SepPolarXY is SepPiInv


def test_pie_separator_minimal() -> None:
    """x_out is the hull of box ∩ pie, x_in the hull of box minus pie (dense sampling of each box)."""
    rng = np.random.default_rng(8)
    s = SepPiInv((2.1, 4.0), (-2.0, 2.5))  # crosses the ±π cut through θ + 2π? no: aperture 4.5
    lo, hi = random_xy(rng, 60, 5, 1.5)
    xin, xout = s.separate(lo, hi)
    for i in range(len(lo)):
        g = np.stack(
            np.meshgrid(np.linspace(lo[i, 0], hi[i, 0], 400), np.linspace(lo[i, 1], hi[i, 1], 400)), -1
        )
        g = g.reshape(-1, 2)
        r, t = np.hypot(g[:, 0], g[:, 1]), np.arctan2(g[:, 1], g[:, 0])
        ins = (r >= 2.1) & (r <= 4.0) & (t >= -2.0) & (t <= 2.5)
        tol = 2 * (hi[i] - lo[i]) / 399 + 1e-9
        for part, mask in ((xout, ins), (xin, ~ins)):
            if mask.any():
                assert np.all(part[0][i] <= g[mask].min(0) + 1e-12) and np.all(
                    part[1][i] >= g[mask].max(0) - 1e-12
                )
                assert np.all(np.abs(part[0][i] - g[mask].min(0)) <= tol)
                assert np.all(np.abs(part[1][i] - g[mask].max(0)) <= tol)


def test_sep_pi_on_rho_theta() -> None:
    """S_π (Eq. 3.51): (ρ, θ) whose image lies in the box [x]×[y] = [-3, 4]×[1, 2]."""
    rng = np.random.default_rng(9)
    s = SepPi(((-3.0, 4.0), (1.0, 2.0)))
    c, w = np.c_[rng.uniform(0, 5, 2000), rng.uniform(-4, 7, 2000)], rng.uniform(0, 0.8, (2000, 2))
    lo, hi = c - w, c + w
    xin, xout = s.separate(lo, hi)
    assert not check_separation(xin, xout, lo, hi).any()
    pts = rng.uniform(lo, hi)
    x, y = pts[:, 0] * np.cos(pts[:, 1]), pts[:, 0] * np.sin(pts[:, 1])
    inside = (x >= -3) & (x <= 4) & (y >= 1) & (y <= 2)
    assert ((xout[0] <= pts) & (pts <= xout[1])).all(1)[inside].all()
    assert ((xin[0] <= pts) & (pts <= xin[1])).all(1)[~inside].all()


def test_generic_theorem_3_2_with_a_subpaving() -> None:
    """Y = two boxes (Figure 3.4): the complement subpaving and the separator for π⁻¹(Y)."""
    ylo, yhi = np.array([[1.0, 1.0], [3.0, 1.0]]), np.array([[2.0, 3.0], [4.0, 3.0]])
    clo, chi = complement_boxes(ylo, yhi)
    pts = np.random.default_rng(1).uniform(-2, 7, (5000, 2))
    in_y = ((ylo[None] <= pts[:, None]) & (pts[:, None] <= yhi[None])).all(2).any(1)
    in_c = ((clo[None] <= pts[:, None]) & (pts[:, None] <= chi[None])).all(2).any(1)
    assert (in_y | in_c).all() and not (in_y & in_c).any()
    s = SepCtcPreimage(CTC, (2, 3), (ylo, yhi))
    rng = np.random.default_rng(2)
    c, w = np.c_[rng.uniform(0, 5, 1000), rng.uniform(-1, 2.5, 1000)], rng.uniform(0, 0.5, (1000, 2))
    lo, hi = c - w, c + w
    xin, xout = s.separate(lo, hi)
    assert not check_separation(xin, xout, lo, hi).any()
    q = rng.uniform(lo, hi)
    img = np.c_[q[:, 0] * np.cos(q[:, 1]), q[:, 0] * np.sin(q[:, 1])]
    inside = ((ylo[None] <= img[:, None]) & (img[:, None] <= yhi[None])).all(2).any(1)
    assert ((xout[0] <= q) & (q <= xout[1])).all(1)[inside].all()
    assert ((xin[0] <= q) & (q <= xin[1])).all(1)[~inside].all()


def fwd_bwd_landmark(m, rho, theta) -> SepInverse:
    from digslam.observer import atan2, sqrt

    f = Function(lambda x: (sqrt((m[0] - x[0]) ** 2 + (m[1] - x[1]) ** 2), atan2(m[1] - x[1], m[0] - x[0])))
    return SepInverse(f, Box([rho, theta]))


def test_landmark_beats_forward_backward() -> None:
    """§3.4.1.1: first outer box never larger, fewer bisections at equal ε, same set."""
    rho, theta = (4.0, 6.0), (-np.pi / 12, np.pi / 4)
    ours, fb = SepLandmark((0, 0), rho, theta), fwd_bwd_landmark((0, 0), rho, theta)
    x0 = Box([(-6, 4), (-6, 4)])
    (_, o1), (_, o2) = ours(x0), fb(x0)
    assert (o1.lo >= o2.lo).all() and (o1.hi <= o2.hi).all()
    pa, pb = pave(x0, ours, 0.05), pave(x0, fb, 0.05)
    assert pa.bisections < pb.bisections
    exact = 0.5 * (36 - 16) * (np.pi / 3)
    assert pa.inner_area <= exact <= pa.inner_area + pa.boundary_area
    assert pb.inner_area <= exact <= pb.inner_area + pb.boundary_area
    rng = np.random.default_rng(4)
    lo, hi = random_xy(rng, 2000, 6, 1)
    xin, xout = ours.separate(lo, hi)
    assert not check_separation(xin, xout, lo, hi).any()


#: codac 2.1.2's best pavings of the landmark of §3.4.1.1 (``benchmarks/bench_polar.py``): bisections
#: and undetermined area of ``pave`` with ``SepInverse`` (its fewest bisections at both ε).
CODAC_BEST = {0.01: (1818, 0.037320), 0.001: (17161, 0.004060)}


@pytest.mark.parametrize("eps", [0.01, 0.001])
def test_landmark_paving_beats_codac_at_equal_eps(eps: float) -> None:
    """The minimal polar separator with the grid cut and ``max_volume = ε²/2``: fewer bisections and
    less undetermined area than codac's best at the same ε, and the exact set stays enclosed."""
    rho, theta = (4.0, 6.0), (-np.pi / 12, np.pi / 4)
    p = pave(Box([(-6, 4), (-6, 4)]), SepLandmark((0, 0), rho, theta), eps, cut="grid", max_volume=eps**2 / 2)
    bisections, area = CODAC_BEST[eps]
    assert p.bisections < bisections and p.boundary_area < area
    exact = 0.5 * (36 - 16) * (np.pi / 3)
    assert p.inner_area <= exact <= p.inner_area + p.boundary_area
    assert (np.maximum(p.boundary[1] - p.boundary[0], 0).max(axis=1) < eps).all()
    rng = np.random.default_rng(5)
    pts = rng.uniform(*p.inner)
    r, a = np.hypot(pts[:, 0], pts[:, 1]), np.arctan2(-pts[:, 1], -pts[:, 0])  # m - x = π(ρ, θ)
    assert ((r >= 4) & (r <= 6) & (a >= -np.pi / 12) & (a <= np.pi / 4)).all()


def test_landmark_fewer_bisections_than_forward_backward_with_the_same_policy() -> None:
    """§3.4.1.1 at ε = 0.01 with the grid cut: the minimal separator needs fewer bisections than
    forward-backward, for the same undetermined area within 1 %."""
    rho, theta = (4.0, 6.0), (-np.pi / 12, np.pi / 4)
    x0, kw = Box([(-6, 4), (-6, 4)]), {"cut": "grid", "max_volume": 0.01**2 / 2}
    pa = pave(x0, SepLandmark((0, 0), rho, theta), 0.01, **kw)
    pb = pave(x0, fwd_bwd_landmark((0, 0), rho, theta), 0.01, **kw)
    assert pa.bisections < pb.bisections and pa.boundary_area <= pb.boundary_area * 1.01


@pytest.mark.parametrize(
    ("rho", "theta", "match"),
    [
        ((-1.0, 2.0), (0.0, 1.0), "rho"),
        ((1.0, 2.0), (0.0, 7.0), "aperture"),
        ((1.0, 2.0), (1.0, 1.0), "aperture"),
        ((1.0, 2.0), (2.0, 1.0), "aperture"),
        ((2.0, 1.0), (0.0, 1.0), "rho"),
        ((1.0, 2.0), (0.0, np.inf), "aperture"),
        ((1.0, 2.0, 3.0), (0.0, 1.0), "two"),
    ],
)
def test_bad_pie(rho, theta, match) -> None:
    with pytest.raises(ValueError, match=match):
        SepPiInv(rho, theta)


def test_bad_input_others() -> None:
    with pytest.raises(ValueError, match="landmark"):
        SepLandmark((0.0, np.nan), (1.0, 2.0), (0.0, 1.0))
    with pytest.raises(ValueError, match="box"):
        SepPi(((1.0, 0.0), (0.0, 1.0)))
    with pytest.raises(ValueError, match="x_cols"):
        SepCtcPreimage(CTC, (0, 5), (np.zeros(2), np.ones(2)))
    with pytest.raises(ValueError, match="dimension 2"):
        SepCtcPreimage(CTC, (2, 3), (np.zeros(3), np.ones(3)))
    with pytest.raises(ValueError, match="dimension"):
        SepLandmark((0, 0), (1, 2), (0, 1))(Box([(0, 1), (0, 1), (0, 1)]))


def test_xy_only_mode_matches_full_contractor() -> None:
    """``need_theta=False`` (used by the (x, y) separators) contracts x, y, ρ exactly as the full one."""
    lo, hi = random_boxes(np.random.default_rng(11), 3000)
    a, b = CtcPolar(need_theta=True).contract(lo, hi), CtcPolar(need_theta=False).contract(lo, hi)
    ea, eb = (a[0] > a[1]).any(1), (b[0] > b[1]).any(1)
    assert (ea == eb).all()
    assert (a[0][~ea, :3] == b[0][~ea, :3]).all() and (a[1][~ea, :3] == b[1][~ea, :3]).all()
    assert (b[0][~eb, 3] <= a[0][~ea, 3]).all() and (b[1][~eb, 3] >= a[1][~ea, 3]).all()


def test_degenerate_sets() -> None:
    """Y = R² (nothing outside), and a cone without range bounds (ρ ∈ [0, ∞))."""
    s = SepCtcPreimage(CTC, (2, 3), (np.full(2, -np.inf), np.full(2, np.inf)))
    (ilo, ihi), (olo, ohi) = s.separate(np.array([[1.0, 0.0]]), np.array([[2.0, 1.0]]))
    assert (ilo > ihi).all() and olo.tolist() == [[1.0, 0.0]] and ohi.tolist() == [[2.0, 1.0]]
    cone = SepPiInv((0.0, np.inf), (0.0, np.pi / 2))  # the first quadrant
    rng = np.random.default_rng(12)
    lo, hi = random_xy(rng, 2000, 4, 1)
    xin, xout = cone.separate(lo, hi)
    assert not check_separation(xin, xout, lo, hi).any()
    quad = (lo >= 0).all(1)
    assert ((xin[0] > xin[1]).any(1) == quad).all()  # closed quadrant: interior boxes proved inside
    out = (hi < 0).any(1)
    assert ((xout[0] > xout[1]).any(1) == out).all()


def test_theorem_3_2_with_a_separator_for_y() -> None:
    """Y given by a separator: sound, and never tighter than the subpaving (minimal) construction."""
    from digslam.observer import SepBox

    rng = np.random.default_rng(13)
    c, w = np.c_[rng.uniform(0, 5, 800), rng.uniform(-1, 2.5, 800)], rng.uniform(0, 0.5, (800, 2))
    lo, hi = c - w, c + w
    by_sep = SepCtcPreimage(CTC, (2, 3), SepBox(Box([(1, 2), (1, 3)])))
    minimal = SepCtcPreimage(CTC, (2, 3), (np.array([1.0, 1.0]), np.array([2.0, 3.0])))
    (ai, ao), (bi, bo) = by_sep.separate(lo, hi), minimal.separate(lo, hi)
    assert not check_separation(ai, ao, lo, hi).any()
    for small, big in ((bi, ai), (bo, ao)):
        empty = (small[0] > small[1]).any(1)
        assert (empty | ((small[0] >= big[0]) & (small[1] <= big[1])).all(1)).all()
    with pytest.raises(ValueError, match="separator of dimension 3"):
        SepCtcPreimage(CTC, (2, 3), SepBox(Box([(0, 1), (0, 1), (0, 1)])))
