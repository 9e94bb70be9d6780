"""Run a short episode of digslam/Explore-v0 (and variants) and save PNG frames.

Usage: ``python examples/explore_env.py [OUT_DIR] [--env ID] [--steps N] [--seed S]`` (default ``out/``).
Writes ``OUT_DIR/<env-name>.png`` with the map, the path, the cones with their measured ranges and the robot,
and ``OUT_DIR/<env-name>.npz`` with the recorded episode.
"""

from __future__ import annotations

import os

import gymnasium as gym
import numpy as np
import pygame
from _common import out_dir, parser

import digslam.envs  # noqa: F401  (registers the environments)
from digslam.envs import record_episode


def wander(n: int, rng: np.random.Generator) -> np.ndarray:
    """Forward motion with slowly varying turns."""
    turn = np.repeat(rng.uniform(-0.8, 0.8, n // 20 + 1), 20)[:n]
    return np.column_stack([np.full(n, 0.8), turn]).astype(np.float32)


def main(argv: list[str] | None = None) -> None:
    ap = parser(__doc__, out=None, steps=300, seed=0)
    ap.add_argument("out", nargs="?", default="out", help="output folder (default: out/)")
    ap.add_argument("--env", default="digslam/Explore-v0", help="environment id (default digslam/Explore-v0)")
    args = ap.parse_args(argv)
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    out = out_dir(args.out)
    env = gym.make(args.env, render_mode="rgb_array")
    episode = record_episode(env, args.seed, wander(args.steps, np.random.default_rng(args.seed)))
    frame = env.render()
    name = args.env.split("/")[-1]
    pygame.image.save(pygame.surfarray.make_surface(frame.transpose(1, 0, 2)), str(out / f"{name}.png"))
    episode.save(out / f"{name}.npz")
    cov = env.unwrapped.coverage
    print(
        f"{args.env}: {len(episode.actions)} steps, covered {cov.fraction:.1%} of the free area, "
        f"bumps {int(episode.truth.bumps_total[-1])}, frame {out / (name + '.png')}"
    )
    env.close()


if __name__ == "__main__":
    main()
