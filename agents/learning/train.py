"""PPO training on the certified-coverage environments (stable-baselines3), from a config file plus overrides.

:class:`TrainConfig` is a frozen dataclass read from TOML or JSON with ``key=value`` overrides
(``env_kwargs.map_size=40`` sets one environment keyword); unknown keys and badly typed values raise
``ValueError`` naming the key. :func:`train` runs SB3's ``PPO("MultiInputPolicy")`` with the
:class:`~digslam.agents.learning.extractor.MapStateExtractor`, ``SubprocVecEnv`` workers (spawn-safe: the
factory
:class:`EnvFactory` is a picklable module-level object and uses the ``"digslam.envs:<id>"`` form),
TensorBoard logs, checkpoints, evaluation on held-out map seeds and a progress bar. Torch is pinned to
``torch_threads`` threads in every process (one thread is several times faster on small machines).

>>> cfg = TrainConfig().override(["n_envs=1", "env_kwargs.map_size=40"])
>>> cfg.n_envs, cfg.env_kwargs["map_size"], cfg.eval_seeds()[:2]  # validation levels (digslam.envs.splits)
(1, 40, (1000000, 1000001))
>>> TrainConfig.from_dict({"n_env": 2})  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: TrainConfig: unknown key(s) ['n_env']; known: ...
"""

from __future__ import annotations

import json
import math
import os
import signal
import threading
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from digslam.agents.goals.teacher import TEACHERS
from digslam.agents.learning.wrappers import ACTION_MODES, wrap_training_env
from digslam.envs.splits import VALIDATION, check_not_test
from digslam.observer.core.config import Config, config_dataclass

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

#: The default configuration file (the recipe of the shipped policy).
DEFAULT_CONFIG = Path(__file__).parents[1] / "configs" / "ppo_digcoverage.toml"


def _default_env_kwargs() -> dict[str, Any]:
    return {"map_size": 36, "crop": 4.0, "fixed_world": False}


