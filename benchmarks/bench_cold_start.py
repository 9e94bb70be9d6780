"""Cold start: each public entry point run twice in fresh processes, with an empty numba cache, then warm.

Every entry point runs in a subprocess whose ``NUMBA_CACHE_DIR`` is a new temporary folder, so that
every kernel it needs compiles (cold); then once more with that folder filled (warm). The times are the
whole subprocess, interpreter start and imports included. Entry points:

* ``contract``: the README's ring, ``from digslam.observer import ...``, ``CtcFwdBwd`` of
  ``(x - 2)² + (y - 2.5)² ∈ [1, 2.25]`` and one contraction of 1000 random boxes;
* ``env``: ``gym.make("digslam/DigCoverage-v0")``, ``reset`` and one ``step``;
* ``demo``: ``digslam demo --steps 100 --out <tmp>``.

The stale-kernel guard (:mod:`digslam.observer.core.cache`) keeps its stamp in ``NUMBA_CACHE_DIR``: an
empty folder has none, and the guard would then clear the caches of every other folder too (the
source tree's, shared with other processes). The benchmark writes the current stamp into the new
folder first, which changes nothing for the measured process (its folder holds no kernel to clear).

``--profile ENTRY`` runs one entry point cold and prints the compile time of each function (CPU
seconds, its own time without the functions it compiles in turn, from numba's ``numba:compile`` and
``numba:run_pass`` events). Prints ``key=value`` lines at the end; ``--quick`` runs the contract only.
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
    from digslam.observer.core import cache

    folder = tempfile.mkdtemp(prefix="digslam-cold-")
    Path(folder, cache.STAMP).write_text(cache.digest(cache.kernel_sources()) + "\n")
    return folder


def run(entry: str, cache_dir: str, profile: bool = False) -> tuple[float, float]:
    """Run ``entry`` in a subprocess with ``NUMBA_CACHE_DIR=cache_dir``: ``(wall s, CPU s)``."""
    code = PROFILE.replace("ENTRY", repr(ENTRIES[entry])) if profile else ENTRIES[entry]
    env = {**os.environ, "NUMBA_CACHE_DIR": cache_dir, "DIGSLAM_COMPILE_NOTICE": "0"}
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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="the contract entry point only")
    ap.add_argument("--entries", nargs="+", choices=sorted(ENTRIES), default=None)
    ap.add_argument("--profile", choices=sorted(ENTRIES), default=None, help="per-function compile times")
    args = ap.parse_args()
    if args.profile:
        folder = fresh_cache()
        try:
            run(args.profile, folder, profile=True)
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        return
    entries = args.entries or (["contract"] if args.quick else list(ENTRIES))
    results = {}
    for entry in entries:
        folder = fresh_cache()
        try:
            cold, cold_cpu = run(entry, folder)
            warm, warm_cpu = run(entry, folder)
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        results[entry] = (cold, warm, cold_cpu, warm_cpu)
        print(f"{entry}: cold {cold:.1f} s ({cold_cpu:.1f} s CPU), warm {warm:.1f} s ({warm_cpu:.1f} s CPU)")
    for entry, (cold, warm, cold_cpu, warm_cpu) in results.items():
        key = KEYS[entry]
        print(f"cold_{key}_s={cold:.2f}")
        print(f"warm_{key}_s={warm:.2f}")
        print(f"cold_{key}_cpu_s={cold_cpu:.2f}")
        print(f"warm_{key}_cpu_s={warm_cpu:.2f}")
    for entry, (cold, warm, cold_cpu, warm_cpu) in results.items():
        print(f"cold_over_warm_{entry}={cold / warm:.2f}")
        print(f"cold_over_warm_{entry}_cpu={cold_cpu / warm_cpu:.2f}")


if __name__ == "__main__":
    main()
