"""The ``floorplan`` generator: seeded windows of real plans, closed at their border, with a reachable start;
the shipped plans and their split."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from digslam.envs.sim.generators.floorplan import PLANS_DIR, SHIPPED, SPLIT, Floorplan, shipped_paths
from digslam.envs.sim.occupancy import OccupancyMap, load_plan

START_CLEARANCE = 1.5 * 0.2 + 1.5 * 1.0 * 0.1 / 4  # ExploreEnv's start clearance with the default config


@pytest.fixture(scope="module")
def gen() -> Floorplan:
    return Floorplan()


def test_same_seed_same_level_other_seeds_differ(gen: Floorplan) -> None:
    a, b = gen.generate(7), gen.generate(7)
    assert a.name == b.name and np.array_equal(a.edges, b.edges)
    assert gen.window(7)[0] == gen.window(7)[0]
    rng_a, rng_b = np.random.default_rng(3), np.random.default_rng(3)
    assert np.array_equal(a.sample_reachable_pose(rng_a, START_CLEARANCE),
                          b.sample_reachable_pose(rng_b, START_CLEARANCE))  # fmt: skip
    names = {gen.window(s)[0].label for s in range(20)}
    assert len(names) == 20


def test_levels_are_closed_with_enough_reachable_free_space(gen: Floorplan) -> None:
    rotations, plans = set(), set()
    for seed in range(30):
        win, free = gen.window(seed)
        world = gen.generate(seed)
        rotations.add(win.rotation)
        plans.add(win.plan)
        assert world.name == win.label and world.frame == (-10.0, -10.0, 10.0, 10.0)
        assert np.all(np.abs(world.edges) <= 10.0 + 1e-9)  # every edge inside the frame: closed at its border
        assert free.shape == (200, 200) and win.free_share >= gen.min_free
        assert win.free_share == pytest.approx(free.mean())
        # The start ExploreEnv draws lies in the level's free space, which is one piece.
        pose = world.sample_reachable_pose(np.random.default_rng(seed), START_CLEARANCE)
        col, row = np.floor((pose[:2] + 10.0) / 0.1).astype(int)
        assert free[199 - row, col]
        assert world.raster(0.1)[free[::-1] == 0].min() > 0  # nothing free outside the level's free space
    assert rotations == {0, 90, 180, 270}
    assert len(plans) >= 4


def test_the_world_is_the_plan_window_rotated(gen: Floorplan) -> None:
    plans = {p.name: p for p in gen.plans}
    rng = np.random.default_rng(0)
    for seed in (1, 2, 3, 4, 5, 6):
        win, free = gen.window(seed)
        world = gen.generate(seed)
        plan = plans[win.plan]
        # World points (off the pixel borders) are free exactly where the level's mask is.
        ij = rng.integers(0, 200, (400, 2))
        pts = np.column_stack([-10.0 + (ij[:, 1] + 0.5) * 0.1, 10.0 - (ij[:, 0] + 0.5) * 0.1])
        assert np.array_equal(world.is_free(pts), free[ij[:, 0], ij[:, 1]])
        # Turned back, the mask lies in the plan's free space at the window's corner.
        back = np.rot90(free, -win.rotation // 90)
        c0 = int(round((win.corner[0] - plan.origin[0]) / plan.resolution))
        r0 = plan.shape[0] - 200 - int(round((win.corner[1] - plan.origin[1]) / plan.resolution))
        assert not (back & ~plan.free[r0 : r0 + 200, c0 : c0 + 200]).any()


def test_user_maps_mixed_and_small(tmp_path: Path) -> None:
    img = np.full((60, 80), 254, dtype=np.uint8)
    img[:, 40] = 0
    img[25:35, 40] = 254  # a 0.5 m door at 0.05 m/px
    h, w = img.shape
    (tmp_path / "lab.pgm").write_bytes(b"P5\n%d %d\n255\n" % (w, h) + img.tobytes())
    (tmp_path / "lab.yaml").write_text(
        "image: lab.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    mask = OccupancyMap(np.ones((30, 30), dtype=bool), 0.1, (0.0, 0.0), "square")
    gen = Floorplan([tmp_path / "lab.yaml", shipped_paths()[6], mask], size=2.0, weighting="plan")
    seen = {gen.window(s)[0].plan for s in range(40)}
    assert seen == {"lab", "kth_50052751", "square"}
    for s in range(10):
        win, free = gen.window(s)
        assert free.shape == ((80, 80) if win.plan == "lab" else (40, 40))
        assert gen.generate(s).frame == (-2.0, -2.0, 2.0, 2.0)


def test_bad_plans_get_one_line(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="plans: the list is empty"):
        Floorplan([])
    with pytest.raises(ValueError, match="wrap it in"):
        Floorplan(str(shipped_paths()[0]))  # type: ignore[arg-type]  # a single path, refused on purpose
    np.save(tmp_path / "m.npy", np.ones((10, 10), dtype=bool))
    with pytest.raises(ValueError, match=r"m\.npy: resolution: required"):
        Floorplan([tmp_path / "m.npy"])
    tiny = OccupancyMap(np.ones((3, 3), dtype=bool), 0.1, name="tiny")  # no room for the robot
    with pytest.raises(ValueError, match="plans: no window of 20 m") as e:
        Floorplan([tiny], max_draws=5).generate(0)
    assert "\n" not in str(e.value)
    with pytest.raises(ValueError, match="min_free"):
        Floorplan([tiny], min_free=0.0)


def test_splits_hold_every_shipped_plan_once() -> None:
    names = [n for split in SPLIT.values() for n in split]
    assert sorted(names) == sorted(SHIPPED) and len(set(names)) == len(names)
    assert set(SPLIT) == {"train", "validation", "test"}
    for n in SHIPPED:
        assert (PLANS_DIR / f"{n}.npz").is_file()
    assert (PLANS_DIR / "LICENSE-MapEx.txt").is_file() and (PLANS_DIR / "README.md").is_file()
    test = Floorplan(shipped_paths("test"))
    assert {test.window(s)[0].plan for s in range(30)} == set(SPLIT["test"])
    for split in SPLIT.values():  # both buildings in every split
        assert {n[4:9] for n in split} == {"50010", "50052"}
    with pytest.raises(ValueError, match="split"):
        shipped_paths("tuning")


def test_shipped_plan_sizes() -> None:
    m = load_plan(PLANS_DIR / "kth_50052751.npz")
    assert m.frame == pytest.approx((0.0, 0.0, 78.6, 25.6))


def test_from_config_takes_the_world_size() -> None:
    from digslam.envs.config import ExploreConfig

    gen = Floorplan.from_config(ExploreConfig(world_size=6.0))
    assert isinstance(gen, Floorplan) and gen.frame == (-6.0, -6.0, 6.0, 6.0) and len(gen.plans) == 10