@config_dataclass
class TrainConfig(Config):
    """A PPO training run (all fields type-checked; see the module docstring).

    Attributes:
        env_id: Registered environment id (``digslam/...``).
        env_kwargs: Keyword arguments of ``gym.make`` (e.g. ``map_size``, ``crop``, ``max_episode_steps``).
        n_envs: Parallel environments (``SubprocVecEnv`` if > 1).
        total_timesteps: Environment steps to train for.
        seed: Seed of the model and of the training envs (env ``i`` is seeded ``seed + i``).
        learning_rate, n_steps, batch_size, n_epochs, gamma, ent_coef: PPO's hyperparameters (``n_steps``
            per environment).
        features_dim: Output size of the features extractor.
        eval_freq: Timesteps between evaluations on the held-out maps (0: none).
        eval_maps: Number of held-out maps (seeds ``eval_seed, eval_seed + 1, ...``).
        eval_seed: First held-out seed (default: the validation split's first, :mod:`digslam.envs.splits`);
            the held-out seeds must not meet the training seeds, and neither may lie in the test split.
        checkpoint_freq: Timesteps between checkpoints (0: none).
        out_dir: Folder for the model, checkpoints, TensorBoard logs and evaluations.
        device: Torch device (``"cpu"``).
        torch_threads: Torch threads per process.
        progress_bar: Show SB3's progress bar.
        verbose: SB3 verbosity.
        actions: ``"continuous"`` (the env's ``(v, ω)`` box) or ``"turn_go"`` (discrete drive-straight or
            turn-in-place actions, :class:`~.wrappers.TurnGoActions`: the deterministic policy is then one
            of the actions it was trained on).
        tube_penalty: Reward units per metre of growth of the pose box's widest side
            (:class:`~.wrappers.TubePenalty`; 0: none).
        algo: ``"ppo"`` (stable-baselines3) or ``"maskable_ppo"`` (sb3-contrib's ``MaskablePPO``, for the
            goal-selection envs of :mod:`digslam.agents.goals`, whose invalid candidates are masked).
        resume: Continue the run in ``out_dir`` from its latest saved model (:func:`latest_checkpoint`: the
            checkpoints and ``interrupted_model.zip``) up to ``total_timesteps``; a fresh start when there is
            none.
        heuristic_prior: With ``maskable_ppo``: the initial logit of candidate ``k`` is
            ``heuristic_prior * (1 - k / K)`` (the candidates come sorted by the frontier heuristic's cost,
            so the untrained policy already prefers the heuristic's pick; 0: uniform).
        policy: With ``maskable_ppo``: ``"attention"`` (:class:`~.attention.CandidateAttentionPolicy`: one
            network scores every candidate, after self-attention over the valid ones; ``features_dim`` is a
            candidate's vector) or ``"mlp"`` (an MLP on the flattened candidate features and globals).
        warm_start: With ``maskable_ppo``, before PPO: ``"frontier"``, ``"rollout"`` or
            ``"rollout_fresh_noise"`` (:data:`~digslam.agents.goals.teacher.TEACHERS`), the teacher whose
            picks the policy is first fitted to (:mod:`.warm_start`; ``""``: none). The fitted policy is also
            saved as ``warm_start_model.zip``.
        warm_start_levels: Training levels of the first warm-start round (seeds from
            :data:`.warm_start.DEMO_SEED` on; every round plays new ones).
        warm_start_rounds: Rounds of the warm start: the teacher drives the first; in each further one the
            policy fitted so far drives and the teacher labels its decisions (DAgger).
        dagger_levels: Levels of each round after the first (0: ``warm_start_levels``).
        bc_epochs: Epochs of the behaviour-cloning fit (each round).
    """

    env_id: str = "digslam/DigCoverage-v0"
    env_kwargs: dict[str, Any] = field(default_factory=_default_env_kwargs)
    n_envs: int = 2
    total_timesteps: int = 245_760
    seed: int = 0
    learning_rate: float = 3e-4
    n_steps: int = 512
    batch_size: int = 128
    n_epochs: int = 4
    gamma: float = 0.99
    ent_coef: float = 0.0
    features_dim: int = 128
    eval_freq: int = 40_960
    eval_maps: int = 3
    eval_seed: int = VALIDATION.start
    checkpoint_freq: int = 10_240
    out_dir: str = "runs/ppo_digcoverage"
    device: str = "cpu"
    torch_threads: int = 1
    progress_bar: bool = True
    verbose: int = 0
    actions: str = "continuous"
    tube_penalty: float = 0.0
    algo: str = "ppo"
    heuristic_prior: float = 0.0
    policy: str = "mlp"
    warm_start: str = ""
    warm_start_levels: int = 16
    warm_start_rounds: int = 1
    dagger_levels: int = 0
    bc_epochs: int = 20
    resume: bool = False

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            want = {"dict[str, Any]": dict, "float": float, "int": int, "str": str, "bool": bool}[str(f.type)]
            if want is float and isinstance(v, int) and not isinstance(v, bool):
                object.__setattr__(self, f.name, float(v))
            elif not isinstance(v, want) or (want is int and isinstance(v, bool)):
                raise ValueError(f"{f.name}: must be {want.__name__}, got {v!r} ({type(v).__name__})")
        positive = ("n_envs", "total_timesteps", "n_steps", "batch_size", "n_epochs", "features_dim",
                    "eval_maps", "torch_threads", "warm_start_levels", "warm_start_rounds",
                    "bc_epochs")  # fmt: skip
        for name in positive:
            if getattr(self, name) < 1:
                raise ValueError(f"{name}: must be >= 1, got {getattr(self, name)!r}")
        for name in ("eval_freq", "checkpoint_freq", "ent_coef", "seed", "eval_seed", "dagger_levels"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name}: must be >= 0, got {getattr(self, name)!r}")
        if self.actions not in ACTION_MODES:
            raise ValueError(f"actions: must be one of {ACTION_MODES}, got {self.actions!r}")
        if self.algo not in ALGOS:
            raise ValueError(f"algo: must be one of {ALGOS}, got {self.algo!r}")
        if self.policy not in POLICIES:
            raise ValueError(f"policy: must be one of {POLICIES}, got {self.policy!r}")
        if self.warm_start not in ("", *TEACHERS):
            raise ValueError(f"warm_start: must be one of {('', *TEACHERS)}, got {self.warm_start!r}")
        if self.warm_start and self.algo != "maskable_ppo":
            raise ValueError('warm_start: a teacher picks candidate goals; it needs algo = "maskable_ppo"')
        if self.policy == "attention" and self.algo != "maskable_ppo":
            raise ValueError('policy: "attention" scores candidate goals; it needs algo = "maskable_ppo"')
        if not (math.isfinite(self.heuristic_prior) and self.heuristic_prior >= 0):
            raise ValueError(f"heuristic_prior: must be finite and >= 0, got {self.heuristic_prior!r}")
        if not (math.isfinite(self.tube_penalty) and self.tube_penalty >= 0):
            raise ValueError(f"tube_penalty: must be finite and >= 0, got {self.tube_penalty!r}")
        if not 0.0 < self.learning_rate < 1.0:
            raise ValueError(f"learning_rate: must be in (0, 1), got {self.learning_rate!r}")
        if not 0.0 < self.gamma <= 1.0:
            raise ValueError(f"gamma: must be in (0, 1], got {self.gamma!r}")
        if set(self.train_seeds()) & set(self.eval_seeds()):
            raise ValueError(
                f"eval_seed: held-out seeds {self.eval_seeds()} meet the training seeds {self.train_seeds()}"
            )
        check_not_test("seed", self.train_seeds())  # the benchmark's levels stay unseen
        check_not_test("eval_seed", self.eval_seeds())

    def train_seeds(self) -> tuple[int, ...]:
        """Seeds of the training environments."""
        return tuple(range(self.seed, self.seed + self.n_envs))

    def eval_seeds(self) -> tuple[int, ...]:
        """Seeds of the held-out evaluation maps."""
        return tuple(range(self.eval_seed, self.eval_seed + self.eval_maps))

    # --- construction (``from_dict``, ``replace`` and ``to_dict`` come from the config base) ----------------
    @classmethod
    def from_file(cls, path: str | Path | None = None, overrides: Iterable[str] = ()) -> TrainConfig:
        """Read a ``.toml`` or ``.json`` file (None: :data:`DEFAULT_CONFIG`), then apply ``overrides``."""
        return cls.from_dict(read_config_file(path if path is not None else DEFAULT_CONFIG)).override(
            overrides
        )

    def override(self, overrides: Iterable[str]) -> TrainConfig:
        """Apply ``key=value`` strings (values parsed as TOML literals, else taken as strings)."""
        return TrainConfig.from_dict(apply_overrides(self.to_dict(), overrides, dotted=("env_kwargs",)))


