"""Cold start: each public entry point run in fresh processes just after an install, then warm.

An install (``pip install``) compiles every kernel into the kernel store
(:mod:`digslam.observer.cache.store`). The benchmark does the same into a new folder (``digslam warmup``'s
jobs with ``DIGSLAM_KERNEL_STORE`` pointing there, timed as ``store_build_s``), then runs each entry point in
a subprocess with a copy of that store and an empty ``NUMBA_CACHE_DIR`` (cold: the first run after the
install), then once more (warm). Without ``--quick`` it also runs each entry point with an empty store
(``compile_first_*``: what an editable install, ``DIGSLAM_BUILD_KERNELS=0`` or a read-only install meets,
every kernel compiling at first use). The times are the whole subprocess, interpreter start and imports
included. Entry points:

* ``contract``: the README's ring, ``from digslam.observer import ...``, ``CtcFwdBwd`` of
  ``(x - 2)² + (y - 2.5)² ∈ [1, 2.25]`` and one contraction of 1000 random boxes;
* ``env``: ``gym.make("digslam/DigCoverage-v0")``, ``reset`` and one ``step``;
* ``demo``: ``digslam demo --steps 100 --out <tmp>``.

The stale-kernel guard (:mod:`digslam.observer.cache`) keeps its stamp in ``NUMBA_CACHE_DIR``: an
empty folder has none, and the guard would then clear the caches of every other folder too (the
source tree's, shared with other processes). The benchmark writes the current stamp into the new
folder first, which changes nothing for the measured process (its folder holds no kernel to clear).

``--profile ENTRY`` runs one entry point with an empty store and prints the compile time of each function
(CPU seconds, its own time without the functions it compiles in turn, from numba's ``numba:compile`` and
``numba:run_pass`` events). Prints ``key=value`` lines at the end; ``--quick`` builds the interval
library's part of the store and runs the contract only.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ENTRIES = {
    "contract": """
import numpy as np
from digslam.observer import CtcFwdBwd, Function, Interval
f = Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2)
ctc = CtcFwdBwd(f, Interval(1, 2.25))
lo = np.random.default_rng(0).uniform(-1, 5, (1000, 2))
ctc.contract(lo, lo + np.random.default_rng(1).uniform(0, 1, (1000, 2)))
""",
    "env": """
import gymnasium as gym
import numpy as np
import digslam.envs
env = gym.make("digslam/DigCoverage-v0")
env.reset(seed=0)
env.step(np.zeros(env.action_space.shape, env.action_space.dtype))
""",
    "demo": """
import sys
from digslam.agents.cli.main import main
sys.exit(main(["demo", "--steps", "100", "--out", sys.argv[1]]))
""",
}
KEYS = {"contract": "first_contract", "env": "env_first_step", "demo": "demo"}

PROFILE = """
import sys, time
from numba.core import event
clock, stack, own, passes = time.process_time, [], {}, {}
class L(event.Listener):
    def __init__(self, kind):
        self.kind = kind
    def on_start(self, ev):
        d = ev.data.get("dispatcher")
        name = f"{d.py_func.__module__}.{d.py_func.__qualname__}" if self.kind == "c" else ev.data["name"]
        stack.append([self.kind, name, clock(), 0.0])
    def on_end(self, ev):
        kind, name, t0, child = stack.pop()
        dt = clock() - t0
        if stack:
            stack[-1][3] += dt
        fn = next((f[1] for f in reversed(stack + [[kind, name]]) if f[0] == "c"), "?")
        own[fn] = own.get(fn, 0.0) + dt - child
        if kind == "p":
            key = name.split(" [")[0]
            passes[key] = passes.get(key, 0.0) + dt - child
event.register("numba:compile", L("c"))
event.register("numba:run_pass", L("p"))
try:
    exec(compile(ENTRY, "<entry>", "exec"))
except SystemExit:
    pass
print(f"profile: {sum(own.values()):.2f} s compiling {len(own)} functions", file=sys.stderr)
for k, v in sorted(passes.items(), key=lambda kv: -kv[1])[:6]:
    print(f"  pass {v:6.2f} s  {k}", file=sys.stderr)
for k, v in sorted(own.items(), key=lambda kv: -kv[1])[:25]:
    print(f"  {v:6.2f} s  {k}", file=sys.stderr)
"""


def fresh_cache() -> str:
    """A new empty ``NUMBA_CACHE_DIR`` holding the stale-kernel guard's current stamp."""
    from digslam.observer import cache

    return str(cache.empty_cache(tempfile.mkdtemp(prefix="digslam-cold-")))


