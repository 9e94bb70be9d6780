"""The dig zone M⁻ and the impact contractor (thesis Eq. 6.21–6.22) against brute-force ground truth."""

from __future__ import annotations

import numpy as np
import pytest

from digslam.observer.record.grid import Grid
from digslam.observer.slam.digmap import DigMap

GRID = Grid((-3.0, -2.0), (3.0, 2.5), (45, 60))


def corners(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The 4 corners ``(..., 4, 2)`` of 2-d boxes."""
    return np.stack(
        [lo, np.stack([hi[..., 0], lo[..., 1]], -1), hi, np.stack([lo[..., 0], hi[..., 1]], -1)], -2
    )


def random_poses(rng: np.random.Generator, n: int, width: float = 0.4) -> tuple[np.ndarray, np.ndarray]:
    c = rng.uniform([-2.0, -1.5], [2.0, 2.0], (n, 2))
    w = rng.uniform(0, width, (n, 2))
    return c - w / 2, c + w / 2


def test_dig_disks_sound_and_tight():
    rng = np.random.default_rng(1)
    lo, hi = random_poses(rng, 40)
    r = rng.uniform(0.2, 1.5, 40)
    clo, chi = GRID.cell_boxes()
    # farthest distance between a pose box and a cell is reached at corners
    far = np.linalg.norm(
        corners(clo, chi)[None, :, :, None, :] - corners(lo, hi)[:, None, None, :, :], axis=-1
    )
    far = far.max(axis=(2, 3))  # (poses, cells)
    inside = (far < r[:, None]).any(axis=0).reshape(GRID.shape)
    m = DigMap(GRID)
    m.dig_disks(lo, hi, r)
    assert not (m.free & ~inside).any(), "a dug cell is not inside the free disk of some pose"
    margin = (far < r[:, None] - 1e-9).any(axis=0).reshape(GRID.shape)
    assert not (margin & ~m.free).any(), "a cell inside a disk with margin was not dug"


def sector_inside(p: np.ndarray, psi: np.ndarray, alpha: float, gamma: float, r: float) -> np.ndarray:
    ang = np.arctan2(p[..., 1], p[..., 0])
    diff = np.abs((ang - psi - alpha + np.pi) % (2 * np.pi) - np.pi)
    return (np.linalg.norm(p, axis=-1) < r) & ((diff <= gamma) | (np.linalg.norm(p, axis=-1) == 0))


@pytest.mark.parametrize("gamma", [np.pi / 12, np.pi / 3, 0.8 * np.pi])
def test_dig_sectors_sound(gamma):
    rng = np.random.default_rng(2)
    n = 12
    lo, hi = random_poses(rng, n, 0.2)
    psi_lo = rng.uniform(-np.pi, np.pi, n)
    psi_hi = psi_lo + rng.uniform(0, 0.05, n)
    alpha = rng.uniform(-np.pi, np.pi, n)
    r = rng.uniform(0.5, 2.0, n)
    m = DigMap(GRID)
    m.dig_sectors(lo, hi, psi_lo, psi_hi, alpha, np.full(n, gamma), r)
    assert m.free.any()
    rows, cols = np.nonzero(m.free)
    clo, chi = GRID.cell_boxes(rows, cols)
    # each dug cell: some sector contains it for every pose corner, cell point and heading sampled
    pts = np.concatenate(
        [corners(clo, chi), clo[:, None] + (chi - clo)[:, None] * rng.random((len(rows), 6, 2))], 1
    )
    ok_any = np.zeros(len(rows), dtype=bool)
    for i in range(n):
        ok = np.ones(len(rows), dtype=bool)
        for x in corners(lo[i], hi[i]):
            for psi in (psi_lo[i], psi_hi[i], 0.5 * (psi_lo[i] + psi_hi[i])):
                ok &= sector_inside(pts - x, psi, alpha[i], gamma, r[i]).all(axis=1)
        ok_any |= ok
    assert ok_any.all(), f"{int((~ok_any).sum())} dug cells lie outside every sector"


def test_dig_sectors_covers_most_of_a_narrow_cone():
    m = DigMap(Grid((-1.0, -1.0), (3.0, 3.0), (200, 200)))
    m.dig_sectors([[0.0, 0.0]], [[0.0, 0.0]], [0.0], [0.0], [np.pi / 4], [np.pi / 12], [2.5])
    area = m.free.sum() * 0.02**2
    exact = np.pi / 12 * 2.5**2
    assert 0.85 * exact < area < exact


def brute_clearance(free: np.ndarray, grid: Grid) -> np.ndarray:
    """Min over non-free cells (and the outside) of the box-to-box distance, per cell."""
    clo, chi = grid.cell_boxes()
    occ = ~free.ravel()
    gap = np.maximum(0, np.maximum(clo[:, None] - chi[None, occ], clo[None, occ] - chi[:, None]))
    d = np.linalg.norm(gap, axis=-1).min(axis=1, initial=np.inf)
    out = np.minimum.reduce([clo[:, 0] - grid.lo[0], clo[:, 1] - grid.lo[1], grid.hi[0] - chi[:, 0],
                             grid.hi[1] - chi[:, 1]])  # fmt: skip
    return np.where(free.ravel(), np.minimum(d, out), 0.0).reshape(grid.shape)


def test_clearance_lower_bounds_the_exact_distance():
    rng = np.random.default_rng(3)
    g = Grid((-1.0, -1.0), (1.0, 1.5), (25, 20))
    m = DigMap(g)
    lo, hi = random_poses(rng, 6, 0.1)
    m.dig_disks(lo * 0.4, hi * 0.4, rng.uniform(0.3, 0.9, 6))
    m.free[rng.random(g.shape) < 0.03] = False  # small holes
    low, exact = m.clearance_lower(), brute_clearance(m.free, g)
    assert np.all(low <= exact)
    assert np.all(exact - low <= np.hypot(*g.cell_size) + 1e-9)


def test_contract_impacts_keeps_every_feasible_pose():
    rng = np.random.default_rng(4)
    m = DigMap(GRID)
    m.dig_disks([[-1.5, -1.0], [0.5, 0.0]], [[-1.4, -0.9], [0.6, 0.2]], [1.2, 1.6])
    clo, chi = GRID.cell_boxes()
    occ = ~m.free.ravel()
    x = rng.uniform([-2.5, -1.8], [2.5, 2.2], (300, 2))
    # exact distance from x to comp M⁻ (non-free cells, or outside the frame)
    gap = np.maximum(0, np.maximum(clo[None, occ] - x[:, None], x[:, None] - chi[None, occ]))
    d = np.minimum(np.linalg.norm(gap, axis=-1).min(axis=1),
                   np.min(np.c_[x - GRID.lo, np.array(GRID.hi) - x], axis=1))  # fmt: skip
    r_hi = d * (1 + rng.uniform(0, 0.3, x.shape[0]))  # the true impact is within y⁺
    w = rng.uniform(0, 0.5, (x.shape[0], 2))
    lo, hi = x - w * rng.random((x.shape[0], 2)), x + w * rng.random((x.shape[0], 2))
    nlo, nhi = m.contract_impacts(lo, hi, r_hi)
    assert np.all((nlo <= x) & (x <= nhi)), "a feasible pose was removed"
    assert np.any(nhi - nlo < hi - lo - 1e-9), "nothing was contracted"
    # a box entirely in the deep interior of M⁻ with a tiny range is inconsistent: it becomes empty
    elo, ehi = m.contract_impacts([[0.5, 0.05]], [[0.55, 0.1]], [0.05])
    assert elo[0, 0] == np.inf and ehi[0, 0] == -np.inf


def test_bad_input():
    m = DigMap(GRID)
    with pytest.raises(ValueError, match="pos_lo"):
        m.dig_disks(np.zeros((2, 3)), np.zeros((2, 3)), np.ones(2))
    with pytest.raises(ValueError, match="alpha"):
        m.dig_sectors(np.zeros((2, 2)), np.zeros((2, 2)), [0, 0], [0, 0], [0], [0.1, 0.1], [1, 1])
    with pytest.raises(TypeError, match="grid"):
        DigMap("not a grid")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="shape"):
        Grid((0, 0), (1, 1), (0, 3))
    with pytest.raises(ValueError, match="cell_size"):
        Grid.from_cell_size((0, 0), (1, 1), 0.0)
    with pytest.raises(ValueError, match="positive size"):
        Grid((0, 0), (0, 1), (3, 3))


def test_grid_count_below_matches_searchsorted():
    rng = np.random.default_rng(5)
    g = Grid.from_cell_size((-10, -10), (10, 10), 0.05)
    v = np.concatenate([rng.uniform(-11, 11, 5000), g.xs, np.nextafter(g.xs, 11), np.nextafter(g.xs, -11)])
    for strict, side in ((True, "left"), (False, "right")):
        assert np.array_equal(Grid.count_below(g.xs, v, strict), np.searchsorted(g.xs, v, side))
