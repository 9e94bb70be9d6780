"""PPO training on the certified-coverage environments (stable-baselines3): :func:`train` runs a
:class:`~.train_config.TrainConfig`.

The run: the model (:mod:`.algos`) on ``n_envs`` training environments (:mod:`.vec_env`: ``SubprocVecEnv``
workers, spawn-safe, torch pinned to ``torch_threads`` threads in every process), TensorBoard logs,
checkpoints and evaluation on held-out map seeds, a progress bar, an optional behaviour-cloning warm start
(:mod:`.warm_start`), and every model saved with its sidecar (:mod:`.checkpoints`). Ctrl-C saves the model
so far and raises :class:`TrainingInterrupted`.
"""

from __future__ import annotations

import contextlib
import json
import signal
import threading
import warnings
from collections.abc import Sequence
from contextlib import AbstractContextManager
from pathlib import Path
from typing import TYPE_CHECKING, Any

from digslam.agents.learning.algos import build_model, load_model
from digslam.agents.learning.checkpoints import latest_checkpoint, save_model, write_sidecar
from digslam.agents.learning.train_config import TrainConfig
from digslam.agents.learning.vec_env import EnvFactory, make_vec_env, pin_threads

if TYPE_CHECKING:  # stable-baselines3 is imported on use only
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import VecEnv


class TrainingInterrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`train`: the model so far was saved to ``path`` after ``timesteps`` steps."""

    def __init__(self, path: Path, timesteps: int) -> None:
        super().__init__(f"interrupted after {timesteps} timesteps; saved {path}")
        self.path, self.timesteps = path, timesteps


def train(
    cfg: TrainConfig,
    callbacks: Sequence[BaseCallback] = (),
    worker_guard: AbstractContextManager[Any] | None = None,
) -> Path:
    """Train PPO as ``cfg`` says; returns the saved final model (``<out_dir>/final_model.zip``).

    ``callbacks`` are extra SB3 callbacks given to ``learn`` (e.g. the Ray Tune reporter of
    :mod:`.sweep`). ``worker_guard`` is a context manager held while the worker processes start (the
    command line's ignores SIGINT there, so Ctrl-C reaches the main process only). Ctrl-C during ``learn``
    saves the model so far to ``<out_dir>/interrupted_model.zip`` and raises :class:`TrainingInterrupted`:
    in the main thread SIGINT only sets a flag that a callback reads at the next environment step, so the
    signal never lands inside a kernel being compiled or a half-done update.

    ``out_dir`` also gets ``config.json``, ``checkpoints/``, ``tb/`` (TensorBoard), and with evaluation
    ``best_model.zip`` and ``eval/evaluations.npz`` (held-out maps ``cfg.eval_seeds()``). Every model
    saved here has its sidecar ``<model>.json`` (:func:`~.checkpoints.write_sidecar`); a checkpoint's
    keywords are read from ``config.json`` one folder up.
    """
    from stable_baselines3.common.callbacks import BaseCallback, CheckpointCallback, EvalCallback

    class StopOnSigint(BaseCallback):  # type: ignore[misc]  # SB3's classes are untyped (Any) here
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

    with worker_guard if worker_guard is not None else contextlib.nullcontext():
        factory = EnvFactory(
            cfg.env_id, cfg.env_kwargs, cfg.torch_threads, None, cfg.actions, cfg.tube_penalty
        )
        env = make_vec_env(factory, cfg.n_envs, cfg.seed)
    callbacks = list(callbacks)
    eval_env: VecEnv | None = None
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
            from digslam.agents.learning.warm_start import warm_start

            warm_start(cfg, model, out)
        todo = cfg.total_timesteps - (last[1] if last is not None else 0)
        if last is not None and cfg.verbose:
            print(f"resuming from {last[0]} at {last[1]} timesteps")
        bar = _has_progress() and cfg.progress_bar
        with warnings.catch_warnings():  # Subproc training env vs Dummy eval env is intended
            warnings.filterwarnings("ignore", message="Training and eval env are not of the same type")
            stop = StopOnSigint()
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
                save_model(model, path, cfg)
                raise TrainingInterrupted(path, int(model.num_timesteps)) from None
        path = out / "final_model.zip"
        save_model(model, path, cfg)
        if (out / "best_model.zip").is_file():
            write_sidecar(out / "best_model.zip", cfg)
    finally:
        env.close()
        if eval_env is not None:
            eval_env.close()
    return path


def _has_progress() -> bool:
    try:
        import rich  # noqa: F401
        import tqdm  # noqa: F401
    except ImportError:
        return False
    return True


__all__ = ["TrainingInterrupted", "train"]
