"""The guarantee on real walls (issue 48): the independent auditor on floorplan levels, both dynamics.

Real plans have what the procedural generators lack: walls 1-10 px thick traced pixel by pixel (many edges,
many convex and concave corners), doors of 0.8-1.6 m that are gaps in them, and slits narrower than the
robot. :mod:`auditor` checks every claim of the observer at every step against the exact truth (the pose in
its boxes, no dug or clear cell on an obstacle, every clear cell seen, no dark cell seen, certified coverage
at or below the ground truth), here on ``digslam/DigCoverageFloorplan-v0`` levels of the three splits under
``pymunk`` and ``unicycle`` dynamics, with

* a scripted driver (:func:`drive`) that finds a door in the level (:func:`find_doors`: a gap in a straight
  wall with a room on both sides), starts in front of it, drives through at full speed, rams the jamb and
  presses into it with tiny, subnormal, huge and sign-alternating yaw actions, slides along the wall, and
  drives back through;
* a robot pressed into a door jamb for many steps, with zero noise bounds too (degenerate intervals);
* a ROS map with doors of 0.40, 0.45 and 0.50 m at 0.05 m/px (the robot's passable width; see
  ``tests/envs/sim/test_occupancy.py`` for the loader's side): the robot driven into each;
* the random policies of :mod:`auditor` on floorplan levels (the long runs are ``expensive``).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from auditor import TINY_YAWS, Auditor, audit_episode, random_actions

import digslam.envs  # noqa: F401  (registers the environments)
from digslam.envs.sim.raster import FREE
from digslam.envs.splits import seeds

ENV_ID = "digslam/DigCoverageFloorplan-v0"
DYNAMICS = ("pymunk", "unicycle")
ZERO = {"speed": 0.0, "yaw_rate": 0.0, "heading": 0.0, "range": 0.0}
#: The largest action the env accepts (clipped to 1): its action tolerance.
HUGE = 1.0 + 1e-6
#: Seeds each test looks through, per split, for a level with a door (offsets chosen once, no tuning).
FAST_SEEDS = {"train": seeds("train", 12, 480_000), "validation": seeds("validation", 12, 480),
              "test": seeds("test", 12, 480)}  # fmt: skip


# --- doors -------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Door:
    """A gap in a straight wall: its centre (m), the passage direction (unit vector), its width (m)."""

    centre: np.ndarray
    direction: np.ndarray
    width: float

    @property
    def across(self) -> np.ndarray:
        """Unit vector along the wall (the passage direction turned by +90 degrees)."""
        return np.array([-self.direction[1], self.direction[0]])


def _runs(free: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """Free run lengths (cells) from each cell towards lower and higher indices along ``axis``, the cell
    included (0 on non-free cells)."""
    f = np.moveaxis(free, axis, 0)
    lo, hi = np.zeros(f.shape, dtype=int), np.zeros(f.shape, dtype=int)
    for i in range(f.shape[0]):
        lo[i] = np.where(f[i], (lo[i - 1] if i else 0) + 1, 0)
    for i in range(f.shape[0] - 1, -1, -1):
        hi[i] = np.where(f[i], (hi[i + 1] if i + 1 < f.shape[0] else 0) + 1, 0)
    return np.moveaxis(lo, 0, axis), np.moveaxis(hi, 0, axis)


def find_doors(world: Any, res: float = 0.1, widths: tuple[float, float] = (0.6, 1.6), reach: float = 1.5,
               room: float = 2.0) -> list[Door]:  # fmt: skip
    """Doors of a level whose walls lie on a grid of ``res`` (a floorplan level): free cells centred in a
    free run of ``widths`` across the passage, with ``reach`` metres of free cells straight ahead and behind,
    where the free run across is at least ``room`` wide 0.7 m and ``reach`` metres away (the wall is thinner
    than 1.4 m and there is a room on each side, not a corridor); one door per cluster, the cell nearest the
    cluster's mean, doors closer than 1 m merged."""
    from scipy import ndimage

    free = world.raster(res) == FREE  # row 0 at ymin
    ny, nx = free.shape
    x0, y0 = world.frame[0], world.frame[1]
    k, wall = int(round(reach / res)), int(round(0.7 / res))
    doors: list[Door] = []
    for axis in (0, 1):  # the passage along x (a gap in a wall along y: runs along rows), then along y
        lo, hi = _runs(free, axis)
        run = lo + hi - 1
        cand = free & (np.abs(lo - hi) <= 1) & (run * res >= widths[0]) & (run * res <= widths[1])
        ok = np.zeros_like(cand)
        for i, j in zip(*np.nonzero(cand), strict=True):
            good = True
            for s in (-1, 1):
                line = [(i, j + s * t) if axis == 0 else (i + s * t, j) for t in range(1, k + 1)]
                if not all(0 <= a < ny and 0 <= b < nx and free[a, b] for a, b in line):
                    good = False
                    break
                if min(run[line[t]] for t in (wall - 1, k - 1)) * res < room:
                    good = False
                    break
            ok[i, j] = good
        lab, n = ndimage.label(ok, structure=np.ones((3, 3), dtype=bool))
        for m in range(1, n + 1):
            ii, jj = np.nonzero(lab == m)
            c = int(np.argmin((ii - ii.mean()) ** 2 + (jj - jj.mean()) ** 2))
            centre = np.array([x0 + (jj[c] + 0.5) * res, y0 + (ii[c] + 0.5) * res])
            if any(np.hypot(*(centre - d.centre)) < 1.0 for d in doors):
                continue
            direction = np.array([1.0, 0.0]) if axis == 0 else np.array([0.0, 1.0])
            doors.append(Door(centre, direction, float(run[ii[c], jj[c]] * res)))
    return doors