def read_config_file(path: str | Path) -> dict[str, Any]:
    """The table of settings in a ``.toml`` or ``.json`` file; ``ValueError`` saying what is wrong."""
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"path: no configuration file {str(p)!r}")
    if p.suffix not in (".json", ".toml"):
        raise ValueError(f"path: configuration must be .toml or .json, got {str(p)!r}")
    try:
        text = p.read_text()
        data = json.loads(text) if p.suffix == ".json" else tomllib.loads(text)
    except (OSError, UnicodeDecodeError, ValueError) as exc:  # TOMLDecodeError, JSONDecodeError
        raise ValueError(f"path: cannot read {str(p)!r} as {p.suffix[1:].upper()} ({exc})") from None
    if not isinstance(data, dict):
        raise ValueError(f"path: {str(p)!r} must hold a table of settings, got {type(data).__name__}")
    return data


def apply_overrides(data: Mapping[str, Any], overrides: Iterable[str],
                    dotted: Sequence[str] = ()) -> dict[str, Any]:  # fmt: skip
    """``data`` with ``key=value`` strings applied (values parsed as TOML literals, else taken as strings);
    ``head.sub=value`` sets one entry of a table field named in ``dotted``."""
    data = dict(data)
    for item in overrides:
        key, sep, raw = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ValueError(f"overrides: expected key=value, got {item!r}")
        value = parse_value(raw.strip())
        head, _, sub = key.partition(".")
        if head not in data:
            raise ValueError(f"{head}: unknown key; known: {sorted(data)}")
        if sub:
            if head not in dotted:
                raise ValueError(f"{key}: only {' and '.join(dotted)} takes dotted keys" if dotted
                                 else f"{key}: no key takes dotted keys")  # fmt: skip
            data[head] = {**data[head], sub: value}
        else:
            data[head] = value
    return data


