"""What a world generator is: :class:`Generator`, the protocol an env needs, and :class:`WorldGenerator`, the
base of the registry's generators (one hook, ``_gen_world``; one constructor from an env config,
:meth:`WorldGenerator.from_config`). Worlds lie in the frame ``[-size, size]^2``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import numpy as np

from digslam.envs.sim.world import World

if TYPE_CHECKING:  # (only the config's fields are read)
    from digslam.envs.config import ExploreConfig

#: The procedural generators, in the benchmark's column order (what ``world="mixed"`` draws from).
PROCEDURAL: tuple[str, ...] = ("room", "rocks", "caves", "rooms")


class Generator(Protocol):
    """What an env needs of a world generator: the frame its worlds lie in, and one world per seed (the same
    seed, the same world). A :class:`WorldGenerator` also takes the split of the env's reset seed."""

    @property
    def frame(self) -> tuple[float, float, float, float]: ...

    def generate(self, seed: int | None = None) -> World: ...


class WorldGenerator:
    """Base class: ``generate(seed)`` calls the ``_gen_world(rng)`` hook of the subclass.

    Args:
        size: Half-width of the square frame (m).
        keep_clear: Radius of the obstacle-free disc around the origin (m).
    """

    name = "world"

    def __init__(self, size: float = 10.0, keep_clear: float = 1.0) -> None:
        if not size > 0:
            raise ValueError(f"size: must be > 0, got {size!r}")
        self.size = float(size)
        self.keep_clear = float(keep_clear)

    @property
    def frame(self) -> tuple[float, float, float, float]:
        """``(-size, -size, size, size)``."""
        s = self.size
        return (-s, -s, s, s)

    @classmethod
    def from_config(cls, cfg: ExploreConfig) -> WorldGenerator:
        """The generator with the settings of ``cfg`` (:class:`~digslam.envs.config.ExploreConfig`):
        ``world_size``, and the fields of the subclass's own world."""
        return cls(size=cfg.world_size)

    def generate(self, seed: int | None = None, split: str | None = None) -> World:
        """Build a world from ``seed`` (same seed, same world). ``split`` is the split of the env's reset
        seed (:mod:`digslam.envs.splits`): the procedural generators need none (their seeds are split), a
        generator of real maps keeps each map to one split."""
        return self._gen_world(np.random.default_rng(seed))

    def _gen_world(self, rng: np.random.Generator) -> World:
        raise NotImplementedError

    def _frame_ring(self) -> np.ndarray:
        x0, y0, x1, y1 = self.frame
        return np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])


__all__ = ["PROCEDURAL", "Generator", "WorldGenerator"]
