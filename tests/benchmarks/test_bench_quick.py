"""Every benchmark script runs at its ``--quick`` size and ends with its ``key=value`` lines.

Each ``benchmarks/bench_*.py`` found at collection time (a new script is covered as soon as it exists) runs
in a subprocess (``sys.executable``, in a temporary folder, so that what it writes lands there) with
``--quick``; the test asserts exit status 0, a last line of the form ``key=value`` and, for the scripts of
:data:`KEYS`, each of their key lines with a real value (a finite number, ``True``/``False`` or a name);
a script not in the table must print at least one ``key=value`` line. A script whose peer is codac
(``from _peer import codac``: codac runs in a subprocess of its own, since importing it switches the process
to upward rounding) is skipped when codac is not installed, one that imports Ray when Ray is not; neither is
imported here. The scripts of :data:`EXPENSIVE` are too slow for the default run even at ``--quick``
(``-m expensive`` runs them); every script must still declare ``--quick``.
"""

from __future__ import annotations

import importlib.util
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
SCRIPTS = sorted(p.stem for p in BENCHMARKS.glob("bench_*.py"))

#: The key lines each script must print (at least these; scripts not named here: at least one key line).
KEYS: dict[str, tuple[str, ...]] = {
    name: tuple(keys.split())
    for name, keys in {
        "bench_agents": "best_heuristic heuristic_level_success eval_steps_per_s eval_over_observed speedup "
        "oracle_speedup predictor_iou_dark",
        "bench_cold_start": "cold_first_contract_s warm_first_contract_s cold_over_warm_contract",
        "bench_certify": "certify_realtime_factor certify_realtime_factor_all_beams online_realtime_factor "
        "certify_peak_mb",
        "bench_levels": "levels_match",
        "bench_digslam": "seconds offline_over_online_coverage offline_over_online_coverage_min "
        "offline_over_online_coverage_rooms truth_in_offline_tube dig_slam_over_thesis",
        "bench_env": "ours_steps_per_s ours_unwrapped_steps_per_s ours_steps_per_s_unicycle hard_stops "
        "reference_steps_per_s ratio_vs_raycast_unicycle ratio_vs_raycast floorplan_over_rooms "
        "floorplan_over_rooms_unicycle",
        "bench_interval": "ratio_vs_codac",
        "bench_localization": "detections truth_inside iterations seconds",
        "bench_observer": "raw_steps_per_s observed_steps_per_s_q1 observer_overhead_q1 observed_q1_over_q0 "
        "observer_overhead_unicycle observed_steps_per_s observer_update_median_ms observer_overhead "
        "observer_overhead_loop observer_update_p99_ms_loop floorplan_over_rooms",
        "bench_paver": "ratio_vs_codac",
        "bench_predictor": "predictor_iou_dark predictor_iou_floorplan predictor_accuracy predictor_ece base_rate_iou "
        "dilate_iou",
        "bench_polar": "ratio_vs_codac",
        "bench_sweep": "speedup",
        "bench_teacher": "levels rollout_speedup_t90 fresh_noise_speedup_t90",
        "bench_thick": "ratio_vs_codac1",
    }.items()
}

#: Too slow for the default run even with ``--quick`` (warm numba cache, CPU time): bench_agents plays every
#: agent on the suite's generators and measures the step rate (about 28 s), bench_teacher the look-ahead
#: teachers on two workers (about 42 s).
EXPENSIVE = {"bench_agents", "bench_cold_start", "bench_teacher"}  # bench_cold_start compiles cold by design

#: A ``key=value`` token: at the start of a line or after a blank (``a=1 b=2`` holds two).
_KEY = re.compile(r"(?:^|\s)([A-Za-z_]\w*)=(\S+)")


def key_values(stdout: str) -> dict[str, str]:
    """Every ``key=value`` token of ``stdout`` (the last value of a key repeated)."""
    return {k: v for line in stdout.splitlines() for k, v in _KEY.findall(line)}


def real_value(v: str) -> bool:
    """A finite number, ``True``/``False``, or a name (``frontier``); not ``nan`` or ``inf``."""
    try:
        return math.isfinite(float(v))
    except ValueError:
        return v in ("True", "False") or (v.isidentifier() and v.lower() not in ("nan", "inf"))


def needs(script: str) -> str | None:
    """The optional module ``script`` needs (``codac``, ``ray``) and that is missing, else None."""
    text = (BENCHMARKS / f"{script}.py").read_text()
    wanted = (["codac"] if re.search(r"^from _peer import", text, re.M) else []) + (
        ["ray"] if re.search(r"^\s*(?:import|from) ray\b", text, re.M) else []
    )
    return next((m for m in wanted if importlib.util.find_spec(m) is None), None)


def _param(script: str) -> object:
    return pytest.param(script, marks=pytest.mark.expensive) if script in EXPENSIVE else script


def test_the_table_names_existing_scripts() -> None:
    assert set(KEYS) <= set(SCRIPTS) and EXPENSIVE <= set(SCRIPTS)


@pytest.mark.parametrize("script", SCRIPTS)
def test_every_script_declares_quick(script: str) -> None:
    assert '"--quick"' in (BENCHMARKS / f"{script}.py").read_text(), f"{script}.py: no --quick option"


@pytest.mark.parametrize("script", [_param(s) for s in SCRIPTS])
def test_quick_run_prints_its_key_lines(script: str, tmp_path: Path) -> None:
    missing = needs(script)
    if missing is not None:
        pytest.skip(f"{script} needs {missing}, not installed")
    env = {**os.environ, "MPLBACKEND": "Agg", "SDL_VIDEODRIVER": "dummy"}
    res = subprocess.run([sys.executable, str(BENCHMARKS / f"{script}.py"), "--quick"], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=600)  # fmt: skip
    assert res.returncode == 0, f"{script} --quick: exit {res.returncode}\n{res.stderr[-2000:]}"
    lines = [ln for ln in res.stdout.splitlines() if ln.strip()]
    assert lines and _KEY.match(lines[-1]), f"{script}: the last line is no key=value line: {lines[-1:]}"
    found = key_values(res.stdout)
    want = KEYS.get(script, ())
    absent = [k for k in want if k not in found]
    assert not absent, f"{script}: no {absent} among {sorted(found)}"
    bad = {k: found[k] for k in want if not real_value(found[k])}
    assert not bad, f"{script}: key lines without a real value: {bad}"
    assert found, f"{script}: no key=value line"