def door_level(dynamics: str, candidates: list[int], **kw: Any) -> tuple[int, Door, tuple[float, ...]]:
    """The first seed of ``candidates`` whose level has a door, the door, and a start pose 1.1 m before it
    facing it (clearance for the robot's start checked)."""
    env = gym.make(ENV_ID, dynamics=dynamics, **kw)
    try:
        for seed in candidates:
            env.reset(seed=seed)
            world = env.unwrapped.world
            for door in find_doors(world):
                for back in (1.1, 0.9, 1.3):
                    p = door.centre - back * door.direction
                    if world.clearance(p[None])[0] >= 0.3:
                        heading = math.atan2(door.direction[1], door.direction[0])
                        return seed, door, (float(p[0]), float(p[1]), heading)
    finally:
        env.close()
    raise AssertionError(f"no floorplan level with a door among the seeds {candidates}")


# --- the scripted driver -----------------------------------------------------------------------------------
def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _toward(pose: np.ndarray, target: np.ndarray, gain: float = 3.0) -> tuple[float, float]:
    """Full speed at ``target`` when facing it, else a turn in place (full yaw far off, proportional near)."""
    err = _wrap(math.atan2(target[1] - pose[1], target[0] - pose[0]) - pose[2])
    return (1.0 if abs(err) < 0.35 else 0.0), float(np.clip(gain * err, -1.0, 1.0))


def _face(pose: np.ndarray, heading: float) -> tuple[float, float]:
    return 0.0, float(np.clip(3.0 * _wrap(heading - pose[2]), -1.0, 1.0))


