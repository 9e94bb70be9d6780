"""``GoalSelectionEnv``: certified coverage as a choice among candidate goals (a semi-MDP over DigCoverage).

Each decision picks one of ``n_candidates`` goals (:mod:`.candidates`: frontier clusters, an in-place turn,
loop-closure clusters); :class:`~.driver.GoalDriver` then drives the base env towards it with the frontier
agent's loop (turn in place, drive straight, re-plan every ``replan_every`` steps towards the *fixed* goal)
until an event ends the macro step: the goal reached, the goal gone stale or overtaken by a cheaper frontier
(the frontier agent's hysteresis, see :mod:`.driver`), given up, unreachable, the turn done, the episode
over, or ``step_cap`` low-level steps.

* action: ``Discrete(n_candidates)``; :meth:`GoalSelectionEnv.action_masks` gives the valid ones
  (sb3-contrib's ``MaskablePPO`` / ``ActionMasker``); a masked action raises ``ValueError``. A random
  valid action: ``env.action_space.sample(mask=env.action_masks().astype(np.int8))``;
* observation: ``{"candidates": Box(-1, 1, (n, F)), "mask": MultiBinary(n), "global": Box(-1, 1, (G,))}``
  (+ ``"map"``, the base map, with ``include_map``): the features of :data:`.candidates.FEATURES` (then
  those of the ``candidate_features`` entry point, :mod:`.extra`) and
  :data:`GLOBALS` (the base ``"state"``, the observer's own certified share ``State.CERTIFIED`` among them,
  never ``info["certified_coverage"]`` or ``info["true_coverage"]``). A function of the base observations
  only;
* reward: ``reward_scale`` x the base rewards summed over the macro step (certified area gained, m², minus
  the base env's bump penalty) ``- step_cost`` per low-level step ``+ target_bonus`` when a frontier or
  closure goal is reached;
* episode: the base env's termination (certified coverage at its ``target``), truncation when the low-level
  steps reach ``max_steps`` (also the base env's ``TimeLimit`` and ``horizon`` when built here);
* ``info``: the base env's last info plus ``steps`` (low-level steps of the macro step), ``elapsed``,
  ``event``, ``kind``, ``goal`` and ``base_reward``.

**Fidelity.** Candidate 0 is the frontier agent's own pick and the driver is its loop, so always taking
candidate 0 (:class:`~.policy.FirstCandidatePolicy`) makes the same low-level actions as
:class:`~digslam.agents.baselines.FrontierAgent` on the base env (identical actions and certified-coverage
curves, checked by ``tests/agents/goals/test_fidelity.py``). A macro step
may end before any low-level step (a goal given up at once, a closure target reached at once): the next
decision is then made on the same observation; after ``MAX_EMPTY`` of those in a row the next one takes its
first step whatever happens.

**Semi-MDP.** SB3 discounts per decision: ``gamma`` applies once per macro step, whatever its length. No
discount inside a macro step is applied here; time is charged by ``step_cost`` instead (with
``gamma`` near 1 the return is about the coverage gained minus ``step_cost`` times the steps taken; the
default, 0.02 m² per step, is about a tenth of the area the frontier agent certifies per step early in an
episode). ``info["steps"]`` gives the durations for a duration-aware discount (``gamma ** steps``).

**A wrapper.** ``GoalSelectionEnv`` is a ``gymnasium.Wrapper`` with spaces of its own: ``env.unwrapped`` is
the raw env at the bottom of the stack, onto which ``gym.make`` writes the spec of the id it made;
:func:`digslam.envs.stack.find_wrapper` finds this layer in a stack (``find_wrapper(env, GoalSelectionEnv)``).
A goal id's entry point is this class, built with ``env=None`` (it makes its base env): its ``spec`` is then
the goal id's, as ``gym.make`` wrote it onto ``env.unwrapped`` (``spec.make()`` builds the same env again);
around a given env it is Gymnasium's wrapper spec.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.envs.registration import EnvSpec

from digslam.agents.baselines.policy import Memory, parse
from digslam.agents.goals.candidates import N_FEATURES, Candidates, candidates
from digslam.agents.goals.driver import CLOSURE, FRONTIER, KINDS, TURN, GoalDriver, driver_for
from digslam.agents.goals.extra import n_extra, with_extra
from digslam.agents.goals.registry import ENTRY_POINT
from digslam.envs.observation import N_STATE

#: Global features: the base ``"state"`` (its ``N_STATE`` entries, :class:`~digslam.envs.observation.State`),
#: then these (all in ``[-1, 1]``).
GLOBALS = ("state",) * N_STATE + ("elapsed", "frontier_clusters", "closure_clusters", "dark_share",
                                  "penumbra_share")  # fmt: skip
#: Consecutive macro steps of no low-level step allowed before the next one takes its step anyway.
MAX_EMPTY = 2


class GoalSelectionEnv(gym.Wrapper):
    """Goal selection over a certified-coverage env (module docstring).

    Args:
        env: A ``digslam/DigCoverage*`` env (possibly wrapped); None: ``gym.make(base_id, **base_kwargs)``
            with ``max_episode_steps=max_steps`` and ``horizon=max_steps`` unless given.
        base_id: The base env id when ``env`` is None.
        n_candidates: Candidate slots (the action count).
        step_cap: Longest macro step (low-level steps).
        max_steps: Low-level steps per episode (truncation).
        replan_every: Steps between re-plans while driving (the frontier agent's).
        step_cost: Reward charged per low-level step (base reward units, m²).
        target_bonus: Reward when a frontier or closure goal is reached.
        reward_scale: Factor on the base rewards.
        include_map: Add the base ``"map"`` to the observation.
        candidate_features: Entry point (``"module:name"``) of more features per candidate, appended to
            :data:`.candidates.FEATURES` (:mod:`.extra`; the map predictor's gains:
            ``"digslam.agents.prediction.features:PredictedGain"``); None: none.
        driver_kwargs: More :class:`~.driver.GoalDriver` arguments (frontier agent settings).
        render_mode: Passed to the base env when built here.
        **base_kwargs: DigCoverage keywords (``world``, ``map_size``, ``target``, ...).
    """

    def __init__(
        self,
        env: gym.Env | None = None,
        *,
        base_id: str = "digslam/DigCoverage-v0",
        n_candidates: int = 16,
        step_cap: int = 100,
        max_steps: int = 3000,
        replan_every: int = 10,
        step_cost: float = 0.02,
        target_bonus: float = 0.0,
        reward_scale: float = 1.0,
        include_map: bool = False,
        candidate_features: str | None = None,
        driver_kwargs: Mapping[str, Any] | None = None,
        render_mode: str | None = None,
        **base_kwargs: Any,
    ) -> None:
        for name, v, lo in (("n_candidates", n_candidates, 2), ("step_cap", step_cap, 1),
                            ("max_steps", max_steps, 1)):  # fmt: skip
            if not (isinstance(v, int) and not isinstance(v, bool) and v >= lo):
                raise ValueError(f"{name}: must be an integer >= {lo}, got {v!r}")
        for name, x in (("step_cost", step_cost), ("target_bonus", target_bonus),
                        ("reward_scale", reward_scale)):  # fmt: skip
            if not np.isfinite(x):
                raise ValueError(f"{name}: must be finite, got {x!r}")
        built_here = env is None
        if env is None:
            kw = {"horizon": max_steps, **base_kwargs}
            if render_mode is not None:
                kw["render_mode"] = render_mode
            env = gym.make(base_id, max_episode_steps=max_steps, **kw)
        elif base_kwargs or render_mode is not None:
            raise ValueError(f"base keywords {sorted(base_kwargs)} need env=None (the env is built here)")
        super().__init__(env)
        self._built_here = built_here
        self.n, self.step_cap, self.max_steps = n_candidates, step_cap, max_steps
        self.step_cost, self.target_bonus = float(step_cost), float(target_bonus)
        self.reward_scale = float(reward_scale)
        self.include_map = bool(include_map)
        self.candidate_features = candidate_features
        n_more = n_extra(candidate_features)
        self.driver = driver_for(env, replan_every=replan_every, **dict(driver_kwargs or {}))
        self.action_space = spaces.Discrete(self.n)
        base_space = env.observation_space
        map_space = base_space["map"] if include_map and isinstance(base_space, spaces.Dict) else None
        if include_map and map_space is None:
            raise ValueError(f"include_map: the base env has no 'map' observation ({base_space})")
        self.observation_space = goal_space(self.n, map_space, n_more)
        self._base_obs: dict[str, np.ndarray] | None = None
        self._info: dict[str, Any] = {}
        self._cands: Candidates | None = None
        self._t, self._empty = 0, 0
        #: The driver's memory of the episode (visited pixels, tube widths, goal); None before ``reset``.
        self.mem: Memory | None = None

    # --- gymnasium API -------------------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[dict, dict]:
        obs, info = self.env.reset(seed=seed, options=options)
        self._t, self._empty = 0, 0
        self.mem = mem = self.driver.begin(np.asarray(obs["map"]).shape[-1])
        self._info = info
        return self._decide(obs, mem), dict(info)

    def step(self, action: Any) -> tuple[dict, float, bool, bool, dict]:
        if self._cands is None or self._base_obs is None or self.mem is None:
            raise RuntimeError("step: call reset first")
        a = self._check(action, self._cands)
        mem = self.mem
        kind, goal = start_goal(self.driver, mem, self._cands, a)
        obs, info = self._base_obs, self._info
        total, steps, event = 0.0, 0, "cap"
        terminated = truncated = False
        while True:
            low, ev = drive(self.driver, obs, mem)
            if ev is not None and ends(ev, steps, self._empty):
                event = ev
                break
            obs, r, terminated, truncated, info = self.env.step(low)
            mem.t += 1
            steps, self._t, total = steps + 1, self._t + 1, total + float(r)
            if terminated or truncated or self._t >= self.max_steps:
                truncated = bool(truncated or (self._t >= self.max_steps and not terminated))
                event = "done"
                break
            if steps >= self.step_cap:
                break
        self._empty = self._empty + 1 if steps == 0 else 0
        mem.extra["ended"] = event
        self._info = info
        reached = event == "reached" and kind in (FRONTIER, CLOSURE)
        reward = self.reward_scale * total - self.step_cost * steps + (self.target_bonus if reached else 0.0)
        info = {**info, "steps": steps, "elapsed": self._t, "event": event, "kind": KINDS[kind], "goal": goal,
                "base_reward": total}  # fmt: skip
        return self._decide(obs, mem), float(reward), bool(terminated), bool(truncated), info

    def action_masks(self) -> np.ndarray:
        """``(n_candidates,)`` bool: the valid actions of the current decision."""
        if self._cands is None:
            raise RuntimeError("action_masks: call reset first")
        return self._cands.mask.copy()

    @property
    def spec(self) -> EnvSpec | None:  # type: ignore[override]  # Env's is writable, a wrapper's read-only
        """The goal id's spec when that id made this env (this layer built its base env, and ``gym.make``
        wrote the id's spec onto ``env.unwrapped``); otherwise Gymnasium's wrapper spec."""
        raw = self.unwrapped.spec
        if self._built_here and raw is not None and raw.entry_point in (ENTRY_POINT, GoalSelectionEnv):
            return raw
        return super().spec

    # --- the decision's state ---------------------------------------------------------------------------
    @property
    def elapsed(self) -> int:
        """Low-level steps taken in the episode."""
        return self._t

    @property
    def candidates(self) -> Candidates | None:
        """The current decision's candidates (goals, kinds, features); None before ``reset``."""
        return self._cands

    @property
    def base_observation(self) -> dict[str, np.ndarray] | None:
        """The base env's observation the current decision was made on; None before ``reset``."""
        return self._base_obs

    # --- pieces --------------------------------------------------------------------------------------------
    def _check(self, action: Any, cands: Candidates) -> int:
        a = np.asarray(action)
        whole = np.issubdtype(a.dtype, np.integer) or (
            np.issubdtype(a.dtype, np.floating) and a.size == 1 and float(a.reshape(-1)[0]).is_integer()
        )
        if a.size != 1 or not whole:
            raise ValueError(f"action: expected one integer candidate index, got {action!r}")
        i = int(a.reshape(-1)[0])
        if not 0 <= i < self.n:
            raise ValueError(f"action: candidate {i} is out of range [0, {self.n})")
        mask = cands.mask
        if not mask[i]:
            raise ValueError(f"action: candidate {i} is masked out (valid: {np.flatnonzero(mask).tolist()})")
        return i

    def _decide(self, obs: dict[str, np.ndarray], mem: Memory) -> dict[str, np.ndarray]:
        """Candidates and observation of the decision on the base observation ``obs``."""
        self._base_obs = obs
        self._cands, out = decide(self.driver, obs, mem, self.n, self._t, self.max_steps,
                                  self.include_map, self.candidate_features)  # fmt: skip
        return out


# --- shared with :class:`~.agent.GoalAgent` (the same macro steps, one low-level step at a time) ---------
def goal_space(n: int, map_space: spaces.Space | None = None, n_more: int = 0) -> spaces.Dict:
    """The observation space of ``n`` candidate slots (with the base ``map_space``: ``include_map``; with
    ``n_more`` extra features per candidate: ``candidate_features``)."""
    obs: dict[str, spaces.Space] = {
        "candidates": spaces.Box(-1.0, 1.0, (n, N_FEATURES + n_more), np.float32),
        "mask": spaces.MultiBinary(n),
        "global": spaces.Box(-1.0, 1.0, (len(GLOBALS),), np.float32),
    }
    if map_space is not None:
        obs["map"] = map_space
    return spaces.Dict(obs)


def decide(driver: GoalDriver, obs: Mapping[str, np.ndarray], mem: Memory, n: int, t: int, max_steps: int,
           include_map: bool = False, candidate_features: str | None = None,
           ) -> tuple[Candidates, dict[str, np.ndarray]]:  # fmt: skip
    """The candidates and the observation of a decision on the base observation ``obs``, ``t`` low-level
    steps into an episode of ``max_steps`` (runs the driver's bookkeeping on it), with the extra features
    of the ``candidate_features`` entry point (:mod:`.extra`)."""
    view = parse(obs["map"], obs["state"])
    c = candidates(driver, view, mem, n)
    nf = float(n)
    extra = [t / max_steps, c.n_frontier / nf, c.n_closure / nf, view.dark.mean(), view.penumbra.mean()]
    glob = np.concatenate([np.asarray(obs["state"], np.float32)[:N_STATE], np.asarray(extra, np.float32)])
    out = {"candidates": with_extra(candidate_features, driver, view, c), "mask": c.mask.astype(np.int8),
           "global": np.clip(glob, -1.0, 1.0).astype(np.float32)}  # fmt: skip
    if include_map:
        out["map"] = np.array(obs["map"], copy=True)
    return c, out


def start_goal(driver: GoalDriver, mem: Memory, c: Candidates, a: int) -> tuple[int, tuple[int, int]]:
    """Start the macro step towards candidate ``a`` of ``c``; returns its kind and goal pixel."""
    kind, goal = int(c.kind[a]), (int(c.goal[a, 0]), int(c.goal[a, 1]))
    driver.start(mem, kind, goal, slack=float(c.slack[a]), keep=bool(c.keep[a]),
                 watch=kind == TURN and c.n_frontier == 0)  # fmt: skip
    return kind, goal


def drive(driver: GoalDriver, obs: Mapping[str, np.ndarray], mem: Memory) -> tuple[np.ndarray, str | None]:
    """The driver's low-level action on the base observation ``obs`` and the event that ends the macro step
    (None: go on); zero and no event when the observer found the data inconsistent."""
    view = parse(obs["map"], obs["state"])
    return driver.act(view, mem) if view.consistent else (np.zeros(2, np.float32), None)


def ends(event: str | None, steps: int, empty: int) -> bool:
    """Whether ``event`` ends a macro step that took ``steps`` low-level steps, after ``empty`` macro steps in
    a row that took none (after :data:`MAX_EMPTY` of those the next one takes its first step anyway)."""
    return event is not None and (steps > 0 or empty < MAX_EMPTY)


__all__ = [
    "GLOBALS",
    "GoalSelectionEnv",
    "MAX_EMPTY",
    "decide",
    "drive",
    "ends",
    "goal_space",
    "start_goal",
]
