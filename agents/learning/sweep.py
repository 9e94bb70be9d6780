"""Hyper-parameter and seed sweeps of the PPO recipe on Ray Tune (``digslam sweep CONFIG``).

A :class:`SweepConfig` (TOML or JSON, unknown keys rejected) names a base
:class:`~digslam.agents.learning.train_config.TrainConfig` (file or table), a search space over its keys
(:data:`SPACE_KINDS`: ``grid``, ``choice``, ``uniform``, ``loguniform``, ``randint``; ``env_kwargs`` takes a
nested table), the seeds (a grid dimension), the samples per grid point, the CPUs per trial, early stopping
on certified coverage (ASHA and/or a threshold) and where results land. :func:`run_sweep` runs one Tune
trial per configuration; each trial is the project's own :func:`~digslam.agents.learning.train.train` with a
:class:`CoverageReport` callback that evaluates the certified coverage on the held-out maps of the
``TrainConfig`` (``eval_seeds()``) every ``eval_freq`` timesteps and reports it with ``tune.report``.

Results land in ``<storage_path>/<name>/``: Tune's experiment state (what :func:`run_sweep` with
``resume=True`` restores with ``Tuner.restore``), ``models/<trial id>/`` (each trial's ``out_dir``: final
and best-coverage models, config, TensorBoard logs) and ``results.csv`` plus the markdown table returned.

The configuration lives in :mod:`.sweep_config`; the ``digslam sweep`` command in
:mod:`digslam.agents.cli.distributed`.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from digslam.agents.learning.sweep_config import FIXED_KEYS, SPACE_KINDS, SweepConfig
from digslam.agents.learning.train_config import TrainConfig
from digslam.agents.learning.vec_env import EnvFactory

if TYPE_CHECKING:  # the types; stable-baselines3 is imported by the trials only
    from stable_baselines3.common.callbacks import BaseCallback

    from digslam.agents.common.policy import PolicyPredictor


def sweep_trial(params: dict[str, Any], sweep: dict[str, Any]) -> None:
    """One Tune trial: the base ``TrainConfig`` with ``params``, trained by ``train`` while
    :class:`CoverageReport` reports the held-out certified coverage (``eval_freq`` 0 in the config passed
    to ``train``: this callback replaces SB3's reward-based evaluation)."""
    from ray import tune

    cfg = SweepConfig.from_dict(sweep)
    base = cfg.base_config()
    data = base.to_dict()
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


def evaluate_coverage(model: PolicyPredictor, cfg: TrainConfig, eval_steps: int = 0) -> tuple[float, float]:
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


def train_with_callback(cfg: TrainConfig, callback: BaseCallback) -> Path:
    """``train(cfg)`` with ``callback`` added to SB3's ``learn``."""
    from digslam.agents.learning.train import train

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

    from digslam.agents.evaluation.ray_pool import start_ray

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


__all__ = [
    "FIXED_KEYS",
    "SPACE_KINDS",
    "SweepConfig",
    "evaluate_coverage",
    "results_table",
    "run_sweep",
    "sweep_trial",
    "train_with_callback",
]