def drive(door: Door, side: float = 1.0, press: int = 40, slide: int = 30) -> Iterator[tuple[float, float]]:
    """The door script; it reads the true pose (``.send(pose)``) and yields actions ``(v, omega)``.

    Through the door at full speed along its centre line; to the jamb on the ``side`` of ``door.across``,
    rammed at full speed and pressed for ``press`` steps (tiny and subnormal yaws, sign-alternating, then
    huge ones and a back-off); along the wall beyond the jamb for ``slide`` steps, half of them turned 0.3 rad
    into it (pymunk slides, the unicycle is blocked), half parallel to it (grazing); back through the door."""
    c, d, a = door.centre, door.direction, door.across * side
    pose = yield (0.0, 0.0)
    for _ in range(40):  # through, steering on the centre line
        if np.dot(pose[:2] - c, d) > 1.0:
            break
        pose = yield _toward(pose, c + 1.6 * d)
    jamb = c + 0.5 * door.width * a  # the jamb's end, mid-wall
    for _ in range(30):  # at the jamb from the far side, until stopped there
        pose = yield _toward(pose, jamb, gain=2.0)
    for k in range(press):  # pressed into it
        y = TINY_YAWS[k % len(TINY_YAWS)]
        pose = yield (1.0, y if k % 2 else -y)
    for y in (HUGE, -HUGE, 1.0, -1.0, HUGE, 0.0):
        pose = yield (HUGE, y)
    for _ in range(3):
        pose = yield (-1.0, 0.0)
    for _ in range(4):
        pose = yield (1.0, 5e-324)
    wall = math.atan2(a[1], a[0])  # along the wall, away from the door
    into = 1.0 if a[1] * d[0] - a[0] * d[1] > 0 else -1.0  # the turn from ``wall`` towards the wall
    for tilt, steps in ((0.3, slide - slide // 2), (0.0, slide // 2)):  # pressed into it, then grazing it
        for _ in range(20):
            if abs(_wrap(wall + into * tilt - pose[2])) < 0.02:
                break
            pose = yield _face(pose, wall + into * tilt)
        for k in range(steps):
            pose = yield (1.0, (2e-12, -1e-9, 5e-324, 1e-12)[k % 4])
    for _ in range(10):
        pose = yield (-1.0, -2e-12)
    for target in (c + 1.2 * d, c + 0.4 * d, c - 1.2 * d):  # back through the door
        for _ in range(40):
            if np.hypot(*(pose[:2] - target)) < 0.2:
                break
            pose = yield _toward(pose, target)


@dataclass
class Run:
    """What an audited scripted run did."""

    aud: Auditor
    path: np.ndarray
    certified: np.ndarray
    true: np.ndarray
    bumps: int
    stops: int


def audit_script(seed: int, dynamics: str, start: tuple[float, ...], script: Iterator[tuple[float, float]],
                 env_id: str = ENV_ID, **kw: Any) -> Run:  # fmt: skip
    """Run ``script`` (a generator fed the true pose) on the level of ``seed`` from ``start``, auditing every
    step; the path of true positions and both coverages at every step."""
    env = gym.make(env_id, dynamics=dynamics, start=start, **kw)
    try:
        _, info = env.reset(seed=seed)
        aud = Auditor(env, max_outliers=getattr(env.unwrapped.config.noise, "max_outliers", None), seed=seed)
        aud.reset(info)
        path, cert, true = [info["truth"].pose.copy()], [info["certified_coverage"]], [info["true_coverage"]]
        next(script)
        for _ in range(2000):
            try:
                action = script.send(path[-1])
            except StopIteration:
                break
            _, _, term, trunc, info = env.step(np.asarray(action, dtype=np.float64))
            aud.step(info)
            path.append(info["truth"].pose.copy())
            cert.append(info["certified_coverage"])
            true.append(info["true_coverage"])
            if term or trunc:
                break
        sim = env.unwrapped.sim
        return Run(aud, np.array(path), np.array(cert), np.array(true), int(sim.bumps), int(sim.stops))
    finally:
        env.close()


def _check_door_run(run: Run, door: Door) -> None:
    assert np.all(run.certified <= run.true)
    s = (run.path[:, :2] - door.centre) @ door.direction
    crossed = np.nonzero(s > 0.5)[0]
    assert crossed.size, "the robot never went through the door"
    assert (s[crossed[0] :] < -0.5).any(), "the robot never came back through the door"
    assert run.bumps >= 1, "the robot never touched the jamb or the wall"
    assert run.aud.free_ok.any() and run.aud.seen_ok.any()


# --- the tests ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("dynamics", "split"), [("pymunk", "train"), ("unicycle", "validation"),
                                                 ("pymunk", "test")])  # fmt: skip
def test_through_a_door_into_the_jamb_and_along_the_wall(dynamics: str, split: str) -> None:
    seed, door, start = door_level(dynamics, FAST_SEEDS[split])
    assert 0.6 <= door.width <= 1.6
    run = audit_script(seed, dynamics, start, drive(door, side=1.0 if seed % 2 else -1.0))
    _check_door_run(run, door)


@pytest.mark.parametrize("dynamics", DYNAMICS)
def test_pressed_into_a_door_jamb_with_zero_noise(dynamics: str) -> None:
    """Zero noise bounds (degenerate intervals): the observer's rounding alone keeps its claims true."""
    seed, door, start = door_level(dynamics, FAST_SEEDS["test"][4:], noise=ZERO)
    run = audit_script(seed, dynamics, start, drive(door, side=-1.0, press=80, slide=6), noise=ZERO)
    _check_door_run(run, door)


def test_random_policy_unicycle() -> None:
    """The auditor's random policy (tiny, subnormal and sign-alternating yaws, full-speed runs into walls) on
    floorplan levels under unicycle dynamics (``test_guarantee_audit.py`` runs it under pymunk)."""
    env = gym.make(ENV_ID, dynamics="unicycle")
    try:
        for seed in (1_000_900, 2_000_900):
            aud = audit_episode(env, seed, random_actions(np.random.default_rng(seed), 60))
            assert aud.k == 60
    finally:
        env.close()


@pytest.mark.expensive
@pytest.mark.parametrize("noise", ["default", "zero"])
@pytest.mark.parametrize("split", ["train", "validation", "test"])
@pytest.mark.parametrize("dynamics", DYNAMICS)
def test_doors_long(dynamics: str, split: str, noise: str) -> None:
    """Four levels with a door per split, both jambs: the script with long presses and slides."""
    kw: dict[str, Any] = {"noise": ZERO} if noise == "zero" else {}
    offset = {"train": 490_000, "validation": 500, "test": 500}[split]
    seen: list[int] = []
    for _ in range(4):
        seed, door, start = door_level(dynamics, [s for s in seeds(split, 80, offset) if s > max(seen, default=-1)],
                                       **kw)  # fmt: skip
        seen.append(seed)
        for side in (1.0, -1.0):
            run = audit_script(seed, dynamics, start, drive(door, side=side, press=150, slide=60), **kw)
            _check_door_run(run, door)


