"""Run a short episode of digslam/Explore-v0 (and variants) and save PNG frames.

Usage: ``python examples/explore_env.py [OUT_DIR] [--env ID] [--steps N] [--seed S]`` (default ``out/``).
Writes ``OUT_DIR/<env-name>.png`` with the map, the path, the cones with their measured ranges and the robot,
and ``OUT_DIR/<env-name>.npz`` with the recorded episode.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import gymnasium as gym
import numpy as np
import pygame

import digslam.envs  # noqa: F401  (registers the environments)
from digslam.envs import record_episode


def wander(n: int, rng: np.random.Generator) -> np.ndarray:
    """Forward motion with slowly varying turns."""
    turn = np.repeat(rng.uniform(-0.8, 0.8, n // 20 + 1), 20)[:n]
    return np.column_stack([np.full(n, 0.8), turn]).astype(np.float32)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("out", nargs="?", default="out")
    parser.add_argument("--env", default="digslam/Explore-v0")
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
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
