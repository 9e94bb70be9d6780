"""``world="file"``: one map from a file, stretched over the frame (no metric scale).

For a map at metric scale (a ROS map file, a floor plan, an image with its resolution) use
:mod:`digslam.envs.sim.occupancy` and the ``floorplan`` generator (:mod:`.floorplan`).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from digslam.envs.sim.generators.base import WorldGenerator
from digslam.envs.sim.tracing import mask_edges
from digslam.envs.sim.world import World

if TYPE_CHECKING:  # (only the config's fields are read)
    from digslam.envs.config import ExploreConfig


class FileMap(WorldGenerator):
    """A map from a file: JSON ``{"frame": [x0, y0, x1, y1], "rings": [[[x, y], ...], ...]}`` (free where the
    crossing count is odd; its own frame and coordinates), or a binary image (``.npy`` bool array, or
    ``.png``/``.bmp`` where bright is free) stretched over ``[-size, size]^2`` whatever its size and aspect
    ratio, its border pixels closed.

    An image has no metric scale here: a pixel is ``2 * size / cols`` by ``2 * size / rows`` metres. For a
    map at metric scale (a ROS map YAML file, a floor-plan ``.npz``, an image with its resolution) use
    ``world="floorplan"`` with ``floorplans=[...]`` (:class:`~.floorplan.Floorplan`), which loads it with
    :func:`~digslam.envs.sim.occupancy.load_map`."""

    name = "file"

    def __init__(self, path: str | Path, size: float = 10.0, **kw: float) -> None:
        super().__init__(size, **kw)
        self.path = Path(path)
        if not self.path.exists():
            raise ValueError(f"map_path: file {str(self.path)!r} does not exist")

    @classmethod
    def from_config(cls, cfg: ExploreConfig) -> WorldGenerator:
        """The map of ``map_path`` stretched over the frame of ``world_size``."""
        if cfg.map_path is None:
            raise ValueError("map_path: is required when world='file'")
        return cls(cfg.map_path, size=cfg.world_size)

    def _gen_world(self, rng: np.random.Generator) -> World:
        suffix = self.path.suffix.lower()
        if suffix == ".json":
            data = json.loads(self.path.read_text())
            for key in ("frame", "rings"):
                if key not in data:
                    raise ValueError(f"map_path: {self.path.name} lacks the key {key!r}")
            return World(tuple(data["frame"]), [np.asarray(r, float) for r in data["rings"]], self.path.stem)
        if suffix == ".npy":
            img = np.load(self.path).astype(bool)
        else:
            import pygame  # only for image maps

            arr = pygame.surfarray.array3d(pygame.image.load(str(self.path))).astype(float)  # (w, h, 3)
            img = arr.mean(axis=2).T > 127.5
        if img.ndim != 2:
            raise ValueError(f"map_path: image must be 2-D, got shape {img.shape}")
        free = img[::-1].copy()  # image row 0 is the top
        free[[0, -1], :] = free[:, [0, -1]] = False
        return World.from_edges(self.frame, mask_edges(free, self.frame), self.path.stem)


__all__ = ["FileMap"]
