"""Hyper-parameter and seed sweeps of the PPO recipe on Ray Tune (``digslam sweep CONFIG``).

A :class:`SweepConfig` (TOML or JSON, unknown keys rejected) names a base
:class:`~digslam.agents.train.TrainConfig` (file or table), a search space over its keys
(:data:`SPACE_KINDS`: ``grid``, ``choice``, ``uniform``, ``loguniform``, ``randint``; ``env_kwargs`` takes a
nested table), the seeds (a grid dimension), the samples per grid point, the CPUs per trial, early stopping
on certified coverage (ASHA and/or a threshold) and where results land. :func:`run_sweep` runs one Tune
trial per configuration; each trial is the project's own :func:`~digslam.agents.train.train` with a
:class:`CoverageReport` callback that evaluates the certified coverage on the held-out maps of the
``TrainConfig`` (``eval_seeds()``) every ``eval_freq`` timesteps and reports it with ``tune.report``.

Results land in ``<storage_path>/<name>/``: Tune's experiment state (what :func:`run_sweep` with
``resume=True`` restores with ``Tuner.restore``), ``models/<trial id>/`` (each trial's ``out_dir``: final
and best-coverage models, config, TensorBoard logs) and ``results.csv`` plus the markdown table returned.

>>> cfg = SweepConfig.from_dict({"base": {"total_timesteps": 512}, "seeds": [0, 1],
...                              "space": {"learning_rate": {"loguniform": [1e-4, 1e-3]}}})
>>> cfg.name, cfg.seeds, cfg.space_keys()
('sweep', (0, 1), ['learning_rate', 'seed'])
>>> SweepConfig.from_dict({"seed": [0]})  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: SweepConfig: unknown key(s) ['seed']; known: ...
"""

from __future__ import annotations

import argparse
import functools
import json
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np

from .train import EnvFactory, TrainConfig

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

#: Kinds of search dimension and their argument (a list of values, or ``[low, high]``).
SPACE_KINDS = ("grid", "choice", "uniform", "loguniform", "randint")
#: TrainConfig keys a sweep may not vary (``seed`` comes from ``seeds``; ``out_dir`` is set per trial).
FIXED_KEYS = ("seed", "out_dir")


