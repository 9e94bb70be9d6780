"""Occupancy maps at metric scale: ROS map files, floor-plan ``.npz``, plain masks, and their doors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage

from digslam.envs.sim.generators.floorplan import shipped_paths
from digslam.envs.sim.occupancy import (
    OccupancyMap,
    disc_reachable,
    load_map,
    load_mask,
    load_plan,
    load_ros_map,
)

RES = 0.05
ORIGIN = (-1.0, 2.0)


def _picture() -> np.ndarray:
    """40 x 60 grey picture (row 0 at the top): free (254), a wall (0) at columns 30-31, a wall along rows
    0-3, and a grey patch (128, between the thresholds) at rows 30-35, columns 5-10."""
    img = np.full((40, 60), 254, dtype=np.uint8)
    img[:, 30:32] = 0
    img[0:4, :] = 0
    img[30:36, 5:11] = 128
    return img


def _write_p5(path: Path, img: np.ndarray) -> Path:
    h, w = img.shape
    path.write_bytes(b"P5\n# CREATOR: test\n%d %d\n# a comment in the header\n255\n" % (w, h) + img.tobytes())
    return path


def _write_p2(path: Path, img: np.ndarray) -> Path:
    h, w = img.shape
    rows = "\n".join(" ".join(str(v) for v in r) for r in img)
    path.write_text(f"P2\n# plain\n{w} {h}\n255\n{rows}\n")
    return path


def _write_png(path: Path, img: np.ndarray) -> Path:
    import pygame

    rgb = np.repeat(img.T[:, :, None], 3, axis=2)  # surfarray is (w, h, 3)
    pygame.image.save(pygame.surfarray.make_surface(rgb), str(path))
    return path


def _write_yaml(path: Path, image: str, over: dict[str, object] | None = None) -> Path:
    keys: dict[str, object] = {
        "image": image,
        "resolution": RES,
        "origin": f"[{ORIGIN[0]}, {ORIGIN[1]}, 0.0]",
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    }
    keys.update(over or {})
    path.write_text("".join(f"{k}: {v}\n" for k, v in keys.items() if v is not None))
    return path


def _check_picture_world(m: OccupancyMap) -> None:
    assert m.resolution == RES and m.origin == ORIGIN
    assert m.frame == pytest.approx((-1.0, 2.0, 2.0, 4.0))
    w = m.world()
    y = 2.0 + 10 * RES  # a row of the lower half
    # The wall of columns 30-31 spans x in [0.5, 0.6].
    assert w.is_free(np.array([[0.45, y], [0.55, y], [0.65, y]])).tolist() == [True, False, True]
    # The top four rows span y in [3.8, 4.0]; the grey patch (unknown) is obstacle: rows 30-35 (y 2.2-2.5),
    # columns 5-10 (x -0.75..-0.45).
    assert w.is_free(np.array([[0.0, 3.9], [0.0, 3.7], [-0.6, 2.35], [-0.6, 2.6]])).tolist() == [
        False, True, False, True,
    ]  # fmt: skip
    assert not w.is_free(np.array([[-1.1, 3.0], [2.1, 3.0]])).any()  # outside the mask: closed


def test_ros_map_p5_places_the_walls_in_metres(tmp_path: Path) -> None:
    _write_p5(tmp_path / "map.pgm", _picture())
    _check_picture_world(load_ros_map(_write_yaml(tmp_path / "map.yaml", "map.pgm")))


def test_ros_map_negate_p2_png_and_absolute_image_path(tmp_path: Path) -> None:
    neg = tmp_path / "neg.pgm"
    _write_p5(neg, 255 - _picture())
    _check_picture_world(load_ros_map(_write_yaml(tmp_path / "neg.yaml", str(neg), {"negate": 1})))
    _write_p2(tmp_path / "plain.pgm", _picture())
    _check_picture_world(load_ros_map(_write_yaml(tmp_path / "plain.yaml", "plain.pgm")))
    sub = tmp_path / "maps"
    sub.mkdir()
    _write_png(sub / "map.png", _picture())
    _check_picture_world(load_map(_write_yaml(sub / "map.yml", "map.png")))


def test_ros_map_thresholds_and_modes(tmp_path: Path) -> None:
    img = np.array([[0, 60, 128, 200, 254, 255]], dtype=np.uint8)  # p = 1, .76, .5, .22, .004, 0
    _write_p5(tmp_path / "g.pgm", img)
    free = load_ros_map(_write_yaml(tmp_path / "a.yaml", "g.pgm")).free[0].tolist()
    assert free == [False, False, False, False, True, True]
    free = load_ros_map(_write_yaml(tmp_path / "b.yaml", "g.pgm", {"free_thresh": 0.3})).free[0].tolist()
    assert free == [False, False, False, True, True, True]
    free = load_ros_map(_write_yaml(tmp_path / "c.yaml", "g.pgm", {"negate": 1})).free[0].tolist()
    assert free == [True, False, False, False, False, False]
    free = load_ros_map(_write_yaml(tmp_path / "d.yaml", "g.pgm", {"mode": "scale"})).free[0].tolist()
    assert free == [False, False, False, False, True, True]
    raw = np.array([[0, 1, 100, 255]], dtype=np.uint8)  # raw: 0 free, 1..100 occupied, 255 unknown
    _write_p5(tmp_path / "r.pgm", raw)
    assert load_ros_map(_write_yaml(tmp_path / "r.yaml", "r.pgm", {"mode": "raw"})).free[0].tolist() == [
        True, False, False, False,
    ]  # fmt: skip


def _one_line_error(path: Path, *needles: str) -> None:
    with pytest.raises(ValueError) as e:
        load_map(path)
    msg = str(e.value)
    assert "\n" not in msg, msg
    for needle in (path.name, *needles):
        assert needle in msg, msg


@pytest.mark.parametrize(
    ("over", "key"),
    [
        ({"resolution": None}, "resolution"),
        ({"origin": None}, "origin"),
        ({"free_thresh": None}, "free_thresh"),
        ({"resolution": -0.05}, "resolution"),
        ({"resolution": 0}, "resolution"),
        ({"image": "nowhere.pgm"}, "image"),
        ({"free_thresh": 0.7}, "free_thresh"),
        ({"occupied_thresh": 1.5}, "occupied_thresh"),
        ({"negate": 2}, "negate"),
        ({"mode": "fancy"}, "mode"),
        ({"origin": "[0.0, 0.0, 0.5]"}, "origin"),
    ],
)
def test_bad_ros_yaml_gets_one_line_naming_file_and_key(tmp_path: Path, over: dict, key: str) -> None:
    _write_p5(tmp_path / "map.pgm", _picture())
    _one_line_error(_write_yaml(tmp_path / "bad.yaml", "map.pgm", over), key)


def test_unreadable_yaml_and_image_without_free_pixel(tmp_path: Path) -> None:
    bad = tmp_path / "broken.yaml"
    bad.write_text("image: [map.pgm\nresolution: 0.05: 3\n")
    _one_line_error(bad, "yaml")
    _write_p5(tmp_path / "black.pgm", np.zeros((5, 5), dtype=np.uint8))
    _one_line_error(_write_yaml(tmp_path / "black.yaml", "black.pgm"), "image", "black.pgm", "no free pixel")
    (tmp_path / "junk.pgm").write_bytes(b"P5\n4 4\n255\n\x00")
    _one_line_error(_write_yaml(tmp_path / "junk.yaml", "junk.pgm"), "image")


def test_the_callers_array_is_not_modified() -> None:
    free = np.ones((4, 5), dtype=bool)
    m = OccupancyMap(free, 0.1, (1, 2), "m")
    free[0, 0] = False
    assert m.free.all() and not m.free.flags.writeable
    with pytest.raises(ValueError, match="resolution"):
        OccupancyMap(free, 0.0)


def _two_rooms(gap_px: int) -> np.ndarray:
    """Two 3 m x 3 m rooms at 0.1 m/px side by side, a 0.2 m wall between them with a centred gap."""
    free = np.zeros((32, 64), dtype=bool)
    free[1:31, 1:31] = free[1:31, 33:63] = True
    lo = 16 - gap_px // 2
    free[lo : lo + gap_px, 31:33] = True
    return free


@pytest.mark.parametrize(("gap_px", "disc", "world"), [(3, False, False), (4, False, False),
                                                       (5, True, False), (8, True, True)])  # fmt: skip
def test_doors_of_the_robots_width_stay_open(tmp_path: Path, gap_px: int, disc: bool, world: bool) -> None:
    """A gap of k px is k * 0.1 m wide in the world. The robot (radius 0.2 m) passes a gap of 0.5 m: the
    disc test connects both rooms; World.reachable_cells (0.1 m cells, conservative) from 0.7 m on. A slit
    of 0.4 m or less is free in the map but closed to the robot."""
    path = tmp_path / "rooms.npy"
    np.save(path, _two_rooms(gap_px))
    m = load_mask(path, 0.1)
    assert m.free.sum() == _two_rooms(gap_px).sum()  # nothing closed: the gap is in the map
    w = m.world()
    centre = np.array([[3.2, 3.2 - (16 - gap_px // 2 + gap_px / 2) * 0.1]])  # the gap's middle
    assert w.is_free(centre)[0]
    assert w.clearance(centre)[0] == pytest.approx(gap_px * 0.05)
    reach = disc_reachable(m.free, m.resolution, 0.2)
    assert bool(reach[16, 10] and reach[16, 50]) == disc
    cells = w.reachable_cells(0.2)  # row 0 at ymin
    assert bool(cells[16, 10] and cells[16, 50]) == world


def _building() -> tuple[np.ndarray, np.ndarray]:
    """A 10 m x 6 m building (1 px walls) in a 14 m x 10 m picture, with a 2 m entrance in its outer wall,
    a 1 m door between its two rooms (labelled 1 and 2), and a hollow pillar outside it."""
    wall = np.zeros((100, 140), dtype=bool)
    wall[20, 20:121] = wall[80, 20:121] = True
    wall[20:81, 20] = wall[20:81, 120] = True
    wall[20:81, 70] = True
    wall[45:55, 70] = False  # inner door, 1 m
    wall[80, 90:110] = False  # entrance, 2 m
    wall[5:10, 5:10] = True
    wall[6:9, 6:9] = False  # hollow pillar
    rooms = np.zeros(wall.shape, dtype=np.uint8)
    rooms[21:80, 21:70] = 1
    rooms[21:80, 71:120] = 2
    rooms[45:55, 70] = 0
    return wall, rooms


def test_plan_outside_is_closed_and_doors_stay_open(tmp_path: Path) -> None:
    wall, rooms = _building()
    np.savez(tmp_path / "b.npz", wall=wall, rooms=rooms, pixels_per_metre=10.0)
    m = load_plan(tmp_path / "b.npz")
    assert m.resolution == pytest.approx(0.1) and m.name == "b"
    assert not m.free[0, 0] and not m.free[90, 100] and not m.free[7, 7]  # outside, hollow pillar
    assert m.free[(rooms > 0)].all() and m.free[50, 70] and m.free[80, 100]  # rooms, door, entrance
    lab, n = ndimage.label(m.free)
    assert n == 1  # one floor: the door between the rooms is open


def test_shipped_plans_load_with_their_rooms_inside_and_doors_open() -> None:
    for path in shipped_paths():
        m = load_plan(path)
        with np.load(path) as z:
            wall, rooms = z["wall"], z["rooms"]
        assert m.resolution == pytest.approx(0.1)
        assert m.free[(rooms > 0) & ~wall].all(), f"{path.name}: a labelled room pixel is outside"
        assert not (m.free & wall).any()
        # Doors stay open: removing the outside never splits a free component of the plan in two.
        before, _ = ndimage.label(~wall)
        after, _ = ndimage.label(m.free)
        pairs = np.unique(before[m.free].astype(np.int64) * (after.max() + 1) + after[m.free])
        assert len(np.unique(pairs // (after.max() + 1))) == len(pairs), f"{path.name}: a room was split"
        if path.stem in ("kth_50052748", "kth_50052750"):  # plans that show the outside of the building
            outside = ~wall & ~m.free
            assert outside.sum() > 80_000 and not m.free[0, 0] and not m.free[-1, 0]


def test_load_map_dispatch_and_its_errors(tmp_path: Path) -> None:
    np.save(tmp_path / "m.npy", _two_rooms(8))
    assert load_map(tmp_path / "m.npy", resolution=0.1).shape == (32, 64)
    _write_png(tmp_path / "m.png", np.where(_two_rooms(8), 255, 0).astype(np.uint8))
    assert np.array_equal(load_map(tmp_path / "m.png", resolution=0.1).free, _two_rooms(8))
    with pytest.raises(ValueError, match=r"m\.png: resolution: required"):
        load_map(tmp_path / "m.png")
    with pytest.raises(ValueError, match=r"x\.yaml: resolution"):
        load_map(tmp_path / "x.yaml", resolution=0.1)
    with pytest.raises(ValueError, match=r"x\.tif: path: unknown map suffix"):
        load_map(tmp_path / "x.tif")
    np.savez(tmp_path / "nowall.npz", rooms=np.zeros((3, 3)), pixels_per_metre=10.0)
    _one_line_error(tmp_path / "nowall.npz", "wall", "missing key")


@pytest.mark.parametrize("dynamics", ["pymunk", "unicycle"])
def test_the_robot_drives_through_a_half_metre_door_not_a_slit(dynamics: str) -> None:
    """The simulator decides passability by geometry: the robot (radius 0.2 m, skin 0.0375 m), driven
    straight at the gap's middle, crosses a 0.5 m door and stops at a 0.4 m slit."""
    from digslam.envs.sim.robot import RobotSim

    for gap_px, through in ((4, False), (5, True)):
        world = OccupancyMap(_two_rooms(gap_px), 0.1).world()
        y = 3.2 - (16 - gap_px // 2 + gap_px / 2) * 0.1
        sim = RobotSim(world, 0.2, np.array([1.5, y, 0.0]), 50.0, 50.0, 0.0375, dynamics, 1.0, 1.0)
        for _ in range(40):
            sim.step(1.0, 0.0, 0.1, 4)
        assert (sim.pose[0] > 4.0) == through
