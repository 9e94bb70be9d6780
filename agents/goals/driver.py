"""The goal driver: the frontier agent's loop, driven towards one goal that the caller fixes.

:class:`GoalDriver` is a :class:`~digslam.agents.baselines.uncertainty.UncertaintyAwareFrontier` (for its
loop-closure targets) whose goal choice is replaced: ``NavigatingAgent._act`` still does the bookkeeping
(visited pixels, the narrowest tube seen near each pixel), the reach check, the give-up budget, the re-plan
every ``replan_every`` steps, the soft-planning Dijkstra of ``NavigatingAgent._plan`` and the turn-then-go
driving; only :meth:`GoalDriver._costs` differs: it keeps the fixed goal, and says when the macro step is
over (an *event*):

* ``"reached"``: the goal reached (within a pixel, ``NavigatingAgent``'s test; a frontier goal also once
  visited, i.e. within ``visit_radius`` of a past position, when the frontier agent drops it);
* ``"interrupted"`` (frontier goals, at a re-plan): the goal's *regret*, its frontier cost minus
  ``1.2 x`` the cheapest frontier cost minus 3 pixels (the frontier agent's hysteresis,
  ``NavigatingAgent._plan``), exceeds both 0 and its value when it was chosen. For the frontier agent's own
  pick (regret <= 0 then) this is exactly when the frontier agent switches goals: a cheaper frontier opened
  (new ground seen) or the goal stopped being a frontier;
* ``"gave_up"``: the goal budget ran out (``NavigatingAgent._act`` marks the goal's disc visited);
* ``"unreachable"``: the goal left the reachable clear pixels;
* ``"turned"``: the in-place turn made a full circle; ``"frontier"``: a turn chosen when no frontier was
  left sees one appear (the frontier agent's look-around, re-planned every step, would take it).

:meth:`GoalDriver.probe` runs one planning pass without moving the goal, for the candidates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np

from digslam.agents.baselines.navigating import KEEP_FACTOR, KEEP_SLACK, NavigatingAgent, keep_bound
from digslam.agents.baselines.policy import Memory, View
from digslam.agents.baselines.uncertainty import UncertaintyAwareFrontier

#: Candidate kinds.
FRONTIER, CLOSURE, TURN = 0, 1, 2
KINDS = ("frontier", "closure", "turn")


@dataclass
class Plan:
    """One planning pass from the robot's pixel (``NavigatingAgent._plan``'s soft Dijkstra).

    Attributes:
        dist: ``(m, m)`` path costs (pixels; ``inf`` = unreachable).
        reach: ``(m, m)`` reachable clear pixels.
        cost: ``(m, m)`` frontier costs (``FrontierAgent.frontier_costs``; ``inf`` off the candidates and on
            the robot's pixel).
    """

    dist: np.ndarray
    reach: np.ndarray
    cost: np.ndarray


def regret(cost: np.ndarray, goal: tuple[int, int]) -> float:
    """How much worse ``goal`` is than the frontier agent tolerates (> 0: it would switch; ``inf`` when
    ``goal`` is no frontier candidate)."""
    c = float(cost[goal])
    return c - keep_bound(float(cost.min())) if math.isfinite(c) else math.inf


class GoalDriver(UncertaintyAwareFrontier):
    """Drives to a fixed goal with the frontier agent's loop (module docstring).

    Takes the arguments of :class:`UncertaintyAwareFrontier` (and so of :class:`FrontierAgent`); of its own,
    only ``spread`` and ``shrink`` matter: a reached closure target keeps the loop-closure targets within
    ``spread`` m of it out until the tube is below ``shrink`` times its width at that visit.
    """

    @property
    def n_turn(self) -> int:
        """Steps of a full in-place turn at the full yaw rate."""
        return max(int(math.ceil(2.0 * math.pi / self._turn - 1e-9)), 1)

    # --- what the environment calls -------------------------------------------------------------------------
    def begin(self, m: int) -> Memory:
        """A fresh memory for an ``m x m`` map (one episode)."""
        mem = Memory(m)
        mem.extra.update(kind=None, goal=None, event=None, started=False, probe=False, ended=None,
                         slack=0.0, watch=False, turned=0, visits=[])  # fmt: skip
        mem.extra["pass"] = 0  # planning passes of the current re-plan (the plain planner may make two)
        return mem

    def probe(self, view: View, mem: Memory) -> Plan:
        """The bookkeeping of one step and one planning pass on ``view``, the goal state left as it was."""
        saved = (mem.goal, mem.waypoint, mem.moving, mem.age, mem.goal_steps, mem.goal_budget, mem.last_v)
        mem.goal = mem.waypoint = None
        mem.extra["probe"] = True
        try:
            NavigatingAgent._act(self, view, mem)
        finally:
            mem.extra["probe"] = False
            mem.goal, mem.waypoint, mem.moving, mem.age, mem.goal_steps, mem.goal_budget, mem.last_v = saved
        return mem.extra.pop("plan")

    def start(self, mem: Memory, kind: int, goal: tuple[int, int], slack: float = 0.0, keep: bool = False,
              watch: bool = False) -> None:  # fmt: skip
        """Fix the goal of the next steps. ``keep``: the frontier goal being driven to continues (its
        waypoint and budget kept, as the frontier agent keeps them); ``slack``: the regret tolerated
        (:func:`regret`); ``watch``: a turn ends when a frontier appears."""
        x = mem.extra
        x.update(kind=int(kind), goal=(int(goal[0]), int(goal[1])), slack=float(slack), watch=bool(watch),
                 turned=0, event=None)  # fmt: skip
        if not keep:
            mem.goal = mem.waypoint = None
            x["started"] = False

    def act(self, view: View, mem: Memory) -> tuple[np.ndarray, str | None]:
        """The low-level action on ``view`` and the event that ends the macro step (None: go on)."""
        x = mem.extra
        x["event"] = None
        if x["kind"] == TURN and x["turned"] >= self.n_turn:
            x["event"] = "turned"
        saved = (mem.moving, list(mem.drives), mem.backing, mem.last_v, mem.blocked.copy())
        action = NavigatingAgent._act(self, view, mem)
        if x["event"] is not None:  # the action is dropped: so is its controller state (turning or driving,
            # and the stall watch, which the next macro step's first action runs again on this same view)
            mem.moving, mem.drives, mem.backing, mem.last_v, mem.blocked = saved
        elif x["kind"] == TURN:
            x["turned"] += 1
        return np.clip(action, -1.0, 1.0).astype(np.float32), x["event"]

    def closure_mask(self, view: View, mem: Memory, reach: np.ndarray) -> np.ndarray:
        """``(m, m)`` loop-closure targets now (:meth:`UncertaintyAwareFrontier.closure_targets` at the
        current tube width), minus the robot's own pixel surroundings (reached at once) and the ``spread``
        discs of the closure visits still in force."""
        x = mem.extra
        x["visits"] = [(p, t) for p, t in x["visits"] if view.tube > self.shrink * t]
        x["closing"], x["done_at"] = view.tube, [p for p, _ in x["visits"]]
        return self.closure_targets(view, mem, reach) & ~self._disk(view.clear.shape[0], view.pos, 1.0)

    # --- NavigatingAgent's hooks -------------------------------------------------------------------------
    def _act(self, view: View, mem: Memory) -> np.ndarray:
        return NavigatingAgent._act(self, view, mem)

    def _recover(self, view: View, mem: Memory) -> np.ndarray | None:
        return None if mem.extra["probe"] else super()._recover(view, mem)

    def _plan(self, view: View, mem: Memory) -> None:
        x = mem.extra
        if x["kind"] == TURN and not x["watch"] and not x["probe"]:  # turning blind: no planning pass
            mem.age = 0
            mem.goal = mem.waypoint = None
            return
        x["pass"] = 0
        NavigatingAgent._plan(self, view, mem)

    def _goal_reached(self, view: View, mem: Memory) -> None:
        x = mem.extra
        x["event"] = "reached"
        if x["kind"] == CLOSURE:
            x["visits"].append((view.pos.copy(), view.tube))

    def _costs(self, view: View, mem: Memory, reach: np.ndarray, dist: np.ndarray) -> np.ndarray:
        x = mem.extra
        cost = self.frontier_costs(view, mem, reach, dist)
        cost[view.cell] = np.inf  # as NavigatingAgent._plan does after this call
        x["pass"] += 1
        out = np.full(dist.shape, np.inf)
        if x["probe"]:  # the frontier agent's own choice (and so its cautious pass, if any), undone after
            x["plan"] = Plan(dist, reach, cost)
            return cost.copy()
        if x["event"] is not None:
            return out
        kind, g = x["kind"], x["goal"]
        if not self.soft and self.cautious and x["pass"] == 1 and not np.isfinite(cost).any():
            return out  # the plain planner finds no frontier: its cautious pass (across penumbra) decides
        if x["started"] and mem.goal is None:  # NavigatingAgent._act gave the goal up (budget)
            x["event"] = "gave_up"
        elif kind == TURN:
            if x["watch"] and np.isfinite(cost).any():
                x["event"] = "frontier"
        elif not (reach[g] or (kind == FRONTIER and math.isfinite(cost[g]))):  # penumbra frontiers too
            x["event"] = "unreachable"
        elif kind == FRONTIER and mem.visited[g]:
            x["event"] = "reached"
        elif kind == FRONTIER and not regret(cost, g) <= x["slack"]:
            x["event"] = "interrupted"
        else:
            x["started"] = True
            out[g] = dist[g]
        return out


def driver_for(env: gym.Env, **kw: Any) -> GoalDriver:
    """A :class:`GoalDriver` sized from ``env`` as :func:`~digslam.agents.baselines.registry.make_baseline`
    sizes the frontier agent (grid span, speeds, step, sensor range), with ``kw`` on top."""
    from digslam.agents.baselines.registry import make_baseline

    ref = make_baseline("frontier", env)
    size = {k: getattr(ref, k) for k in ("span", "max_speed", "max_yaw_rate", "dt", "sensor_range")}
    return GoalDriver(env.action_space, env.observation_space, **{**size, **kw})


__all__ = [
    "CLOSURE",
    "FRONTIER",
    "GoalDriver",
    "KEEP_FACTOR",
    "KEEP_SLACK",
    "KINDS",
    "Plan",
    "TURN",
    "driver_for",
    "regret",
]
