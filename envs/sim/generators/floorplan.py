"""The ``floorplan`` generator: square windows of real building floor plans at metric scale.

A level of :class:`Floorplan` (``generate(seed)``) is drawn from the seed's random stream: a plan (with a
probability proportional to its floor area, so that every square metre of floor is about equally likely to
be in view; ``weighting="plan"``: each plan equally likely), a square window of side ``2 * size`` at a
uniform pixel position in the plan (a plan smaller than the window is padded with obstacle), and a rotation
by a multiple of 90 degrees. The window is closed at its border. Its free space is then what a disc of
radius ``clearance`` (the robot, 0.2 m) sweeps from the largest region where it fits
(:func:`~digslam.envs.sim.occupancy.disc_reachable`); every other free pixel is closed (rooms whose door lies
outside the window, pockets), so the start that ``ExploreEnv`` draws with
:meth:`~digslam.envs.sim.world.World.sample_reachable_pose` always lies in it. A window whose free space
covers less than ``min_free`` of its area is redrawn from the same stream: the level stays a function of
the seed. ``min_free = 0.2``: the coverage denominator is that free space, and the procedural generators
leave 40-90 % of their frame free (caves 43 %, rooms 51 %, room 67 %, rocks 91 %); below a fifth, a window
is mostly walls and the outside, or a room cut off by the window's border. On the shipped plans a 20 m
window keeps 58-87 % on average, and about 1 window in 50 is redrawn. The registered ids and the benchmark
cut 20 m windows (:data:`digslam.envs.FLOORPLAN_WORLD_SIZE`: the largest window on which a baseline
certifies a level the rule vouches for in 3000 steps, ``docs/benchmark.md``).

The window maps to the frame ``(-size, -size, size, size)``: its centre at the origin, turned by ``rotation``
degrees counterclockwise. With a plan resolution ``res`` the window is ``n = round(2 size / res)`` pixels
wide, stretched onto the frame (a scale error below ``res / 2`` over the window; none at 0.1 m/px).

The shipped plans (:data:`SHIPPED`) are the ten KTH floor plans of ``envs/data/floorplans/`` (MapEx's test
maps; Clear BSD licence, ``LICENSE-MapEx.txt``); :data:`SPLIT` assigns each to one split.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from digslam.envs.sim.generators.base import WorldGenerator
from digslam.envs.sim.occupancy import OccupancyMap, disc_reachable, load_map
from digslam.envs.sim.tracing import mask_edges
from digslam.envs.sim.world import World

if TYPE_CHECKING:  # (only the config's fields are read)
    from digslam.envs.config import ExploreConfig

#: The folder of the shipped plans (package data).
PLANS_DIR = Path(__file__).resolve().parents[2] / "data" / "floorplans"
#: The shipped plans' names (file stems in :data:`PLANS_DIR`): two KTH buildings, 500527xx (seven floors)
#: and 500105xx (three floors).
SHIPPED: tuple[str, ...] = (
    "kth_50010535_PLAN1",
    "kth_50010535_PLAN2",
    "kth_50010536_PLAN3",
    "kth_50052748",
    "kth_50052749",
    "kth_50052750",
    "kth_50052751",
    "kth_50052752",
    "kth_50052753",
    "kth_50052754",
)
#: The shipped plans by split: no window of a test level comes from a plan of train or validation.
#:
#: Each split holds whole plans of both buildings, so that validation predicts test and neither measures a
#: change of building (the buildings kept out of this folder do that). Floors that are near copies stay in
#: one split: the four 25.6 m x 78.6 m floors 50052751-54 share their walls but for a few offices, so all
#: four train. The two 65 m x 85 m floors 50052749 and 50052750 share their office wing and differ in
#: their halls: one validates, one tests. The three 60 m x 206 m floors of 500105xx, each about as large
#: as the 500527xx floors of a split together, are one per split (and :class:`Floorplan` draws plans by
#: floor area, so that they weigh as much as their size). 50052748, a floor unlike any other, trains.
SPLIT: dict[str, tuple[str, ...]] = {
    "train": (
        "kth_50010535_PLAN1",
        "kth_50052748",
        "kth_50052751",
        "kth_50052752",
        "kth_50052753",
        "kth_50052754",
    ),
    "validation": ("kth_50010535_PLAN2", "kth_50052749"),
    "test": ("kth_50010536_PLAN3", "kth_50052750"),
}
WEIGHTINGS: tuple[str, ...] = ("area", "plan")


def shipped_paths(split: str | None = None) -> list[Path]:
    """The paths of the shipped plans, of ``split`` (``train``, ``validation``, ``test``) or all (None)."""
    if split is not None and split not in SPLIT:
        raise ValueError(f"split: must be one of {', '.join(SPLIT)} or None, got {split!r}")
    names = SHIPPED if split is None else SPLIT[split]
    return [PLANS_DIR / f"{name}.npz" for name in names]


@dataclass(frozen=True)
class Window:
    """Where a level comes from.

    Attributes:
        plan: The plan's name.
        corner: ``(x, y)`` (m, in the plan's frame) of the window's lower-left corner before the rotation.
        rotation: Degrees counterclockwise, one of 0, 90, 180, 270.
        free_share: Share of the window that is the level's free space.
        draws: Windows drawn for this level (1: the first was kept).
    """

    plan: str
    corner: tuple[float, float]
    rotation: int
    free_share: float
    draws: int

    @property
    def label(self) -> str:
        """E.g. ``kth_50052750 @ (12.3, 40.1) rot 90``: the level's
        :attr:`~digslam.envs.sim.world.World.name`."""
        return f"{self.plan} @ ({self.corner[0]:.1f}, {self.corner[1]:.1f}) rot {self.rotation}"


class Floorplan(WorldGenerator):
    """Levels cut from floor plans (see the module).

    Args:
        plans: Maps to cut from: paths of ROS map YAML files or ``.npz`` plans, or
            :class:`~digslam.envs.sim.occupancy.OccupancyMap` (e.g. an image with its resolution, from
            :func:`~digslam.envs.sim.occupancy.load_mask`), mixed; None: the ten shipped plans.
        size: Half-width of the frame (m); a window is ``2 * size`` wide.
        min_free: Least share of the window that its free space must cover, in (0, 1].
        clearance: Radius (m) of the disc whose reachable region decides the free space (the robot's).
        weighting: ``area`` (a plan drawn with a probability proportional to its free area) or ``plan``.
        max_draws: Windows drawn per level before giving up (ValueError naming ``plans``).
    """

    name = "floorplan"

    def __init__(
        self,
        plans: Sequence[str | Path | OccupancyMap] | None = None,
        size: float = 10.0,
        min_free: float = 0.2,
        clearance: float = 0.2,
        weighting: str = "area",
        max_draws: int = 200,
        **kw: float,
    ) -> None:
        super().__init__(size, **kw)
        if not 0.0 < min_free <= 1.0:
            raise ValueError(f"min_free: must be in (0, 1], got {min_free!r}")
        if not (math.isfinite(clearance) and clearance > 0):
            raise ValueError(f"clearance: must be a finite number > 0 (m), got {clearance!r}")
        if weighting not in WEIGHTINGS:
            raise ValueError(f"weighting: must be one of {', '.join(WEIGHTINGS)}, got {weighting!r}")
        if not (isinstance(max_draws, int) and max_draws >= 1):
            raise ValueError(f"max_draws: must be an integer >= 1, got {max_draws!r}")
        if isinstance(plans, (str, Path)):
            raise ValueError(f"plans: must be a list of maps, got the path {str(plans)!r}; wrap it in [ ]")
        items = shipped_paths() if plans is None else list(plans)
        if not items:
            raise ValueError("plans: the list is empty; give at least one map, or None for the shipped plans")
        self.plans: tuple[OccupancyMap, ...] = tuple(
            p if isinstance(p, OccupancyMap) else load_map(p) for p in items
        )
        self.min_free, self.clearance, self.max_draws = float(min_free), float(clearance), max_draws
        #: True when the plans are the shipped ones: a level's split then chooses among them (:data:`SPLIT`).
        self.shipped = plans is None
        area = np.array([p.free_area for p in self.plans])
        self.weights = area / area.sum() if weighting == "area" else np.full(len(area), 1.0 / len(area))

    @classmethod
    def from_config(cls, cfg: ExploreConfig) -> WorldGenerator:
        """The plans of ``cfg.floorplans`` (the shipped ones when it is None or absent) at ``world_size``."""
        return cls(None if cfg.floorplans is None else list(cfg.floorplans), size=cfg.world_size)

    def generate(self, seed: int | None = None, split: str | None = None) -> World:
        """The level of ``seed`` (same seed and split, same level). With the shipped plans, ``split`` (that of
        the env's reset seed, :func:`digslam.envs.splits.split_of`) restricts the plans to those of
        :data:`SPLIT`: a level of the test split is cut from a test plan only. With the user's plans, or
        ``split`` None (a seed outside every split), every plan serves."""
        rng = np.random.default_rng(seed)
        win, free = self._draw(rng, self._subset(split))
        return World.from_edges(self.frame, mask_edges(free[::-1], self.frame), win.label)

    def window(self, seed: int | None = None, split: str | None = None) -> tuple[Window, np.ndarray]:
        """The level of ``seed``: its provenance and its free mask ``(n, n)`` (row 0 at the top, rotated)."""
        return self._draw(np.random.default_rng(seed), self._subset(split))

    def _subset(self, split: str | None) -> np.ndarray:
        """Indices of the plans a level of ``split`` is cut from."""
        if split is not None and split not in SPLIT:
            raise ValueError(f"split: must be one of {', '.join(SPLIT)} or None, got {split!r}")
        if not self.shipped or split is None:
            return np.arange(len(self.plans))
        names = set(SPLIT[split])
        return np.array([i for i, p in enumerate(self.plans) if p.name in names])

    def _gen_world(self, rng: np.random.Generator) -> World:
        win, free = self._draw(rng, np.arange(len(self.plans)))
        frame = self.frame
        return World.from_edges(frame, mask_edges(free[::-1], frame), win.label)

    def _draw(self, rng: np.random.Generator, subset: np.ndarray) -> tuple[Window, np.ndarray]:
        best = 0.0
        w = self.weights[subset] / self.weights[subset].sum()
        for draw in range(1, self.max_draws + 1):
            plan = self.plans[int(subset[int(rng.choice(len(subset), p=w))])]
            n = max(1, int(round(2.0 * self.size / plan.resolution)))
            rows, cols = plan.shape
            r0 = int(rng.integers(min(0, rows - n), max(0, rows - n) + 1))
            c0 = int(rng.integers(min(0, cols - n), max(0, cols - n) + 1))
            k = int(rng.integers(4))
            cut = np.zeros((n, n), dtype=bool)
            ra, rb, ca, cb = max(r0, 0), min(r0 + n, rows), max(c0, 0), min(c0 + n, cols)
            cut[ra - r0 : rb - r0, ca - c0 : cb - c0] = plan.free[ra:rb, ca:cb]
            free = self._level_free(np.rot90(cut, k), 2.0 * self.size / n)
            share = float(np.count_nonzero(free)) / (n * n)
            best = max(best, share)
            if share >= self.min_free:
                ox, oy = plan.origin
                corner = (
                    round(ox + c0 * plan.resolution, 9),
                    round(oy + (rows - r0 - n) * plan.resolution, 9),
                )
                return Window(plan.name, corner, 90 * k, share, draw), np.ascontiguousarray(free)
        raise ValueError(
            f"plans: no window of {2 * self.size:g} m has a free space of {self.min_free:.0%} of its area in "
            f"{self.max_draws} draws (best {best:.0%}); give larger maps, a smaller size or a lower min_free"
        )

    def _level_free(self, free: np.ndarray, res: float) -> np.ndarray:
        """The free space the robot can sweep: the free pixels within ``sqrt(2) (clearance + res)`` of a
        centre of the disc's largest reachable region (:func:`~digslam.envs.sim.occupancy.disc_reachable`:
        centres ``clearance + res / sqrt(2)`` from every wall pixel, so that a room's corner pixel lies
        ``sqrt(2) clearance + res`` from the nearest), in the 4-connected component that holds that region;
        all False if the disc fits nowhere. A room that the window's border leaves behind a slit narrower
        than the robot is closed (but for a sliver at the slit), so that the coverage denominator holds no
        room the robot cannot enter."""
        from scipy import ndimage

        reach = disc_reachable(free, res, self.clearance)
        if not reach.any():
            return np.zeros_like(free)
        sweep = math.sqrt(2.0) * (self.clearance + res)
        swept = ndimage.distance_transform_edt(~reach) * res <= sweep
        lab, _ = ndimage.label(free & swept)
        return np.asarray(lab == lab[np.nonzero(reach)][0])


__all__ = [
    "PLANS_DIR",
    "SHIPPED",
    "SPLIT",
    "WEIGHTINGS",
    "Floorplan",
    "Window",
    "shipped_paths",
]
