"""The procedural generators: the thesis room (Fig. 6.10), a rock field, caves and rooms off corridors.

Each keeps a clear disc of radius ``keep_clear`` around the origin so that the default start pose ``(0, 0)``
is free; the same seed gives the same world.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from digslam.envs.sim.generators.base import WorldGenerator
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


__all__ = ["THESIS_ROOM", "Caves", "RockField", "RoomsCorridors", "ThesisRoom"]