@pytest.mark.expensive
@pytest.mark.parametrize("noise", ["default", "zero"])
@pytest.mark.parametrize("dynamics", DYNAMICS)
def test_random_policy_long(dynamics: str, noise: str) -> None:
    """The auditor's random policy, 400 steps on four levels of each split."""
    kw: dict[str, Any] = {"noise": ZERO} if noise == "zero" else {}
    env = gym.make(ENV_ID, dynamics=dynamics, **kw)
    try:
        for split in ("train", "validation", "test"):
            for seed in seeds(split, 4, {"train": 491_000, "validation": 600, "test": 600}[split]):
                aud = audit_episode(env, seed, random_actions(np.random.default_rng(seed), 400))
                assert aud.k == 400
    finally:
        env.close()


def _symmetric_rooms(n: int, gap: int) -> np.ndarray:
    """An ``n`` x ``n`` grey picture (254 free, 0 wall) of four rooms, walls 4 px thick along the middle row
    and column, each half of each wall with a gap of ``gap`` px: the same picture under every rotation by a
    multiple of 90 degrees (so a level cut from it is this picture, whatever the rotation drawn)."""
    img = np.full((n, n), 254, dtype=np.uint8)
    img[[0, -1], :] = img[:, [0, -1]] = 0
    h = n // 2
    img[h - 2 : h + 2, :] = img[:, h - 2 : h + 2] = 0
    a = n // 4 - gap // 2
    for lo in (a, n - a - gap):
        img[lo : lo + gap, h - 2 : h + 2] = 254
        img[h - 2 : h + 2, lo : lo + gap] = 254
    assert all(np.array_equal(img, np.rot90(img, k)) for k in range(4))
    return img


@pytest.mark.parametrize(("gap", "passes"), [(8, {"pymunk": False, "unicycle": False}),
                                             (9, {"pymunk": False, "unicycle": True}),
                                             (10, {"pymunk": True, "unicycle": True})])  # fmt: skip
@pytest.mark.parametrize("dynamics", DYNAMICS)
def test_ros_map_doors_the_robot_passes_or_not_audited(tmp_path: Path, dynamics: str, gap: int,
                                                       passes: dict[str, bool]) -> None:  # fmt: skip
    """A ROS map at 0.05 m/px with doors of 0.40, 0.45 and 0.50 m, driven into at full speed: the robot
    (radius 0.2 m) passes 0.50 m under both dynamics, 0.45 m only as a unicycle (pymunk's collision disc
    adds the skin, 0.0375 m), and is stopped by 0.40 m, a slit that closes the rooms behind it (the level
    keeps only what the robot's disc sweeps); pressed into the slit, no claim is false."""
    n, res = 128, 0.05
    img = _symmetric_rooms(n, gap)
    (tmp_path / "rooms.pgm").write_bytes(b"P5\n%d %d\n255\n" % (n, n) + img.tobytes())
    (tmp_path / "rooms.yaml").write_text("image: rooms.pgm\nresolution: 0.05\norigin: [-3.2, -3.2, 0.0]\n"
                                         "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")  # fmt: skip
    yc = n * res / 2 - (n // 4 - gap // 2 + gap / 2) * res  # the upper door's centre line
    door = Door(np.array([0.0, yc]), np.array([1.0, 0.0]), gap * res)

    def straight() -> Iterator[tuple[float, float]]:
        yield (0.0, 0.0)
        for k in range(40):
            yield (1.0, 0.0 if k < 20 else TINY_YAWS[k % len(TINY_YAWS)])

    kw = {"world": "floorplan", "floorplans": [str(tmp_path / "rooms.yaml")], "world_size": n * res / 2}
    env = gym.make("digslam/DigCoverage-v0", dynamics=dynamics, **kw)
    env.reset(seed=5)
    free = env.unwrapped.world.raster(res) == FREE
    env.close()
    drawn = img[::-1] > 127
    if gap >= 9:  # doors the robot's disc passes: the map, as it was drawn
        assert np.array_equal(free, drawn)
    else:  # a slit narrower than the robot: the rooms behind it are closed (the level is the start's room)
        assert np.all(free <= drawn) and 0.2 < free.sum() / drawn.sum() < 0.3
    run = audit_script(5, dynamics, (-1.0, yc, 0.0), straight(), "digslam/DigCoverage-v0", **kw)
    assert np.all(run.certified <= run.true)
    assert (run.path[-1, 0] > 1.0) == passes[dynamics], run.path[-1]
    assert run.path[:, 0].max() > door.centre[0] - 0.25 - 0.0375 - 1e-3  # it reached the slit