def parse_value(raw: str) -> Any:
    """A TOML literal (``3``, ``1e-4``, ``true``, ``"x"``, ``{map_size = 40}``), or the raw string."""
    try:
        return tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        return raw


def pin_threads(n: int) -> None:
    """Pin torch (and the BLAS/OpenMP pools of child processes) to ``n`` threads."""
    for var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
        os.environ[var] = str(n)
    import torch

    torch.set_num_threads(n)


class SeedCycle(gym.Wrapper):
    """Unseeded resets walk through ``seeds`` in turn (the held-out maps of the evaluation callback)."""

    def __init__(self, env: gym.Env, seeds: tuple[int, ...]) -> None:
        super().__init__(env)
        self.seeds, self.k = tuple(seeds), 0

    def reset(self, *, seed: int | None = None, options: Any = None) -> Any:
        if seed is None:
            seed, self.k = self.seeds[self.k % len(self.seeds)], self.k + 1
        return self.env.reset(seed=seed, options=options)


@dataclass(frozen=True)
class EnvFactory:
    """Picklable environment factory for vectorized envs (``spawn``-safe).

    Args:
        env_id: Registered id; made as ``"digslam.envs:<id>"`` so a fresh worker imports the package.
        env_kwargs: ``gym.make`` keyword arguments.
        torch_threads: Torch threads in the worker.
        seeds: If given, unseeded resets cycle through these seeds (held-out evaluation maps).
        actions, tube_penalty: The training wrappers (:func:`~.wrappers.wrap_training_env`).
    """

    env_id: str
    env_kwargs: Mapping[str, Any] = field(default_factory=dict)
    torch_threads: int = 1
    seeds: tuple[int, ...] | None = None
    actions: str = "continuous"
    tube_penalty: float = 0.0

    def __call__(self) -> Any:
        from stable_baselines3.common.monitor import Monitor

        pin_threads(self.torch_threads)
        env_id = self.env_id if ":" in self.env_id else f"{env_module(self.env_id)}:{self.env_id}"
        env = gym.make(env_id, **dict(self.env_kwargs))
        env = wrap_training_env(env, self.actions, self.tube_penalty)
        if self.seeds:
            env = SeedCycle(env, self.seeds)
        return Monitor(env)


def make_vec_env(factory: EnvFactory, n: int, seed: int) -> Any:
    """``n`` copies of ``factory``: a ``DummyVecEnv`` if ``n == 1``, else a spawn ``SubprocVecEnv``;
    env ``i`` is seeded ``seed + i``."""
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    fns = [factory] * n
    vec = DummyVecEnv(fns) if n == 1 else SubprocVecEnv(fns, start_method="spawn")
    vec.seed(seed)
    return vec


#: The learning algorithms of :class:`TrainConfig` (``algo``).
ALGOS = ("ppo", "maskable_ppo")
#: The goal-selection networks of :class:`TrainConfig` (``policy``).
POLICIES = ("mlp", "attention")


def env_module(env_id: str) -> str:
    """The module that registers ``env_id`` (``gym.make("<module>:<id>")`` imports it first in a fresh
    worker): :mod:`digslam.agents.goals` for the goal-selection ids, else :mod:`digslam.envs`."""
    return "digslam.agents.goals" if env_id.split("/")[-1].startswith("DigCoverageGoals") else "digslam.envs"


def _ppo_kwargs(cfg: TrainConfig, tensorboard_log: str | None) -> dict[str, Any]:
    """The PPO hyperparameters of ``cfg`` that PPO and MaskablePPO share."""
    return {"learning_rate": cfg.learning_rate, "n_steps": cfg.n_steps, "batch_size": cfg.batch_size,
            "n_epochs": cfg.n_epochs, "gamma": cfg.gamma, "ent_coef": cfg.ent_coef,
            "tensorboard_log": tensorboard_log, "seed": cfg.seed, "device": cfg.device,
            "verbose": cfg.verbose}  # fmt: skip


