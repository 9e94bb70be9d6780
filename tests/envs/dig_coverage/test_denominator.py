"""The coverage denominator: the certifiable reachable free area (closed cells that meet no obstacle).

The checker here is independent of the raster code: the hand-made worlds are axis-aligned, so whether a
closed cell meets an obstacle is a comparison of its bounds with the rectangles'.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import digslam.envs  # noqa: F401  (registers the ids)
from digslam.agents.baselines import make_baseline
from digslam.envs.dig_coverage.wrapper import reachable_free
from digslam.envs.sim.raster import FREE, MIXED, rasterize
from digslam.envs.sim.world import World
from digslam.observer.record.grid import Grid

FRAME = (-2.0, -2.0, 2.0, 2.0)
CELL = 0.25
#: An obstacle whose left edge lies on the grid line x = 0.5 and whose bottom edge on y = -0.5.
BLOCK = np.array([(0.5, -0.5), (1.0, -0.5), (1.0, 0.5), (0.5, 0.5)])


def _ring(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    return np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])


def _expected(rects_solid: list[tuple[float, float, float, float]], n: int) -> np.ndarray:
    """``(n, n)`` bool, row 0 at the top: closed cells of the frame grid that meet no solid rectangle and
    no frame wall (the frame's own edges lie on the outer cell edges)."""
    out = np.zeros((n, n), dtype=bool)
    for r in range(n):
        for c in range(n):
            x0, x1 = FRAME[0] + c * CELL, FRAME[0] + (c + 1) * CELL
            y1, y0 = FRAME[3] - r * CELL, FRAME[3] - (r + 1) * CELL
            touches_frame = x0 <= FRAME[0] or x1 >= FRAME[2] or y0 <= FRAME[1] or y1 >= FRAME[3]
            touches = any(
                x0 <= bx1 and bx0 <= x1 and y0 <= by1 and by0 <= y1 for bx0, by0, bx1, by1 in rects_solid
            )
            out[r, c] = not (touches_frame or touches)
    return out


def test_closed_raster_marks_cells_that_touch_an_edge() -> None:
    world = World(FRAME, [_ring(*FRAME), BLOCK])
    open_ = rasterize(world.edges, FRAME, CELL)
    closed = rasterize(world.edges, FRAME, CELL, closed=True)
    # column 9 spans x in [0.25, 0.5]: its right side lies on the block's left edge
    row = 8  # y in [0, 0.25] (row index along y)
    assert open_[row, 9] == FREE and closed[row, 9] == MIXED
    assert open_[row, 8] == FREE and closed[row, 8] == FREE
    # the corner cell below-left of the block touches it at one vertex only
    assert open_[5, 9] == FREE and closed[5, 9] == MIXED
    # every cell along the frame touches a frame wall
    assert (closed[0] == MIXED).all() and (closed[:, -1] == MIXED).all()
    # the closed raster only adds MIXED cells
    assert ((closed == open_) | (closed == MIXED)).all()


def test_denominator_excludes_cells_touching_walls_and_keeps_their_neighbours() -> None:
    world = World(FRAME, [_ring(*FRAME), BLOCK])
    n = 16
    grid = Grid(FRAME[:2], FRAME[2:], (n, n))
    got = reachable_free(world, grid, np.array([-1.1, -1.1, 0.0]))
    want = _expected([(0.5, -0.5, 1.0, 0.5)], n)
    np.testing.assert_array_equal(got, want)
    # the cell left of the block's edge is out, the one next to it (and every other free cell) in
    r = int((FRAME[3] - 0.1) // CELL)  # y in [0, 0.25]
    assert not got[r, 9] and got[r, 8]
    assert got.sum() == (n - 2) ** 2 - 4 * 6  # the inner 14 x 14 less the block grown by one cell (4 x 6)


@pytest.mark.parametrize("world_name", ["rocks", "rooms"])
def test_denominator_holds_no_cell_that_touches_an_obstacle(world_name: str) -> None:
    """On generated levels: every counted cell's closed box, shrunk by nothing, meets no obstacle edge
    (checked with an exact segment / box test on the cell's bounds, outside the raster code)."""
    env = gym.make("digslam/DigCoverage-v0", world=world_name)
    _, info = env.reset(seed=123457)
    layer = env
    while not hasattr(layer, "reachable"):
        layer = layer.env
    g, world = layer.grid, env.unwrapped.world
    ny, nx = g.shape
    res = (g.hi[0] - g.lo[0]) / nx
    rows, cols = np.nonzero(layer.reachable)
    x0 = g.lo[0] + cols * res
    y1 = g.hi[1] - rows * res
    e = world.edges
    # an edge meets a closed box iff their bounding boxes overlap and the box's corners are not all on one
    # strict side of the edge's line (separating axis test, exact enough at these magnitudes)
    for a in range(len(e)):
        ex0, ey0, ex1, ey1 = e[a]
        bb = (np.minimum(ex0, ex1) <= x0 + res) & (x0 <= np.maximum(ex0, ex1))
        bb &= (np.minimum(ey0, ey1) <= y1) & (y1 - res <= np.maximum(ey0, ey1))
        if not bb.any():
            continue
        dx, dy = ex1 - ex0, ey1 - ey0
        side = [
            dx * (cy - ey0) - dy * (cx - ex0)
            for cx in (x0[bb], x0[bb] + res)
            for cy in (y1[bb] - res, y1[bb])
        ]
        s = np.stack(side)
        assert ((s > 0).all(axis=0) | (s < 0).all(axis=0)).all(), f"edge {a} meets a counted cell"
    env.close()


def test_exact_odometry_certifies_a_convex_room_to_one() -> None:
    """With no noise and a zero-width start box, every certifiable cell of a convex room is proved clear:
    the denominator leaves out exactly the cells that no sound observer can certify."""
    env = gym.make("digslam/DigCoverage-v0", world="rocks", n_obstacles=0, world_size=2.0, room_jitter=0.0,
                   target=1.0, start_box=0.0, noise={"speed": 0.0, "yaw_rate": 0.0, "heading": 0.0, "range": 0.0})  # fmt: skip
    agent = make_baseline("frontier", env)
    obs, info = env.reset(seed=3)
    for _ in range(600):
        obs, _, terminated, truncated, info = env.step(agent.predict(obs)[0])
        assert info["certified_coverage"] <= info["true_coverage"] <= 1.0
        if terminated or truncated:
            break
    assert info["certified_coverage"] == 1.0 and terminated
    env.close()
