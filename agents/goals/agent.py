"""``GoalAgent``: a goal-level chooser as a policy of the low-level env (SB3's ``predict``, step by step).

The goal-selection env (:class:`~.env.GoalSelectionEnv`) runs a whole macro step inside one ``step``;
evaluation, ``digslam demo / evaluate / record`` and the benchmarks drive the *low-level*
``digslam/DigCoverage*`` env one action at a time. :class:`GoalAgent` is the same machinery turned inside out:
at each low-level step, when no macro step is running, it builds the candidates and the goal observation from
the low-level observation (:func:`.env.decide`), asks the chooser for a candidate and starts the macro step
(:func:`.env.start_goal`); then it returns the driver's action (:func:`.env.drive`). A macro step ends on the
env's events (``"reached"``, ``"interrupted"``, ``"gave_up"``, ``"unreachable"``, ``"turned"``,
``"frontier"``; :func:`.env.ends` with its :data:`~.env.MAX_EMPTY` rule) or after ``step_cap`` low-level
steps; the episode's end is the caller's (a new episode starts on ``episode_start`` or when the observation's
elapsed share is 0, as for the baselines, and on :meth:`GoalAgent.reset`).

The chooser is any object with ``predict(goal_obs, action_masks=mask)`` (sb3-contrib's ``MaskablePPO``: the
mask is ``goal_obs["mask"].astype(bool)``) or ``predict(goal_obs)`` (:class:`~.policy.FirstCandidatePolicy`)
returning a candidate index, or a tuple whose first item is one (SB3's ``(action, state)``).

**Fidelity.** ``GoalAgent`` with :class:`~.policy.FirstCandidatePolicy` takes the same low-level actions as
:class:`~digslam.agents.baselines.FrontierAgent` and as the goal env driven by that policy (identical
certified-coverage curves, checked by ``tests/agents/goals/test_agent.py``).

Like the baselines it has ``reset`` and no ``policy`` attribute, so ``run_episode`` resets it before every
episode; a VecEnv batch is handled per index (one macro-step state per environment of the batch).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from digslam.agents.baselines.policy import Memory
from digslam.agents.common.policy import PolicyPredictor, reset_policy
from digslam.agents.goals.candidates import Candidates
from digslam.agents.goals.driver import KINDS, GoalDriver, driver_for
from digslam.agents.goals.env import GoalSelectionEnv, decide, drive, ends, goal_space, start_goal
from digslam.agents.goals.extra import n_extra
from digslam.envs.observation import N_STATE, State
from digslam.envs.stack import find_wrapper, observer_of

_GOAL_PARAMS = inspect.signature(GoalSelectionEnv.__init__).parameters
#: The keywords of :class:`~.env.GoalSelectionEnv` that are its own (the rest go to the base env), with their
#: defaults; a goal model's sidecar may hold them among its ``env_kwargs``.
GOAL_KWARGS: dict[str, Any] = {k: p.default for k, p in _GOAL_PARAMS.items()
                               if p.kind is p.KEYWORD_ONLY and k != "render_mode"}  # fmt: skip
#: Of :data:`GOAL_KWARGS`, those that shape the rewards or build the base env only (no part of how the agent
#: acts): :meth:`GoalAgent.from_env` accepts and ignores them.
REWARD_KWARGS = ("base_id", "step_cost", "target_bonus", "reward_scale")


def split_goal_kwargs(kwargs: Mapping[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """``(goal, base)``: the keywords of :data:`GOAL_KWARGS` and the others (the base env's)."""
    goal = {k: v for k, v in kwargs.items() if k in GOAL_KWARGS}
    return goal, {k: v for k, v in kwargs.items() if k not in GOAL_KWARGS}


def base_env_kwargs(kwargs: Mapping[str, Any]) -> dict[str, Any]:
    """The low-level env's keywords of a goal env's ``kwargs``: the base keywords, with the ``horizon`` that
    the goal env gives its base env (``max_steps`` unless given), so that the elapsed share in ``"state"``
    reads as it did in training."""
    goal, base = split_goal_kwargs(kwargs)
    return {"horizon": goal.get("max_steps", GOAL_KWARGS["max_steps"]), **base}


@dataclass
class MacroState:
    """One environment's state of a :class:`GoalAgent`.

    Attributes:
        mem: The driver's memory of the episode.
        t: Low-level steps taken in the episode.
        running: Whether a macro step is running.
        steps: Low-level steps of the running (or last) macro step.
        empty: Macro steps in a row that took no low-level step.
        decisions: Decisions made in the episode.
        kind, goal: The candidate chosen last (``"frontier"``, ``"closure"`` or ``"turn"``; its pixel).
        event: What ended the last macro step (``"cap"`` at ``step_cap``; None while the first runs).
        candidates: The candidates of the last decision.
    """

    mem: Memory
    t: int = 0
    running: bool = False
    steps: int = 0
    empty: int = 0
    decisions: int = 0
    kind: str | None = None
    goal: tuple[int, int] | None = None
    event: str | None = None
    candidates: Candidates | None = None


class GoalAgent:
    """A goal-level ``chooser`` driving the low-level env through :class:`~.driver.GoalDriver` (module
    docstring). Use :meth:`from_env` to size the driver from the env.

    Args:
        chooser: Picks a candidate from a goal observation (module docstring).
        driver: The goal driver (:func:`~.driver.driver_for`).
        n_candidates: Candidate slots (the chooser's action count).
        step_cap: Longest macro step (low-level steps).
        max_steps: Low-level steps of an episode, which scales the ``elapsed`` global feature (the goal env's
            base env has ``horizon = max_steps``).
        include_map: Add the low-level ``"map"`` to the goal observation (a chooser trained with it).
        candidate_features: Entry point of the extra candidate features the chooser was trained with
            (:mod:`.extra`); None: none.
        deterministic: Passed to the chooser when the caller passes none.
        action_space, observation_space: The low-level env's (for symmetry with SB3).
    """

    def __init__(
        self,
        chooser: PolicyPredictor,
        driver: GoalDriver,
        *,
        n_candidates: int = 16,
        step_cap: int = 100,
        max_steps: int = 3000,
        include_map: bool = False,
        candidate_features: str | None = None,
        deterministic: bool = True,
        action_space: spaces.Space | None = None,
        observation_space: spaces.Space | None = None,
    ) -> None:
        if not callable(getattr(chooser, "predict", None)):
            raise ValueError(f"chooser: expected an object with predict(goal_obs), got {type(chooser)}")
        if not isinstance(driver, GoalDriver):
            raise ValueError(f"driver: expected a GoalDriver, got {type(driver).__name__}")
        for name, v, lo in (("n_candidates", n_candidates, 2), ("step_cap", step_cap, 1),
                            ("max_steps", max_steps, 1)):  # fmt: skip
            if not (isinstance(v, int) and not isinstance(v, bool) and v >= lo):
                raise ValueError(f"{name}: must be an integer >= {lo}, got {v!r}")
        self.chooser, self.driver = chooser, driver
        self.n, self.step_cap, self.max_steps = n_candidates, step_cap, max_steps
        self.include_map, self.deterministic = bool(include_map), bool(deterministic)
        self.candidate_features = candidate_features
        self._n_more = n_extra(candidate_features)
        self.action_space, self.observation_space = action_space, observation_space
        params = _params(chooser.predict)
        self._masks = "action_masks" in params or "**" in params
        self._det = "deterministic" in params or "**" in params
        self.choices: dict[str, int] = {}  # over every episode since construction (:meth:`choice_stats`)
        self.reset()

    @classmethod
    def from_env(cls, env: gym.Env, chooser: PolicyPredictor, **kw: Any) -> GoalAgent:
        """A :class:`GoalAgent` whose driver is sized from the low-level ``env`` as
        :func:`~digslam.agents.baselines.registry.make_baseline` sizes the frontier agent.

        ``kw``: the goal env's keywords (:data:`GOAL_KWARGS`): ``n_candidates``, ``step_cap``,
        ``max_steps`` (default: the env's ``horizon``, else 3000), ``replan_every``, ``include_map``,
        ``candidate_features``, ``driver_kwargs``; those of :data:`REWARD_KWARGS` are ignored; and
        ``deterministic``.

        Raises:
            ValueError: an unknown keyword, or ``env`` is a goal-selection env (give its base env).
        """
        if find_wrapper(env, GoalSelectionEnv) is not None:
            raise ValueError("env: give the low-level DigCoverage env the agent acts in, not the goal env")
        unknown = sorted(set(kw) - set(GOAL_KWARGS) - {"deterministic"})
        if unknown:
            raise ValueError(f"GoalAgent.from_env: unknown keyword argument(s) {unknown}; known: "
                             f"{sorted({*GOAL_KWARGS, 'deterministic'})}")  # fmt: skip
        g = {**GOAL_KWARGS, "max_steps": _horizon(env) or GOAL_KWARGS["max_steps"], **kw}
        driver = driver_for(env, replan_every=g["replan_every"], **dict(g["driver_kwargs"] or {}))
        return cls(chooser, driver, n_candidates=g["n_candidates"], step_cap=g["step_cap"],
                   max_steps=g["max_steps"], include_map=g["include_map"],
                   candidate_features=g["candidate_features"], deterministic=kw.get("deterministic", True),
                   action_space=env.action_space, observation_space=env.observation_space)  # fmt: skip

    @property
    def goal_observation_space(self) -> spaces.Dict:
        """The chooser's observation space (the goal env's), given the low-level observation space."""
        low = self.observation_space
        map_space = low["map"] if self.include_map and isinstance(low, spaces.Dict) else None
        if self.include_map and map_space is None:
            raise ValueError("goal_observation_space: include_map needs the low-level observation_space")
        return goal_space(self.n, map_space, self._n_more)

    def reset(self) -> None:
        """Forget every environment's episode (and reset the chooser, if it has per-episode state)."""
        self._state: dict[int, MacroState] = {}
        reset_policy(self.chooser)

    def state(self, i: int = 0) -> MacroState | None:
        """Environment ``i``'s :class:`MacroState` (None before its first step)."""
        return self._state.get(i)

    def predict(
        self,
        observation: dict[str, np.ndarray],
        state: tuple[np.ndarray, ...] | None = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool | None = None,
    ) -> tuple[np.ndarray, None]:
        """The low-level action for one observation ``{"map": (C, m, m), "state": (N_STATE,)}`` (a ``(2,)``
        float32 array), or for a VecEnv batch of them (``(n, 2)``, one macro-step state per index)."""
        if not isinstance(observation, dict) or "map" not in observation or "state" not in observation:
            raise ValueError("observation: expected a dict with 'map' and 'state' (the low-level env's)")
        maps, states = np.asarray(observation["map"]), np.asarray(observation["state"])
        single = states.ndim == 1
        if single:
            maps, states = maps[None], states[None]
        if maps.ndim != 4 or states.ndim != 2 or states.shape[-1] < N_STATE or len(maps) != len(states):
            raise ValueError(f"observation: bad shapes map {maps.shape}, state {states.shape}")
        starts = np.zeros(len(states), bool) if episode_start is None else np.asarray(episode_start, bool)
        starts = starts.reshape(-1)
        if starts.size == 1:
            starts = np.repeat(starts, len(states))
        if starts.size != len(states):
            raise ValueError(f"episode_start: expected {len(states)} flags, got {starts.size}")
        det = self.deterministic if deterministic is None else bool(deterministic)
        out = np.zeros((len(states), 2), np.float32)
        for i in range(len(states)):
            obs = {"map": maps[i], "state": states[i]}
            s = self._state.get(i)
            m = maps.shape[-1]
            if s is None or s.mem.m != m or bool(starts[i]) or states[i, State.ELAPSED] <= 0:
                s = self._state[i] = MacroState(self.driver.begin(m))
            out[i] = self._step(s, obs, det)
        return (out[0] if single else out), None

    # --- pieces --------------------------------------------------------------------------------------------
    def _step(self, s: MacroState, obs: dict[str, np.ndarray], det: bool) -> np.ndarray:
        """One low-level step of ``GoalSelectionEnv.step``'s loop (decisions on ``obs`` first, if due)."""
        while True:
            if not s.running:
                s.candidates, goal_obs = decide(self.driver, obs, s.mem, self.n, s.t, self.max_steps,
                                                self.include_map, self.candidate_features)  # fmt: skip
                a = self._choose(goal_obs, s.candidates, det)
                kind, s.goal = start_goal(self.driver, s.mem, s.candidates, a)
                s.kind, s.running, s.steps, s.decisions = KINDS[kind], True, 0, s.decisions + 1
            low, ev = drive(self.driver, obs, s.mem)
            if ev is not None and ends(ev, s.steps, s.empty):
                self._end(s, ev)
                continue  # the next decision, on the same observation
            s.mem.t += 1
            s.t, s.steps = s.t + 1, s.steps + 1
            if s.steps >= self.step_cap:
                self._end(s, "cap")
            return low

    @staticmethod
    def _end(s: MacroState, event: str) -> None:
        s.empty = s.empty + 1 if s.steps == 0 else 0
        s.mem.extra["ended"] = s.event = event
        s.running = False

    def _choose(self, goal_obs: dict[str, np.ndarray], c: Candidates, det: bool) -> int:
        kw: dict[str, Any] = {}
        if self._masks:
            kw["action_masks"] = goal_obs["mask"].astype(bool)
        if self._det:
            kw["deterministic"] = det
        out = self.chooser.predict(goal_obs, **kw)
        a = np.asarray(out[0] if isinstance(out, tuple) else out)
        whole = np.issubdtype(a.dtype, np.integer) or (
            np.issubdtype(a.dtype, np.floating) and a.size == 1 and float(a.reshape(-1)[0]).is_integer()
        )
        if a.size != 1 or not whole:
            raise ValueError(f"chooser: expected one integer candidate index, got {out!r}")
        i = int(a.reshape(-1)[0])
        if not 0 <= i < self.n or not c.mask[i]:
            valid = np.flatnonzero(c.mask).tolist()
            raise ValueError(f"chooser: candidate {i} is out of range or masked out (valid: {valid})")
        for key in ("decisions", KINDS[int(c.kind[i])]) + (("not_first",) if i else ()):
            self.choices[key] = self.choices.get(key, 0) + 1
        return i

    def choice_stats(self) -> dict[str, float]:
        """Over every decision since construction (episodes included; :meth:`reset` keeps them): the count
        of decisions, the share that differ from the frontier agent's pick (``not_first``: not candidate
        0), and the share of each kind chosen (``frontier``, ``closure``: back to close a loop, ``turn``)."""
        n = self.choices.get("decisions", 0)
        out: dict[str, float] = {"decisions": float(n)}
        for key in ("not_first", *KINDS):
            out[key] = self.choices.get(key, 0) / n if n else 0.0
        return out


def _params(fn: Callable[..., object]) -> set[str]:
    """Names of ``fn``'s parameters (``"**"`` when it takes any keyword)."""
    try:
        ps = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return set()
    return {"**" if p.kind is p.VAR_KEYWORD else p.name for p in ps}


def _horizon(env: gym.Env) -> int | None:
    """The ``horizon`` of a (wrapped) certified-coverage env's observer, which normalises the elapsed share
    of its ``"state"``; None if there is none."""
    try:
        horizon = observer_of(env).obs_config.horizon
    except ValueError:  # no GuaranteedObserver layer
        return None
    return horizon if isinstance(horizon, int) else None


__all__ = [
    "GOAL_KWARGS",
    "GoalAgent",
    "MacroState",
    "REWARD_KWARGS",
    "base_env_kwargs",
    "split_goal_kwargs",
]
