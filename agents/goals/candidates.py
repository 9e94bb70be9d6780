"""The candidate goals of one decision and their features, from the observation and the planner's memory.

Everything here reads the parsed observation (:class:`~digslam.agents.baselines.policy.View`: the map's
clear / penumbra / dark channels, the pose box, heading and tube width) and the driver's memory (visited
pixels, the narrowest tube seen near each pixel, past closure visits), never the ground truth.

One planning pass (:meth:`.driver.GoalDriver.probe`: ``NavigatingAgent._plan``'s soft Dijkstra and
``FrontierAgent.frontier_costs``) gives the candidates, in this order:

1. **frontier clusters**: the 8-connected components of the frontier agent's candidate pixels, one tier at a
   time (next to dark ground, next to penumbra only, merely unvisited: the tiers of ``frontier_costs``),
   each represented by its cheapest pixel, sorted by that cost (ties: row-major order, as ``np.argmin``).
   Candidate 0 is therefore the pixel the frontier agent picks; when the previous macro step ended at the
   step cap with a frontier goal the frontier agent would keep (no re-plan due yet, or its hysteresis keeps
   it), that goal represents its cluster and comes first (``continuing`` = 1), with its waypoint and budget,
   while it is still a reachable clear pixel (the frontier agent would drive on to its waypoint regardless
   until its next re-plan: the one case where the two part, seen only with the plain planner,
   ``soft=False``);
2. **one in-place 360° turn** (the frontier agent's look-around: candidate 0 when no frontier is left);
3. **loop-closure clusters**: reachable clear pixels next to penumbra passed with a tube at most half the
   current width (``UncertaintyAwareFrontier.closure_targets``), clustered alike, sorted by path cost.

At most ``n - 1`` frontier and closure clusters are kept (closures get ``n // 4`` slots when frontiers
would fill them), the cheapest first; the rest is zero padding, masked out.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from digslam.agents.baselines.policy import Memory, View
from digslam.agents.goals.driver import CLOSURE, FRONTIER, TURN, GoalDriver, Plan, regret

#: Features of a candidate, in order (all in ``[-1, 1]``).
FEATURES = (
    "frontier", "closure", "turn",  # kind, one-hot
    "tier",  # frontier tier: 1 next to dark ground, 0.5 next to penumbra only, 0 merely unvisited / not one
    "path",  # tanh(planner path cost (m) / map span); 0 for the turn
    "cost",  # tanh(heuristic cost (m) / span): frontier cost with tier and turn penalties; the path otherwise
    "bearing",  # heading change to face the goal / π (signed); 1 for the turn
    "dx", "dy",  # goal minus robot in the world frame (m) / span
    "gain",  # share of the dark pixels within the sensor range of the goal
    "tube",  # tanh(narrowest tube width (m) the robot had near the goal); 1 where it never was
    "clearance",  # distance (m) from the goal to the nearest non-clear pixel / sensor range, at most 1
    "size",  # tanh(cluster pixels / map side); 0 for the turn
    "rank",  # position in the list / (n - 1)
    "continuing",  # 1: the goal being driven to, kept as the frontier agent keeps it
)  # fmt: skip
N_FEATURES = len(FEATURES)
_EIGHT = np.ones((3, 3), dtype=bool)


@dataclass
class Candidates:
    """The ``n`` candidate slots of one decision.

    Attributes:
        kind: ``(n,)`` FRONTIER / CLOSURE / TURN, -1 on padding.
        goal: ``(n, 2)`` goal pixels ``(row, col)`` (the robot's pixel for the turn).
        features: ``(n, N_FEATURES)`` float32 (:data:`FEATURES`), zero on padding.
        mask: ``(n,)`` bool, the valid slots.
        slack: ``(n,)`` the regret each frontier goal has at the decision (its interrupt tolerance, >= 0).
        keep: ``(n,)`` bool, the continuing goal.
        n_frontier, n_closure: clusters found (before the cut to ``n``).
    """

    kind: np.ndarray
    goal: np.ndarray
    features: np.ndarray
    mask: np.ndarray
    slack: np.ndarray
    keep: np.ndarray
    n_frontier: int
    n_closure: int


def clusters(pixels: np.ndarray, cost: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """8-connected components of ``pixels``: each one's cheapest pixel (flat index; ties: the first in
    row-major order), its cost and its size, sorted by (cost, flat index)."""
    labels, n = ndimage.label(pixels, structure=_EIGHT)
    if n == 0:
        return np.zeros(0, np.int64), np.zeros(0), np.zeros(0, np.int64)
    flat = np.flatnonzero(labels)
    order = np.lexsort((flat, cost.flat[flat]))  # by cost, then flat index
    lab = labels.flat[flat[order]]
    _, first = np.unique(lab, return_index=True)
    reps = flat[order][first]
    sizes = np.bincount(lab)[1:]
    by = np.lexsort((reps, cost.flat[reps]))
    return reps[by], cost.flat[reps[by]], sizes[by]


def tiers(driver: GoalDriver, view: View, mem: Memory, reach: np.ndarray) -> np.ndarray:
    """``(m, m)`` frontier tier per pixel: 1 next to dark ground, 2 next to penumbra only, 3 merely unvisited,
    0 not a candidate; read from ``frontier_costs`` itself with no path length and no turn term."""
    flat = copy.copy(driver)
    flat.turn_weight = flat.gain_weight = 0.0
    pen = flat.frontier_costs(view, mem, reach, np.zeros(reach.shape))
    px = driver.px(reach.shape[0])
    out = np.zeros(reach.shape, np.int8)
    out[np.isfinite(pen)] = 3
    out[np.isclose(pen, driver.penumbra_penalty / px)] = 2
    out[pen == 0.0] = 1
    return out


def candidates(driver: GoalDriver, view: View, mem: Memory, n: int = 16) -> Candidates:
    """The candidates of the decision on ``view`` (module docstring); runs the driver's bookkeeping on it."""
    plan: Plan = driver.probe(view, mem)
    m = view.clear.shape[0]
    cost = plan.cost
    x = mem.extra
    g = None if mem.goal is None else (int(mem.goal[0]), int(mem.goal[1]))
    # the frontier agent drives on to its goal until a re-plan is due, then keeps it by its hysteresis
    drives_on = mem.waypoint is not None and mem.age < driver.replan_every
    keep_goal = (x["ended"] == "cap" and x["kind"] == FRONTIER and g is not None and g == x["goal"]
                 and bool(plan.reach[g] or np.isfinite(cost[g]))  # a penumbra frontier is reachable too
                 and (drives_on or regret(cost, g) <= 0.0))  # fmt: skip
    tier = tiers(driver, view, mem, plan.reach)
    fr = [clusters((tier == t) & np.isfinite(cost), cost) for t in (1, 2, 3)]
    reps = np.concatenate([f[0] for f in fr])
    order = np.lexsort((reps, cost.flat[reps]))
    f_rep, f_size = reps[order], np.concatenate([f[2] for f in fr])[order]
    if keep_goal and g is not None:  # the continuing goal stands for its cluster, first
        k = g[0] * m + g[1]
        lab = ndimage.label((tier == tier[g]) & np.isfinite(cost), structure=_EIGHT)[0]
        same = np.flatnonzero(lab.flat[f_rep] == lab[g]) if lab[g] else np.zeros(0, np.int64)
        f_size = np.concatenate([f_size[same] if same.size else [1], np.delete(f_size, same)])
        f_rep = np.concatenate([[k], np.delete(f_rep, same)])
    c_rep, _, c_size = clusters(driver.closure_mask(view, mem, plan.reach), plan.dist)
    nc = min(len(c_rep), n // 4)
    nf = min(len(f_rep), n - 1 - nc)
    nc = min(len(c_rep), n - 1 - nf)
    kind = np.full(n, -1, np.int64)
    goal = np.zeros((n, 2), np.int64)
    size = np.zeros(n)
    rows: list[tuple[int, np.ndarray, np.ndarray]] = [
        (FRONTIER, f_rep[:nf], f_size[:nf]), (TURN, np.array([view.cell[0] * m + view.cell[1]]), np.zeros(1)),
        (CLOSURE, c_rep[:nc], c_size[:nc])]  # fmt: skip
    i = 0
    for kd, flat, sz in rows:
        j = i + len(flat)
        kind[i:j], goal[i:j] = kd, np.stack([np.asarray(flat) // m, np.asarray(flat) % m], axis=1)
        size[i:j] = sz
        i = j
    mask = kind >= 0
    slack = np.zeros(n)
    keep = np.zeros(n, bool)
    keep[0] = keep_goal and nf > 0
    for s in np.flatnonzero(kind == FRONTIER):
        slack[s] = max(regret(cost, (int(goal[s, 0]), int(goal[s, 1]))), 0.0)
    slack[keep] = 0.0  # the continuing goal: the frontier agent's own tolerance
    feats = features(driver, view, mem, plan, kind, goal, size, tier, keep, n)
    return Candidates(kind, goal, feats, mask, slack, keep, int(len(f_rep)), int(len(c_rep)))


def features(driver: GoalDriver, view: View, mem: Memory, plan: Plan, kind: np.ndarray, goal: np.ndarray,
             size: np.ndarray, tier: np.ndarray, keep: np.ndarray, n: int) -> np.ndarray:  # fmt: skip
    """``(n, N_FEATURES)`` float32 features of the candidate slots (:data:`FEATURES`)."""
    m = view.clear.shape[0]
    px, span, rng = driver.px(m), driver.span, driver.sensor_range
    out = np.zeros((n, N_FEATURES), np.float32)
    clearance = ndimage.distance_transform_edt(view.clear) * px
    rr, cc = np.ogrid[:m, :m]
    r2 = (rng / px) ** 2
    for s in np.flatnonzero(kind >= 0):
        r, c = int(goal[s, 0]), int(goal[s, 1])
        kd = int(kind[s])
        disc = (rr + 0.5 - (r + 0.5 if kd != TURN else view.pos[0])) ** 2 + (
            cc + 0.5 - (c + 0.5 if kd != TURN else view.pos[1])
        ) ** 2 <= r2
        dr, dc = view.pos[0] - (r + 0.5), (c + 0.5) - view.pos[1]
        bearing = math.atan2(dr, dc) - view.heading
        bearing = (bearing + math.pi) % (2 * math.pi) - math.pi
        turn = kd == TURN
        path = 0.0 if turn else float(plan.dist[r, c]) * px
        heur = 0.0 if turn else float(plan.cost[r, c] if kd == FRONTIER else plan.dist[r, c]) * px
        out[s, kd] = 1.0
        out[s, 3] = {1: 1.0, 2: 0.5}.get(int(tier[r, c]), 0.0) if kd == FRONTIER else 0.0
        out[s, 4], out[s, 5] = math.tanh(path / span), math.tanh(heur / span)
        out[s, 6] = 1.0 if turn else bearing / math.pi
        out[s, 7], out[s, 8] = (0.0, 0.0) if turn else (dc * px / span, dr * px / span)
        out[s, 9] = int(np.count_nonzero(view.dark & disc)) / max(int(np.count_nonzero(disc)), 1)
        out[s, 10] = math.tanh(float(mem.best_tube[r, c]))
        out[s, 11] = min(float(clearance[r, c]) / rng, 1.0)
        out[s, 12] = math.tanh(float(size[s]) / m)
        out[s, 13] = float(s) / max(n - 1, 1)
        out[s, 14] = float(keep[s])
    return np.clip(out, -1.0, 1.0)


__all__ = [
    "Candidates",
    "FEATURES",
    "N_FEATURES",
    "candidates",
    "clusters",
    "tiers",
]
