"""Pygame rendering of the exploration env: exact map, path, cones with their measured ranges, robot.

``rgb_array`` draws off-screen (no display needed); ``human`` opens a window (headless with
``SDL_VIDEODRIVER=dummy``).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Protocol

import numpy as np

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
import pygame  # noqa: E402

from digslam.observer.record.mission import MissionRecord

if TYPE_CHECKING:  # (types only)
    from digslam.envs.config import ExploreConfig
    from digslam.envs.sim.robot import RobotSim
    from digslam.envs.sim.sensors import SensorSuite
    from digslam.envs.sim.world import World

SIZE = 512
_COLOURS = np.array([[250, 250, 250], [60, 60, 70], [150, 150, 160]], dtype=np.uint8)  # free, occupied, mixed


class Scene(Protocol):
    """What :meth:`Renderer.draw` reads of an env (an :class:`~digslam.envs.explore.env.ExploreEnv`): the
    world, the path so far, the robot, its sensors and its configuration."""

    world: World | None
    path: list[np.ndarray]
    sim: RobotSim | None
    suite: SensorSuite
    config: ExploreConfig


class Renderer:
    """Draws an :class:`~digslam.envs.explore.env.ExploreEnv` into a ``SIZE x SIZE`` picture."""

    def __init__(self, mode: str, fps: int) -> None:
        self.mode, self.fps = mode, fps
        self._bg: pygame.Surface | None = None
        self._bg_world: World | None = None
        self.window: pygame.Surface | None = None
        self.clock: pygame.time.Clock | None = None
        if mode == "human":
            pygame.display.init()  # display only: no audio (no ALSA probing on headless machines)
            self.window = pygame.display.set_mode((SIZE, SIZE))
            self.clock = pygame.time.Clock()

    def _background(self, world: World) -> pygame.Surface:
        if self._bg is None or self._bg_world is not world:
            x0, y0, x1, y1 = world.frame
            res = max(x1 - x0, y1 - y0) / SIZE
            cells = world.raster(res)
            img = np.full((SIZE, SIZE, 3), 255, dtype=np.uint8)
            h, w = min(cells.shape[0], SIZE), min(cells.shape[1], SIZE)
            img[:h, :w] = _COLOURS[cells[:h, :w]]
            # Surface arrays are (x, y) with y downwards; world y goes up.
            self._bg = pygame.surfarray.make_surface(np.ascontiguousarray(img[::-1].transpose(1, 0, 2)))
            self._bg_world = world
            self._scale, self._x0, self._y1 = 1.0 / res, x0, y0 + SIZE * res
        return self._bg

    def _px(self, x: float, y: float) -> tuple[int, int]:
        return int(round((x - self._x0) * self._scale)), int(round((self._y1 - y) * self._scale))

    def draw(self, env: Scene, record: MissionRecord) -> np.ndarray | None:
        """Render the env's current state with its last ``record`` (the cones' measured ranges); return an
        ``(H, W, 3)`` array in ``rgb_array`` mode."""
        if env.world is None or env.sim is None:
            raise RuntimeError("render: call reset() first")
        canvas = self._background(env.world).copy()
        if len(env.path) > 1:
            pygame.draw.lines(canvas, (40, 120, 220), False, [self._px(*p) for p in env.path], 2)
        x, y, th = env.sim.pose
        rec, suite = record, env.suite
        for k in range(suite.n):
            lo, hi = rec.range[k]
            r = suite.r_max[k] if rec.no_echo[k] else 0.5 * (lo + hi)
            a = th + suite.alpha[k]
            g = suite.gamma[k]
            angs = np.linspace(a - g, a + g, max(3, int(g * 20)))
            pts = [self._px(x, y)] + [self._px(x + r * np.cos(b), y + r * np.sin(b)) for b in angs]
            colour = (230, 160, 40) if rec.no_echo[k] else (220, 60, 60)
            if rec.outlier[k]:
                colour = (160, 60, 200)
            if suite.gamma[k] < np.pi:
                pygame.draw.polygon(canvas, colour, pts, 1)
            else:
                pygame.draw.circle(canvas, colour, self._px(x, y), max(1, int(r * self._scale)), 1)
        rad = max(2, int(env.config.robot_radius * self._scale))
        pygame.draw.circle(canvas, (20, 160, 60), self._px(x, y), rad)
        pygame.draw.line(
            canvas,
            (0, 0, 0),
            self._px(x, y),
            self._px(
                x + 2 * env.config.robot_radius * np.cos(th), y + 2 * env.config.robot_radius * np.sin(th)
            ),
            2,
        )
        if self.mode == "human":
            assert self.window is not None and self.clock is not None
            pygame.event.pump()
            self.window.blit(canvas, (0, 0))
            pygame.display.flip()
            self.clock.tick(self.fps)
            return None
        return np.transpose(pygame.surfarray.array3d(canvas), (1, 0, 2)).copy()

    def close(self) -> None:
        """Close the window if one was opened."""
        if self.window is not None:
            pygame.display.quit()
            self.window = None


class Window:
    """A ``size x size`` pygame window showing ``(H, W, 3)`` uint8 pictures at ``fps`` frames a second at
    most: the ``human`` render mode of an env that draws pictures (headless with ``SDL_VIDEODRIVER=dummy``).
    """

    def __init__(self, size: int, fps: int) -> None:
        pygame.display.init()  # display only: no audio
        self.surface: pygame.Surface | None = pygame.display.set_mode((size, size))
        self.clock, self.fps = pygame.time.Clock(), fps

    def show(self, picture: np.ndarray) -> None:
        """Draw ``picture`` (row 0 at the top) from the window's corner and wait for the next frame."""
        if self.surface is None:
            raise RuntimeError("show: the window is closed")
        pygame.event.pump()
        frame = pygame.surfarray.make_surface(np.ascontiguousarray(picture.transpose(1, 0, 2)))
        self.surface.blit(frame, (0, 0))
        pygame.display.flip()
        self.clock.tick(self.fps)

    def close(self) -> None:
        """Close the window (again: nothing)."""
        if self.surface is not None:
            pygame.display.quit()
            self.surface = None


__all__ = ["Renderer", "Scene", "Window"]
