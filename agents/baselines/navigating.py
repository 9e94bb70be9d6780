"""The planning agents' loop: goal choice by a cost map, path following on the observation's map, stalls.

:class:`NavigatingAgent` is the base of every navigating baseline (frontier, lawnmower, loop closure, tour,
distance advantage) and of the goal driver. It plans on the observation's map (:mod:`.planning`): the
traversable pixels are the clear ones eroded by ``margin`` pixels (proved free with room for the robot's
disc), one Dijkstra from the robot's pixel per re-plan gives the path lengths to every pixel, a goal is the
cheapest pixel of the subclass's cost map (:meth:`NavigatingAgent._costs`), and the waypoint is the
farthest pixel of its path in straight sight. The robot turns in place and drives straight.

The soft planner (``soft=True``, the default) runs that Dijkstra over every pixel not dark, each at a cost:
1 on the traversable pixels, ``edge_weight`` on the other clear ones, ``penumbra_weight`` on penumbra. A
corridor about as wide as the robot plus the pose box is clear only along a strip narrower than the
erosion (penumbra along both walls): the plain planner (``soft=False``) cannot enter it until nothing else
is left (its ``cautious`` pass), the soft one takes it when it is the shorter way. Goals are clear pixels
either way.

The current goal is kept while its cost stays within :func:`keep_bound` of the cheapest (hysteresis). A
robot that drives without moving (pressed into a door frame the map showed as free) blocks the pixel ahead
and backs off (``unstick``, :meth:`NavigatingAgent._stalled`). A waypoint so close that the driver counts
it as reached at once is moved one pixel on along the path.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces

from digslam.agents.baselines import planning as pl
from digslam.agents.baselines.policy import BaselinePolicy, Memory, View

#: Hysteresis of the goal choice: the current goal is kept while its cost is at most :func:`keep_bound`
#: of the cheapest candidate's cost ``best``: ``KEEP_FACTOR * best + KEEP_SLACK`` pixels when ``best >= 0``.
KEEP_FACTOR, KEEP_SLACK = 1.0, 3.0


def keep_bound(best: float) -> float:
    """The largest cost at which the current goal is kept: ``best + (KEEP_FACTOR - 1) |best| + KEEP_SLACK``
    (``KEEP_FACTOR * best + KEEP_SLACK`` for ``best >= 0``; the gain term of ``FrontierAgent`` can make costs
    negative, and the tolerance still grows with their size)."""
    return best + (KEEP_FACTOR - 1.0) * abs(best) + KEEP_SLACK


#: Stall detection (:meth:`NavigatingAgent._stalled`): over ``STALL_STEPS`` driving steps the robot covered
#: less than ``STALL_SHARE`` of the commanded distance; it then backs off for ``BACK_STEPS`` steps.
STALL_STEPS, STALL_SHARE, BACK_STEPS = 8, 0.25, 3


class NavigatingAgent(BaselinePolicy):
    """Base of the planning agents: goal choice by :meth:`_costs`, path following and bookkeeping.

    Args:
        margin: Erosion of the clear pixels (pixels) that leaves room for the robot; half the tube width
            is added.
        visit_radius: Radius (m) of the disc marked visited around each position.
        replan_every: Steps between re-plans while driving.
        cautious: When no goal is reachable over clear ground, plan over the non-dark pixels with penumbra
            pixels costing ``penumbra_weight`` times more (they may hold obstacles: bumps are possible).
        penumbra_weight: Cost of a penumbra pixel relative to a clear one (soft and ``cautious`` planning).
        soft: Plan over every pixel not dark with the costs of :meth:`weights` (module docstring).
        edge_weight: Cost of a clear pixel that the erosion removed (soft planning).
        unstick: Detect a stall (driving without moving, :meth:`_stalled`), block the pixel ahead and back
            off; off, a robot pressed into a door frame pushes on until its goal's step budget runs out.
        **kw: :class:`BaselinePolicy` arguments.
    """

    def __init__(
        self,
        action_space: spaces.Space,
        observation_space: spaces.Space | None = None,
        seed: int | None = None,
        margin: int = 1,
        visit_radius: float = 1.2,
        replan_every: int = 10,
        cautious: bool = True,
        penumbra_weight: float = 3.0,
        soft: bool = True,
        edge_weight: float = 2.0,
        unstick: bool = True,
        **kw: Any,
    ) -> None:
        self.unstick = bool(unstick)
        for name, v in (("penumbra_weight", penumbra_weight), ("edge_weight", edge_weight)):
            if not (math.isfinite(v) and v >= 1.0):
                raise ValueError(f"{name}: must be finite and >= 1, got {v!r}")
        self.cautious, self.penumbra_weight = bool(cautious), float(penumbra_weight)
        self.soft, self.edge_weight = bool(soft), float(edge_weight)
        if not (isinstance(margin, int) and margin >= 0):
            raise ValueError(f"margin: must be an integer >= 0, got {margin!r}")
        if not (math.isfinite(visit_radius) and visit_radius > 0):
            raise ValueError(f"visit_radius: must be finite and > 0, got {visit_radius!r}")
        if not (isinstance(replan_every, int) and replan_every >= 1):
            raise ValueError(f"replan_every: must be an integer >= 1, got {replan_every!r}")
        self.margin, self.visit_radius, self.replan_every = margin, visit_radius, replan_every
        super().__init__(action_space, observation_space, seed, **kw)

    # --- to override -------------------------------------------------------------------------------------
    def _costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """``(m, m)`` goal costs (pixels; ``inf`` = not a goal)."""
        raise NotImplementedError

    def _goal_reached(self, view: View, mem: Memory) -> None:
        """Called when the robot reaches its goal pixel."""

    # --- the loop ----------------------------------------------------------------------------------------
    def _stalled(self, view: View, mem: Memory) -> bool:
        """Whether the robot, driving straight over the last :data:`STALL_STEPS` steps, covered less than
        :data:`STALL_SHARE` of the commanded distance (pressed into an obstacle the map showed as free
        room: a door frame, a corner the erosion missed). The pixel ahead is then marked blocked (never
        planned over again), the goal and waypoint are dropped and the robot backs off for
        :data:`BACK_STEPS` steps."""
        if not self.unstick or not mem.moving:
            mem.drives.clear()
            return False
        mem.drives.append(
            (view.pos.copy(), mem.last_v * self.max_speed * self.dt / self.px(view.clear.shape[0]))
        )
        if len(mem.drives) <= STALL_STEPS:
            return False
        del mem.drives[0]
        moved = float(np.hypot(*(mem.drives[-1][0] - mem.drives[0][0])))
        if moved >= STALL_SHARE * sum(v for _, v in mem.drives[1:]):
            return False
        ahead = view.pos + np.array([-math.sin(view.heading), math.cos(view.heading)])
        block = self._disk(view.clear.shape[0], ahead, 0.75)
        block[view.cell] = False
        mem.blocked |= block
        mem.drives.clear()
        mem.goal = mem.waypoint = None
        mem.moving, mem.backing = False, BACK_STEPS
        return True

    def _recover(self, view: View, mem: Memory) -> np.ndarray | None:
        """The backing-off action while recovering from a stall (:meth:`_stalled`), else None."""
        if mem.backing > 0 or self._stalled(view, mem):
            mem.backing -= 1
            mem.last_v = 0.0
            return np.array([-0.5, 0.0], dtype=np.float32)
        return None

    def _act(self, view: View, mem: Memory) -> np.ndarray:
        m = view.clear.shape[0]
        px = self.px(m)
        back = self._recover(view, mem)
        if back is not None:
            return back
        near = self._disk(m, view.pos, self.visit_radius / px)
        mem.visited |= near
        np.minimum(mem.best_tube, view.tube, out=mem.best_tube, where=near)
        if mem.goal is not None and np.hypot(*(np.array(mem.goal) + 0.5 - view.pos)) < 1.0:
            self._goal_reached(view, mem)
            mem.goal = mem.waypoint = None
        if mem.goal is not None and mem.goal_steps > mem.goal_budget:  # stuck: give the goal up
            mem.visited |= self._disk(m, np.array(mem.goal) + 0.5, self.visit_radius / px)
            mem.goal = mem.waypoint = None
        if mem.waypoint is None or mem.age >= self.replan_every:
            self._plan(view, mem)
        mem.age += 1
        mem.goal_steps += 1
        action = self._drive(view, mem)
        mem.last_v = float(action[0]) if mem.moving else 0.0
        return action

    def traversable(self, view: View) -> np.ndarray:
        """Clear pixels eroded by ``margin`` plus half the tube width (the true robot may be anywhere in
        the pose box)."""
        return pl.erode(view.clear, self.erosion(view))

    def erosion(self, view: View) -> int:
        """Pixels of erosion: ``margin`` plus half the tube width (rounded, pixels)."""
        return self.margin + max(int(math.ceil(0.5 * view.tube / self.px(view.clear.shape[0]) - 0.25)), 0)

    def _plan(self, view: View, mem: Memory) -> None:
        """Choose (or keep) the goal and set the waypoint along its shortest path."""
        mem.age = 0
        cell = view.cell
        if self.soft:
            eroded = self.traversable(view) & ~mem.blocked
            weight = self.weights(view, eroded)
            weight[mem.blocked] = np.inf
            trav = np.isfinite(weight)
            dist, pred = pl.shortest_paths(trav, cell, np.where(trav, weight, 1.0))
            cost = self._costs(view, mem, np.isfinite(dist) & view.clear, dist)
            cost[cell] = np.inf
        else:
            trav = self.traversable(view) & ~mem.blocked
            dist, pred = pl.shortest_paths(trav, cell)
            reach = np.isfinite(dist)
            if np.count_nonzero(reach) <= 1:  # boxed in by the erosion: plan over the plain clear pixels
                trav = view.clear & ~mem.blocked
                dist, pred = pl.shortest_paths(trav, cell)
                reach = np.isfinite(dist)
            cost = self._costs(view, mem, reach, dist)
            cost[cell] = np.inf
            if not np.isfinite(cost).any() and self.cautious:
                # nothing over the clear ground (e.g. a map too coarse for a narrow passage): cross
                # penumbra, at a cost, towards the same kind of goals
                trav = ~view.dark & ~mem.blocked
                dist, pred = pl.shortest_paths(trav, cell, np.where(view.clear, 1.0, self.penumbra_weight))
                cost = self._costs(view, mem, np.isfinite(dist), dist)
                cost[cell] = np.inf
        k = int(np.argmin(cost))
        best = float(cost.flat[k])
        if not math.isfinite(best):
            mem.goal = mem.waypoint = None
            return
        goal = mem.goal
        if goal is None or not (math.isfinite(cost[goal]) and cost[goal] <= keep_bound(best)):
            goal = mem.goal = (k // cost.shape[1], k % cost.shape[1])
            mem.goal_steps = 0
            steps_per_px = self.px(view.clear.shape[0]) / (self.max_speed * self.dt)
            mem.goal_budget = int(2.0 * float(dist[goal]) * steps_per_px + 60)
        path = pl.path_to(pred, trav.shape, goal)
        start = np.clip(view.pos, 0, trav.shape[0] - 1e-6)
        sight = (eroded if self.soft else trav) | self._disk(trav.shape[0], view.pos, 1.0)
        if self.soft:  # a straight line may also follow the path's own pixels (a corridor in penumbra)
            on_path = np.zeros_like(sight)
            on_path[path[:, 0], path[:, 1]] = True
            sight |= on_path
        j = pl.line_of_sight(sight, start, path)
        while j + 1 < len(path) and float(np.hypot(*(path[j] + 0.5 - view.pos))) < 0.75:
            j += 1  # a waypoint that _drive counts as reached at once would stop the robot for good
        mem.waypoint = path[j].astype(np.float64) + 0.5

    def planner_graph(
        self, view: View, mem: Memory, reach: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """``(free, weight)`` of the graph :meth:`_plan` searches, for path lengths between other pixels
        (:func:`.planning.path_lengths`): the soft planner's pixels not dark and not blocked with their costs
        (:meth:`weights`), or the plain planner's reachable pixels not blocked, unweighted."""
        if not self.soft:
            return reach & ~mem.blocked, None
        weight = self.weights(view, self.traversable(view) & ~mem.blocked)
        weight[mem.blocked] = np.inf
        free = np.isfinite(weight)
        return free, np.where(free, weight, 1.0)

    def weights(self, view: View, eroded: np.ndarray | None = None) -> np.ndarray:
        """``(m, m)`` cost per pixel of the soft planner: 1 on the traversable pixels (clear, eroded; pass
        them as ``eroded`` if already computed), ``edge_weight`` on the other clear pixels,
        ``penumbra_weight`` on penumbra, ``inf`` on dark ground."""
        w = np.full(view.clear.shape, np.inf)
        w[view.penumbra] = self.penumbra_weight
        w[view.clear] = self.edge_weight
        w[self.traversable(view) if eroded is None else eroded] = 1.0
        return w


__all__ = [
    "BACK_STEPS",
    "KEEP_FACTOR",
    "KEEP_SLACK",
    "NavigatingAgent",
    "STALL_SHARE",
    "STALL_STEPS",
    "keep_bound",
]
