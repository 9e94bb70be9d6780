"""``world="mixed"``: each level from one of several generators, drawn from the level's seed."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from digslam.envs.sim.generators.base import PROCEDURAL, WorldGenerator
from digslam.envs.sim.generators.procedural import Caves, RockField, RoomsCorridors, ThesisRoom
from digslam.envs.sim.world import World

if TYPE_CHECKING:  # (only the config's fields are read)
    from digslam.envs.config import ExploreConfig

#: The procedural generators by name.
PROCEDURAL_CLASSES: dict[str, type[WorldGenerator]] = {
    "room": ThesisRoom,
    "rocks": RockField,
    "caves": Caves,
    "rooms": RoomsCorridors,
}


class Mixed(WorldGenerator):
    """Each level from one of ``generators`` (the procedural ones by default, :data:`~.base.PROCEDURAL`:
    room, rocks, caves, rooms), drawn from the level's seed (uniformly), then built by that generator from the
    same random stream: one env id over the procedural generators, for training across them. The same seed
    gives the same world.

    Args:
        generators: The generators to draw from (built by the caller with their own settings).
    """

    name = "mixed"

    def __init__(self, generators: tuple[WorldGenerator, ...] = (), size: float = 10.0, **kw: float) -> None:
        super().__init__(size, **kw)
        self.generators = tuple(generators) or tuple(PROCEDURAL_CLASSES[w](size) for w in PROCEDURAL)
        for g in self.generators:
            if g.frame != self.frame:
                raise ValueError(f"generators: {g.name} has frame {g.frame}, expected {self.frame}")

    @classmethod
    def from_config(cls, cfg: ExploreConfig) -> WorldGenerator:
        """The procedural generators, each with the settings of ``cfg`` it gets on its own."""
        return cls(tuple(PROCEDURAL_CLASSES[w].from_config(cfg) for w in PROCEDURAL), size=cfg.world_size)

    def _gen_world(self, rng: np.random.Generator) -> World:
        return self.generators[int(rng.integers(len(self.generators)))]._gen_world(rng)


__all__ = ["PROCEDURAL_CLASSES", "Mixed"]
