"""Seeded world generators, and the one registry that names them (:data:`GENERATORS`).

A generator is anything with a ``frame`` and a ``generate(seed, split)`` that builds a world from a seed
(:class:`~.base.Generator`). Those of the registry subclass :class:`~.base.WorldGenerator` and override one
hook, ``_gen_world``; each builds itself from an env config (:meth:`~.base.WorldGenerator.from_config`), and
:func:`make_generator` builds the one a config names (``config.world``). They build worlds in the frame
``[-size, size]^2``.

Lives here: :mod:`.base` (the protocol and the base class), :mod:`.procedural` (the thesis room, rocks,
caves, rooms off corridors), :mod:`.mixed` (one of several per level), :mod:`.file` (one map stretched over
the frame) and :mod:`.floorplan` (windows of real floor plans at metric scale, from
:mod:`digslam.envs.sim.occupancy`).

>>> sorted(GENERATORS)
['caves', 'file', 'floorplan', 'mixed', 'rocks', 'room', 'rooms']
>>> BENCHMARK
('room', 'rocks', 'caves', 'rooms', 'floorplan')
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .base import PROCEDURAL, Generator, WorldGenerator
from .file import FileMap
from .floorplan import Floorplan
from .mixed import Mixed
from .procedural import THESIS_ROOM, Caves, RockField, RoomsCorridors, ThesisRoom

if TYPE_CHECKING:  # (only the config's fields are read)
    from digslam.envs.config import ExploreConfig

#: The generators by the name an env config gives them (``ExploreConfig.world``): the one registry.
GENERATORS: dict[str, type[WorldGenerator]] = {
    "room": ThesisRoom,
    "rocks": RockField,
    "caves": Caves,
    "rooms": RoomsCorridors,
    "file": FileMap,
    "mixed": Mixed,
    "floorplan": Floorplan,
}
#: The generators of the coverage benchmark (:mod:`digslam.agents.evaluation.suite`), in its column order:
#: the procedural ones (:data:`~.base.PROCEDURAL`, what ``world="mixed"`` draws from), then real floor plans.
BENCHMARK: tuple[str, ...] = (*PROCEDURAL, "floorplan")


def make_generator(cfg: ExploreConfig) -> WorldGenerator:
    """The generator that ``cfg.world`` names in :data:`GENERATORS`, built with the settings of ``cfg``
    (:meth:`WorldGenerator.from_config`).

    Raises:
        ValueError: ``cfg.world`` names no generator.
    """
    if cfg.world not in GENERATORS:
        raise ValueError(f"world: must be one of {sorted(GENERATORS)}, got {cfg.world!r}")
    return GENERATORS[cfg.world].from_config(cfg)


__all__ = [
    "BENCHMARK",
    "Caves",
    "FileMap",
    "Floorplan",
    "GENERATORS",
    "Generator",
    "Mixed",
    "PROCEDURAL",
    "RockField",
    "RoomsCorridors",
    "THESIS_ROOM",
    "ThesisRoom",
    "WorldGenerator",
    "make_generator",
]
