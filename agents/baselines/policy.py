"""Base of the heuristic baselines: observation parsing, per-environment memory, SB3's ``predict``.

Every agent reads only the observation (no privileged ``info``): the ``"map"`` (clear / penumbra / dark /
pose-box channels over the world frame, row 0 = largest ``y``) and the ``"state"`` (normalised pose box,
``cos``/``sin`` of the mid heading, ``tanh`` of the tube width, ...), whose layout is the schema of
:mod:`digslam.envs.observation` (:class:`~digslam.envs.observation.Channel`,
:class:`~digslam.envs.observation.State`). :func:`parse` reads one observation into a :class:`View`;
:meth:`BaselinePolicy.predict` takes one observation or a VecEnv batch and keeps one :class:`Memory` per
environment index (renewed on ``episode_start`` or when the elapsed share is 0, i.e. right after ``reset``).

>>> state = np.zeros(N_STATE, np.float32); state[[State.COS, State.CONSISTENT]] = 1.0  # centre, heading +x
>>> img = np.zeros((4, 36, 36), np.uint8); img[Channel.CLEAR] = 255
>>> v = parse(img, state)
>>> v.pos.tolist(), v.heading, bool(v.clear.all()), v.tube
([18.0, 18.0], 0.0, True, 0.0)
>>> agent = RandomAgent(spaces.Box(-1, 1, (2,)), seed=0)
>>> agent.predict({"map": img[None].repeat(3, 0), "state": state[None].repeat(3, 0)})[0].shape
(3, 2)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from gymnasium import spaces

from digslam.agents.baselines import planning as pl
from digslam.agents.baselines import policy_jit as pj
from digslam.envs.observation import N_STATE, Channel, State

_KNOWN_KW = {"span", "max_speed", "max_yaw_rate", "dt", "sensor_range"}


@dataclass
class View:
    """One observation in planning terms: masks, the robot's fractional pixel, heading and tube width."""

    clear: np.ndarray
    penumbra: np.ndarray
    dark: np.ndarray
    pos: np.ndarray  # (row, col), fractional pixels
    heading: float
    tube: float  # m
    consistent: bool
    image: np.ndarray | None = None  # the observation's uint8 map itself (what a map predictor reads)

    @property
    def cell(self) -> tuple[int, int]:
        m = self.clear.shape[0]
        return int(min(max(float(self.pos[0]), 0.0), m - 1)), int(min(max(float(self.pos[1]), 0.0), m - 1))


def parse(obs_map: np.ndarray, state: np.ndarray) -> View:
    """:class:`View` of one (unbatched) observation."""
    img = np.asarray(obs_map) > 127
    m = img.shape[-1]
    s = np.asarray(state, dtype=np.float64)
    ux, uy = 0.5 * (s[State.X_LO] + s[State.X_HI]), 0.5 * (s[State.Y_LO] + s[State.Y_HI])
    pos = np.array([(1.0 - uy) * 0.5 * m, (ux + 1.0) * 0.5 * m])
    tube = math.atanh(min(max(float(s[State.TUBE]), 0.0), 1.0 - 1e-7))
    heading = math.atan2(s[State.SIN], s[State.COS])
    return View(img[Channel.CLEAR], img[Channel.PENUMBRA], img[Channel.DARK], pos, heading, tube,
                bool(s[State.CONSISTENT] > 0.5), np.asarray(obs_map))  # fmt: skip


@dataclass
class Memory:
    """Per-environment state of a navigating agent."""

    m: int
    visited: np.ndarray = field(init=False)
    best_tube: np.ndarray = field(init=False)  # smallest tube width (m) the robot had near each pixel
    goal: tuple[int, int] | None = None
    waypoint: np.ndarray | None = None
    moving: bool = False
    age: int = 0  # steps since the waypoint was chosen
    goal_steps: int = 0  # steps spent on the current goal
    goal_budget: int = 0
    t: int = 0
    extra: dict[str, Any] = field(default_factory=dict)
    blocked: np.ndarray = field(init=False)  # pixels where the robot drove and did not move (never planned)
    drives: list[tuple[np.ndarray, float]] = field(default_factory=list)  # (position, speed) of recent drives
    backing: int = 0  # steps of reversing left after a stall
    last_v: float = 0.0  # normalised speed of the last action while driving (0 when turning)

    def __post_init__(self) -> None:
        self.visited = np.zeros((self.m, self.m), dtype=bool)
        self.best_tube = np.full((self.m, self.m), np.inf)
        self.blocked = np.zeros((self.m, self.m), dtype=bool)