@dataclass(frozen=True)
class SweepConfig:
    """A Ray Tune sweep of :func:`~digslam.agents.train.train` (see the module docstring).

    Attributes:
        name: Experiment name (folder under ``storage_path``).
        base: The base ``TrainConfig``: a ``.toml``/``.json`` path (relative to the sweep file) or a table.
        space: ``{TrainConfig key: {kind: argument}}``; ``env_kwargs`` maps to a table of such entries.
        seeds: Training seeds, swept as a grid dimension.
        num_samples: Samples per grid point (for the random dimensions).
        cpus_per_trial, gpus_per_trial: Resources of one trial.
        max_concurrent_trials: At most this many trials at once (0: as the resources allow).
        metric: The reported metric (only ``"certified_coverage"``, maximised).
        scheduler: ``"asha"`` (stop the worst trials at each rung of evaluations) or ``"none"``.
        grace_period, reduction_factor: ASHA's first rung (in evaluations) and its halving factor.
        stop_coverage: Stop a trial once its certified coverage reaches this (0: never).
        eval_steps: Step cap of an evaluation episode (0: the environment's own limit).
        storage_path: Folder of the results (on a cluster: a filesystem mounted on every node).
    """

    name: str = "sweep"
    base: str | dict[str, Any] = field(default_factory=dict)
    space: dict[str, Any] = field(default_factory=dict)
    seeds: tuple[int, ...] = (0,)
    num_samples: int = 1
    cpus_per_trial: float = 1.0
    gpus_per_trial: float = 0.0
    max_concurrent_trials: int = 0
    metric: str = "certified_coverage"
    scheduler: str = "asha"
    grace_period: int = 1
    reduction_factor: int = 2
    stop_coverage: float = 0.0
    eval_steps: int = 0
    storage_path: str = "runs/sweeps"

    def __post_init__(self) -> None:
        object.__setattr__(self, "seeds", tuple(self.seeds))
        for name in ("cpus_per_trial", "gpus_per_trial", "stop_coverage"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise ValueError(f"{name}: must be a number, got {v!r}")
            object.__setattr__(self, name, float(v))
        for name in (
            "num_samples",
            "max_concurrent_trials",
            "grace_period",
            "reduction_factor",
            "eval_steps",
        ):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                raise ValueError(f"{name}: must be an int >= 0, got {v!r}")
        if not self.name or "/" in self.name:
            raise ValueError(f"name: must be a non-empty folder name, got {self.name!r}")
        if not self.seeds or not all(
            isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in self.seeds
        ):
            raise ValueError(f"seeds: must be a non-empty list of ints >= 0, got {list(self.seeds)!r}")
        if self.num_samples < 1 or self.grace_period < 1 or self.reduction_factor < 2:
            raise ValueError("num_samples, grace_period: must be >= 1; reduction_factor: must be >= 2")
        if self.cpus_per_trial <= 0 or self.gpus_per_trial < 0:
            raise ValueError(
                f"cpus_per_trial: must be > 0 (and gpus_per_trial >= 0), got {self.cpus_per_trial}"
            )
        if self.metric != "certified_coverage":
            raise ValueError(f"metric: only 'certified_coverage' is reported, got {self.metric!r}")
        if self.scheduler not in ("asha", "none"):
            raise ValueError(f"scheduler: must be 'asha' or 'none', got {self.scheduler!r}")
        if not 0.0 <= self.stop_coverage <= 1.0:
            raise ValueError(f"stop_coverage: must be in [0, 1], got {self.stop_coverage}")
        if not isinstance(self.base, (str, dict)):
            raise ValueError(f"base: must be a TrainConfig path or table, got {type(self.base).__name__}")
        if "://" in self.storage_path:
            raise ValueError(f"storage_path: must be a (shared) filesystem folder, got {self.storage_path!r}")
        _check_space(self.space)
        self.base_config()  # the base must be a valid TrainConfig

    # --- construction -------------------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data: Mapping[str, Any], root: str | Path | None = None) -> SweepConfig:
        """Build from a mapping; unknown keys raise ``ValueError``. A relative ``base`` path is taken from
        the working directory, else from ``root`` (the sweep file's folder), and made absolute."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f"SweepConfig: unknown key(s) {unknown}; known: {sorted(known)}")
        data = dict(data)
        base = data.get("base")
        if isinstance(base, str):  # absolute: trials run in other working directories
            near = Path(root) / base if root is not None else Path(base)
            data["base"] = str(
                (near if near.is_file() and not Path(base).is_file() else Path(base)).resolve()
            )
        return cls(**data)

    @classmethod
    def from_file(cls, path: str | Path) -> SweepConfig:
        """Read a ``.toml`` or ``.json`` sweep file."""
        p = Path(path)
        if not p.is_file():
            raise ValueError(f"path: no sweep configuration file {str(p)!r}")
        if p.suffix == ".json":
            data = json.loads(p.read_text())
        elif p.suffix == ".toml":
            data = tomllib.loads(p.read_text())
        else:
            raise ValueError(f"path: sweep configuration must be .toml or .json, got {str(p)!r}")
        return cls.from_dict(data, root=p.parent)

    # --- views --------------------------------------------------------------------------------------------
    def base_config(self) -> TrainConfig:
        """The base ``TrainConfig`` (progress bar off: trials log to Tune)."""
        if isinstance(self.base, str):
            cfg = TrainConfig.from_file(self.base)
        else:
            cfg = TrainConfig.from_dict(self.base)
        return cfg.override(["progress_bar=false"])

    def space_keys(self) -> list[str]:
        """Swept keys (``env_kwargs.<k>`` for environment keywords), ``seed`` last."""
        keys = [f"env_kwargs.{k}" for k in self.space.get("env_kwargs", {})]
        return sorted([k for k in self.space if k != "env_kwargs"] + keys) + ["seed"]

    def experiment_path(self) -> str:
        """``<storage_path>/<name>``, absolute."""
        return str(Path(self.storage_path).resolve() / self.name)

    def param_space(self) -> dict[str, Any]:
        """Tune's ``param_space``: the search space plus ``seed`` as a grid."""
        from ray import tune

        def dim(spec: Mapping[str, Any]) -> Any:
            ((kind, arg),) = spec.items()
            if kind == "grid":
                return tune.grid_search(list(arg))
            if kind == "choice":
                return tune.choice(list(arg))
            return {"uniform": tune.uniform, "loguniform": tune.loguniform, "randint": tune.randint}[kind](
                *arg
            )

        space: dict[str, Any] = {k: dim(v) for k, v in self.space.items() if k != "env_kwargs"}
        if "env_kwargs" in self.space:
            space["env_kwargs"] = {k: dim(v) for k, v in self.space["env_kwargs"].items()}
        space["seed"] = tune.grid_search(list(self.seeds))
        return space

    def to_dict(self) -> dict[str, Any]:
        """Plain data (JSON-able)."""
        d = asdict(self)
        d["seeds"] = list(self.seeds)
        return d


def _check_space(space: Any) -> None:
    if not isinstance(space, Mapping):
        raise ValueError(f"space: must be a table of dimensions, got {type(space).__name__}")
    known = {f.name for f in fields(TrainConfig)} - set(FIXED_KEYS)
    for key, spec in space.items():
        if key == "env_kwargs":
            if not isinstance(spec, Mapping) or not spec:
                raise ValueError("space.env_kwargs: must be a non-empty table of dimensions")
            for k, s in spec.items():
                _check_dim(f"space.env_kwargs.{k}", s)
            continue
        if key not in known:
            raise ValueError(f"space: unknown or fixed TrainConfig key {key!r}; sweepable: {sorted(known)}")
        _check_dim(f"space.{key}", spec)


def _check_dim(where: str, spec: Any) -> None:
    if not isinstance(spec, Mapping) or len(spec) != 1 or next(iter(spec)) not in SPACE_KINDS:
        raise ValueError(f"{where}: must be one of {{{', '.join(SPACE_KINDS)} = ...}}, got {spec!r}")
    ((kind, arg),) = spec.items()
    if not isinstance(arg, (list, tuple)) or not arg:
        raise ValueError(f"{where}: {kind} needs a non-empty list, got {arg!r}")
    if kind in ("uniform", "loguniform", "randint"):
        if len(arg) != 2 or not all(isinstance(a, (int, float)) for a in arg) or not arg[0] < arg[1]:
            raise ValueError(f"{where}: {kind} needs [low, high] with low < high, got {arg!r}")
        if kind == "loguniform" and arg[0] <= 0:
            raise ValueError(f"{where}: loguniform needs low > 0, got {arg!r}")


def sweep_trial(params: dict[str, Any], sweep: dict[str, Any]) -> None:
    """One Tune trial: the base ``TrainConfig`` with ``params``, trained by ``train`` while
    :class:`CoverageReport` reports the held-out certified coverage (``eval_freq`` 0 in the config passed
    to ``train``: this callback replaces SB3's reward-based evaluation)."""
    from ray import tune

    cfg = SweepConfig.from_dict(sweep)
    base = cfg.base_config()
    data = asdict(base)
    params = dict(params)
    data["env_kwargs"] = {**data["env_kwargs"], **params.pop("env_kwargs", {})}
    data.update(params)
    trial = tune.get_context().get_trial_id()
    data["out_dir"] = str(Path(cfg.experiment_path()) / "models" / trial)
    freq = data["eval_freq"] or data["total_timesteps"]
    data["eval_freq"] = 0
    tcfg = TrainConfig.from_dict(data)
    callback = _coverage_report_class()(tcfg, freq, eval_steps=cfg.eval_steps, report=tune.report)
    train_with_callback(tcfg, callback)
    callback.flush()


def evaluate_coverage(model: Any, cfg: TrainConfig, eval_steps: int = 0) -> tuple[float, float]:
    """Mean final certified and true coverage of ``model`` (deterministic) on the held-out maps
    ``cfg.eval_seeds()``; an episode ends with the environment's or after ``eval_steps`` steps (0: no cap)."""
    env = EnvFactory(cfg.env_id, cfg.env_kwargs, cfg.torch_threads)()
    cert, true = [], []
    try:
        for s in cfg.eval_seeds():  # one episode per held-out map
            obs, info = env.reset(seed=s)
            k, done = 0, False
            while not done:
                action, _ = model.predict(obs, deterministic=True)
                obs, _, terminated, truncated, info = env.step(action)
                k += 1
                done = terminated or truncated or (eval_steps > 0 and k >= eval_steps)
            cert.append(float(info["certified_coverage"]))
            true.append(float(info.get("true_coverage", np.nan)))
    finally:
        env.close()
    return float(np.mean(cert)), float(np.mean(true))


@functools.cache
def _coverage_report_class() -> type:
    """Build :class:`CoverageReport` on first use (SB3 and torch are imported only by trials)."""
    from stable_baselines3.common.callbacks import BaseCallback

    class CoverageReport(BaseCallback):
        """SB3 callback: every ``freq`` timesteps (and at the end) evaluates the certified coverage on the
        held-out maps, saves the best model as ``<out_dir>/best_certified_model.zip`` and calls
        ``report({"certified_coverage", "true_coverage", "timesteps"})`` (``tune.report`` in a trial); the
        end-of-training evaluation is held back until :meth:`flush`."""

        def __init__(self, cfg: TrainConfig, freq: int, eval_steps: int = 0,
                     report: Callable[[dict[str, Any]], None] | None = None) -> None:  # fmt: skip
            super().__init__()
            if freq < 1:
                raise ValueError(f"freq: must be >= 1, got {freq}")
            self.cfg, self.freq, self.eval_steps, self.report = cfg, freq, eval_steps, report
            self.last, self.best = 0, -np.inf
            self.final: dict[str, Any] | None = None
            self.history: list[dict[str, Any]] = []

        def _on_step(self) -> bool:
            if self.num_timesteps - self.last >= self.freq:
                self._evaluate(final=self.num_timesteps >= self.cfg.total_timesteps)
            return True

        def _on_training_end(self) -> None:
            if self.last != self.num_timesteps or not self.history:
                self._evaluate(final=True)

        def flush(self) -> None:
            """Report the final evaluation (call it after the final model is saved: a scheduler may stop the
            trial at any report)."""
            if self.final is not None and self.report is not None:
                self.report(self.final)
            self.final = None

        def _evaluate(self, final: bool = False) -> None:
            self.last = self.num_timesteps
            cert, true = evaluate_coverage(self.model, self.cfg, self.eval_steps)
            if cert > self.best:
                self.best = cert
                self.model.save(Path(self.cfg.out_dir) / "best_certified_model.zip")
            metrics = {
                "certified_coverage": cert,
                "true_coverage": true,
                "timesteps": int(self.num_timesteps),
            }
            self.history.append(metrics)
            if final:
                self.final = metrics
            elif self.report is not None:
                self.report(metrics)

    return CoverageReport


def __getattr__(name: str) -> Any:
    if name == "CoverageReport":
        return _coverage_report_class()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def train_with_callback(cfg: TrainConfig, callback: Any) -> Path:
    """``train(cfg)`` with ``callback`` added to SB3's ``learn``."""
    from .train import train

    return train(cfg, callbacks=[callback])


def results_table(grid: Any, keys: list[str], total_timesteps: int) -> tuple[str, list[dict[str, Any]]]:
    """The markdown table (best certified coverage first) and CSV rows of a Tune ``ResultGrid``."""
    rows: list[dict[str, Any]] = []
    results = list(grid)
    trials = getattr(getattr(grid, "_experiment_analysis", None), "trials", None)  # aligned with the results
    if trials is None or len(trials) != len(results):
        trials = [None] * len(results)
    for result, trial in zip(results, trials):
        conf = result.config or getattr(trial, "config", None) or {}
        metrics = result.metrics or {}
        tid = getattr(trial, "trial_id", None) or metrics.get("trial_id") or Path(str(result.path)).name
        row: dict[str, Any] = {"trial": tid}
        for k in keys:
            head, _, sub = k.partition(".")
            row[k] = conf.get(head, {}).get(sub) if sub else conf.get(k)
        df = result.metrics_dataframe
        has = df is not None and "certified_coverage" in df
        row["best_certified"] = float(df["certified_coverage"].max()) if has else float("nan")
        row["last_certified"] = float(metrics.get("certified_coverage", float("nan")))
        row["last_true"] = float(metrics.get("true_coverage", float("nan")))
        row["timesteps"] = int(metrics.get("timesteps", 0))
        row["evals"] = int(metrics.get("training_iteration", 0))
        status = str(getattr(trial, "status", "TERMINATED"))
        if result.error or status == "ERROR":
            row["status"] = "error"
        elif status == "TERMINATED":
            row["status"] = "done" if row["timesteps"] >= total_timesteps else "stopped early"
        else:  # PENDING / RUNNING / PAUSED: an interrupted sweep (resume it)
            row["status"] = status.lower()
        rows.append(row)
    rows.sort(key=lambda r: -r["best_certified"] if np.isfinite(r["best_certified"]) else np.inf)

    def fmt(v: Any) -> str:
        return f"{v:.4g}" if isinstance(v, float) else str(v)

    cols = list(rows[0]) if rows else ["trial"]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(fmt(r[c]) for c in cols) + " |" for r in rows]
    return "\n".join(lines), rows