def build_store(folder: str, jobs: tuple[str, ...]) -> float:
    """Fill the kernel store ``folder`` as ``pip install`` does (``warmup.build`` with ``jobs``); seconds."""
    env = {**os.environ, "DIGSLAM_KERNEL_STORE": folder, "NUMBA_CACHE_DIR": fresh_cache()}
    code = f"import sys; from digslam.agents.cli.warmup import build; sys.exit(build({jobs!r}))"
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    shutil.rmtree(env["NUMBA_CACHE_DIR"], ignore_errors=True)
    if proc.returncode:
        raise SystemExit(
            f"bench_cold_start: building the store failed: {proc.stderr.strip().splitlines()[-1:]}"
        )
    return time.perf_counter() - t0


def run(entry: str, cache_dir: str, store: str, profile: bool = False) -> tuple[float, float]:
    """Run ``entry`` in a subprocess with ``NUMBA_CACHE_DIR=cache_dir`` and the kernel store ``store``:
    ``(wall s, CPU s)``."""
    code = PROFILE.replace("ENTRY", repr(ENTRIES[entry])) if profile else ENTRIES[entry]
    env = {**os.environ, "NUMBA_CACHE_DIR": cache_dir, "DIGSLAM_KERNEL_STORE": store,
           "DIGSLAM_COMPILE_NOTICE": "0"}  # fmt: skip
    with tempfile.TemporaryDirectory() as out:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-c", code, out], env=env, cwd=out,
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)  # fmt: skip
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode:
        raise SystemExit(f"bench_cold_start: {entry} failed: {proc.stderr.strip().splitlines()[-1:]}")
    if profile:
        print("\n".join(line for line in proc.stderr.splitlines() if not line.startswith("digslam: warning")))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def cold_then_warm(entry: str, store: str) -> tuple[float, float, float, float]:
    """``(cold s, warm s, cold CPU s, warm CPU s)`` of ``entry``: two runs with a copy of ``store`` and a new
    empty ``NUMBA_CACHE_DIR``."""
    cache_dir = fresh_cache()
    with tempfile.TemporaryDirectory() as tmp:
        copy = str(Path(tmp, "store"))
        shutil.copytree(store, copy)
        try:
            cold, cold_cpu = run(entry, cache_dir, copy)
            warm, warm_cpu = run(entry, cache_dir, copy)
        finally:
            shutil.rmtree(cache_dir, ignore_errors=True)
    return cold, warm, cold_cpu, warm_cpu


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="the interval library's store, the contract only")
    ap.add_argument("--entries", nargs="+", choices=sorted(ENTRIES), default=None)
    ap.add_argument("--profile", choices=sorted(ENTRIES), default=None, help="per-function compile times")
    args = ap.parse_args()
    if args.profile:
        folder = fresh_cache()
        try:
            with tempfile.TemporaryDirectory() as empty:
                run(args.profile, folder, empty, profile=True)
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        return
    from digslam.agents.cli.warmup import JOBS
    from digslam.observer.cache import store as cache_store

    entries = args.entries or (["contract"] if args.quick else list(ENTRIES))
    results, first = {}, {}
    with tempfile.TemporaryDirectory(prefix="digslam-store-") as store:
        jobs = ("interval",) if args.quick else JOBS
        built = build_store(store, jobs)
        n_files = len(cache_store.files(Path(store)))
        print(f"store: {n_files} files built in {built:.1f} s ({', '.join(jobs)})")
        for entry in entries:
            results[entry] = cold, warm, cold_cpu, warm_cpu = cold_then_warm(entry, store)
            print(
                f"{entry}: cold {cold:.1f} s ({cold_cpu:.1f} s CPU), warm {warm:.1f} s ({warm_cpu:.1f} s CPU)"
            )
            if not args.quick:
                with tempfile.TemporaryDirectory() as empty:
                    cache_dir = fresh_cache()
                    try:
                        first[entry] = run(entry, cache_dir, empty)
                    finally:
                        shutil.rmtree(cache_dir, ignore_errors=True)
                print(f"{entry}: every kernel compiling at first use {first[entry][0]:.1f} s")
    print(f"store_build_s={built:.1f}")
    print(f"store_files={n_files}")
    for entry, (cold, warm, cold_cpu, warm_cpu) in results.items():
        key = KEYS[entry]
        print(f"cold_{key}_s={cold:.2f}")
        print(f"warm_{key}_s={warm:.2f}")
        print(f"cold_{key}_cpu_s={cold_cpu:.2f}")
        print(f"warm_{key}_cpu_s={warm_cpu:.2f}")
        if entry in first:
            print(f"compile_{key}_s={first[entry][0]:.2f}")
            print(f"compile_over_warm_{entry}={first[entry][0] / warm:.2f}")
    for entry, (cold, warm, cold_cpu, warm_cpu) in results.items():
        print(f"cold_over_warm_{entry}={cold / warm:.2f}")
        print(f"cold_over_warm_{entry}_cpu={cold_cpu / warm_cpu:.2f}")


if __name__ == "__main__":
    main()