class BaselinePolicy:
    """Base of the heuristic agents: SB3-compatible :meth:`predict` over single or batched observations.

    Args:
        action_space: The env's ``Box(-1, 1, (2,))`` action space.
        observation_space: The env's observation space (unused; for symmetry with SB3).
        seed: Seed of the agent's random generator.
        span: Side of the grid frame (m) that the map and the normalised pose box cover.
        max_speed, max_yaw_rate, dt: Speed (m/s) and yaw rate (rad/s) of a full-scale action; step (s).
        sensor_range: Longest sensor range (m).
    """

    def __init__(self, action_space: spaces.Space, observation_space: spaces.Space | None = None,
                 seed: int | None = None, **kw: Any) -> None:  # fmt: skip
        unknown = sorted(set(kw) - _KNOWN_KW)
        if unknown:
            raise ValueError(f"{type(self).__name__}: unknown keyword argument(s) {unknown}; known: "
                             f"{sorted(_KNOWN_KW)}")  # fmt: skip
        shape = getattr(action_space, "shape", None)
        if shape != (2,):
            raise ValueError(f"action_space: expected a Box of shape (2,), got {action_space!r}")
        self.action_space, self.observation_space = action_space, observation_space
        self.seed = seed
        self.span = float(kw.get("span", 20.0))
        self.max_speed = float(kw.get("max_speed", 1.0))
        self.max_yaw_rate = float(kw.get("max_yaw_rate", 1.0))
        self.dt = float(kw.get("dt", 0.1))
        self.sensor_range = float(kw.get("sensor_range", 5.0))
        for name in ("span", "max_speed", "max_yaw_rate", "dt", "sensor_range"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name}: must be finite and > 0, got {v!r}")
        self.reset()

    def reset(self) -> None:
        """Forget every environment's memory and reseed."""
        self.rng = np.random.default_rng(self.seed)
        self._mem: dict[int, Memory] = {}

    def predict(
        self,
        observation: dict[str, np.ndarray],
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, None]:
        """Actions for one observation ``{"map": (C, m, m), "state": (N_STATE,)}`` or a batch of them."""
        if not isinstance(observation, dict) or "map" not in observation or "state" not in observation:
            raise ValueError("observation: expected a dict with 'map' and 'state'")
        maps, states = np.asarray(observation["map"]), np.asarray(observation["state"])
        single = states.ndim == 1
        if single:
            maps, states = maps[None], states[None]
        if maps.ndim != 4 or states.shape[-1] < N_STATE or len(maps) != len(states):
            raise ValueError(f"observation: bad shapes map {maps.shape}, state {states.shape}")
        starts = np.zeros(len(states), bool) if episode_start is None else np.asarray(episode_start, bool)
        out = np.zeros((len(states), 2), dtype=np.float32)
        for i in range(len(states)):  # one planner call per environment of the batch
            view = parse(maps[i], states[i])
            mem = self._mem.get(i)
            fresh = bool(starts.reshape(-1)[i]) or states[i, State.ELAPSED] <= 0
            if mem is None or mem.m != view.clear.shape[0] or fresh:
                mem = self._mem[i] = Memory(view.clear.shape[0])
            out[i] = np.minimum(np.maximum(self._act(view, mem), -1.0), 1.0) if view.consistent else 0.0
            mem.t += 1
        return (out[0] if single else out), None

    def memory(self, i: int = 0) -> Memory | None:
        """Environment ``i``'s :class:`Memory` (None before its first step)."""
        return self._mem.get(i)

    def _act(self, view: View, mem: Memory) -> np.ndarray:
        raise NotImplementedError

    # --- helpers for the navigating agents ---------------------------------------------------------------
    @property
    def _turn(self) -> float:
        return self.max_yaw_rate * self.dt

    def px(self, m: int) -> float:
        """Pixel side (m) of an ``m x m`` map."""
        return self.span / m

    def _disk(self, m: int, centre: np.ndarray, radius_px: float) -> np.ndarray:
        """``(m, m)`` bool: the pixels whose centre lies within ``radius_px`` of ``centre`` (row, column),
        computed on the disc's bounding window only (the compiled :func:`.policy_jit.disk`)."""
        radius_px = float(radius_px)
        return pj.disk(int(m), float(centre[0]), float(centre[1]), radius_px, radius_px**2)

    def _drive(self, view: View, mem: Memory) -> np.ndarray:
        """Turn-then-go towards ``mem.waypoint``; clears it when reached."""
        if mem.waypoint is None:
            mem.moving = False
            return np.array([0.0, 1.0], dtype=np.float32)  # look around
        d = mem.waypoint - view.pos
        dist = float(np.hypot(*d)) * self.px(view.clear.shape[0])
        if dist < 0.6 * self.px(view.clear.shape[0]):
            mem.waypoint, mem.moving = None, False
            return np.zeros(2, dtype=np.float32)
        err = pl.wrap(math.atan2(-d[0], d[1]) - view.heading)
        a, mem.moving = pl.turn_then_go(err, dist, mem.moving, turn_per_step=self._turn,
                                        step_length=self.max_speed * self.dt)  # fmt: skip
        return a


class RandomAgent(BaselinePolicy):
    """Uniform random actions in ``[-1, 1]²`` (seeded)."""

    def _act(self, view: View, mem: Memory) -> np.ndarray:
        return self.rng.uniform(-1.0, 1.0, 2).astype(np.float32)


__all__ = [
    "BaselinePolicy",
    "Memory",
    "RandomAgent",
    "View",
    "parse",
]
