"""Guaranteed explored zone (thesis App. B): soundness against ground truth over random trajectories.

Every cell proved clear must lie inside the true explored zone (dense samples of the cell, borders
included, against the true poses), every truly explored sample must fall in a non-dark cell, and a
dark cell must hold no explored point. Noise draws include values exactly at the tube's bounds.
"""

from __future__ import annotations

import numpy as np
import pytest

from digslam.observer.record.grid import Grid
from digslam.observer.slam.explored import (
    SepExploredDisks,
    explored_disks_grid,
    explored_disks_thick_sep,
    explored_hypotheses,
    explored_thick_sep,
)
from digslam.observer.slam.explored_sweep import explored_sectors_grid, explored_sweep_grid, sweep_gates
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA
from digslam.observer.thick.sep import ThickSep, thick_classify_grid

GRID = Grid((-6.0, -6.0), (6.0, 6.0), (48, 48))


def cell_samples(grid: Grid, mask: np.ndarray, k: int = 5) -> np.ndarray:
    """``(n_cells, k*k, 2)`` lattice points of the masked cells, corners and edges included."""
    r, c = np.nonzero(mask)
    u = np.linspace(0.0, 1.0, k)
    fx = grid.xs[c][:, None] + u[None] * (grid.xs[c + 1] - grid.xs[c])[:, None]
    fy = grid.ys[r + 1][:, None] + u[None] * (grid.ys[r] - grid.ys[r + 1])[:, None]
    px = np.repeat(fx, k, axis=1)
    py = np.tile(fy, (1, k))
    return np.stack([px, py], -1)


