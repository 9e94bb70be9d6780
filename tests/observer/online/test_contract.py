"""The impact contractor of one pose box (Eq. 6.22, :func:`digslam.observer.online.pose_jit.contract`) decides
every cell as its definition does, :func:`~digslam.observer.online.pose_jit.contract_cells` (one clearance
search per cell), to the bit.

``contract`` searches cell by cell within a budget, then decides the cells left a row of the box at once from
the nearest not-free cell of each column; that is the same predicate only because the clearance bound and
the searched offsets are monotone in the row and column offsets. These tests compare the two, with the
default budget, with none (every cell a row at a time) and with the whole window's (mostly cell by cell), on
random maps (sparse and dense obstacles, walls, a box on the grid's
edge or outside the frame's window, point boxes, radii from 0 to far past the grid) and on the maps and
boxes of a Dig-SLAM mission in the thesis's room: equal floats, so the filter and the offline fixpoint that
call it give the same sets, to the bit, as with the definition.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import binary_dilation

from digslam.envs.sim.generators import ThesisRoom
from digslam.envs.sim.missions import loop_mission
from digslam.observer.online.pose_jit import contract, contract_cells
from digslam.observer.online.smoother import dig_slam, impact_radius
from digslam.observer.online.window import grid_frame
from digslam.observer.record.grid import Grid

#: Budgets of the cell-by-cell searches, as the window's area over ``share``: none, and the whole window.
SHARES = (1 << 40, 1)


def random_free(rng: np.random.Generator, ny: int, nx: int, kind: int) -> np.ndarray:
    """A random ``M⁻``: scattered, a few holes, dilated blobs, or a walled room with specks."""
    if kind == 0:
        free = rng.random((ny, nx)) < rng.uniform(0.5, 1.0)
    elif kind == 1:
        free = np.ones((ny, nx), bool)
        k = int(rng.integers(0, 5))
        free[rng.integers(0, ny, k), rng.integers(0, nx, k)] = False
    elif kind == 2:
        free = ~binary_dilation(rng.random((ny, nx)) < 0.01, iterations=int(rng.integers(1, 4)))
    else:
        free = np.zeros((ny, nx), bool)
        free[2:-2, 2:-2] = True
        free &= rng.random((ny, nx)) < 0.98
    return np.ascontiguousarray(free)


def same(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    """Equal floats, bit for bit (the signs of zeros included)."""
    return np.array_equal(np.array(a).view(np.int64), np.array(b).view(np.int64))


@pytest.mark.parametrize("seed", range(4))
def test_contract_is_its_definition_on_random_maps(seed: int) -> None:
    rng = np.random.default_rng(seed)
    cut = empty = 0
    for trial in range(400):
        ny, nx = (int(v) for v in rng.integers(5, 80, 2))
        cs = float(rng.choice([0.05, 0.1, 0.125, 0.3]))
        g = Grid((-nx * cs / 2, -ny * cs / 2), (nx * cs / 2, ny * cs / 2), (ny, nx))
        frame, free = grid_frame(g), random_free(rng, ny, nx, trial % 4)
        for _ in range(8):
            c = rng.uniform(g.lo, g.hi)
            w = rng.exponential(0.3, 2) * rng.choice([0.0, 1.0, 1.0, 5.0])
            lo, hi = np.maximum(c - w * rng.random(2), g.lo), np.minimum(c + w * rng.random(2), g.hi)
            r = float(rng.choice([rng.uniform(0, 0.3), rng.uniform(0, 2), rng.uniform(0, 10), 0.0, 1e3]))
            got = contract(free, frame, lo[0], lo[1], hi[0], hi[1], r)
            ref = contract_cells(free, frame, lo[0], lo[1], hi[0], hi[1], r)
            assert same(got, ref), (seed, trial, lo, hi, r)
            for share in SHARES:
                assert same(contract(free, frame, lo[0], lo[1], hi[0], hi[1], r, share), ref), (
                    seed,
                    trial,
                    share,
                )
            empty += got[0] == np.inf
            cut += not same(got, (lo[0], lo[1], hi[0], hi[1]))
    assert empty > 50 and cut > 100  # the contractor did cut, and emptied, boxes


def test_contract_is_its_definition_on_a_mission() -> None:
    """The maps of the thesis's room half-way and at the end of a loop, the boxes of the offline tube widened
    up to a few cells, each step's impact radius."""
    world = ThesisRoom().generate(0)
    record, truth = loop_mission(world, duration=60.0, seed=0)
    grid = Grid.from_cell_size((-10.0, -10.0), (10.0, 10.0), 0.05)
    frame, rng = grid_frame(grid), np.random.default_rng(0)
    r_hi = impact_radius(record, 0)
    cut = 0
    for part in (len(record) // 2, len(record)):
        res = dig_slam(record[:part], grid, truth[0, :2], truth[0, :2])
        assert res.consistent and res.tube is not None and res.dig is not None
        free = np.ascontiguousarray(res.dig.free)
        for k in range(0, part, 3):
            grow = rng.uniform(0.0, 0.3, 4)
            lo = np.maximum(res.tube.gate_lo[k] - grow[:2], grid.lo)
            hi = np.minimum(res.tube.gate_hi[k] + grow[2:], grid.hi)
            got = contract(free, frame, lo[0], lo[1], hi[0], hi[1], float(r_hi[k]))
            ref = contract_cells(free, frame, lo[0], lo[1], hi[0], hi[1], float(r_hi[k]))
            assert same(got, ref), k
            for share in SHARES:
                assert same(contract(free, frame, lo[0], lo[1], hi[0], hi[1], float(r_hi[k]), share), ref), k
            cut += not same(got, (lo[0], lo[1], hi[0], hi[1]))
    assert cut > 40  # about a fifth of the widened boxes are cut
