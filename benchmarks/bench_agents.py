"""The coverage benchmark: every agent on the test levels of every generator, certified coverage uncapped.

Every baseline of :data:`digslam.agents.baselines.registry.BASELINES` (and the shipped learned agent
``agents/data/goals_attention.zip``, row ``ppo``, the learned chooser of the map predictor's gains
``agents/data/goals_predictive.zip``, row ``predictive_chooser``, and the low-level PPO
``agents/data/ppo_digcoverage.zip``, row ``ppo_lowlevel``, when they exist, each on the env keywords of its
``.json`` sidecar: they change the observation, not the levels) runs on the same ``--maps`` levels of each
generator of :data:`digslam.agents.evaluation.suite.GENERATORS` (room, rocks, caves, rooms, and floorplan:
20 m windows of the test split's real floor plans): the first seeds of the test split
(``digslam.envs.splits``), ``target=1.0`` (no early end), ``--steps`` steps
(:func:`digslam.agents.evaluation.suite.run_suite`). The headline is ``T_level``, the steps to each
generator's target level (:data:`digslam.agents.evaluation.levels.TARGET_LEVELS`, fixed on the validation
split by ``bench_levels.py``). Prints the leaderboard as two tables (``T_level`` per generator with its
success rate; ``T_level`` / T90 / AUC / final pose box over all maps, and the geometric-mean speedup over
the best baseline with its paired bootstrap 95 % interval), writes ``leaderboard.md``, ``leaderboard.png``,
``suite.json`` and ``best.json`` (the best agent overall, learned ones included; copied to
``agents/data/leaderboard.json`` it becomes ``digslam demo``'s default agent) to ``--out``, and ends with:

* ``target_levels=room:…,rocks:…,caves:…,rooms:…,floorplan:…``;
* ``best_heuristic_<generator>=`` (the baseline of smallest mean ``T_level`` there) and ``best_heuristic=``
  (over all maps);
* ``heuristic_level_success=<share of the test maps, over all generators, on which the best heuristic
  reaches its generator's level>``;
* ``eval_steps_per_s=<observed env steps per second with the frontier agent, one process>`` and
  ``eval_over_observed=<that over the observed env's own steps per second on the same path, its step calls
  timed apart from the agent's in the same run>`` (:func:`digslam.agents.evaluation.suite.eval_rates`);
* with a learned agent: ``speedup_<generator>=`` and ``speedup=<geometric mean over the test maps of all
  generators of T_level(best heuristic) / T_level(best learned agent)> [paired bootstrap 95 % interval]``;
* with ``predictive_frontier``: ``oracle_speedup_<generator>=`` and ``oracle_speedup=``, the same for the
  ``oracle`` row (the predictive planner on the true map, :mod:`digslam.agents.prediction.oracle`: a
  diagnosis, not an agent, never the best agent), and ``predictor_iou_dark=`` (the shipped map predictor's
  IoU on the open pixels of its validation snapshots, from its sidecar).

``--model`` takes any model of ``digslam train``, a goal-selection MaskablePPO model included.

Usage: ``python benchmarks/bench_agents.py [--quick] [--maps 30] [--steps 3000] [--out DIR] [--model PATH]
[--chooser PATH] [--predictive TOML] [--predictor PT] [--split test|validation] [--set KEY=VALUE ...] [--generators G ...] [--agents A ...] [--from F ...] [--ray [--address A]
[--workers N]]`` (also ``digslam benchmark agents ...``). ``--split validation`` runs the same suite on the validation
split's levels, where every setting of an agent or predictor is chosen (the test split is run once, at the
end, and its figure chooses nothing); ``--from`` refuses to merge runs of different splits. ``--set`` gives every agent and generator an
environment keyword (``--set grid_cell=0.078125``: the observer on a grid twice as fine; ``--set
'noise={speed=0.0, yaw_rate=0.0}'``: exact odometry, the certified ceiling of a planner when the pose box
does not drift); ``--generators`` runs some generators only; ``--agents`` some agents only (``--agents
frontier``: the reference baseline alone; the best baseline and ``heuristic_level_success`` are then those
of the agents run); ``--from`` reads the suite JSONs of earlier runs on the same levels (for example one run
per agent, in parallel processes) and merges them instead of running (the speed figures are still measured
here). The full suite (5 generators x 30 maps x 3000 steps x 8 agents, about 3.6 M steps) takes about an
hour and a quarter on one core; ``--quick`` (3 maps, 300 steps) a minute. ``--ray`` runs the same suite on a pool of Ray
actors (:func:`digslam.agents.evaluation.ray_eval.run_suite_ray`; a local instance with ``--workers`` CPUs,
or the cluster at ``--address``) with identical results; the speed figures are still measured in this
process.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import gymnasium as gym

import digslam.envs  # noqa: F401  (registers the environments)
from digslam.agents.baselines.registry import BASELINES, make_baseline
from digslam.agents.evaluation.levels import TARGET_LEVELS, format_levels
from digslam.agents.evaluation.metrics import paired_bootstrap_geomean
from digslam.agents.evaluation.ray_eval import run_suite_ray
from digslam.agents.evaluation.suite import SuiteResult, check_generators, eval_rates, merge, run_suite
from digslam.agents.learning.models import leaderboard_record

ENV_ID = "digslam/DigCoverage-v0"
MODEL = Path(__file__).resolve().parents[1] / "agents" / "data" / "goals_attention.zip"
#: The low-level PPO policy (continuous actions on the map), a comparison row (``ppo_lowlevel``).
LOWLEVEL = Path(__file__).resolve().parents[1] / "agents" / "data" / "ppo_digcoverage.zip"
#: The learned chooser of the predicted gains (a goal-level MaskablePPO), the ``predictive_chooser`` row.
CHOOSER = Path(__file__).resolve().parents[1] / "agents" / "data" / "goals_predictive.zip"
#: The learned rows: ``ppo`` (``--model``), ``ppo_lowlevel`` (``--lowlevel``), ``predictive_frontier`` (the
#: frontier agent on the shipped map predictor's map, ``agents/data/map_predictor.pt``) and
#: ``predictive_chooser`` (``--chooser``).
LEARNED = ("ppo", "ppo_lowlevel", "predictive_frontier", "predictive_chooser")
#: The diagnosis row that runs beside ``predictive_frontier``: the same planner on the true map.
ORACLE = "oracle"


def model_kwargs(model: Path) -> dict[str, Any]:
    """Env keywords of a saved model (:func:`digslam.agents.learning.models.model_env_kwargs`: its sidecar's,
    or its training run's, less the training-only ones; the low-level keywords of a goal-selection model)."""
    from digslam.agents.learning.models import model_env_kwargs

    return model_env_kwargs(model)


def env_settings(items: list[str]) -> dict[str, Any]:
    """``--set KEY=VALUE`` items as environment keywords (values parsed as TOML literals, else strings;
    ValueError naming ``--set`` for an item without ``=``)."""
    from digslam.observer.core.config import parse_assignment

    return dict(parse_assignment(item, "--set") for item in items)


def chosen_baselines(agents: list[str] | None) -> list[str]:
    """The baselines that ``--agents`` names (all of them for None), in the registry's order, the frontier
    agent always among them (``eval_steps_per_s`` measures it, and it is the reference baseline).

    Raises:
        ValueError: a name that is neither a baseline nor ``ppo``.
    """
    if agents is None:
        return list(BASELINES)
    unknown = [a for a in agents if a not in BASELINES and a not in LEARNED and a != ORACLE]
    if unknown:
        raise ValueError(f"--agents: unknown {unknown}; known: {sorted(BASELINES)}, {', '.join(LEARNED)}")
    return [a for a in BASELINES if a in agents or a == "frontier"]


def load_ppo(model: Path) -> Any:
    """The saved model at ``model`` as a policy of the low-level env (torch on one thread; a goal-selection
    MaskablePPO model comes as a ``GoalAgent``), or None with a printed note."""
    if not model.is_file():
        print(f"note: no PPO model at {model}; skipped")
        return None
    try:
        from digslam.agents.learning.models import load_ppo as load
    except ImportError as exc:
        print(f"note: stable-baselines3 unavailable ({exc}); PPO skipped")
        return None
    env = gym.make(ENV_ID, **model_kwargs(model))
    try:
        return load(model, env)
    finally:
        env.close()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--maps", type=int, default=30, help="levels per generator (default 30)")
    ap.add_argument("--split", choices=("test", "validation"), default="test",
                    help="the levels: the test split (the headline, run once at the end) or the validation "
                         "split (where every setting is chosen)")  # fmt: skip
    ap.add_argument("--steps", type=int, default=3000, help="steps per episode (default 3000)")
    ap.add_argument("--quick", action="store_true", help="a smoke run: 3 maps, 300 steps")
    ap.add_argument("--model", type=Path, default=MODEL, help="the learned model of the ppo row (.zip)")
    ap.add_argument("--chooser", type=Path, default=CHOOSER,
                    help="the model of the predictive_chooser row (.zip; default the shipped one)")  # fmt: skip
    ap.add_argument("--lowlevel", type=Path, default=LOWLEVEL,
                    help="the model of the ppo_lowlevel row (.zip; default the shipped low-level PPO)")  # fmt: skip
    ap.add_argument(
        "--out", type=Path, default=Path("out/leaderboard"), help="where to write the leaderboard"
    )
    ap.add_argument("--predictive", type=Path, default=None, metavar="TOML",
                    help="settings of the predictive_frontier row and the oracle (default: the shipped "
                         "agents/configs/predictive_frontier.toml)")  # fmt: skip
    ap.add_argument("--predictor", type=Path, default=None, metavar="PT",
                    help="map predictor of the predictive_frontier row (.pt of digslam train; default: the "
                         "shipped one)")  # fmt: skip
    ap.add_argument("--ray", action="store_true", help="run the suite on Ray actors (identical results)")
    ap.add_argument("--address", default=None, help="with --ray: Ray cluster to attach to (default: local)")
    ap.add_argument("--workers", type=int, default=None, help="with --ray: actors (default: one per CPU)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="an environment keyword for every agent and generator, e.g. grid_cell=0.078125 "
                         "(repeatable; values parsed as TOML literals)")  # fmt: skip
    ap.add_argument("--generators", nargs="+", default=None, metavar="G",
                    help="run these generators only (default: room rocks caves rooms floorplan)")  # fmt: skip
    ap.add_argument("--from", dest="sources", nargs="+", type=Path, default=None, metavar="F",
                    help="suite JSONs of earlier runs on the same levels to merge instead of running")  # fmt: skip
    ap.add_argument("--agents", nargs="+", default=None, metavar="A",
                    help="run these agents only: baselines, ppo and/or ppo_lowlevel (default: all of them); "
                         "the frontier agent always runs, since eval_steps_per_s measures it")  # fmt: skip
    args = ap.parse_args()
    if (args.address is not None or args.workers is not None) and not args.ray:
        ap.error("--address/--workers: only with --ray")
    try:
        common = env_settings(args.set)
        gym.make(ENV_ID, **common).close()  # an unknown key or a bad value: one line, before any episode
        check_generators(args.generators)
        baselines = chosen_baselines(args.agents)
        missing = [str(p) for p in args.sources or [] if not p.is_file()]
        if missing:
            raise ValueError(f"--from: no such file {missing[0]}")
        loaded = merge([SuiteResult.from_json(p) for p in args.sources]) if args.sources else None
        check_predictive(args.predictive, args.predictor)
    except ValueError as exc:
        ap.error(str(exc).splitlines()[0])
    maps, steps = (3, 300) if args.quick else (args.maps, args.steps)
    env = gym.make(ENV_ID, **common)
    names = baselines if not args.ray else ["frontier"]  # with --ray, only eval_steps_per_s runs here
    policies: dict[str, Any] = {name: make_baseline(name, env, seed=0) for name in names}
    env.close()
    extra = {name: dict(common) for name in names}
    if loaded is not None:  # the rows of the runs read: their baselines and learned agents
        baselines = [a for a in BASELINES if a in loaded.agents]
        args.agents = [a for a in loaded.agents if a in BASELINES or a in LEARNED or a == ORACLE]
    ppo = load_ppo(args.model) if args.agents is None or "ppo" in args.agents else None
    if ppo is not None:
        policies["ppo"], extra["ppo"] = ppo, {**model_kwargs(args.model), **common}
        print(f"PPO env keywords: {extra['ppo']}")
    low = None
    wanted = args.agents is None or "ppo_lowlevel" in args.agents
    if wanted and args.lowlevel.resolve() != args.model.resolve():  # the same file is one row, ppo
        low = load_ppo(args.lowlevel)
    if low is not None:
        policies["ppo_lowlevel"], extra["ppo_lowlevel"] = low, {**model_kwargs(args.lowlevel), **common}
    wanted = args.agents is None or "predictive_chooser" in args.agents
    chooser = load_ppo(args.chooser) if wanted and loaded is None else None
    if chooser is not None:
        policies["predictive_chooser"] = chooser
        extra["predictive_chooser"] = {**model_kwargs(args.chooser), **common}
    wanted = args.agents is None or "predictive_frontier" in args.agents
    if wanted and loaded is None:
        add_predictive(policies, extra, common, args.ray, args.predictive, args.predictor)
    if common:
        print(f"environment keywords of every agent: {common}")
    t0 = time.perf_counter()
    if loaded is not None:
        res = loaded
        maps, steps = len(res.seeds), res.steps
    elif args.ray:  # the same policies as specs: baselines sized from ENV_ID with seed 0, the PPO .zip
        specs = {name: name for name in baselines} | ({"ppo": str(args.model)} if ppo is not None else {})
        specs |= {"ppo_lowlevel": str(args.lowlevel)} if low is not None else {}
        extra = {name: dict(common) for name in baselines} | extra
        res = run_suite_ray(specs, n_maps=maps, steps=steps, generators=args.generators, agent_env_kwargs=extra,
                            address=args.address, workers=args.workers, policy_env=ENV_ID, policy_seed=0,
                            progress=True, split=args.split)  # fmt: skip
    else:
        res = run_suite(policies, n_maps=maps, steps=steps, generators=args.generators, agent_env_kwargs=extra,
                        progress=True, split=args.split)  # fmt: skip
    wall = time.perf_counter() - t0
    print(f"{len(res.results)} generators x {maps} {res.split} maps (seeds {res.seeds[0]}..{res.seeds[-1]}), "
          f"{steps} steps, target 1.0; {wall:.0f} s")  # fmt: skip
    table = res.table(baselines)
    print(table)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "leaderboard.md").write_text(table + "\n")
    print(f"wrote {args.out / 'leaderboard.md'}, {res.figure(args.out / 'leaderboard.png')} and "
          f"{res.to_json(args.out / 'suite.json')}")  # fmt: skip
    best = res.best(baselines + [a for a in LEARNED if a in res.agents])  # never the oracle: not an agent
    record = leaderboard_record(best, float(res.times()[best].mean()), maps, steps, list(res.results),
                                {g: TARGET_LEVELS.get(g, 0.9) for g in res.results})  # fmt: skip
    text = json.dumps(record, indent=2) + "\n"
    (args.out / "best.json").write_text(text)  # shipped as agents/data/leaderboard.json (models.LEADERBOARD)
    print(f"wrote {args.out / 'best.json'} (best agent overall: {best})")
    best = res.best(baselines)
    for g in res.results:
        print(f"best_heuristic_{g}={res.best(baselines, generator=g)}")
    rate, alone = eval_rates(policies["frontier"], ENV_ID, steps=min(4000, 10 * steps), env_kwargs=common)
    levels = {g: TARGET_LEVELS.get(g, 0.9) for g in res.results}
    print(f"target_levels={format_levels(levels)}")
    print(f"best_heuristic={best}")
    print(f"heuristic_level_success={res.success(best):.4f}")
    print(f"eval_steps_per_s={rate:.0f}")
    print(
        f"eval_over_observed={rate / alone:.3f} (the observed env alone on the same path: {alone:.0f} steps/s)"
    )
    st = ppo.choice_stats() if callable(getattr(ppo, "choice_stats", None)) else {}  # a goal-level model
    if st.get("decisions"):  # its choices (in this process: none with --ray)
        print(f"learned_choices: {st['decisions']:.0f} decisions, {100 * st['not_first']:.1f} % differ from the "
              f"frontier agent's pick; frontier {100 * st['frontier']:.1f} %, loop closure "
              f"{100 * st['closure']:.1f} %, turn in place {100 * st['turn']:.1f} %")  # fmt: skip
    learned = [a for a in LEARNED if a in res.agents]
    if learned:  # the best learned agent: geometric mean over the maps of T_level(best) / T_level(learned)
        top = res.best(learned)
        print_speedup(res, best, top, "speedup")
    if ORACLE in res.agents:
        print_speedup(res, best, ORACLE, "oracle_speedup")
    iou = predictor_iou()
    if iou is not None:
        print(
            f"predictor_iou_dark={iou:.4f} (the shipped map predictor on validation snapshots, open pixels)"
        )