def run_sweep(
    cfg: SweepConfig, address: str | None = None, resume: bool = False, num_cpus: int | None = None
) -> tuple[str, Path]:
    """Run (or with ``resume``, restore and finish) the sweep; returns the markdown table and the CSV path.

    Args:
        cfg: The sweep.
        address: Ray cluster to attach to; None starts a local instance (shut down at the end).
        resume: Restore the interrupted experiment ``<storage_path>/<name>`` (finished trials are kept;
            unfinished and errored ones train again).
        num_cpus: CPUs of the local instance (None: all).

    Raises:
        ValueError: ``resume`` without an experiment to restore, or a new sweep over an existing one.
    """
    import ray
    from ray import tune
    from ray.tune.schedulers import ASHAScheduler

    from .ray_eval import start_ray

    path = cfg.experiment_path()
    trainable = tune.with_resources(
        tune.with_parameters(sweep_trial, sweep=cfg.to_dict()),
        {"cpu": cfg.cpus_per_trial, "gpu": cfg.gpus_per_trial},
    )
    started = start_ray(address, num_cpus)
    try:
        exists = tune.Tuner.can_restore(path)
        if resume:
            if not exists:
                raise ValueError(f"resume: no sweep to restore at {path!r}")
            tuner = tune.Tuner.restore(path, trainable=trainable, resume_unfinished=True, resume_errored=True)
        else:
            if exists:
                raise ValueError(f"name: a sweep already exists at {path!r}; pass resume=True or a new name")
            base = cfg.base_config()
            max_t = -(-base.total_timesteps // (base.eval_freq or base.total_timesteps)) + 1  # ceil + 1
            scheduler = None
            if cfg.scheduler == "asha":
                scheduler = ASHAScheduler(max_t=max_t, grace_period=min(cfg.grace_period, max_t),
                                          reduction_factor=cfg.reduction_factor)  # fmt: skip
            stop = {"certified_coverage": cfg.stop_coverage} if cfg.stop_coverage > 0 else None
            tuner = tune.Tuner(
                trainable,
                param_space=cfg.param_space(),
                tune_config=tune.TuneConfig(metric=cfg.metric, mode="max", scheduler=scheduler,
                                            num_samples=cfg.num_samples,
                                            max_concurrent_trials=cfg.max_concurrent_trials or None),
                run_config=tune.RunConfig(name=cfg.name, storage_path=str(Path(cfg.storage_path).resolve()),
                                          stop=stop, verbose=1),
            )  # fmt: skip
        grid = tuner.fit()
        table, rows = results_table(grid, cfg.space_keys(), cfg.base_config().total_timesteps)
    finally:
        if started:
            ray.shutdown()
    csv_path = _write_csv(rows, path)
    return table, csv_path


def _write_csv(rows: list[dict[str, Any]], path: str) -> Path:
    import csv

    out = Path(path) / "results.csv"
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]) if rows else ["trial"])
        w.writeheader()
        w.writerows(rows)
    return out


