"""Steps per second of ``digslam/Explore-v0`` (raw) and ``digslam/DigCoverage-v0`` (with the observer).

Both run the default map (the thesis room) and sensors (8 sonar cones + the omnidirectional sensor, a
128 x 128 observer grid, a 64 x 64 map) under the same random forward-biased actions, reset every
``--episode`` steps. Besides the two step rates it reports the online filter's median and 99th-percentile
update time (``OnlineDigSlam.last_update_seconds``, the filter alone) and the rest of the wrapper's time
(map and state images, info sets).

Measurement: the two envs run the same actions, reset with the same seeds at the same steps (resets
excluded), after an untimed warm-up of 50 steps each. To keep a load spike on a shared machine from landing
on one env only, the timed steps alternate between them in chunks of ``--chunk`` steps (raw chunk, then
the same steps on the observed env, then the next chunk...); each env's time is the total over its chunks
and the overhead is the ratio of the two totals. (Before, the raw run and the observed run were timed one
after the other, each in one piece; the envs, actions, seeds and defaults compared are unchanged.)

Usage: ``python benchmarks/bench_observer.py [--steps N] [--episode K] [--chunk C]``. Last line:
``observer_overhead=<raw steps per second / observed steps per second>``.
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import digslam.envs  # noqa: F401  (registers the environments)


def filter_layer(env: gym.Env) -> gym.Env:
    """The wrapper layer that holds the online filter."""
    layer = env
    while not hasattr(layer, "filter"):
        layer = layer.env
    return layer


def timed(env: gym.Env, actions: np.ndarray, probe: list[float] | None = None) -> float:
    """Wall time of ``env.step`` over ``actions``; filter update times appended to ``probe``."""
    if probe is None:
        t0 = time.perf_counter()
        for a in actions:
            env.step(a)
        return time.perf_counter() - t0
    f = filter_layer(env).filter
    t0 = time.perf_counter()
    for a in actions:
        env.step(a)
        probe.append(f.last_update_seconds)
    return time.perf_counter() - t0


def run_pair(raw: gym.Env, obs: gym.Env, actions: np.ndarray, episode: int, chunk: int,
             probe: list[float]) -> tuple[float, float]:  # fmt: skip
    """Total step times of ``raw`` and ``obs`` over ``actions``, reset every ``episode`` steps (untimed),
    alternating chunks of ``chunk`` steps."""
    t_raw = t_obs = 0.0
    for start in range(0, len(actions), episode):
        raw.reset(seed=start)
        obs.reset(seed=start)
        block = actions[start : start + episode]
        for c in range(0, len(block), chunk):
            t_raw += timed(raw, block[c : c + chunk])
            t_obs += timed(obs, block[c : c + chunk], probe)
    return t_raw, t_obs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--episode", type=int, default=500)
    parser.add_argument("--chunk", type=int, default=100)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    actions = np.column_stack([rng.uniform(0.2, 1.0, args.steps), rng.uniform(-1, 1, args.steps)])
    actions = actions.astype(np.float32)
    raw = gym.make("digslam/Explore-v0", max_episode_steps=args.episode + 1)
    obs = gym.make("digslam/DigCoverage-v0", max_episode_steps=args.episode + 1, target=1.0)
    run_pair(raw, obs, actions[:50], 50, 50, [])  # warm-up
    probe: list[float] = []
    t_raw, t_obs = run_pair(raw, obs, actions, args.episode, args.chunk, probe)
    up = np.array(probe)
    raw_sps, obs_sps = args.steps / t_raw, args.steps / t_obs
    layer = filter_layer(obs)
    print(f"grid={layer.grid.shape} map={layer.obs_config.map_size} sensors={raw.unwrapped.suite.n}")
    print(f"raw_steps_per_s={raw_sps:.0f}")
    print(f"observed_steps_per_s={obs_sps:.0f}")
    print(f"observer_update_median_ms={1e3 * np.median(up):.3f}")
    print(f"observer_update_p99_ms={1e3 * np.percentile(up, 99):.3f}")
    print(f"wrapper_other_ms_per_step={1e3 * (t_obs - t_raw - up.sum()) / args.steps:.3f}")
    print(f"observer_overhead={raw_sps / obs_sps:.3f}")


if __name__ == "__main__":
    main()
