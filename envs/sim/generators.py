"""Seeded world generators, and the one registry that names them (:data:`GENERATORS`).

A generator is anything with a ``frame`` and a ``generate(seed)`` that builds a world from a seed
(:class:`Generator`). Those of the registry subclass :class:`WorldGenerator` and override one hook,
``_gen_world``; each builds itself from an env config (:meth:`WorldGenerator.from_config`), and
:func:`make_generator` builds the one a config names (``config.world``). They build worlds in the frame
``[-size, size]^2`` and keep a clear disc of radius ``keep_clear`` around the origin so that the default
start pose ``(0, 0)`` is free.

>>> sorted(GENERATORS), BENCHMARK
(['caves', 'file', 'mixed', 'rocks', 'room', 'rooms'], ('room', 'rocks', 'caves', 'rooms'))
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np

from digslam.envs.sim.tracing import marching_squares, mask_edges, smooth_noise
from digslam.envs.sim.world import World

if TYPE_CHECKING:  # (only the config's fields are read)
    from digslam.envs.config import ExploreConfig

# Thesis Fig. 6.10: a polygonal room in the frame [-10, 10]^2 made of segments (shape redrawn, not traced).
THESIS_ROOM = np.array(
    [
        (-9.0, -9.0),
        (-3.0, -8.0),
        (1.0, -9.2),
        (8.5, -8.0),
        (9.0, -2.0),
        (6.0, 1.0),
        (9.2, 5.0),
        (7.0, 9.0),
        (1.0, 8.5),
        (-1.0, 5.0),
        (-4.0, 9.0),
        (-9.0, 8.0),
        (-8.0, 2.0),
        (-5.0, 0.0),
        (-9.3, -3.0),
    ]
)


class Generator(Protocol):
    """What an env needs of a world generator: the frame its worlds lie in, and one world per seed (the same
    seed, the same world)."""

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

    def generate(self, seed: int | None = None) -> World:
        """Build a world from ``seed`` (same seed, same world)."""
        return self._gen_world(np.random.default_rng(seed))

    def _gen_world(self, rng: np.random.Generator) -> World:
        raise NotImplementedError

    def _frame_ring(self) -> np.ndarray:
        x0, y0, x1, y1 = self.frame
        return np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])


class ThesisRoom(WorldGenerator):
    """The polygonal room of thesis Fig. 6.10, scaled to the frame, optionally jittered by ``jitter`` m."""

    name = "room"

    def __init__(self, size: float = 10.0, jitter: float = 0.0, **kw: float) -> None:
        super().__init__(size, **kw)
        self.jitter = float(jitter)

    @classmethod
    def from_config(cls, cfg: ExploreConfig) -> WorldGenerator:
        """The room of ``world_size``, jittered by ``room_jitter``."""
        return cls(size=cfg.world_size, jitter=cfg.room_jitter)

    def _gen_world(self, rng: np.random.Generator) -> World:
        ring = THESIS_ROOM * (self.size / 10.0)
        ring = ring + rng.uniform(-self.jitter, self.jitter, ring.shape)
        return World(self.frame, [ring], self.name)


class RockField(WorldGenerator):
    """A walled square with ``n`` irregular, star-shaped, non-overlapping rocks."""

    name = "rocks"

    def __init__(
        self, size: float = 10.0, n: int = 30, radius: tuple[float, float] = (0.3, 1.2), **kw: float
    ) -> None:
        super().__init__(size, **kw)
        if n < 0:
            raise ValueError(f"n: must be >= 0, got {n!r}")
        self.n, self.radius = int(n), (float(radius[0]), float(radius[1]))

    @classmethod
    def from_config(cls, cfg: ExploreConfig) -> WorldGenerator:
        """``n_obstacles`` rocks in the frame of ``world_size``."""
        return cls(size=cfg.world_size, n=cfg.n_obstacles)

    def _gen_world(self, rng: np.random.Generator) -> World:
        s, (rmin, rmax) = self.size, self.radius
        centres: list[np.ndarray] = []
        radii: list[float] = []
        cand = rng.uniform(-s + rmax + 0.5, s - rmax - 0.5, (40 * max(self.n, 1), 2))
        crad = rng.uniform(rmin, rmax, len(cand))
        for c, r in zip(cand, crad, strict=True):
            if len(centres) == self.n:
                break
            if np.hypot(*c) < r + self.keep_clear:
                continue
            if centres and np.min(np.hypot(*(np.array(centres) - c).T) - np.array(radii)) < r + 0.6:
                continue
            centres.append(c)
            radii.append(r)
        rings = [self._frame_ring()]
        for c, r in zip(centres, radii, strict=True):
            k = int(rng.integers(6, 13))
            ang = (np.arange(k) + rng.uniform(0.1, 0.9, k)) * (2 * np.pi / k)
            rad = r * rng.uniform(0.45, 1.0, k)
            rings.append(c + np.column_stack([rad * np.cos(ang), rad * np.sin(ang)]))
        return World(self.frame, rings, self.name)


class Caves(WorldGenerator):
    """Caves: a smoothed noise field thresholded at the ``fill`` quantile and traced by marching squares.

    The start area is carved free and, if it would be a closed pocket, joined to the largest cave by a
    straight corridor.
    """

    name = "caves"

    def __init__(
        self, size: float = 10.0, fill: float = 0.45, feature: float = 2.0, nodes: int = 81, **kw: float
    ) -> None:
        super().__init__(size, **kw)
        if not 0 < fill < 1:
            raise ValueError(f"fill: must be in (0, 1), got {fill!r}")
        self.fill, self.feature, self.nodes = float(fill), float(feature), int(nodes)

    def _gen_world(self, rng: np.random.Generator) -> World:
        n = self.nodes
        step = 2 * self.size / (n - 1)
        f = smooth_noise(rng, (n, n), self.feature / step)
        xs = np.linspace(-self.size, self.size, n)
        r = np.hypot(xs[None, :], xs[:, None])
        f = f - 3.0 * np.clip(1.5 - r / max(self.keep_clear, 1e-9), 0.0, None)  # carve the start area
        level = float(np.quantile(f, self.fill))
        f[[0, -1], :] = f[:, [0, -1]] = level + 1.0  # closed outer wall
        f = self._connect_start(f, level, xs)
        return World.from_edges(self.frame, marching_squares(f, level, self.frame), self.name)

    def _connect_start(self, f: np.ndarray, level: float, xs: np.ndarray) -> np.ndarray:
        """Carve a corridor from the start area to the largest cave, so that the start is not in a pocket."""
        from scipy import ndimage

        labels, n = ndimage.label(f <= level)
        c = len(xs) // 2
        if n <= 1 or labels[c, c] == 0:
            return f
        sizes = np.bincount(labels.ravel())
        sizes[0] = 0
        big = int(np.argmax(sizes))
        if labels[c, c] == big:
            return f
        ii, jj = np.nonzero(labels == big)
        k = int(np.argmin((ii - c) ** 2 + (jj - c) ** 2))
        ti, tj = ii[k], jj[k]
        steps = int(max(abs(ti - c), abs(tj - c))) + 1
        half = max(1, int(np.ceil(self.keep_clear / (xs[1] - xs[0]))))  # corridor half-width in nodes
        out = f.copy()
        for a in np.linspace(0.0, 1.0, 2 * steps):
            i, j = int(round(c + a * (ti - c))), int(round(c + a * (tj - c)))
            out[max(i - half, 1) : i + half + 1, max(j - half, 1) : j + half + 1] = np.minimum(
                out[max(i - half, 1) : i + half + 1, max(j - half, 1) : j + half + 1], level - 1.0
            )
        out[[0, -1], :] = out[:, [0, -1]] = level + 1.0
        return out


class RoomsCorridors(WorldGenerator):
    """A ``grid x grid`` layout of rectangular rooms joined by corridors along a random spanning tree."""

    name = "rooms"

    def __init__(
        self, size: float = 10.0, grid: int = 3, corridor: float = 1.2, cell: float = 0.1, **kw: float
    ) -> None:
        super().__init__(size, **kw)
        self.grid, self.corridor, self.cell = int(grid), float(corridor), float(cell)

    def _gen_world(self, rng: np.random.Generator) -> World:
        g, s = self.grid, self.size
        npx = int(round(2 * s / self.cell))
        free = np.zeros((npx, npx), dtype=bool)
        block = 2 * s / g
        xs = -s + (np.arange(npx) + 0.5) * self.cell
        X, Y = np.meshgrid(xs, xs)
        centres = -s + (np.arange(g) + 0.5) * block

        def carve(x0: float, y0: float, x1: float, y1: float) -> None:
            free[(X > x0) & (X < x1) & (Y > y0) & (Y < y1)] = True

        for i in range(g):
            for j in range(g):
                hw, hh = rng.uniform(0.25, 0.42, 2) * block
                carve(centres[j] - hw, centres[i] - hh, centres[j] + hw, centres[i] + hh)
        # Random spanning tree over the room grid (randomised Prim), plus the centre room holding the origin.
        seen, edges = {(g // 2, g // 2)}, []
        while len(seen) < g * g:
            frontier = [
                ((i, j), (i + di, j + dj))
                for (i, j) in sorted(seen)
                for di, dj in ((0, 1), (1, 0), (0, -1), (-1, 0))
                if 0 <= i + di < g and 0 <= j + dj < g and (i + di, j + dj) not in seen
            ]
            a, b = frontier[int(rng.integers(len(frontier)))]
            seen.add(b)
            edges.append((a, b))
        w = self.corridor / 2
        for (i0, j0), (i1, j1) in edges:
            xa, xb = sorted((centres[j0], centres[j1]))
            ya, yb = sorted((centres[i0], centres[i1]))
            carve(xa - w, ya - w, xb + w, yb + w)
        carve(-self.keep_clear, -self.keep_clear, self.keep_clear, self.keep_clear)
        free[[0, -1], :] = free[:, [0, -1]] = False
        return World.from_edges(self.frame, mask_edges(free, self.frame), self.name)


class FileMap(WorldGenerator):
    """A map from a file: JSON ``{"frame": [x0, y0, x1, y1], "rings": [[[x, y], ...], ...]}`` (free where the
    crossing count is odd), or a binary image (``.npy`` bool array, or ``.png``/``.bmp`` where bright is free)
    stretched over ``[-size, size]^2``."""

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


class Mixed(WorldGenerator):
    """Each level from one of ``generators`` (those of :data:`BENCHMARK` by default: room, rocks, caves,
    rooms), drawn from the level's seed (uniformly), then built by that generator from the same random
    stream: one env id over every generator of the coverage suite, for training across them. The same seed
    gives the same world.

    Args:
        generators: The generators to draw from (built by the caller with their own settings).
    """

    name = "mixed"

    def __init__(self, generators: tuple[WorldGenerator, ...] = (), size: float = 10.0, **kw: float) -> None:
        super().__init__(size, **kw)
        self.generators = tuple(generators) or tuple(GENERATORS[w](size) for w in BENCHMARK)
        for g in self.generators:
            if g.frame != self.frame:
                raise ValueError(f"generators: {g.name} has frame {g.frame}, expected {self.frame}")

    @classmethod
    def from_config(cls, cfg: ExploreConfig) -> WorldGenerator:
        """The generators of :data:`BENCHMARK`, each with the settings of ``cfg`` it gets on its own."""
        return cls(tuple(GENERATORS[w].from_config(cfg) for w in BENCHMARK), size=cfg.world_size)

    def _gen_world(self, rng: np.random.Generator) -> World:
        return self.generators[int(rng.integers(len(self.generators)))]._gen_world(rng)


#: The generators by the name an env config gives them (``ExploreConfig.world``): the one registry.
GENERATORS: dict[str, type[WorldGenerator]] = {
    "room": ThesisRoom,
    "rocks": RockField,
    "caves": Caves,
    "rooms": RoomsCorridors,
    "file": FileMap,
    "mixed": Mixed,
}
#: The generators of the coverage benchmark (:mod:`digslam.agents.evaluation.suite`), in its column order.
BENCHMARK: tuple[str, ...] = ("room", "rocks", "caves", "rooms")


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
    "GENERATORS",
    "Generator",
    "Mixed",
    "RockField",
    "RoomsCorridors",
    "THESIS_ROOM",
    "ThesisRoom",
    "WorldGenerator",
    "make_generator",
]
