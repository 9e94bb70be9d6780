"""Configuration of the Ray Tune sweeps of :mod:`.sweep`: :class:`SweepConfig` and its search space.

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

from collections.abc import Iterable, Mapping
from dataclasses import field, fields
from pathlib import Path
from typing import Any

from digslam.agents.learning.train_config import TrainConfig
from digslam.observer.core.config import Config, config_dataclass, read_config_file, reject_unknown

#: Kinds of search dimension and their argument (a list of values, or ``[low, high]``).
SPACE_KINDS = ("grid", "choice", "uniform", "loguniform", "randint")
#: TrainConfig keys a sweep may not vary (``seed`` comes from ``seeds``; ``out_dir`` is set per trial).
FIXED_KEYS = ("seed", "out_dir")


@config_dataclass
class SweepConfig(Config):
    """A Ray Tune sweep of :func:`~digslam.agents.learning.train.train` (see the module docstring).

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
    def from_dict(
        cls, data: Mapping[str, Any] | None = None, root: str | Path | None = None, **kwargs: Any
    ) -> SweepConfig:
        """Build from a mapping and keyword overrides; unknown keys raise ``ValueError``. A relative ``base``
        path is taken from the working directory, else from ``root`` (the sweep file's folder), and made
        absolute."""
        data = {**(data or {}), **kwargs}
        reject_unknown(cls, data)
        base = data.get("base")
        if isinstance(base, str):  # absolute: trials run in other working directories
            near = Path(root) / base if root is not None else Path(base)
            data["base"] = str(
                (near if near.is_file() and not Path(base).is_file() else Path(base)).resolve()
            )
        return cls(**data)

    @classmethod
    def from_file(cls, path: str | Path, overrides: Iterable[str] = ()) -> SweepConfig:
        """Read a ``.toml`` or ``.json`` sweep file (:func:`~digslam.observer.core.config.read_config_file`;
        a relative ``base`` is taken from the file's folder), then apply ``overrides``."""
        return cls.from_dict(read_config_file(path), root=Path(path).parent).override(overrides)

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
        d = super().to_dict()
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


__all__ = ["FIXED_KEYS", "SPACE_KINDS", "SweepConfig"]
