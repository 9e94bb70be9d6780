"""Steps per second of ``digslam/Explore-v0`` (raw) and ``digslam/DigCoverage-v0`` (with the observer).

Both run the default map (the thesis room) and sensors (8 sonar cones + the omnidirectional sensor, a
128 x 128 observer grid, a 64 x 64 map) under the same random forward-biased actions, reset every
``--episode`` steps. Besides the two step rates it reports the online filter's median and 99th-percentile
update time (``OnlineDigSlam.last_update_seconds``, the filter alone) and the rest of the wrapper's time
(map and state images, info sets).

Usage: ``python benchmarks/bench_observer.py [--steps N] [--episode K]``. Last line:
``observer_overhead=<raw steps per second / observed steps per second>``.
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import digslam.envs  # noqa: F401  (registers the environments)


def run(env: gym.Env, actions: np.ndarray, episode: int, probe: list[float] | None = None) -> float:
    """Wall time of ``len(actions)`` steps (resets excluded); filter update times appended to ``probe``."""
    total = 0.0
    layer = env
    while probe is not None and not hasattr(layer, "filter"):
        layer = layer.env
    for start in range(0, len(actions), episode):
        env.reset(seed=start)
        t0 = time.perf_counter()
        for a in actions[start : start + episode]:
            env.step(a)
            if probe is not None:
                probe.append(layer.filter.last_update_seconds)
        total += time.perf_counter() - t0
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--episode", type=int, default=500)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    actions = np.column_stack([rng.uniform(0.2, 1.0, args.steps), rng.uniform(-1, 1, args.steps)])
    actions = actions.astype(np.float32)
    raw = gym.make("digslam/Explore-v0", max_episode_steps=args.episode + 1)
    obs = gym.make("digslam/DigCoverage-v0", max_episode_steps=args.episode + 1, target=1.0)
    run(raw, actions[:50], 50)  # warm-up
    run(obs, actions[:50], 50)
    t_raw = run(raw, actions, args.episode)
    probe: list[float] = []
    t_obs = run(obs, actions, args.episode, probe)
    up = np.array(probe)
    raw_sps, obs_sps = args.steps / t_raw, args.steps / t_obs
    layer = obs
    while not hasattr(layer, "filter"):
        layer = layer.env
    print(f"grid={layer.grid.shape} map={layer.obs_config.map_size} sensors={raw.unwrapped.suite.n}")
    print(f"raw_steps_per_s={raw_sps:.0f}")
    print(f"observed_steps_per_s={obs_sps:.0f}")
    print(f"observer_update_median_ms={1e3 * np.median(up):.3f}")
    print(f"observer_update_p99_ms={1e3 * np.percentile(up, 99):.3f}")
    print(f"wrapper_other_ms_per_step={1e3 * (t_obs - t_raw - up.sum()) / args.steps:.3f}")
    print(f"observer_overhead={raw_sps / obs_sps:.3f}")


if __name__ == "__main__":
    main()