def cell_of(grid: Grid, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Row and column of the cell holding each point (points inside the frame only)."""
    c = np.searchsorted(grid.xs, pts[:, 0], side="right") - 1
    r = np.searchsorted(-grid.ys, -pts[:, 1], side="right") - 1
    ok = (c >= 0) & (c < grid.shape[1]) & (r >= 0) & (r < grid.shape[0])
    return r[ok], c[ok], ok


def random_tube(rng: np.random.Generator, m: int) -> dict:
    """A random walk, a tube around it (the truth sits at a random place in each box, at the bounds
    for a third of the times) and true radii inside random radius intervals (endpoints included)."""
    true = np.cumsum(rng.normal(0, 0.6, (m, 2)), axis=0)
    true -= true.mean(0)
    e_lo, e_hi = rng.uniform(0, 0.8, (m, 2)), rng.uniform(0, 0.8, (m, 2))
    at = rng.random(m) < 1 / 3
    e_lo[at], e_hi[at] = 0.0, rng.uniform(0, 1.0, (int(at.sum()), 2))  # truth on the lower corner
    r_lo = rng.uniform(0.5, 2.5, m)
    r_hi = r_lo + rng.uniform(0, 1.0, m) * (rng.random(m) < 0.8)
    pick = rng.integers(0, 3, m)
    r_true = np.where(pick == 0, r_lo, np.where(pick == 1, r_hi, rng.uniform(r_lo, r_hi)))
    psi = rng.uniform(-np.pi, np.pi, m)
    d_lo, d_hi = rng.uniform(0, 0.4, m), rng.uniform(0, 0.4, m)
    d_hi[at] = 0.0
    return {"true": true, "lo": true - e_lo, "hi": true + e_hi, "r_lo": r_lo, "r_hi": r_hi,
            "r": r_true, "psi": psi, "psi_lo": psi - d_lo, "psi_hi": psi + d_hi}  # fmt: skip


def seen_disks(pts: np.ndarray, pos: np.ndarray, r: np.ndarray) -> np.ndarray:
    """``(P,)`` points seen by some closed disk ``(pos_i, r_i)`` and ``(P,)`` seen by an open one."""
    d = np.hypot(pts[:, None, 0] - pos[None, :, 0], pts[:, None, 1] - pos[None, :, 1])
    return (d <= r[None]).any(1), (d < r[None]).any(1)


def seen_sectors(pts: np.ndarray, pos: np.ndarray, psi: np.ndarray, alpha: float, gamma: float,
                 r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Sector membership with the closed and the open disk (angles closed as in Eq. B.2; the apex
    counts as seen in the closed one only)."""
    dx, dy = pts[:, None, 0] - pos[None, :, 0], pts[:, None, 1] - pos[None, :, 1]
    d = np.hypot(dx, dy)
    off = np.abs(np.angle(np.exp(1j * (np.arctan2(dy, dx) - psi[None] - alpha))))
    closed = ((d <= r[None]) & ((off <= gamma) | (d == 0))).any(1)
    opened = ((d < r[None]) & (off <= gamma) & (d > 0)).any(1)
    return closed, opened


def check_sound(grid: Grid, st: np.ndarray, seen: callable) -> None:
    """Clear cells wholly seen (open sets), dark cells wholly unseen (closed sets), seen points non-dark."""
    for code, want in ((CLEAR, True), (DARK, False)):
        mask = st == code
        if not mask.any():
            continue
        pts = cell_samples(grid, mask).reshape(-1, 2)
        closed, opened = seen(pts)
        if want:
            assert opened.all(), f"a clear cell holds an unexplored point {pts[~opened][0]}"
        else:
            assert not closed.any(), f"a dark cell holds an explored point {pts[closed][0]}"
    rng = np.random.default_rng(1)
    pts = rng.uniform(-6, 6, (20000, 2))
    closed, _ = seen(pts)
    r, c, ok = cell_of(grid, pts[closed])
    assert not (st[r, c] == DARK).any(), "an explored point falls in a dark cell"


@pytest.mark.parametrize("seed", range(6))
def test_disks_sound(seed: int) -> None:
    rng = np.random.default_rng(seed)
    t = random_tube(rng, 40)
    st = explored_disks_grid(GRID, t["lo"], t["hi"], t["r_lo"], t["r_hi"])
    assert (st == CLEAR).any() and (st == DARK).any()
    check_sound(GRID, st, lambda p: seen_disks(p, t["true"], t["r"]))
    # any other trajectory of the tube: the box corners opposite to the truth
    check_sound(GRID, st, lambda p: seen_disks(p, t["hi"], t["r_lo"]))


@pytest.mark.parametrize("seed", range(3))
def test_disks_penumbra_is_penumbra(seed: int) -> None:
    """A penumbra cell is in Z⁺ (seen by some pose of the tube) and off Z⁻ (unseen by another)."""
    rng = np.random.default_rng(seed)
    t = random_tube(rng, 30)
    st = explored_disks_grid(GRID, t["lo"], t["hi"], t["r_lo"], t["r_hi"])
    pts = cell_samples(GRID, st == PENUMBRA).reshape(-1, 2)
    assert pts.size
    gap = np.maximum(0, np.maximum(t["lo"][None] - pts[:, None], pts[:, None] - t["hi"][None]))
    assert (np.hypot(gap[..., 0], gap[..., 1]) <= t["r_hi"][None]).any(1).all()
    far = np.maximum(np.abs(pts[:, None] - t["lo"][None]), np.abs(pts[:, None] - t["hi"][None]))
    assert (np.hypot(far[..., 0], far[..., 1]) >= t["r_lo"][None]).all()


def test_disks_exact_box_and_large_batch() -> None:
    """A point tube and exact radius: clear inside the disk, dark outside, nothing else far from it."""
    g = Grid((-4.0, -4.0), (4.0, 4.0), (80, 80))
    st = explored_disks_grid(g, [[0.0, 0.0]], [[0.0, 0.0]], 3.0, 3.0)
    gx, gy = g.centers()
    d = np.hypot(gx, gy)
    assert (st[d < 2.85] == CLEAR).all() and (st[d > 3.15] == DARK).all()
    assert not (st == PENUMBRA).any()


@pytest.mark.parametrize("seed", range(4))
def test_sectors_sound(seed: int) -> None:
    rng = np.random.default_rng(10 + seed)
    t = random_tube(rng, 25)
    alpha, gamma = rng.uniform(-np.pi, np.pi), rng.uniform(0.3, 2.5)
    st = explored_sectors_grid(GRID, t["lo"], t["hi"], t["psi_lo"], t["psi_hi"], alpha, gamma,
                               t["r_lo"] + 0.5, t["r_hi"] + 1.0)  # fmt: skip
    assert (st == CLEAR).any() and (st == DARK).any()
    check_sound(GRID, st, lambda p: seen_sectors(p, t["true"], t["psi"], alpha, gamma, t["r"] + 0.5))
    check_sound(GRID, st, lambda p: seen_sectors(p, t["hi"], t["psi_lo"], alpha, gamma, t["r_hi"] + 1.0))


def test_sector_full_aperture_is_disk() -> None:
    rng = np.random.default_rng(3)
    t = random_tube(rng, 20)
    a = explored_sectors_grid(
        GRID, t["lo"], t["hi"], t["psi_lo"], t["psi_hi"], 0.0, np.pi, t["r_lo"], t["r_hi"]
    )
    b = explored_disks_grid(GRID, t["lo"], t["hi"], t["r_lo"], t["r_hi"])
    assert ((a == CLEAR) <= (b == CLEAR)).all() and ((a == DARK) == (b == DARK)).all()


def test_cross_intersection_fig_b2() -> None:
    """Figure B.2: two candidate trajectories; the crossing of their opposite pies is clear."""
    g = Grid((-3.0, -3.0), (3.0, 3.0), (60, 60))
    pa, pb = np.array([[0.0, -1.2], [-2.5, 2.5]]), np.array([[2.5, -2.5], [0.0, 1.2]])
    sa, sb = np.array([np.pi / 2, np.pi]), np.array([0.0, -np.pi / 2])
    gam, r = np.pi / 5, 2.0
    a = explored_sectors_grid(g, pa, pa, sa, sa, 0.0, gam, r, r)
    b = explored_sectors_grid(g, pb, pb, sb, sb, 0.0, gam, r, r)
    joined = explored_hypotheses([a, b])
    cell = cell_of(g, np.array([[0.01, 0.02]]))[:2]
    assert joined[cell] == CLEAR
    # no single time proves it: the certainly visible set ∩_h V(x^h(t_k)) misses it (left side of B.7)
    for k in (0, 1):
        at_k = [explored_sectors_grid(g, p[k:k + 1], p[k:k + 1], s[k], s[k], 0.0, gam, r, r)
                for p, s in ((pa, sa), (pb, sb))]  # fmt: skip
        assert explored_hypotheses(at_k)[cell] != CLEAR
    lo, hi = np.minimum(pa, pb), np.maximum(pa, pb)
    hull = explored_sectors_grid(g, lo, hi, np.minimum(sa, sb), np.maximum(sa, sb), 0.0, gam, r, r)
    assert not (hull == CLEAR).any()
    # soundness of the join: every clear sample is seen under a and under b
    pts = cell_samples(g, joined == CLEAR).reshape(-1, 2)
    for pos, psi in ((pa, sa), (pb, sb)):
        assert seen_sectors(pts, pos, psi, 0.0, gam, np.full(2, r))[1].all()
    pts = cell_samples(g, joined == DARK).reshape(-1, 2)
    for pos, psi in ((pa, sa), (pb, sb)):
        assert not seen_sectors(pts, pos, psi, 0.0, gam, np.full(2, r))[0].any()


def smooth_path(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A smooth true path at ``n`` fine steps (unit time each): positions, headings, speed."""
    w = np.cumsum(rng.normal(0, 0.02, n))
    psi = np.cumsum(0.01 * np.sin(w) + rng.normal(0, 0.002, n)) + rng.uniform(-np.pi, np.pi)
    v = 0.04
    pos = np.cumsum(v * np.stack([np.cos(psi), np.sin(psi)], 1), axis=0) - [3.0, 0.0]
    return pos, psi, np.abs(np.diff(psi)).max()


@pytest.mark.parametrize("seed", range(3))
def test_sweep_sound(seed: int) -> None:
    rng = np.random.default_rng(20 + seed)
    n, step = 3000, 10  # fine steps of the truth, samples every `step` fine steps
    pos, psi, wmax = smooth_path(rng, n)
    idx = np.arange(0, n, step)
    e = 0.02 + 0.0004 * idx[:, None]
    lo, hi = pos[idx] - e * rng.random((idx.size, 2)), pos[idx] + e * rng.random((idx.size, 2))
    lo[::3], hi[1::3] = pos[idx][::3], pos[idx][1::3]  # truth exactly on a bound
    plo, phi_ = psi[idx] - 0.02, psi[idx] + 0.02
    gates = sweep_gates(lo, hi, plo, phi_, v_max=0.04 * step * 1.01, w_max=wmax * step * 1.01, dt=1.0)
    s_lo, s_hi = -1.5, 2.0
    st = explored_sweep_grid(GRID, lo, hi, plo, phi_, s_lo, s_hi, *gates)
    assert (st == CLEAR).any() and (st == DARK).any()
    # truth on the fine steps between the first and last samples
    p, h = pos[: idx[-1] + 1], psi[: idx[-1] + 1]
    u, nrm = np.stack([np.cos(h), np.sin(h)], 1), np.stack([np.sin(h), -np.cos(h)], 1)

    def coords(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = pts[:, None] - p[None]
        return (d * u[None]).sum(-1), (d * nrm[None]).sum(-1)

    tol = 0.05  # one fine step of travel: the segment may pass a point between two fine steps
    pick = np.random.default_rng(seed).permutation
    pts = cell_samples(GRID, st == CLEAR, 3).reshape(-1, 2)
    pts = pts[pick(len(pts))[:2000]]
    phi, s = coords(pts)
    crosses = (np.sign(phi[:, :-1]) != np.sign(phi[:, 1:])) | (phi[:, :-1] == 0)
    inside = (s[:, :-1] >= s_lo - tol) & (s[:, :-1] <= s_hi + tol)
    assert (crosses & inside).any(1).all(), "a clear cell holds a point the sweep never crossed"
    pts = cell_samples(GRID, st == DARK, 3).reshape(-1, 2)
    pts = pts[pick(len(pts))[:2000]]
    phi, s = coords(pts)
    near = (np.abs(phi) <= 0.04) & (s >= s_lo) & (s <= s_hi)
    assert not near.any(), "a dark cell holds a point the sweep crossed"


def test_thick_sep_matches_grid_and_paves() -> None:
    rng = np.random.default_rng(5)
    t = random_tube(rng, 15)
    ts = explored_disks_thick_sep(t["lo"], t["hi"], t["r_lo"], t["r_hi"])
    g = Grid((-6.0, -6.0), (6.0, 6.0), (40, 40))
    a = thick_classify_grid(([-6.0, -6.0], [6.0, 6.0]), ts, (40, 40))
    b = explored_disks_grid(g, t["lo"], t["hi"], t["r_lo"], t["r_hi"])
    assert (a == b).mean() > 0.999
    from digslam.observer.thick.paver import thick_pave

    p = thick_pave(([-6.0, -6.0], [6.0, 6.0]), ts, 0.2)
    pts = np.concatenate([p.clear[0], p.clear[1], 0.5 * (p.clear[0] + p.clear[1])])
    assert seen_disks(pts, t["true"], t["r"])[1].all()
    pts = np.concatenate([p.dark[0], p.dark[1], 0.5 * (p.dark[0] + p.dark[1])])
    assert not seen_disks(pts, t["true"], t["r"])[0].any()
    assert p.clear_area > 0 and p.penumbra_area > 0


def test_generic_thick_sep_agrees_with_closed_form() -> None:
    from digslam.observer import Function, Interval, SepInverse

    def disk(r: float) -> SepInverse:
        return SepInverse(Function(lambda x: x[0] ** 2 + x[1] ** 2), Interval(0, r * r))

    lo, hi = np.array([[-0.2, -0.1]]), np.array([[0.2, 0.3]])
    gen = explored_thick_sep(ThickSep(disk(1.0), disk(1.4)), lo, hi, eps=0.1)
    ref = explored_disks_grid(Grid((-2.0, -2.0), (2.0, 2.0), (12, 12)), lo, hi, 1.0, 1.4)
    st = thick_classify_grid(([-2.0, -2.0], [2.0, 2.0]), gen, (12, 12))
    assert (st == CLEAR).any() and (st == DARK).any()
    # the two are sound: never contradictory (clear vs dark, or clear vs penumbra)
    assert not ((st == CLEAR) & (ref == DARK)).any() and not ((st == DARK) & (ref == CLEAR)).any()
    assert not ((st == CLEAR) & (ref == PENUMBRA)).any() and not ((st == PENUMBRA) & (ref == CLEAR)).any()


def test_bad_input() -> None:
    z = np.zeros((3, 2))
    with pytest.raises(ValueError, match="pos_lo"):
        explored_disks_grid(GRID, np.zeros((3, 3)), np.zeros((3, 3)), 1.0, 2.0)
    with pytest.raises(ValueError, match="pos_lo"):
        explored_disks_grid(GRID, z + 1, z, 1.0, 2.0)
    with pytest.raises(ValueError, match="r_lo"):
        explored_disks_grid(GRID, z, z, 2.0, 1.0)
    with pytest.raises(ValueError, match="r_lo"):
        explored_disks_grid(GRID, z, z, -1.0, 1.0)
    with pytest.raises(ValueError, match="r_lo"):
        explored_disks_grid(GRID, z, z, np.ones(4), 2.0)
    with pytest.raises(ValueError, match="gamma"):
        explored_sectors_grid(GRID, z, z, 0.0, 0.0, 0.0, 4.0, 1.0, 2.0)
    with pytest.raises(ValueError, match="psi_lo"):
        explored_sectors_grid(GRID, z, z, 1.0, 0.0, 0.0, 1.0, 1.0, 2.0)
    with pytest.raises(ValueError, match="gate_lo"):
        explored_sweep_grid(GRID, z, z, 0.0, 0.0, -1.0, 1.0, z, z, 0.0, 0.0)
    with pytest.raises(ValueError, match="s_lo"):
        explored_sweep_grid(GRID, z, z, 0.0, 0.0, 1.0, -1.0, z[:2], z[:2], 0.0, 0.0)
    with pytest.raises(ValueError, match="v_max"):
        sweep_gates(z + [[0, 0], [5, 0], [0, 0]], z + [[0, 0], [5, 0], [0, 0]], 0.0, 0.0, 0.1, 0.1, 1.0)
    with pytest.raises(ValueError, match="statuses"):
        explored_hypotheses([])
    with pytest.raises(ValueError, match="bound"):
        SepExploredDisks(z, z, 1.0, 2.0, "middle")
    with pytest.raises(ValueError, match="visible"):
        explored_thick_sep("disk", z, z, 0.1)  # type: ignore[arg-type]


def test_example_runs(tmp_path) -> None:
    from example_loader import load

    res = load("b5_explored_zone").run(m=300, out=tmp_path, sweep_m=500, cells=160)
    assert res["b2_cross_clear_cells"] > 0 and res["b2_hull_clear_cells"] == 0
    assert res["disks"]["clear"] > 0 and res["sweep"]["clear"] > 0
    assert (tmp_path / "b5_explored_zone.png").exists()