def add_cli(subparsers: Any) -> Callable[[argparse.Namespace], int]:
    """Add ``sweep CONFIG [--address A] [--resume] [--num-cpus N]`` to ``subparsers``; return the handler
    (also set as the parser's ``func`` default), which prints the table and the CSV path and returns 0."""
    p = subparsers.add_parser("sweep", help="hyper-parameter and seed sweep of the PPO recipe on Ray Tune")
    p.add_argument(
        "config", help="sweep configuration (.toml or .json), see agents/configs/sweep_example.toml"
    )
    p.add_argument("--address", default=None, help="Ray cluster to attach to (e.g. auto); default: local")
    p.add_argument("--resume", action="store_true", help="restore an interrupted sweep of the same name")
    p.add_argument("--num-cpus", type=int, default=None, help="CPUs of the local Ray instance")

    def handler(args: argparse.Namespace) -> int:
        table, csv_path = run_sweep(SweepConfig.from_file(args.config), address=args.address,
                                    resume=args.resume, num_cpus=args.num_cpus)  # fmt: skip
        print(table)
        print(f"results: {csv_path}")
        return 0

    p.set_defaults(func=handler)
    return handler


__all__ = ["FIXED_KEYS", "SPACE_KINDS", "SweepConfig", "add_cli", "evaluate_coverage",
           "results_table", "run_sweep", "sweep_trial", "train_with_callback"]  # fmt: skip
