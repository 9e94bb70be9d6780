"""Navigating baselines: lawnmower, frontier exploration and its uncertainty-aware variant.

All plan on the observation's map (:mod:`.planning`): the traversable pixels are the clear ones eroded by
``margin`` pixels (proved free with room for the robot's disc), one Dijkstra from the robot's pixel per
re-plan gives the path lengths to every pixel, a goal is the cheapest candidate pixel, and the waypoint is
the farthest pixel of its path in straight sight. The robot turns in place and drives straight.

The soft planner (``soft=True``, the default) runs that Dijkstra over every pixel not dark, each at a cost:
1 on the traversable pixels, ``edge_weight`` on the other clear ones, ``penumbra_weight`` on penumbra. A
corridor about as wide as the robot plus the pose box is clear only along a strip narrower than the
erosion (penumbra along both walls): the plain planner (``soft=False``) cannot enter it until nothing else
is left (its ``cautious`` pass), the soft one takes it when it is the shorter way. Goals are clear pixels
either way.

* frontier candidates: traversable pixels next to dark ground (within the penumbra band that the tube
  width adds), then next to penumbra, then any pixel not yet visited, each tier with a path-length penalty,
  less a bonus for the dark ground around the pixel (the expected gain, ``gain_weight``);
  a pixel within ``visit_radius`` m of the robot's past positions is no longer a candidate (if it is still
  next to dark ground once the robot was there, it borders an obstacle, not the unexplored);
* loop closure (:class:`UncertaintyAwareFrontier`): pixels next to sensed obstacles (penumbra) that the
  robot passed while its tube was at most half as wide as now.

Two ways an episode would stop for good are handled (``rooms``, validation levels): the unexplored may lie
beyond a corridor seen only in penumbra, so the penumbra pixels next to dark ground and deep in the penumbra
are goals too, at ``penumbra_penalty``, beside the clear tiers (``penumbra_frontier``); and a robot that
drives without moving (pressed into a door frame the map showed as free) blocks the pixel ahead and backs
off (``unstick``). A waypoint so close
that the driver counts it as reached at once is moved one pixel on along the path.

>>> from gymnasium import spaces
>>> agent = FrontierAgent(spaces.Box(-1, 1, (2,)))
>>> state = np.zeros(11, np.float32); state[[4, 10]] = 1.0; state[8] = 0.1    # centre, heading +x
>>> img = np.zeros((4, 36, 36), np.uint8); img[0, 8:28, 8:28] = 255; img[2] = 255 - img[0]
>>> a, _ = agent.predict({"map": img, "state": state})
>>> agent._mem[0].goal is not None, a.shape
(True, (2,))
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from scipy import ndimage

from digslam.agents.baselines import planning as pl
from digslam.agents.baselines.policy import BaselinePolicy, Memory, View

#: Hysteresis of the goal choice: the current goal is kept while its cost is at most :func:`keep_bound`
#: of the cheapest candidate's cost ``best``: ``KEEP_FACTOR * best + KEEP_SLACK`` pixels when ``best >= 0``.
#: With the gain term (``FrontierAgent.gain_weight``), 1.0 (keep within 3 px of the best) matched or beat
#: 1.2 on the validation levels (24 per generator: mean T90 1603 against 1634 steps, 0.9 reached on 73 %
#: against 69 % of them).
KEEP_FACTOR, KEEP_SLACK = 1.0, 3.0


def keep_bound(best: float) -> float:
    """The largest cost at which the current goal is kept: ``best + (KEEP_FACTOR - 1) |best| + KEEP_SLACK``
    (``KEEP_FACTOR * best + KEEP_SLACK`` for ``best >= 0``; the gain term of ``FrontierAgent`` can make costs
    negative, and the tolerance still grows with their size)."""
    return best + (KEEP_FACTOR - 1.0) * abs(best) + KEEP_SLACK


#: Stall detection (:meth:`NavigatingAgent._stalled`): over ``STALL_STEPS`` driving steps the robot covered
#: less than ``STALL_SHARE`` of the commanded distance; it then backs off for ``BACK_STEPS`` steps.
STALL_STEPS, STALL_SHARE, BACK_STEPS = 8, 0.25, 3


@functools.lru_cache(maxsize=8)
def _centres(m: int) -> np.ndarray:
    """``(2, m, m)`` read-only row and column coordinates of the pixel centres of an ``m x m`` map."""
    out = np.mgrid[:m, :m] + 0.5
    out.flags.writeable = False
    return out


class NavigatingAgent(BaselinePolicy):
    """Base of the planning agents: goal choice by :meth:`_costs`, path following and bookkeeping.

    Args:
        margin: Erosion of the clear pixels (pixels) that leaves room for the robot; half the tube width
            is added.
        visit_radius: Radius (m) of the disc marked visited around each position.
        replan_every: Steps between re-plans while driving.
        cautious: When no goal is reachable over clear ground, plan over the non-dark pixels with penumbra
            pixels costing ``penumbra_weight`` times more (they may hold obstacles: bumps are possible).
        penumbra_weight: Cost of a penumbra pixel relative to a clear one (soft and ``cautious`` planning);
            3 beat 5 on the validation levels (seeds 1 000 000-1 000 003 of every generator, 3000 steps: mean
            T90 1777 against 1867 steps, 0.9 reached on 62 % of them against 56 %).
        soft: Plan over every pixel not dark with the costs of :meth:`weights` (module docstring).
        edge_weight: Cost of a clear pixel that the erosion removed (soft planning).
        unstick: Detect a stall (driving without moving, :meth:`_stalled`), block the pixel ahead and back
            off; off, a robot pressed into a door frame pushes on until its goal's step budget runs out.
        **kw: :class:`BaselinePolicy` arguments.
    """

    def __init__(
        self,
        action_space: Any,
        observation_space: Any = None,
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
        g = mem.goal
        if g is None or not (math.isfinite(cost[g]) and cost[g] <= keep_bound(best)):
            mem.goal = (k // cost.shape[1], k % cost.shape[1])
            mem.goal_steps = 0
            steps_per_px = self.px(view.clear.shape[0]) / (self.max_speed * self.dt)
            mem.goal_budget = int(2.0 * float(dist[mem.goal]) * steps_per_px + 60)
        path = pl.path_to(pred, trav.shape, mem.goal)
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


class FrontierAgent(NavigatingAgent):
    """Nearest frontier between clear and dark ground (then penumbra, then unvisited clear ground).

    Args:
        penumbra_penalty: Extra path length (m) of a goal next to penumbra only.
        unvisited_penalty: Extra path length (m) of a goal that is merely not yet visited.
        turn_weight: Weight of the time to turn in place towards a goal, counted as the distance that
            could be driven meanwhile (a half turn takes as long as 3 m of driving at full scale); 4 was
            the best of 0-8 on the maps of seeds 0-2, taking about a fifth fewer steps to 0.8 than 0.
        gain_weight: Weight (m) of the expected gain: a candidate's cost is lowered by ``gain_weight`` times
            the dark share of the square of side twice the sensor range around it (the unexplored it may
            open up), so that of two frontiers about as far the one facing more dark ground wins. 40 was
            the best of 0-160 on the validation levels (seeds 1 000 000-1 000 023 of every generator, 3000
            steps): mean T90 1603 against 1807 steps for the former defaults (0, and ``KEEP_FACTOR`` 1.2),
            0.9 reached on 73 % of them against 62 % (the room: T90 472 against 909; the rocks: 96 %
            against 58 %).
        penumbra_frontier: Also take as goals the reachable penumbra pixels next to dark ground not yet
            visited that lie farther from clear ground than the tube's band along walls (a corridor that the
            cones saw only in penumbra, otherwise entered only once every clear pixel was visited), at the
            ``penumbra_penalty``; when no pixel is a candidate at all, any such penumbra pixel next to dark
            ground (at the ``unvisited_penalty``). On the validation levels (24 per generator, 3000 steps)
            the deep pixels as goals beside the clear tiers lifted the rooms levels certified to 0.8 from
            83 % to 96 % (mean T80 2525 -> 2428) and changed nothing on room, rocks and caves.
        **kw: :class:`NavigatingAgent` arguments.
    """

    def __init__(
        self,
        action_space: Any,
        observation_space: Any = None,
        seed: int | None = None,
        penumbra_penalty: float = 6.0,
        unvisited_penalty: float = 12.0,
        turn_weight: float = 4.0,
        penumbra_frontier: bool = True,
        gain_weight: float = 40.0,
        **kw: Any,
    ) -> None:
        self.penumbra_frontier = bool(penumbra_frontier)
        if not (math.isfinite(gain_weight) and gain_weight >= 0):
            raise ValueError(f"gain_weight: must be finite and >= 0, got {gain_weight!r}")
        self.gain_weight = float(gain_weight)
        named = (("penumbra_penalty", penumbra_penalty), ("unvisited_penalty", unvisited_penalty),
                 ("turn_weight", turn_weight))  # fmt: skip
        for name, v in named:
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"{name}: must be finite and >= 0, got {v!r}")
        self.penumbra_penalty, self.unvisited_penalty = penumbra_penalty, unvisited_penalty
        self.turn_weight = turn_weight
        super().__init__(action_space, observation_space, seed, **kw)

    def frontier_tiers(self, view: View, mem: Memory, reach: np.ndarray) -> tuple[np.ndarray, ...]:
        """The candidate pixels by tier: ``(dark, pen, free)``, reachable unvisited pixels next to dark ground
        (within the band the tube adds), those next to penumbra only, and all reachable unvisited ones."""
        px = self.px(view.clear.shape[0])
        band = self.erosion(view) + 1 + int(math.ceil(view.tube / px))
        free = reach & ~mem.visited
        dark = free & pl.dilate(view.dark, band + 1)
        pen = free & ~dark & pl.dilate(view.penumbra, self.erosion(view) + 1)
        return dark, pen, free

    def frontier_costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """Path length plus the tier penalty of every frontier pixel (``inf`` elsewhere)."""
        px = self.px(view.clear.shape[0])
        dark, pen, free = self.frontier_tiers(view, mem, reach)
        cost = np.full(dist.shape, np.inf)
        cost[free] = dist[free] + self.unvisited_penalty / px
        cost[pen] = dist[pen] + self.penumbra_penalty / px
        cost[dark] = dist[dark]
        if self.penumbra_frontier:
            # the unexplored may lie beyond a passage seen only in penumbra (a corridor that the sonar cones,
            # cut short by its walls, never cleared): its edge with dark ground, deeper in the penumbra than
            # the band that the tube puts along every wall, is a goal beside the clear tiers; with no goal at
            # all, any edge of the penumbra with dark ground
            edge = np.isfinite(dist) & view.penumbra & pl.dilate(view.dark, 1) & ~mem.visited
            deep = edge & ~pl.dilate(view.clear, int(math.ceil(view.tube / px)) + 2)
            if deep.any():
                cost[deep] = np.minimum(cost[deep], dist[deep] + self.penumbra_penalty / px)
            elif not np.isfinite(cost).any():
                cost[edge] = dist[edge] + self.unvisited_penalty / px
        if self.turn_weight > 0:
            rr, cc = _centres(view.clear.shape[0])
            err = np.abs(
                np.angle(np.exp(1j * (np.arctan2(view.pos[0] - rr, cc - view.pos[1]) - view.heading)))
            )
            cost += self.turn_weight * err / self._turn * (self.max_speed * self.dt) / px
        if self.gain_weight > 0:
            cost -= self.gain_weight * self.expected_gain(view, mem, np.isfinite(cost)) / px
        return cost

    def expected_gain(self, view: View, mem: Memory, candidates: np.ndarray) -> np.ndarray:
        """``(m, m)`` expected gain of each candidate pixel, in ``[0, 1]`` (weighted by ``gain_weight``):
        here the dark share of the square of side twice the sensor range around the pixel."""
        k = 2 * int(round(self.sensor_range / self.px(view.clear.shape[0]))) + 1
        return ndimage.uniform_filter(view.dark.astype(np.float64), size=k, mode="constant")

    def _costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        return self.frontier_costs(view, mem, reach, dist)


class LawnmowerAgent(NavigatingAgent):
    """Boustrophedon over the world frame: lanes ``lane_spacing`` m apart, top to bottom, alternating
    direction; each lane end is reached through the planner (the reachable pixel nearest to it).

    Args:
        lane_spacing: Distance between lanes (m).
        edge: Distance of the first and last lanes and lane ends from the frame's border (m).
        **kw: :class:`NavigatingAgent` arguments.
    """

    def __init__(
        self,
        action_space: Any,
        observation_space: Any = None,
        seed: int | None = None,
        lane_spacing: float = 3.0,
        edge: float = 1.0,
        **kw: Any,
    ) -> None:
        for name, v in (("lane_spacing", lane_spacing), ("edge", edge)):
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name}: must be finite and > 0, got {v!r}")
        self.lane_spacing, self.edge = lane_spacing, edge
        super().__init__(action_space, observation_space, seed, **kw)

    def lanes(self, m: int) -> np.ndarray:
        """``(K, 2)`` lane-end pixels ``(row, col)`` of the boustrophedon, in visiting order."""
        px = self.px(m)
        ys = np.arange(self.edge, self.span - self.edge + 1e-9, self.lane_spacing) / px
        a, b = self.edge / px, (self.span - self.edge) / px
        ends = [((a, b) if i % 2 == 0 else (b, a)) for i in range(len(ys))]
        return np.array([(y, c) for y, e in zip(ys, ends, strict=True) for c in e])

    def _costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        m = view.clear.shape[0]
        lanes = mem.extra.setdefault("lanes", self.lanes(m))
        i = mem.extra.setdefault("lane", 0) % len(lanes)
        rr, cc = _centres(m)
        d = np.hypot(rr - lanes[i, 0], cc - lanes[i, 1])
        return np.where(reach, 1e3 * d + dist, np.inf)  # nearest to the lane end, then shortest

    def _act(self, view: View, mem: Memory) -> np.ndarray:
        if mem.goal is not None and mem.goal_steps > mem.goal_budget:
            mem.extra["lane"] = mem.extra.get("lane", 0) + 1  # unreachable lane end: skip it
            mem.goal = mem.waypoint = None
        return super()._act(view, mem)

    def _goal_reached(self, view: View, mem: Memory) -> None:
        m = view.clear.shape[0]
        lanes = mem.extra.setdefault("lanes", self.lanes(m))
        i = mem.extra.get("lane", 0) % len(lanes)
        near = np.hypot(*(lanes[i] - view.pos)) * self.px(m) < 2.0
        if near or mem.extra.get("last") == mem.goal:  # at the lane end, or no nearer to it: next lane
            mem.extra["lane"] = i + 1
        mem.extra["last"] = mem.goal


class UncertaintyAwareFrontier(FrontierAgent):
    """:class:`FrontierAgent` with active loop closure.

    The observer contracts the pose box with the nearest echo, ``dist(x, comp M⁻) <= y⁺`` (Eq. 6.22): the
    side of the box away from the nearest obstacle is cut down to about the obstacle's setback in the dig
    zone, which is small where the obstacle was dug while the tube was narrow. So when the tube width
    exceeds ``tube_high`` m, the agent visits, one after the other, up to ``visits`` clear pixels next to
    sensed obstacles (penumbra) that it passed with a tube at most half as wide as now, each at least
    ``spread`` m from the previous ones (obstacles on other sides cut other sides of the box), until the
    tube is below ``shrink`` times its width at the switch or ``closure_steps`` steps have passed. A
    closure that did not shrink the tube raises the threshold by ``backoff`` (no endless returns).

    Args:
        tube_high: Tube width (m) that triggers a loop closure.
        shrink: Target tube width, as a share of the width at the switch.
        closure_steps: Longest closure (steps).
        visits: Most obstacle visits per closure.
        spread: Least distance (m) between the visits of one closure.
        backoff: Factor on ``tube_high`` after a closure that failed.
        **kw: :class:`FrontierAgent` arguments.
    """

    def __init__(
        self,
        action_space: Any,
        observation_space: Any = None,
        seed: int | None = None,
        tube_high: float = 0.5,
        shrink: float = 0.75,
        closure_steps: int = 300,
        visits: int = 4,
        spread: float = 3.0,
        backoff: float = 1.3,
        **kw: Any,
    ) -> None:
        checks = (("tube_high", tube_high, 0.0), ("shrink", shrink, 0.0), ("backoff", backoff, 1.0),
                  ("spread", spread, 0.0))  # fmt: skip
        for name, v, low in checks:
            if not (math.isfinite(v) and v > low):
                raise ValueError(f"{name}: must be finite and > {low}, got {v!r}")
        for name, n in (("closure_steps", closure_steps), ("visits", visits)):
            if not (isinstance(n, int) and n >= 1):
                raise ValueError(f"{name}: must be an integer >= 1, got {n!r}")
        self.tube_high, self.shrink, self.closure_steps = tube_high, shrink, closure_steps
        self.visits, self.spread, self.backoff = visits, spread, backoff
        super().__init__(action_space, observation_space, seed, **kw)

    def _act(self, view: View, mem: Memory) -> np.ndarray:
        x = mem.extra
        high = x.setdefault("high", self.tube_high)
        if x.get("closing") is None and view.tube > high:
            x.update(closing=view.tube, t0=mem.t, done_at=[])
            x["closures"] = x.get("closures", 0) + 1
            mem.goal = mem.waypoint = None
        if x.get("closing") is not None:
            over = mem.t - x["t0"] > self.closure_steps or len(x["done_at"]) >= self.visits
            if view.tube <= self.shrink * x["closing"] or over:
                self._end_closure(view, mem)
                mem.goal = mem.waypoint = None  # the goal was a loop-closure target
        return super()._act(view, mem)

    def _end_closure(self, view: View, mem: Memory) -> None:
        """Leave the loop-closure mode; a closure that did not shrink the tube raises the threshold."""
        x = mem.extra
        if view.tube > self.shrink * x["closing"]:
            x["high"] = max(x["high"], view.tube) * self.backoff
        x["closing"] = None

    def _plan(self, view: View, mem: Memory) -> None:
        """Plan as :class:`NavigatingAgent`; a closure with no target left in the last planning pass (no
        remembered narrow-tube obstacle pixel reachable, even across penumbra) ends at once, as a failed
        one unless the tube already shrank, and the goal just chosen (a frontier goal) is kept."""
        x = mem.extra
        x["targets"] = False
        super()._plan(view, mem)
        if x.get("closing") is not None and not x["targets"]:
            self._end_closure(view, mem)
            x["exhausted"] = x.get("exhausted", 0) + 1  # closures that ran out of targets (diagnostics)

    def _goal_reached(self, view: View, mem: Memory) -> None:
        if mem.extra.get("closing") is not None:
            mem.extra["done_at"].append(view.pos.copy())

    def closure_targets(self, view: View, mem: Memory, reach: np.ndarray) -> np.ndarray:
        """``(m, m)`` bool: the reachable pixels next to sensed obstacles passed with a tube at most half as
        wide as at the switch, at least ``spread`` m from the visits done in this closure."""
        m = view.clear.shape[0]
        near = (
            reach
            & pl.dilate(view.penumbra, self.erosion(view) + 1)
            & (mem.best_tube <= 0.5 * mem.extra["closing"])
        )
        for p in mem.extra["done_at"]:
            near &= ~self._disk(m, p, self.spread / self.px(m))
        return near

    def _costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """Path lengths to the closure targets while closing a loop; frontier costs otherwise, and when no
        target is reachable in this pass (``_plan`` then ends the closure, unless the cautious pass over
        penumbra reaches one)."""
        x = mem.extra
        if x.get("closing") is None:
            return self.frontier_costs(view, mem, reach, dist)
        near = self.closure_targets(view, mem, reach)
        x["targets"] = bool(near.any())
        if not x["targets"]:
            return self.frontier_costs(view, mem, reach, dist)
        return np.where(near, dist, np.inf)


__all__ = [
    "KEEP_FACTOR",
    "KEEP_SLACK",
    "keep_bound",
    "FrontierAgent",
    "LawnmowerAgent",
    "NavigatingAgent",
    "UncertaintyAwareFrontier",
]