def print_speedup(res: SuiteResult, best: str, agent: str, key: str) -> None:
    """``<key>_<generator>=`` and ``<key>=``: geometric mean over the maps of ``T_level(best) / T_level(agent)``
    with its paired bootstrap 95 % interval."""
    m = res.metrics()
    for g in res.results:
        lv = res.level_name(g)
        r, lo, hi = paired_bootstrap_geomean(m[g][best][lv], m[g][agent][lv])
        print(f"{key}_{g}={r:.4f} [{lo:.4f}, {hi:.4f}]")
    t = res.times()
    r, lo, hi = paired_bootstrap_geomean(t[best], t[agent])
    print(f"{key}={r:.4f} [{lo:.4f}, {hi:.4f}] (T_level of {best} / T_level of {agent}, geometric mean over "
          "the maps)")  # fmt: skip


def add_predictive(
    policies: dict[str, Any], extra: dict[str, Any], common: dict[str, Any], ray: bool,
    settings: Path | None = None, predictor: Path | None = None,
) -> None:  # fmt: skip
    """The ``predictive_frontier`` row on the map ``predictor`` (None: the shipped one) and the ``oracle``
    diagnosis beside it (a factory: it reads the true map of the env it plays), both with the agent's
    ``settings`` (None: the shipped ones), or a printed note why not."""
    if ray:
        print("note: predictive_frontier and the oracle run without --ray only; skipped")
        return
    try:
        from digslam.agents.prediction import make_predictive
        from digslam.agents.prediction.oracle import oracle_factory
        from digslam.agents.prediction.settings import load_settings

        chosen = load_settings(settings)
        net = None
        if predictor is not None:
            from digslam.agents.prediction.model import load

            net = load(predictor)
        env = gym.make(ENV_ID, **common)
        try:
            policies["predictive_frontier"] = make_predictive(env, predictor=net, seed=0, settings=chosen)
        finally:
            env.close()
    except (ImportError, ValueError) as exc:
        print(f"note: predictive_frontier skipped ({str(exc).splitlines()[0]})")
        return
    policies[ORACLE] = oracle_factory(settings=chosen)
    extra["predictive_frontier"], extra[ORACLE] = dict(common), dict(common)


def check_predictive(settings: Path | None, predictor: Path | None) -> None:
    """A ``--predictive`` or ``--predictor`` the user names must load (``ValueError`` in one line)."""
    if settings is not None:
        from digslam.agents.prediction.settings import load_settings

        try:
            load_settings(settings)
        except ValueError as exc:
            raise ValueError(f"--predictive: {exc}") from None
    if predictor is not None and not predictor.is_file():
        raise ValueError(f"--predictor: no such file {predictor}")


def predictor_iou() -> float | None:
    """The shipped map predictor's IoU on the open pixels of its validation snapshots (its sidecar)."""
    from digslam.agents.prediction.model import SHIPPED

    side = SHIPPED.with_suffix(".json")
    if not side.is_file():
        return None
    try:
        return float(json.loads(side.read_text())["validation"]["all"]["predictor"]["iou"])
    except (KeyError, TypeError, ValueError):
        return None


if __name__ == "__main__":
    main()
