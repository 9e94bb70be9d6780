"""``digslam/DigCoverage-v0``: certified coverage, rewarded only for what the guaranteed observer proves.

The raw :class:`~digslam.envs.explore.env.ExploreEnv` under a :class:`~.wrapper.GuaranteedObserver`, with

* reward: the increase over the step of the clear area (cells proved free and certainly explored, in the
  reachable free area, m²) minus ``collision_penalty`` per bump;
* termination: certified coverage (clear cells over the reachable free cells: free in the exact raster and
  8-connected to the start, computed once per world) reaches ``target``; truncation at the registered step
  limit (``TimeLimit``) or when the observer finds the data inconsistent (its claims are then withdrawn);
* ``info``: the observer's sets and both coverages, certified and ground truth (``true_coverage``);
* ``render``: the colour-blind-safe palette of the demo's pictures (Okabe and Ito: clear sky blue,
  penumbra orange, dark near black; obstacles grey) with the pose box (black) and the true robot (green).
  Proved-free space is never red (the thesis's figures use red for it, which invites the opposite reading).
  ``rgb_array`` returns the picture; ``human`` shows it in a window at each reset and step.

The stack follows Gymnasium's habits: this env is the ids' entry point and a wrapper of the raw
:class:`~digslam.envs.explore.env.ExploreEnv` it builds (``env.unwrapped``, built with
``measure_coverage=False``: the wrapper measures the ground truth on the reachable free area itself).
``gym.make`` writes the id's spec onto ``env.unwrapped``, and :attr:`DigCoverageEnv.spec` reads it there.

``digslam/DigCoverageOutliers-v0`` is this env on the rocks world with unflagged outliers, at most one per
step (``noise.max_outliers = 1``), and the observer's q-relaxed mode at ``q = 1`` (thesis §2.6.2): no false
claim from that one bad reading (see :mod:`.wrapper` for what is claimed when the data break
their bounds).

Keyword arguments are routed by :meth:`~.config.DigCoverageConfig.split`: coverage keys, observer
keys, then raw-env keys (unknown keys raise ``ValueError``).

>>> env = DigCoverageEnv(map_size=36, max_speed=0.5)
>>> obs, info = env.reset(seed=1)
>>> _, reward, terminated, truncated, info = env.step(np.array([1.0, 0.0], np.float32))
>>> reward >= 0.0, terminated, truncated, 0.0 < info["certified_coverage"] < 1.0
(True, False, False, True)
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from gymnasium.envs.registration import EnvSpec

from digslam.envs.dig_coverage.config import DigCoverageConfig
from digslam.envs.dig_coverage.wrapper import GuaranteedObserver
from digslam.envs.explore.env import ExploreEnv
from digslam.envs.sim.raster import FREE, rasterize
from digslam.envs.sim.world import World
from digslam.observer.thick.cells import CLEAR, DARK, PENUMBRA

if TYPE_CHECKING:  # pygame is imported on use only
    from digslam.envs.sim.render import Window

#: Colours of the sets as RGB (Okabe-Ito, as ``digslam.agents.evaluation.pictures.PALETTE``).
RGB = {
    int(CLEAR): (86, 180, 233),  # sky blue
    int(PENUMBRA): (230, 159, 0),  # orange
    int(DARK): (38, 38, 56),  # near black
}
OBSTACLE_RGB = (150, 150, 160)
RENDER_SIZE = 512


class DigCoverageEnv(GuaranteedObserver):
    """Certified-coverage environment (see the module docstring).

    Args:
        config: a :class:`DigCoverageConfig`, a mapping, or None.
        render_mode: ``"rgb_array"``, ``"human"`` or None.
        **kwargs: flat overrides (coverage, observer or raw-env keys).
    """

    #: What ``gym.make`` reads before building the env (an instance gets the same dict).
    metadata: dict[str, Any] = {"render_modes": ["rgb_array", "human"], "render_fps": 10}
    _clear_count: int  # the certified count at the last reward (kept by GuaranteedObserver.reset too)

    def __init__(
        self,
        config: DigCoverageConfig | Mapping[str, Any] | None = None,
        render_mode: str | None = None,
        **kwargs: Any,
    ) -> None:
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(f"render_mode: must be one of {self.metadata['render_modes']} or None, got "
                             f"{render_mode!r}")  # fmt: skip
        if isinstance(config, DigCoverageConfig):
            base: dict[str, Any] = {"target": config.target, "collision_penalty": config.collision_penalty,
                                    "observer": config.observer, "explore": config.explore}  # fmt: skip
        else:
            base = dict(config or {})
        cfg = DigCoverageConfig.split({**base, **kwargs})
        self.config = cfg
        super().__init__(ExploreEnv(cfg.explore, measure_coverage=False), config=cfg.observer)
        self.metadata = dict(type(self).metadata)
        self._render_mode = render_mode
        self._window: Window | None = None  # the ``human`` mode's window, opened on first use
        self._bg: np.ndarray | None = None
        self._bg_world: World | None = None
        self._extra_info = {"target": cfg.target}  # info["target"], added by the wrapper's info

    @property
    def render_mode(self) -> str | None:  # type: ignore[override]  # gymnasium's Wrapper reads the env's
        """This env's render mode (its own: the raw env below renders nothing)."""
        return self._render_mode

    @property
    def spec(self) -> EnvSpec | None:  # type: ignore[override]  # gymnasium's Env declares a writeable field
        """The spec of the id that made this env: ``gym.make`` writes it onto ``env.unwrapped``, and it is
        read there unchanged (this env is the id's entry point, not an additional wrapper); None when built
        directly."""
        return self.env.spec

    def reset(self, **kwargs: Any) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        out = super().reset(**kwargs)
        if self._render_mode == "human":
            self.render()
        return out

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        obs, _, _, truncated, info = super().step(action)
        out = obs, self._reward(info), self._terminated(info), truncated, info
        if self._render_mode == "human":
            self.render()
        return out

    def close(self) -> None:
        if self._window is not None:
            self._window.close()
            self._window = None
        super().close()

    # --- pieces of step ------------------------------------------------------------------------------------
    def _reward(self, info: dict[str, Any]) -> float:
        n = self._certified_count()  # the clear cells in the reachable free area
        gained = max(n - self._clear_count, 0) * self.cell_area
        self._clear_count = n
        return float(gained - self.config.collision_penalty * int(info["truth"].bumps))

    def _terminated(self, info: dict[str, Any]) -> bool:
        return bool(info["consistent"] and info["certified_coverage"] >= self.config.target)

    # --- rendering -----------------------------------------------------------------------------------------
    def render(self) -> np.ndarray | None:  # type: ignore[override]  # gymnasium types frames generically
        """``(512, 512, 3)`` picture of the observer's sets, the pose box and the true robot (``rgb_array``);
        ``human`` shows it in a window and returns None."""
        if self._render_mode is None:
            return None
        if self._render_mode == "human":
            if self._window is None:
                from digslam.envs.sim.render import Window

                self._window = Window(RENDER_SIZE, self.metadata["render_fps"])
            self._window.show(self.picture())
            return None
        return self.picture()

    def picture(self) -> np.ndarray:
        """``(512, 512, 3)`` uint8 picture of the observer's sets, the pose box and the true robot."""
        raw, world, f, g = self._explore, self._world(), self.filter, self.grid
        if raw.sim is None:
            raise RuntimeError("render: call reset() first")
        ny, nx = g.shape
        code = f.explored() if f.consistent else np.full(g.shape, PENUMBRA, dtype=np.int8)
        if f.consistent:
            code = np.where(f.clear_mask(), CLEAR, np.where(code == DARK, DARK, PENUMBRA))
        img = np.zeros((ny, nx, 3), dtype=np.uint8)
        for c, rgb in RGB.items():
            img[code == c] = rgb
        if self._bg is None or self._bg_world is not world:
            res = (g.hi[0] - g.lo[0]) / nx
            cells = rasterize(world.edges, g.lo + g.hi, res)[::-1][:ny, :nx]
            self._bg, self._bg_world = cells != FREE, world
        img[self._bg & (code != CLEAR)] = OBSTACLE_RGB
        s = max(RENDER_SIZE // max(ny, nx), 1)
        img = np.repeat(np.repeat(img, s, axis=0), s, axis=1)
        out = np.full((RENDER_SIZE, RENDER_SIZE, 3), 255, dtype=np.uint8)
        h, w = min(img.shape[0], RENDER_SIZE), min(img.shape[1], RENDER_SIZE)
        out[:h, :w] = img[:h, :w]
        sx, sy = s * nx / (g.hi[0] - g.lo[0]), s * ny / (g.hi[1] - g.lo[1])

        def px(x: float, y: float) -> tuple[int, int]:
            return int(np.clip((g.hi[1] - y) * sy, 0, h - 1)), int(np.clip((x - g.lo[0]) * sx, 0, w - 1))

        x, y, _ = raw.sim.pose
        rr, cc = px(x, y)
        rad = max(int(raw.config.robot_radius * sx), 2)
        yy, xx = np.ogrid[:h, :w]
        out[:h, :w][(yy - rr) ** 2 + (xx - cc) ** 2 <= rad * rad] = (20, 160, 60)
        if f.consistent:
            (r0, c0), (r1, c1) = px(f.pose_lo[0], f.pose_hi[1]), px(f.pose_hi[0], f.pose_lo[1])
            out[r0 : r1 + 1, [c0, c1]] = 0
            out[[r0, r1], c0 : c1 + 1] = 0
        return out


__all__ = [
    "DigCoverageEnv",
    "OBSTACLE_RGB",
    "RENDER_SIZE",
    "RGB",
]
