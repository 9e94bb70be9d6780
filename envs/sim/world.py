"""Ground-truth world: exact obstacle geometry kept alongside the physics.

A :class:`World` is a frame plus closed rings (polygons with holes allowed, or traced contours). Free space
is where a point's crossing count over all rings is odd (:func:`geometry.point_free`): a room's outline, the
frame around a rock field, or a cave contour all follow it. The same edges feed the sensors, the rasteriser
and the pymunk space (one static segment per edge: a decomposition into convex pieces that never takes a
convex hull, so concave rooms and holes stay exact).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from digslam.envs.sim import geometry as geo
from digslam.envs.sim.raster import FREE, cell_centres, rasterize
from digslam.envs.sim.tracing import chain_rings


@dataclass(eq=False)
class World:
    """Exact obstacle geometry.

    Attributes:
        frame: ``(xmin, ymin, xmax, ymax)`` bounding the free space.
        rings: Closed polylines ``(k, 2)``.
        edges: Edge array ``(E, 4)`` built from ``rings``.
        bbox: Edge bounding boxes ``(E, 4)``.
        name: Generator name.
    """

    frame: tuple[float, float, float, float]
    rings: list[np.ndarray]
    name: str = "world"
    edges: np.ndarray = field(init=False)
    bbox: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        if len(self.frame) != 4:
            raise ValueError(f"frame: expected (xmin, ymin, xmax, ymax), got {self.frame}")
        x0, y0, x1, y1 = (float(v) for v in self.frame)
        self.frame = (x0, y0, x1, y1)
        if not (self.frame[0] < self.frame[2] and self.frame[1] < self.frame[3]):
            raise ValueError(f"frame: must satisfy xmin < xmax and ymin < ymax, got {self.frame}")
        self.rings = [np.asarray(r, dtype=np.float64) for r in self.rings]
        self.edges = geo.rings_to_edges(self.rings) if self.rings else np.zeros((0, 4))
        if not np.all(np.isfinite(self.edges)):
            raise ValueError("rings: coordinates must be finite")
        self.bbox = geo.edge_bboxes(self.edges)

    @classmethod
    def from_edges(cls, frame: tuple[float, float, float, float], edges: np.ndarray, name: str) -> World:
        """Build from a closed edge soup (e.g. traced contours); ``rings`` are chained where possible."""
        w = cls(frame, [], name)
        w.rings = chain_rings(np.asarray(edges, dtype=np.float64).reshape(-1, 4)) or []
        w.edges = np.ascontiguousarray(edges, dtype=np.float64).reshape(-1, 4)
        w.bbox = geo.edge_bboxes(w.edges)
        return w

    def is_free(self, points: np.ndarray) -> np.ndarray:
        """True where points lie in free space."""
        pts = np.atleast_2d(np.asarray(points, dtype=np.float64))
        inside = (
            (pts[:, 0] > self.frame[0])
            & (pts[:, 0] < self.frame[2])
            & (pts[:, 1] > self.frame[1])
            & (pts[:, 1] < self.frame[3])
        )
        return inside & geo.point_free(pts, self.edges)

    def clearance(self, points: np.ndarray) -> np.ndarray:
        """Distance to the nearest obstacle edge (negative inside obstacles)."""
        d = geo.point_edge_distance(points, self.edges)
        return np.where(self.is_free(points), d, -d)

    def raster(self, resolution: float) -> np.ndarray:
        """Exact FREE/OCCUPIED/MIXED classification of the frame's cells (see :mod:`.raster`), cached.

        The returned array is read-only; copy it to modify it.
        """
        cache = self.__dict__.setdefault("_rasters", {})
        key = float(resolution)
        if key not in cache:
            cells = rasterize(self.edges, self.frame, key)
            cells.flags.writeable = False
            cache[key] = cells
        return cache[key]

    def free_area(self, resolution: float = 0.05) -> float:
        """Area of the cells that are entirely free at ``resolution`` (a lower bound of the free area)."""
        return float(np.count_nonzero(self.raster(resolution) == 0)) * resolution**2

    def sample_free_pose(self, rng: np.random.Generator, clearance: float, tries: int = 4096) -> np.ndarray:
        """A pose ``(x, y, theta)`` with at least ``clearance`` to every obstacle."""
        x0, y0, x1, y1 = self.frame
        for _ in range(0, tries, 256):
            pts = np.column_stack([rng.uniform(x0, x1, 256), rng.uniform(y0, y1, 256)])
            ok = np.nonzero(self.clearance(pts) >= clearance)[0]
            if len(ok):
                return np.array([pts[ok[0], 0], pts[ok[0], 1], rng.uniform(-np.pi, np.pi)])
        raise ValueError(f"start: no free pose with clearance {clearance} found in map {self.name!r}")

    def reachable_cells(self, clearance: float, resolution: float = 0.1) -> np.ndarray:
        """The cells (of :meth:`raster`'s grid, row 0 at ``ymin``) of the largest 8-connected region where a
        disc of radius ``clearance`` centred anywhere in the cell keeps off every obstacle: the space a robot
        of that clearance can roam, away from pockets it cannot reach. Conservative (a cell counts when its
        centre lies ``clearance + resolution`` from every cell not entirely free); cached, read-only."""
        from scipy import ndimage

        cache = self.__dict__.setdefault("_reachable", {})
        key = (float(clearance), float(resolution))
        if key not in cache:
            free = self.raster(resolution) == FREE
            room = ndimage.distance_transform_edt(free) * resolution  # centre to the nearest non-free centre
            ok = room - 1.5 * resolution >= clearance
            lab, n = ndimage.label(ok, structure=np.ones((3, 3), dtype=bool))
            if n == 0:
                best = np.zeros_like(ok)
            else:
                best = lab == 1 + int(np.argmax(np.bincount(lab.ravel())[1:]))
            best.flags.writeable = False
            cache[key] = best
        return cache[key]

    def sample_reachable_pose(
        self, rng: np.random.Generator, clearance: float, resolution: float = 0.1, tries: int = 64
    ) -> np.ndarray:
        """A pose ``(x, y, theta)`` drawn uniformly in the reachable region (:meth:`reachable_cells`), with at
        least ``clearance`` to every obstacle (checked exactly) and a uniform heading; ValueError naming
        ``start`` when the world has no such region."""
        cells = self.reachable_cells(clearance, resolution)
        ii, jj = np.nonzero(cells)
        if ii.size:
            xs, ys = cell_centres(self.frame, resolution)
            for _ in range(tries):
                k = int(rng.integers(ii.size))
                p = np.array([xs[jj[k]], ys[ii[k]]]) + rng.uniform(-0.5, 0.5, 2) * resolution
                if self.clearance(p[None])[0] >= clearance:
                    return np.array([p[0], p[1], rng.uniform(-np.pi, np.pi)])
        raise ValueError(f"start: no reachable free pose with clearance {clearance} in map {self.name!r}")

    def check_start(self, pose: np.ndarray, clearance: float) -> None:
        """Raise ``ValueError`` naming ``start`` if the pose is not free with ``clearance`` to obstacles."""
        c = float(self.clearance(np.asarray(pose[:2])[None])[0])
        if c < clearance:
            where = "inside an obstacle" if c < 0 else f"only {c:.3g} m from an obstacle"
            raise ValueError(
                f"start: pose {tuple(np.round(pose, 3))} is {where} of map {self.name!r} "
                f"(the obstacles enclose it; clearance {clearance} needed)"
            )


__all__ = [
    "World",
]
