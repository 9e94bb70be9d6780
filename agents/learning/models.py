"""The model registry: the shipped PPO policy, the environment it was trained on, loading a saved model.

:data:`PRETRAINED` is the policy shipped in ``digslam/agents/data`` (see its ``README.md``), trained on
:data:`DEFAULT_ENV` with the environment keywords of its ``.json`` sidecar (:func:`model_env_kwargs`; every
model saved by ``digslam train`` has one). :func:`load_ppo` reads a saved PPO ``.zip`` and checks it against
an environment's observation space. A model or sidecar that cannot be used raises :class:`ModelError` (a
``ValueError``) in one line that names the file and says what to do; the command line shows it as is.

Torch and stable-baselines3 are imported only by :func:`load_ppo`.

>>> DEFAULT_ENV, PRETRAINED.name
('digslam/DigCoverage-v0', 'ppo_digcoverage.zip')
>>> sorted(model_env_kwargs())  # the sidecar's keywords, less the training-only ones (``fixed_world``)
['crop', 'map_size']
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

#: The folder of the shipped model (and of its sidecar and README).
DATA = Path(__file__).parents[1] / "data"
#: The shipped policy; the environment keywords it was trained with are in ``<model>.json``.
PRETRAINED = DATA / "ppo_digcoverage.zip"
#: The environment the shipped policy was trained on (the default of every command that runs an agent).
DEFAULT_ENV = "digslam/DigCoverage-v0"


#: Environment keywords of a training run that are no part of what the model sees.
TRAINING_ONLY = ("fixed_world", "max_episode_steps", "render_mode")


class ModelError(ValueError):
    """A saved model or its sidecar cannot be used: missing, not a PPO model, trained on other observations,
    or a damaged sidecar. The message is one line naming the file."""


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def model_env_kwargs(model: str | Path | None = None) -> dict[str, Any]:
    """Environment keywords of a saved model (None: :data:`PRETRAINED`), read from its ``.json`` sidecar,
    else from the ``config.json`` of the ``digslam train`` run that holds it (its folder, or one up for a
    checkpoint), else ``{}``; the training choices of :data:`TRAINING_ONLY`, no part of the observation,
    are left out (each command sets its own episode length).

    Raises:
        ModelError: the sidecar is not one written by ``digslam train``.
    """
    path = Path(model if model is not None else PRETRAINED)
    side = path.with_suffix(".json")
    if not side.is_file():  # a model of a `digslam train` run without its sidecar, or a checkpoint
        runs = [d / "config.json" for d in (path.parent, path.parent.parent)]
        side = next((c for c in runs if c.is_file()), side)
        if not side.is_file():
            return {}
    try:
        kw = dict(json.loads(side.read_text()).get("env_kwargs", {}))
    except (OSError, ValueError, AttributeError, TypeError) as exc:
        raise ModelError(f"{side}: not a model sidecar written by `digslam train` ({_first_line(exc)}); "
                         "fix or delete it") from None  # fmt: skip
    for key in TRAINING_ONLY:
        kw.pop(key, None)
    return kw


def as_policy(model: Any) -> Any:
    """``model`` as a policy of the continuous environment: a model trained on discrete turn-or-go actions
    (``actions = "turn_go"``) wrapped in :class:`~.wrappers.TurnGoPolicy`, any other as it is."""
    if getattr(model.action_space, "n", None) is None:
        return model
    from digslam.agents.learning.wrappers import TurnGoPolicy

    return TurnGoPolicy(model)


def load_ppo(path: str | Path, env: Any, opt: str = "model") -> Any:
    """The saved PPO model at ``path`` (on the CPU, torch on one thread), checked against ``env``'s
    observation space; a model trained on discrete turn-or-go actions (``actions = "turn_go"``) comes
    wrapped in :class:`~.wrappers.TurnGoPolicy`, so that it acts in the continuous environment.

    Args:
        path: A ``.zip`` saved by ``digslam train`` (or SB3's ``PPO.save``).
        env: The environment the model will act in.
        opt: How the messages name the model (the command line passes ``"--model"``).

    Raises:
        ModelError: no such file, stable-baselines3 missing, not a PPO model, or trained on other
            observations than ``env`` gives.
    """
    path = Path(path)
    if not path.is_file():
        what = "is a folder" if path.is_dir() else "does not exist"
        raise ModelError(f"{opt} {path}: {what}; give a .zip saved by `digslam train` "
                         f"(or leave {opt} out for the shipped policy)")  # fmt: skip
    try:
        from stable_baselines3 import PPO
    except ImportError:
        raise ModelError(f"{opt} needs stable-baselines3 and torch; install the train extra: "
                         'pip install "digslam[train]"') from None  # fmt: skip
    from digslam.agents.learning.train import pin_threads

    pin_threads(1)
    try:
        model = PPO.load(path, device="cpu")
    except Exception as exc:  # noqa: BLE001 - any failure to read the file is the file's
        raise ModelError(f"{opt} {path}: not a PPO model saved by `digslam train` "
                         f"({type(exc).__name__}: {_first_line(exc)})") from None  # fmt: skip
    try:
        model = as_policy(model)
    except ValueError as exc:
        raise ModelError(f"{opt} {path}: {_first_line(exc)}") from None
    if model.observation_space != env.observation_space:
        raise ModelError(f"{opt} {path}: trained on observations {model.observation_space}, but the "
                         f"environment gives {env.observation_space}; pass the environment keywords it was "
                         f"trained with in {path.with_suffix('.json')}")  # fmt: skip
    return model


__all__ = ["DATA", "DEFAULT_ENV", "PRETRAINED", "TRAINING_ONLY", "ModelError", "as_policy", "load_ppo",
           "model_env_kwargs"]  # fmt: skip
