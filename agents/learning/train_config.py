"""The configuration of a training run: :class:`TrainConfig`, read from a TOML or JSON file plus overrides.

:class:`TrainConfig` is a frozen dataclass of the config base (:class:`~digslam.observer.core.config.Config`):
:meth:`~digslam.observer.core.config.Config.from_file` reads ``.toml`` or ``.json`` (None:
:data:`DEFAULT_CONFIG`, the recipe of the shipped low-level policy) and
:meth:`~digslam.observer.core.config.Config.override` applies ``key=value`` strings
(``env_kwargs.map_size=40`` sets one environment keyword); unknown keys and badly typed values raise
``ValueError`` naming the key. :func:`~digslam.agents.learning.train.train` runs it.

>>> cfg = TrainConfig().override(["n_envs=1", "env_kwargs.map_size=40"])
>>> cfg.n_envs, cfg.env_kwargs["map_size"], cfg.eval_seeds()[:2]  # validation levels (digslam.envs.splits)
(1, 40, (1000000, 1000001))
>>> TrainConfig.from_dict({"n_env": 2})  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: TrainConfig: unknown key(s) ['n_env']; known: ...
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import field, fields
from pathlib import Path
from typing import Any

from digslam.agents.goals.teacher import TEACHERS
from digslam.agents.learning.wrappers import ACTION_MODES
from digslam.envs.splits import VALIDATION, check_not_test
from digslam.observer.core.config import Config, config_dataclass

#: The default configuration file (the recipe of the shipped low-level policy).
DEFAULT_CONFIG = Path(__file__).parents[1] / "configs" / "ppo_digcoverage.toml"
#: The learning algorithms of :class:`TrainConfig` (``algo``).
ALGOS = ("ppo", "maskable_ppo")
#: The goal-selection networks of :class:`TrainConfig` (``policy``).
POLICIES = ("mlp", "attention")


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
        resume: Continue the run in ``out_dir`` from its latest saved model
            (:func:`~.checkpoints.latest_checkpoint`: the checkpoints and ``interrupted_model.zip``) up to
            ``total_timesteps``; a fresh start when there is none.
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

    @classmethod
    def from_file(cls, path: str | Path | None = None, overrides: Iterable[str] = ()) -> TrainConfig:
        """Read a ``.toml`` or ``.json`` file (None: :data:`DEFAULT_CONFIG`), then apply ``overrides``
        (:meth:`~digslam.observer.core.config.Config.from_file`)."""
        return super().from_file(path if path is not None else DEFAULT_CONFIG, overrides)


__all__ = ["ALGOS", "DEFAULT_CONFIG", "POLICIES", "TrainConfig"]