def build_maskable(cfg: TrainConfig, env: Any, tensorboard_log: str | None = None) -> Any:
    """sb3-contrib's ``MaskablePPO`` of ``cfg`` on the vectorized goal-selection ``env``, its logits started
    from the heuristic's ranking (``cfg.heuristic_prior``): with ``policy = "attention"``
    :class:`~.attention.CandidateAttentionPolicy` (``d = features_dim``), else an MLP on the flattened
    candidate features and globals (``MultiInputPolicy``) whose output bias carries the prior."""
    import torch
    from sb3_contrib import MaskablePPO

    if cfg.policy == "attention":
        from digslam.agents.learning.attention import CandidateAttentionPolicy

        heads = 4 if cfg.features_dim % 4 == 0 else 1
        kw = {"d": cfg.features_dim, "heads": heads, "heuristic_prior": cfg.heuristic_prior}
        ppo = _ppo_kwargs(cfg, tensorboard_log)
        return MaskablePPO(CandidateAttentionPolicy, env, policy_kwargs=kw, **ppo)
    arch = {"pi": [cfg.features_dim, 64], "vf": [cfg.features_dim, 64]}
    model = MaskablePPO(
        "MultiInputPolicy", env, policy_kwargs={"net_arch": arch}, **_ppo_kwargs(cfg, tensorboard_log)
    )
    if cfg.heuristic_prior:
        n = int(env.action_space.n)
        with torch.no_grad():
            head = model.policy.action_net
            head.weight.mul_(0.01)  # start from the prior, not from the random projection
            head.bias.copy_(torch.tensor([cfg.heuristic_prior * (1.0 - k / n) for k in range(n)]))
    return model


def latest_checkpoint(out: str | Path) -> tuple[Path, int] | None:
    """The saved model of the run in ``out`` with the most timesteps, and that count: the checkpoints
    (``checkpoints/*.zip``) and ``interrupted_model.zip``; None when there is none."""
    from stable_baselines3.common.save_util import load_from_zip_file

    out = Path(out)
    best: tuple[Path, int] | None = None
    for path in [*sorted((out / "checkpoints").glob("*.zip")), out / "interrupted_model.zip"]:
        if not path.is_file():
            continue
        try:
            data, _, _ = load_from_zip_file(path, load_data=True, device="cpu")
            steps = int((data or {}).get("num_timesteps", -1))
        except Exception:  # noqa: BLE001 - a damaged file is not a checkpoint to resume from
            continue
        if steps >= 0 and (best is None or steps > best[1]):
            best = (path, steps)
    return best


def load_model(cfg: TrainConfig, path: Path, env: Any, tensorboard_log: str | None = None) -> Any:
    """The model saved at ``path`` (``cfg.algo``'s class) on ``env``, to continue training."""
    if cfg.algo == "maskable_ppo":
        from sb3_contrib import MaskablePPO as Algo
    else:
        from stable_baselines3 import PPO as Algo
    return Algo.load(path, env=env, device=cfg.device, tensorboard_log=tensorboard_log)


def build_model(cfg: TrainConfig, env: Any, tensorboard_log: str | None = None) -> Any:
    """The model of ``cfg`` on the vectorized ``env``: PPO with the map-state extractor, or
    :func:`build_maskable` with ``algo = "maskable_ppo"``."""
    if cfg.algo == "maskable_ppo":
        return build_maskable(cfg, env, tensorboard_log)
    from stable_baselines3 import PPO

    from digslam.agents.learning.extractor import MapStateExtractor

    policy_kwargs = {
        "features_extractor_class": MapStateExtractor,
        "features_extractor_kwargs": {"features_dim": cfg.features_dim},
        "net_arch": {"pi": [64], "vf": [64]},
    }
    return PPO("MultiInputPolicy", env, policy_kwargs=policy_kwargs, **_ppo_kwargs(cfg, tensorboard_log))


class TrainingInterrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`train`: the model so far was saved to ``path`` after ``timesteps`` steps."""

    def __init__(self, path: Path, timesteps: int) -> None:
        super().__init__(f"interrupted after {timesteps} timesteps; saved {path}")
        self.path, self.timesteps = path, timesteps


def train(cfg: TrainConfig, callbacks: Sequence[Any] = (), worker_guard: Any = None) -> Path:
    """Train PPO as ``cfg`` says; returns the saved final model (``<out_dir>/final_model.zip``).

    ``callbacks`` are extra SB3 callbacks given to ``learn`` (e.g. the Ray Tune reporter of
    :mod:`.sweep`). ``worker_guard`` is a context manager held while the worker processes start (the
    command line's ignores SIGINT there, so Ctrl-C reaches the main process only). Ctrl-C during ``learn``
    saves the model so far to ``<out_dir>/interrupted_model.zip`` and raises :class:`TrainingInterrupted`:
    in the main thread SIGINT only sets a flag that a callback reads at the next environment step, so the
    signal never lands inside a kernel being compiled or a half-done update.

    ``out_dir`` also gets ``config.json``, ``checkpoints/``, ``tb/`` (TensorBoard), and with evaluation
    ``best_model.zip`` and ``eval/evaluations.npz`` (held-out maps ``cfg.eval_seeds()``). Every model
    saved here has its sidecar ``<model>.json`` (:func:`write_sidecar`); a checkpoint's keywords are read
    from ``config.json`` one folder up.
    """
    from stable_baselines3.common.callbacks import BaseCallback, CheckpointCallback, EvalCallback

    class _StopOnSigint(BaseCallback):  # type: ignore[misc]
        """Stops ``learn`` at the next step once SIGINT has set the flag."""

        def __init__(self) -> None:
            super().__init__()
            self.flag = False

        def _on_step(self) -> bool:
            return not self.flag

    pin_threads(cfg.torch_threads)
    out = Path(cfg.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "config.json").write_text(json.dumps(cfg.to_dict(), indent=2))
    try:
        import tensorboard  # noqa: F401

        tb: str | None = str(out / "tb")
    except ImportError:
        tb = None
    import contextlib

    with worker_guard if worker_guard is not None else contextlib.nullcontext():
        factory = EnvFactory(
            cfg.env_id, cfg.env_kwargs, cfg.torch_threads, None, cfg.actions, cfg.tube_penalty
        )
        env = make_vec_env(factory, cfg.n_envs, cfg.seed)
    callbacks = list(callbacks)
    eval_env = None
    try:
        if cfg.checkpoint_freq:
            every = max(cfg.checkpoint_freq // cfg.n_envs, 1)
            callbacks.append(CheckpointCallback(every, str(out / "checkpoints"), name_prefix="ppo"))
        if cfg.eval_freq:
            seeds = cfg.eval_seeds()
            held_out = EnvFactory(cfg.env_id, cfg.env_kwargs, cfg.torch_threads, seeds, cfg.actions)
            eval_env = make_vec_env(held_out, 1, seeds[0])
            if cfg.algo == "maskable_ppo":
                from sb3_contrib.common.maskable.callbacks import MaskableEvalCallback as EvalCallback
            callbacks.append(
                EvalCallback(
                    eval_env,
                    n_eval_episodes=cfg.eval_maps,
                    eval_freq=max(cfg.eval_freq // cfg.n_envs, 1),
                    log_path=str(out / "eval"),
                    best_model_save_path=str(out),
                    deterministic=True,
                    verbose=cfg.verbose,
                )
            )
        last = latest_checkpoint(out) if cfg.resume else None
        model = build_model(cfg, env, tb) if last is None else load_model(cfg, last[0], env, tb)
        if last is None and cfg.warm_start:
            _warm_start(cfg, model, out)
        todo = cfg.total_timesteps - (last[1] if last is not None else 0)
        if last is not None and cfg.verbose:
            print(f"resuming from {last[0]} at {last[1]} timesteps")
        bar = _has_progress() and cfg.progress_bar
        with warnings.catch_warnings():  # Subproc training env vs Dummy eval env is intended
            warnings.filterwarnings("ignore", message="Training and eval env are not of the same type")
            stop = _StopOnSigint()
            main = threading.current_thread() is threading.main_thread()
            old = signal.signal(signal.SIGINT, lambda *_: setattr(stop, "flag", True)) if main else None
            try:
                if todo > 0:
                    model.learn(todo, callback=[*callbacks, stop], progress_bar=bar,
                                reset_num_timesteps=last is None)  # fmt: skip
                interrupted = stop.flag
            except KeyboardInterrupt:
                interrupted = True
            finally:
                if main:
                    signal.signal(signal.SIGINT, old)
            if interrupted:
                path = out / "interrupted_model.zip"
                _save(model, path, cfg)
                raise TrainingInterrupted(path, int(model.num_timesteps)) from None
        path = out / "final_model.zip"
        _save(model, path, cfg)
        if (out / "best_model.zip").is_file():
            write_sidecar(out / "best_model.zip", cfg)
    finally:
        env.close()
        if eval_env is not None:
            eval_env.close()
    return path


def _warm_start(cfg: TrainConfig, model: Any, out: Path) -> None:
    """Fit ``model`` to ``cfg.warm_start``'s picks (:mod:`.warm_start`): the teacher drives the first
    ``warm_start_levels`` levels; in each further round (``warm_start_rounds``) the policy fitted so far
    drives ``dagger_levels`` new levels (default as many) while the teacher labels its decisions (DAgger),
    and the fit goes on over everything. Saves ``warm_start_model.zip`` and ``warm_start.json``
    (decisions, the teacher's share of non-first picks, accuracy per epoch, per round)."""
    from digslam.agents.learning import warm_start as ws

    say = print if cfg.verbose else None
    n, more = cfg.warm_start_levels, cfg.dagger_levels or cfg.warm_start_levels
    rounds: list[dict[str, Any]] = []
    parts: list[dict[str, np.ndarray]] = []
    for r in range(cfg.warm_start_rounds):
        actor = None
        if r:
            actor = out / f"warm_start_round{r}.zip"
            _save(model, actor, cfg)
        first, size = (0, n) if r == 0 else (n + (r - 1) * more, more)
        parts.append(ws.collect(cfg.env_id, cfg.env_kwargs, cfg.warm_start, size, out, workers=cfg.n_envs,
                                log=say, first=first, actor=actor))  # fmt: skip
        data = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
        acc = ws.clone(model, data, epochs=cfg.bc_epochs, seed=cfg.seed + r)
        picks = data["action"]
        rounds.append({"decisions": int(len(picks)), "not_first": float(np.mean(picks != 0)),
                       "accuracy": acc})  # fmt: skip
        if say is not None:
            say(f"warm start round {r}: {rounds[-1]['decisions']} decisions, accuracy {acc[-1]:.3f}")
    report = {"teacher": cfg.warm_start, "levels": n + more * (cfg.warm_start_rounds - 1), "rounds": rounds}
    (out / "warm_start.json").write_text(json.dumps(report, indent=2))
    _save(model, out / "warm_start_model.zip", cfg)


def write_sidecar(path: Path, cfg: TrainConfig) -> Path:
    """Write ``<model>.json`` beside the model ``path``: the environment id and keywords it was trained
    with, which ``demo``, ``evaluate``, ``record`` and ``benchmark`` read
    (:func:`~digslam.agents.learning.models.model_env_kwargs`)."""
    side = path.with_suffix(".json")
    meta = {"env_id": cfg.env_id, "env_kwargs": dict(cfg.env_kwargs), "actions": cfg.actions}
    side.write_text(json.dumps(meta, indent=2))
    return side


def _save(model: Any, path: Path, cfg: TrainConfig) -> None:
    """``model.save`` to a scratch file, then renamed (an interrupted save leaves no half-written model),
    and its sidecar (:func:`write_sidecar`)."""
    tmp = path.with_name(f".{path.stem}.part{os.getpid()}.zip")
    try:
        model.save(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    write_sidecar(path, cfg)


def _has_progress() -> bool:
    try:
        import rich  # noqa: F401
        import tqdm  # noqa: F401
    except ImportError:
        return False
    return True


__all__ = ["DEFAULT_CONFIG", "EnvFactory", "SeedCycle", "TrainConfig", "TrainingInterrupted", "build_model",
           "make_vec_env", "parse_value", "pin_threads", "train", "write_sidecar", "ALGOS", "build_maskable",
           "env_module", "latest_checkpoint", "load_model", "POLICIES"]  # fmt: skip
