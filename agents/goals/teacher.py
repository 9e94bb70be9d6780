"""Teachers for a behaviour-cloning warm start of a goal-level learner: who picks, and the decisions recorded.

* ``"frontier"``: candidate 0 at every decision, the frontier agent's own pick
  (:class:`~.policy.FirstCandidatePolicy`);
* ``"rollout"``: :class:`RolloutTeacher`, a one-step look-ahead. At a decision it tries each of the first
  ``k`` valid candidates on a copy of the goal env, follows each with candidate 0 until ``horizon``
  low-level steps have passed, and picks the one whose copy ends with the most certified coverage (one
  point more, and more the sooner, for a copy that reached the env's target); a candidate must beat
  candidate 0 by ``margin`` to be picked. This is policy improvement by rollouts of the frontier agent.
* ``"rollout_fresh_noise"``: the same, but each copy draws its own measurement and odometry noise (a fresh
  random stream, ``fresh_noise=True``) instead of the noise the episode will draw: its picks cannot ride
  on a lucky draw to come, only on the world's layout (``benchmarks/bench_teacher.py`` compares both
  teachers with the frontier agent).

**Ground truth.** The rollout teacher steps *copies of the simulator*: it sees the world and the noise to
come, which no agent may. It exists only to label training decisions; the labels are candidate indices of
observations that come from the observer alone, so the learner that imitates it acts on the observation
and nothing else. Never use it as an agent.

:func:`demonstrations` plays a teacher on levels of a goal env and returns the observations, masks and
picks as arrays (``obs_<key>``, ``mask``, ``action``; ``.npz``-ready).
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterable
from typing import Any

import gymnasium as gym
import numpy as np

from digslam.agents.goals.env import GoalSelectionEnv
from digslam.envs.stack import find_wrapper

#: The teachers :func:`demonstrations` knows.
TEACHERS = ("frontier", "rollout", "rollout_fresh_noise")


class RolloutTeacher:
    """One-step look-ahead over copies of the goal env (module docstring).

    Args:
        k: Valid candidates tried (the first ``k`` in the env's order; candidate 0 always among them).
        horizon: Low-level steps each copy runs from the decision.
        margin: Certified coverage by which a candidate must beat candidate 0 to be picked.
        fresh_noise: Each copy draws its noise from a stream of its own (seeded by ``seed`` and a count of
            the copies made), not the episode's.
        seed: Seed of those streams.
    """

    def __init__(self, k: int = 4, horizon: int = 150, margin: float = 1e-3, fresh_noise: bool = False,
                 seed: int = 0) -> None:  # fmt: skip
        if not (isinstance(k, int) and k >= 1 and isinstance(horizon, int) and horizon >= 1):
            raise ValueError(f"k, horizon: must be integers >= 1, got {k!r}, {horizon!r}")
        if not (np.isfinite(margin) and margin >= 0):
            raise ValueError(f"margin: must be finite and >= 0, got {margin!r}")
        if not (isinstance(seed, int) and seed >= 0):
            raise ValueError(f"seed: must be an integer >= 0, got {seed!r}")
        self.k, self.horizon, self.margin = k, horizon, float(margin)
        self.fresh_noise, self.seed, self._copies = bool(fresh_noise), seed, 0

    def score(self, env: gym.Env, action: int) -> float:
        """Certified coverage of a copy of ``env`` after ``action`` then candidate 0 for :attr:`horizon`
        low-level steps (plus ``1 + unused share`` when the copy reached the target)."""
        sim = copy.deepcopy(env)
        goal = find_wrapper(sim, GoalSelectionEnv)
        if goal is None:
            raise ValueError(f"env: a goal-selection env (GoalSelectionEnv inside), got {type(env).__name__}")
        if self.fresh_noise:
            self._copies += 1
            sim.unwrapped.np_random = np.random.default_rng((self.seed, self._copies))
        t0 = goal.elapsed
        _, _, done, cut, info = sim.step(action)
        while not (done or cut) and goal.elapsed - t0 < self.horizon:
            _, _, done, cut, info = sim.step(0)
        bonus = 1.0 + (self.horizon - (goal.elapsed - t0)) / self.horizon if done else 0.0
        return float(info["certified_coverage"]) + bonus

    def choose(self, env: gym.Env, obs: dict[str, np.ndarray]) -> int:
        """The pick at ``env``'s current decision (``obs`` its observation)."""
        valid = np.flatnonzero(np.asarray(obs["mask"]) > 0)[: self.k]
        if len(valid) < 2:
            return int(valid[0]) if len(valid) else 0
        scores = np.array([self.score(env, int(a)) for a in valid])
        best = int(np.argmax(scores))
        return int(valid[best]) if scores[best] > scores[0] + self.margin else int(valid[0])


def teacher(name: str, **kwargs: Any) -> Callable[[Any, dict[str, np.ndarray]], int]:
    """``choose(env, obs) -> action`` of the teacher ``name`` (:data:`TEACHERS`); ``kwargs`` go to
    :class:`RolloutTeacher` (the frontier teacher takes none and ignores them)."""
    if name == "frontier":
        return lambda env, obs: 0
    if name == "rollout":
        return RolloutTeacher(**kwargs).choose
    if name == "rollout_fresh_noise":
        return RolloutTeacher(**{**kwargs, "fresh_noise": True}).choose
    raise ValueError(f"teacher: must be one of {TEACHERS}, got {name!r}")


#: A teacher: the pick at the goal env's current decision, from the env and its observation.
Chooser = Callable[[gym.Env, dict[str, np.ndarray]], int]
#: A learner's pick from the observation alone.
Actor = Callable[[dict[str, np.ndarray]], int]


def demonstrations(env: gym.Env, choose: Chooser, seeds: Iterable[int],
                   log: Callable[[str], None] | None = None,
                   act: Actor | None = None) -> dict[str, np.ndarray]:  # fmt: skip
    """Every decision of ``choose`` on the goal env ``env`` over the levels ``seeds``: ``obs_<key>`` for
    each observation key, ``mask`` (bool) and ``action`` (int64, ``choose``'s pick), one row a decision.
    With ``act`` (a learner's pick from the observation) the episode follows ``act``'s picks while
    ``choose`` only labels them (DAgger: the teacher's labels on the learner's own states). ``log`` gets a
    line per level."""
    rows: dict[str, list[np.ndarray]] = {}
    for seed in seeds:
        obs, _ = env.reset(seed=int(seed))
        done = cut = False
        n = picks = 0
        info: dict[str, Any] = {}
        while not (done or cut):
            a = int(choose(env, obs))
            for key, v in obs.items():
                rows.setdefault(f"obs_{key}", []).append(np.array(v, copy=True))
            rows.setdefault("mask", []).append(np.asarray(obs["mask"]) > 0)
            rows.setdefault("action", []).append(np.int64(a))
            n, picks = n + 1, picks + (a != 0)
            obs, _, done, cut, info = env.step(a if act is None else int(act(obs)))
        if log is not None:
            cov = float(info.get("certified_coverage", float("nan")))
            log(f"level {seed}: {n} decisions, {picks} not candidate 0, certified {cov:.3f} "
                f"at step {info.get('elapsed')}")  # fmt: skip
    if not rows:
        raise ValueError("seeds: no level given")
    return {k: np.stack(v) for k, v in rows.items()}


__all__ = [
    "RolloutTeacher",
    "TEACHERS",
    "demonstrations",
    "teacher",
]
