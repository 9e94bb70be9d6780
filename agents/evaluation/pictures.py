"""The demo's episode GIF and its curves: :func:`demo_episode` runs one episode, writes its frames
(:mod:`.frames`: the observer's sets, a legend in the thesis's words, the step, both coverages, the pose box
magnified and the estimated path) as a GIF and returns its curves as an
:class:`~digslam.agents.evaluation.evaluate.EvalResult` for the coverage figure; :func:`record_episode_gif`
only writes the GIF.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from digslam.agents.common.policy import PolicyPredictor, reset_policy
from digslam.agents.evaluation.evaluate import EvalResult, make_env
from digslam.agents.evaluation.frames import (
    INDEX,
    INSET_AT,
    INSET_SIZE,
    LEGEND,
    LEGEND_ROW,
    LEGEND_TOP,
    LEGEND_WIDTH,
    MAP_SIZE,
    PALETTE,
    PANEL_WIDTH,
    FrameDrawer,
    flat_palette,
)
from digslam.envs.stack import observer_of

if TYPE_CHECKING:  # Pillow is imported on use only
    from PIL import Image


def demo_episode(
    policy: PolicyPredictor,
    env_id: str = "digslam/DigCoverage-v0",
    path: str | Path = "episode.gif",
    steps: int = 600,
    seed: int = 0,
    env_kwargs: dict[str, Any] | None = None,
    fps: int = 15,
    stride: int = 2,
    name: str = "agent",
    scale: int = 1,
) -> EvalResult:
    """Run one episode of ``policy``, write its GIF to ``path`` (every ``stride``-th step and the last, each
    frame shrunk ``scale`` times) and return its :class:`~digslam.agents.evaluation.evaluate.EvalResult` (one
    episode; its curves end at the episode's last step, ``lengths`` the steps run, so ``n_steps`` is that
    step and the coverage figure's axis ends there)."""
    for key, v in (("steps", steps), ("fps", fps), ("stride", stride), ("scale", scale)):
        if not (isinstance(v, int) and v >= 1):
            raise ValueError(f"{key}: must be an integer >= 1, got {v!r}")
    env = make_env(env_id, steps, env_kwargs)
    reset_policy(policy)
    cert, true = np.empty(steps + 1), np.empty(steps + 1)
    try:
        obs, info = env.reset(seed=seed)
        title = f"{env_id.split('/')[-1]}: {name}"
        guess = getattr(policy, "shown_prediction", None)  # an agent that predicts the map shows its guess
        predicts = callable(guess)
        shown: Callable[[], np.ndarray | None] = guess if callable(guess) else (lambda: None)
        drawer = FrameDrawer(observer_of(env), title, info.get("target"), steps, prediction=predicts)
        frames = [drawer.frame(info, 0)]
        cert[0], true[0] = info["certified_coverage"], info["true_coverage"]
        state, start, n = None, np.ones(1, dtype=bool), 0
        for n in range(1, steps + 1):
            action, state = policy.predict(obs, state=state, episode_start=start, deterministic=True)
            start = np.zeros(1, dtype=bool)
            action = np.clip(np.asarray(action, dtype=np.float32).reshape(env.action_space.shape), -1, 1)
            obs, _, terminated, truncated, info = env.step(action)
            cert[n], true[n] = info["certified_coverage"], info["true_coverage"]
            done = terminated or truncated
            if n % stride == 0 or done or n == steps:
                frames.append(drawer.frame(info, n, shown()))
            else:
                drawer.observe(info, n)  # the estimated path has every step
            if done:
                break
    finally:
        env.close()
    if scale > 1:
        frames = [f.resize((f.width // scale, f.height // scale), 0) for f in frames]  # 0: nearest
    write_gif(frames, path, fps)
    box = np.asarray(info.get("pose_box", np.full((2, 2), np.nan)), dtype=np.float64)
    tube = float(np.max(box[1] - box[0])) if np.all(np.isfinite(box)) else math.nan
    cert, true = (
        cert[: n + 1],
        true[: n + 1],
    )  # the curves end at the episode's last step (so does the figure)
    return EvalResult({name: cert[None]}, {name: true[None]}, {name: np.array([float(info.get("bumps", 0))])},
                      {name: np.array([tube])}, {name: np.array([float(n)])}, env_id, seed, 1)  # fmt: skip


def write_gif(frames: list[Image.Image], path: str | Path, fps: int) -> Path:
    """Write ``P``-mode frames sharing :data:`PALETTE` as a looping GIF."""
    pal = flat_palette()
    for f in frames:
        f.putpalette(pal)
    p = Path(path)
    frames[0].save(p, format="GIF", save_all=True, append_images=frames[1:],
                   duration=max(int(1000 / fps), 20), loop=0, optimize=False)  # fmt: skip
    return p


def record_episode_gif(
    policy: PolicyPredictor,
    env_id: str = "digslam/DigCoverage-v0",
    path: str | Path = "episode.gif",
    steps: int = 300,
    seed: int = 0,
    env_kwargs: dict[str, Any] | None = None,
    fps: int = 15,
    stride: int = 1,
    scale: int = 1,
) -> Path:
    """Animated GIF of one episode of ``policy``: the frames of :mod:`.pictures` (the observer's sets in a
    colour-blind-safe palette, a legend in the thesis's words, the step, both coverages and the pose box;
    :func:`demo_episode`). ``stride`` keeps every ``stride``-th frame and ``scale`` shrinks
    each frame by that factor (file size)."""
    demo_episode(policy, env_id, path, steps=steps, seed=seed, env_kwargs=env_kwargs, fps=fps, stride=stride,
                 scale=scale)  # fmt: skip
    return Path(path)


__all__ = [
    "INDEX",
    "INSET_AT",
    "INSET_SIZE",
    "LEGEND",
    "LEGEND_ROW",
    "LEGEND_TOP",
    "LEGEND_WIDTH",
    "MAP_SIZE",
    "PALETTE",
    "PANEL_WIDTH",
    "FrameDrawer",
    "demo_episode",
    "record_episode_gif",
    "write_gif",
]
