"""Scripted paths for simulated logs: a tour through a world's reachable space and the pure-pursuit law that
follows it (the controller of :func:`~digslam.envs.sim.missions.loop_mission`, on a dense polyline).

:func:`tour` joins seeded goals of the reachable region (:meth:`~.world.World.reachable_cells`: cells whose
disc of radius ``clearance`` keeps off every wall) by shortest 8-connected grid paths and closes the loop;
:class:`PurePursuit` gives the constant ``(v, w)`` of the next slice from the pose.

>>> from digslam.envs.sim.generators import ThesisRoom
>>> path = tour(ThesisRoom().generate(0), np.random.default_rng(0), goals=3)
>>> path.shape[1], bool(np.all(np.hypot(*np.diff(path, axis=0).T) < 0.5))
(2, True)
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from digslam.envs.sim.raster import cell_centres
from digslam.envs.sim.world import World

_STEPS = ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1))


def _bfs(free: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> list[tuple[int, int]]:
    """Cells of a shortest 8-connected path from ``start`` to ``goal`` in ``free`` (both ends included)."""
    prev = {start: start}
    todo = deque([start])
    n, m = free.shape
    while todo:
        c = todo.popleft()
        if c == goal:
            break
        for di, dj in _STEPS:
            d = (c[0] + di, c[1] + dj)
            if 0 <= d[0] < n and 0 <= d[1] < m and free[d] and d not in prev:
                prev[d] = c
                todo.append(d)
    path = [goal]
    while path[-1] != start:
        path.append(prev[path[-1]])
    return path[::-1]


def tour(world: World, rng: np.random.Generator, goals: int = 8, clearance: float = 0.5,
         resolution: float = 0.25) -> np.ndarray:  # fmt: skip
    """A closed polyline ``(k, 2)`` through ``goals`` seeded cells of the reachable region, cell centres
    ``resolution`` apart (first point = last point); ValueError naming ``world`` when nothing is reachable."""
    cells = world.reachable_cells(clearance, resolution)
    ii, jj = np.nonzero(cells)
    if ii.size == 0:
        raise ValueError(f"world: {world.name!r} has no reachable region with clearance {clearance} m")
    pick = rng.choice(ii.size, size=max(2, goals), replace=ii.size < goals)
    stops = [(int(ii[k]), int(jj[k])) for k in pick]
    route: list[tuple[int, int]] = [stops[0]]
    for a, b in zip(stops, stops[1:] + stops[:1]):
        route += _bfs(cells, a, b)[1:]
    xs, ys = cell_centres(world.frame, resolution)
    r = np.array(route)
    return np.column_stack([xs[r[:, 1]], ys[r[:, 0]]])


class PurePursuit:
    """Follows a closed polyline: aims at the first point at least ``lookahead`` ahead, turns at
    ``gain * error`` (clipped to ``max_yaw_rate``), slows to ``speed * max(0.2, cos(error))``."""

    def __init__(self, path: np.ndarray, speed: float, max_yaw_rate: float, lookahead: float = 0.6,
                 gain: float = 1.5) -> None:  # fmt: skip
        self.path = np.asarray(path, dtype=np.float64)
        self.speed, self.max_yaw_rate, self.lookahead, self.gain = speed, max_yaw_rate, lookahead, gain
        self.k = 0

    def start(self) -> np.ndarray:
        """The start pose: the first point, heading to the first point beyond the lookahead."""
        p = self.path[0]
        far = np.nonzero(np.hypot(*(self.path - p).T) >= self.lookahead)[0]
        to = self.path[far[0] if far.size else 1] - p
        return np.array([p[0], p[1], math.atan2(to[1], to[0])])

    def command(self, pose: np.ndarray) -> tuple[float, float]:
        """``(v, w)`` for the slice that starts at ``pose``."""
        n = len(self.path)
        for _ in range(n):
            if math.hypot(*(self.path[self.k] - pose[:2])) >= self.lookahead:
                break
            self.k = (self.k + 1) % n
        to = self.path[self.k] - pose[:2]
        err = (math.atan2(to[1], to[0]) - pose[2] + math.pi) % (2 * math.pi) - math.pi
        w = float(np.clip(self.gain * err, -self.max_yaw_rate, self.max_yaw_rate))
        return self.speed * max(0.2, math.cos(err)), w


__all__ = ["PurePursuit", "tour"]
