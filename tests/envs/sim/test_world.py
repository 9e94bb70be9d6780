"""Worlds: seeded generators, exact rasterisation, file maps, the start-pose check."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from digslam.envs import Caves, FileMap, Mixed, RockField, RoomsCorridors, ThesisRoom, World
from digslam.envs.sim.raster import FREE, MIXED, OCCUPIED, cell_centres, rasterize

GENERATORS = [ThesisRoom(), RockField(n=20), Caves(), RoomsCorridors()]


@pytest.mark.parametrize("gen", GENERATORS, ids=lambda g: g.name)
def test_generators_are_seeded_and_keep_the_origin_free(gen: object) -> None:
    a, b, c = gen.generate(5), gen.generate(5), gen.generate(6)
    assert np.array_equal(a.edges, b.edges)
    if gen.name != "room":
        assert not np.array_equal(a.edges, c.edges) if a.edges.shape == c.edges.shape else True
    assert a.clearance(np.zeros((1, 2)))[0] > 0.3
    assert a.free_area(0.1) > 10.0


@pytest.mark.parametrize("size", [3.0, 10.0, 25.0])
def test_generators_scale_with_size(size: float) -> None:
    for gen in (ThesisRoom(size), RockField(size, n=5), Caves(size), RoomsCorridors(size)):
        w = gen.generate(0)
        assert w.frame == (-size, -size, size, size)
        assert np.all(np.abs(w.edges) <= size + 1e-9)


def _dense_classes(world: World, res: float, k: int = 6) -> tuple[np.ndarray, np.ndarray]:
    """Free/occupied share of k*k interior samples in every cell."""
    xs, ys = cell_centres(world.frame, res)
    off = (np.arange(k) + 0.5) / k - 0.5
    px = (xs[None, :, None, None] + res * off[None, None, None, :]) + 0 * off[None, None, :, None]
    py = (ys[:, None, None, None] + res * off[None, None, :, None]) + 0 * off[None, None, None, :]
    px, py = np.broadcast_arrays(px, py)
    free = world.is_free(np.column_stack([px.ravel(), py.ravel()])).reshape(px.shape)
    return free.all(axis=(2, 3)), (~free).all(axis=(2, 3))


@pytest.mark.parametrize("gen", GENERATORS, ids=lambda g: g.name)
@pytest.mark.parametrize("res", [0.37, 0.5])
def test_raster_is_exact_at_cell_level(gen: object, res: float) -> None:
    world = gen.generate(1)
    cells = world.raster(res)
    all_free, all_occ = _dense_classes(world, res)
    assert np.all(all_free[cells == FREE])
    assert np.all(all_occ[cells == OCCUPIED])
    # MIXED cells are the cells whose interior holds a point of some edge (dense edge samples); an edge that
    # only touches a cell's border (e.g. through a corner) may, within rounding, also make it MIXED.
    e, t = world.edges, np.linspace(0.0, 1.0, 2001)[1:-1]
    fx = ((e[:, :1] + t * (e[:, 2:3] - e[:, :1])).ravel() - world.frame[0]) / res
    fy = ((e[:, 1:2] + t * (e[:, 3:4] - e[:, 1:2])).ravel() - world.frame[1]) / res
    ok = (fx % 1 > 1e-9) & (fy % 1 > 1e-9) & (fx < cells.shape[1]) & (fy < cells.shape[0])
    hit = np.zeros(cells.shape, dtype=bool)
    hit[fy[ok].astype(int), fx[ok].astype(int)] = True
    extra = (cells == MIXED) & ~hit
    assert not np.any(hit & (cells != MIXED))
    assert np.count_nonzero(extra) <= 0.02 * np.count_nonzero(hit)
    xs, ys = cell_centres(world.frame, res)
    iy, ix = np.nonzero(extra)
    near = world.clearance(np.column_stack([xs[ix], ys[iy]]))
    assert np.all(np.abs(near) <= res * np.sqrt(0.5) + 1e-9)


def test_raster_edge_on_cell_border_is_not_mixed() -> None:
    square = np.array([(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)])
    cells = rasterize(World((-2, -2, 2, 2), [square]).edges, (-2, -2, 2, 2), 0.5)
    assert not np.any(cells == MIXED)
    assert np.count_nonzero(cells == FREE) == 16 and np.count_nonzero(cells == OCCUPIED) == 48


def test_thin_obstacle_makes_mixed_cells() -> None:
    frame = np.array([(-2.0, -2.0), (2.0, -2.0), (2.0, 2.0), (-2.0, 2.0)])
    sliver = np.array([(0.1, -1.5), (0.1005, -1.5), (0.1005, 1.5), (0.1, 1.5)])
    cells = World((-2, -2, 2, 2), [frame, sliver]).raster(0.5)
    assert np.count_nonzero(cells == MIXED) == 6 and not np.any(cells == OCCUPIED)


def test_file_maps_json_npy_png(tmp_path: Path) -> None:
    pygame = pytest.importorskip("pygame")
    spec = {
        "frame": [-5, -5, 5, 5],
        "rings": [[[-5, -5], [5, -5], [5, 5], [-5, 5]], [[1, 1], [2, 1], [2, 2], [1, 2]]],
    }
    (tmp_path / "m.json").write_text(json.dumps(spec))
    w = FileMap(tmp_path / "m.json").generate(0)
    assert w.is_free([[0, 0]])[0] and not w.is_free([[1.5, 1.5]])[0]
    img = np.ones((40, 40), dtype=bool)
    img[5:10, 30:35] = False  # top-right block in image coordinates
    np.save(tmp_path / "m.npy", img)
    w = FileMap(tmp_path / "m.npy", size=4.0).generate(0)
    assert w.is_free([[0, 0]])[0] and not w.is_free([[2.6, 2.6]])[0]
    surf = pygame.surfarray.make_surface(np.repeat(img.T[:, :, None] * 255, 3, axis=2).astype(np.uint8))
    pygame.image.save(surf, str(tmp_path / "m.png"))
    w2 = FileMap(tmp_path / "m.png", size=4.0).generate(0)
    assert np.array_equal(w.edges, w2.edges)
    with pytest.raises(ValueError, match="map_path"):
        FileMap(tmp_path / "missing.json")


def test_start_pose_enclosed_by_obstacles_is_rejected() -> None:
    world = RockField(n=20).generate(0)
    inside = world.rings[1].mean(axis=0)
    with pytest.raises(ValueError, match="start"):
        world.check_start(np.array([*inside, 0.0]), 0.2)
    world.check_start(np.array([0.0, 0.0, 0.0]), 0.2)
    with pytest.raises(ValueError, match="frame"):
        World((1, 0, 0, 1), [])


@pytest.mark.parametrize("gen", GENERATORS[2:], ids=lambda g: g.name)
def test_traced_contours_are_closed(gen: object) -> None:
    # Every vertex of a closed edge soup has an even degree (bit-identical shared endpoints).
    e = gen.generate(3).edges
    pts = np.concatenate([e[:, :2], e[:, 2:]])
    _, counts = np.unique(pts, axis=0, return_counts=True)
    assert np.all(counts % 2 == 0)


@pytest.mark.parametrize("seed", range(4))
def test_traced_caves_chain_into_rings(seed: int) -> None:
    from digslam.envs.sim.geometry import point_free, rings_to_edges

    w = Caves().generate(seed)
    assert w.rings and sum(len(r) for r in w.rings) == len(w.edges)
    pts = np.random.default_rng(seed).uniform(-10, 10, (2000, 2))
    assert np.array_equal(point_free(pts, rings_to_edges(w.rings)), point_free(pts, w.edges))


def test_mixed_draws_every_generator_from_the_seed() -> None:
    """``world="mixed"``: each level is one generator's world, which one drawn from the level's seed; the same
    seed gives the same world, and 40 seeds meet all four generators of the coverage suite."""
    gen = Mixed()
    names = [gen.generate(s).name for s in range(40)]
    assert set(names) == {"room", "rocks", "caves", "rooms"}
    for s in (0, 7):
        assert np.array_equal(gen.generate(s).edges, gen.generate(s).edges)
    with pytest.raises(ValueError, match="frame"):
        Mixed((ThesisRoom(5.0),), size=10.0)


def test_the_mixed_env_gives_new_levels_of_every_generator() -> None:
    import gymnasium as gym

    import digslam.envs  # noqa: F401  (registers the ids)

    env = gym.make("digslam/DigCoverage-v0", world="mixed")
    names = set()
    for s in range(16):
        env.reset(seed=s)
        names.add(env.unwrapped.world.name)
    env.reset(seed=3)
    first = env.unwrapped.world.edges.copy()
    env.reset(seed=3)
    assert np.array_equal(first, env.unwrapped.world.edges)
    assert len(names) >= 3


def test_one_registry_names_every_world() -> None:
    """The config's world names are the registry's, and each generator builds itself from a config."""
    from digslam.envs.config import WORLDS, ExploreConfig
    from digslam.envs.sim.generators import BENCHMARK, GENERATORS, PROCEDURAL, make_generator

    assert set(WORLDS) == set(GENERATORS) and set(BENCHMARK) <= set(GENERATORS)
    rocks = make_generator(ExploreConfig(world="rocks", n_obstacles=5, world_size=8.0))
    assert isinstance(rocks, RockField) and rocks.n == 5 and rocks.frame == (-8.0, -8.0, 8.0, 8.0)
    mixed = make_generator(ExploreConfig(world="mixed", n_obstacles=7, room_jitter=0.2))
    assert isinstance(mixed, Mixed) and [g.name for g in mixed.generators] == list(PROCEDURAL)
    assert mixed.generators[1].n == 7 and mixed.generators[0].jitter == 0.2
