"""``digslam warmup``: compile the numba kernels once, in parallel processes, into the kernel store.

``pip install`` runs it on the tree it builds (:func:`build`); after an editable install, or an install
with ``DIGSLAM_BUILD_KERNELS=0``, the first ``reset``/``step`` of a certified-coverage environment and the
first paving otherwise wait for their kernels to compile (tens of seconds on two cores, once). The work
splits into independent jobs, each in its own process so that two cores compile at once:

* ``robot``: the raw environment's reset and step (the exact-arc robot step, cone distances and bounds,
  noise, ground-truth coverage);
* ``observer``: a certified-coverage environment's reset and one filter update fed without moving the
  robot (the online Dig-SLAM kernels and the observation map), with the shipped policy's settings;
* ``interval``: the README's five-line paving (forward-backward separator and paver) and the
  forward-backward contractor, each natural and centred (the centred kernels are kernels of their own);
* ``agents``: the demo's default agent (the frontier planner) for a few steps of a certified-coverage
  environment (its planning kernels).

A job that finds its kernels cached only loads them (about a second). The kernels go to the kernel store
(:mod:`digslam.observer.cache.store`); :func:`build`, run by ``pip install`` on the built tree, fills it and
records the build.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

JOBS = ("robot", "observer", "interval", "agents")


def _robot() -> None:
    import numpy as np

    from digslam.envs.explore.env import ExploreEnv

    for dynamics in ("pymunk", "unicycle"):  # both robots' kernels
        env = ExploreEnv(dynamics=dynamics)
        env.reset(seed=0)
        env.step(np.array([1.0, 0.5], np.float32))


def _observer() -> None:
    import gymnasium as gym
    import numpy as np

    import digslam.envs  # noqa: F401
    from digslam.agents.learning.models import DEFAULT_ENV, model_env_kwargs

    env = gym.make(DEFAULT_ENV, **model_env_kwargs())
    env.reset(seed=0)
    env.step(np.zeros(2, np.float32))  # a step at rest: the filter's and the observation's kernels


def _interval() -> None:
    from digslam.observer import Box, CtcFwdBwd, Function, Interval, SepInverse, pave

    f = Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2)
    box = Box([(-1, 5), (-0.5, 5.5)])
    pave(box, SepInverse(f, Interval(1, 2.25)), eps=0.1)
    pave(box, SepInverse(f, Interval(1, 2.25), centred=True), eps=0.5)  # the centred kernels
    ctc = CtcFwdBwd(f, Interval(1, 2.25))
    ctc.contract(box.lo[None], box.hi[None])
    CtcFwdBwd(f, Interval(1, 2.25), centred=True).contract(box.lo[None], box.hi[None])


def _agents() -> None:
    import gymnasium as gym

    import digslam.envs  # noqa: F401
    from digslam.agents.baselines.registry import make_baseline
    from digslam.agents.learning.models import DEFAULT_ENV

    env = gym.make(DEFAULT_ENV)
    policy = make_baseline("frontier", env, seed=0)
    obs, _ = env.reset(seed=0)
    for _ in range(3):
        action, _ = policy.predict(obs, deterministic=True)
        obs, *_ = env.step(action)
    env.close()


def run_job(name: str) -> None:
    """Run one job in this process."""
    {"robot": _robot, "observer": _observer, "interval": _interval, "agents": _agents}[name]()


def warmup(jobs: int | None = None, verbose: bool = False, names: tuple[str, ...] = JOBS) -> int:
    """Run the jobs ``names`` (default :data:`JOBS`), ``jobs`` processes at a time (default: the CPU count,
    at most 3); 0 if all passed."""
    n = max(1, min(jobs or os.cpu_count() or 1, 3, len(names)))
    start, todo, failed = time.perf_counter(), list(names), []
    running: dict[str, tuple[subprocess.Popen[str], float]] = {}
    while todo or running:
        while todo and len(running) < n:
            name = todo.pop(0)
            code = f"from digslam.agents.cli.warmup import run_job; run_job({name!r})"
            env = {**os.environ, "DIGSLAM_COMPILE_NOTICE": "0"}  # warmup announces itself
            proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.DEVNULL,
                                    stderr=subprocess.PIPE, text=True, env=env)  # fmt: skip
            running[name] = (proc, time.perf_counter())
        for name, (proc, t0) in list(running.items()):
            if proc.poll() is None:
                continue
            del running[name]
            err = (proc.stderr.read() if proc.stderr else "").strip().splitlines()
            if proc.returncode:
                failed.append(name)
                print(f"warmup {name}: failed ({err[-1] if err else proc.returncode})", file=sys.stderr)
            elif verbose:
                print(f"warmup {name}: {time.perf_counter() - t0:.1f} s")
        time.sleep(0.05)
    if verbose:
        print(f"kernels compiled and cached in {time.perf_counter() - start:.1f} s ({n} processes)")
    return 1 if failed else 0


def build(names: tuple[str, ...] = JOBS) -> int:
    """Fill the kernel store of the imported digslam with the jobs ``names`` (``pip install`` runs all of them
    on the built tree) and record the build (:func:`~digslam.observer.cache.store.write_manifest`); 0 if every
    job passed."""
    from digslam.observer.cache import store

    t0 = time.perf_counter()
    rc = warmup(verbose=True, names=names)
    seconds = time.perf_counter() - t0
    store.write_manifest(seconds, built_by="pip install" if rc == 0 else "pip install (some jobs failed)")
    print(f"kernel store: {len(store.files())} files in {seconds:.0f} s")
    return rc


__all__ = ["JOBS", "build", "run_job", "warmup"]
