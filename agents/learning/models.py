"""The model registry: the shipped PPO policy, the environment it was trained on, loading a saved model.

:data:`PRETRAINED` is the learned agent shipped in ``digslam/agents/data`` (see its ``README.md``): a
goal-level ``MaskablePPO`` (attention over the candidate goals, warm-started by imitation of a look-ahead
teacher) that acts in :data:`DEFAULT_ENV` through the goal driver, with the environment keywords of its
``.json`` sidecar (:func:`model_env_kwargs`; every model saved by ``digslam train`` has one).
:data:`LOWLEVEL` is a low-level PPO steering ``(v, ω)`` from the map, a comparison row of the benchmark
(``ppo_lowlevel``). :func:`load_ppo` reads a saved PPO ``.zip`` and
checks it against an environment's observation space. A model or sidecar that cannot be used raises
:class:`ModelError` (a ``ValueError``) in one line that names the file and says what to do; the command line
shows it as is.

**Goal-level models.** A model whose sidecar names a goal-selection env (``digslam/DigCoverageGoals*``,
:mod:`digslam.agents.goals`; sb3-contrib's ``MaskablePPO``, ``algo = "maskable_ppo"``) picks candidate goals,
not low-level actions: :func:`load_ppo` returns it inside a
:class:`~digslam.agents.goals.GoalAgent`, a policy of the low-level env like any other, and
:func:`model_env_kwargs` gives the keywords of the *low-level* env (the goal env's own keywords, such as
``n_candidates`` or ``step_cap``, go to the ``GoalAgent`` instead; the ``horizon`` is the goal env's
``max_steps``). :mod:`digslam.agents.goals` is imported by its name (:func:`~.vec_env.env_module`, as
``gym.make`` imports it for these ids), on use only.

Torch, stable-baselines3 and sb3-contrib are imported only by :func:`load_ppo`.

>>> DEFAULT_ENV, PRETRAINED.name, LOWLEVEL.name
('digslam/DigCoverage-v0', 'goals_attention.zip', 'ppo_digcoverage.zip')
>>> model_env_kwargs()  # the low-level env of a goal model: its horizon (the training levels are left out)
{'horizon': 3000}
>>> sorted(model_env_kwargs(LOWLEVEL))  # the sidecar's keywords, less the training-only ones
['crop', 'dynamics', 'map_size']
"""

from __future__ import annotations

import json
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # gymnasium, stable-baselines3 and the goal agent are imported on use only
    import gymnasium as gym
    from stable_baselines3.common.base_class import BaseAlgorithm

    from digslam.agents.common.policy import PolicyPredictor

#: The folder of the shipped model (and of its sidecar and README).
DATA = Path(__file__).parents[1] / "data"
#: The shipped learned agent (``--agent ppo``); the environment keywords it was trained with are in
#: ``<model>.json``.
PRETRAINED = DATA / "goals_attention.zip"
#: The shipped learned chooser of the map predictor's gains (``--agent predictive_chooser``): a goal-level
#: ``MaskablePPO`` whose candidate features include the predicted gain and its spread
#: (``candidate_features``, :mod:`digslam.agents.prediction.features`).
CHOOSER = DATA / "goals_predictive.zip"
#: The shipped low-level PPO policy (continuous steering from the map), a comparison row of the benchmark.
LOWLEVEL = DATA / "ppo_digcoverage.zip"
#: The best agent of the last full leaderboard run (``benchmarks/bench_agents.py`` writes ``best.json`` to
#: its ``--out``; the shipped copy lives here): ``digslam demo``'s default agent (:func:`best_agent`). Its
#: ``ppo`` means :data:`PRETRAINED`: ship a leaderboard won by a learned model together with that model.
LEADERBOARD = DATA / "leaderboard.json"
#: The environment the shipped policy was trained on (the default of every command that runs an agent).
DEFAULT_ENV = "digslam/DigCoverage-v0"


#: The package of the goal-selection envs (:func:`~.vec_env.env_module` of their ids).
GOALS = "digslam.agents.goals"
#: Environment keywords of a training run that are no part of what the model sees (the levels it trained
#: on among them: each command picks its own, the benchmark each generator of its suite; and the coverage
#: that ended its training episodes: the benchmark runs to its step budget).
TRAINING_ONLY = ("fixed_world", "max_episode_steps", "render_mode", "world", "map_seed", "target")


class ModelError(ValueError):
    """A saved model or its sidecar cannot be used: missing, not a PPO model, trained on other observations,
    or a damaged sidecar. The message is one line naming the file."""


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def model_meta(model: str | Path | None = None) -> dict[str, Any]:
    """The whole sidecar of a saved model (None: :data:`PRETRAINED`): its ``<model>.json`` (``env_id``,
    ``env_kwargs``, ``actions``), else the ``config.json`` of the ``digslam train`` run that holds it (its
    folder, or one up for a checkpoint), else ``{}``; ``env_kwargs`` is always a dict when present.

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
        meta = json.loads(side.read_text())
        meta = {**meta, "env_kwargs": dict(meta.get("env_kwargs", {}))}
    except (OSError, ValueError, AttributeError, TypeError) as exc:
        raise ModelError(f"{side}: not a model sidecar written by `digslam train` ({_first_line(exc)}); "
                         "fix or delete it") from None  # fmt: skip
    return meta


def goal_env_id(meta: dict[str, Any]) -> str | None:
    """The goal-selection env id a sidecar (:func:`model_meta`) names, or None (a low-level model)."""
    from digslam.agents.learning.vec_env import env_module

    env_id = meta.get("env_id")
    return env_id if isinstance(env_id, str) and env_module(env_id) == GOALS else None


def _goals() -> ModuleType:
    """:mod:`digslam.agents.goals` (registers the goal ids), imported on use."""
    import digslam.agents.goals as goals

    return goals


def best_agent(path: str | Path | None = None) -> tuple[str, str]:
    """``(agent, why)``: the best agent of the leaderboard file ``path`` (None: :data:`LEADERBOARD`), the
    agent name the benchmark ranked first by mean ``T_level`` (the steps to each generator's target level)
    over the test maps of every generator, and a line saying where that comes from; ``("frontier", ...)``
    when the file is missing or damaged."""
    path = Path(path) if path is not None else LEADERBOARD
    try:
        data = json.loads(path.read_text())
        name = str(data["best"])
        t, maps, gens = float(data["T_level_mean"]), int(data["maps"]), len(data["generators"])
        why = f"mean T_level {t:.0f} steps over {maps} test maps x {gens} generators"
        return name, f"best on the leaderboard ({path.name}: {why})"
    except (OSError, ValueError, KeyError, TypeError):
        return "frontier", f"no readable leaderboard at {path}; the frontier agent"


def leaderboard_record(best: str, t_level_mean: float, maps: int, steps: int, generators: list[str],
                       levels: dict[str, float] | None = None) -> dict:  # fmt: skip
    """The content of a leaderboard file (:func:`best_agent` reads it back): the best agent, its mean
    ``T_level`` and the target levels it was measured at."""
    return {"best": best, "T_level_mean": float(t_level_mean), "target_levels": dict(levels or {}),
            "maps": int(maps), "steps": int(steps), "generators": list(generators),
            "split": "test"}  # fmt: skip


def model_env_kwargs(model: str | Path | None = None) -> dict[str, Any]:
    """Environment keywords of a saved model (None: :data:`PRETRAINED`), read from its sidecar
    (:func:`model_meta`), else ``{}``; the training choices of :data:`TRAINING_ONLY`, no part of the
    observation, are left out (each command sets its own episode length). For a goal-level model, those of
    the low-level env it acts in: the goal env's own keywords are left out and its ``max_steps`` becomes the
    ``horizon`` (:func:`digslam.agents.goals.base_env_kwargs`).

    Raises:
        ModelError: the sidecar is not one written by ``digslam train``.
    """
    meta = model_meta(model)
    kw = dict(meta.get("env_kwargs", {}))
    if goal_env_id(meta) is not None:
        kw = _goals().base_env_kwargs(kw)
    for key in TRAINING_ONLY:
        kw.pop(key, None)
    return kw


def as_policy(model: BaseAlgorithm) -> PolicyPredictor:
    """``model`` as a policy of the continuous environment: a model trained on discrete turn-or-go actions
    (``actions = "turn_go"``) wrapped in :class:`~.wrappers.TurnGoPolicy`, any other as it is."""
    if getattr(model.action_space, "n", None) is None:
        return model
    from digslam.agents.learning.wrappers import TurnGoPolicy

    return TurnGoPolicy(model)


def load_ppo(path: str | Path, env: gym.Env, opt: str = "model") -> PolicyPredictor:
    """The saved PPO model at ``path`` (on the CPU, torch on one thread), checked against ``env``'s
    observation space; a model trained on discrete turn-or-go actions (``actions = "turn_go"``) comes
    wrapped in :class:`~.wrappers.TurnGoPolicy`, so that it acts in the continuous environment; a goal-level
    model (its sidecar names a ``digslam/DigCoverageGoals*`` env) is loaded as sb3-contrib's ``MaskablePPO``
    and comes inside a :class:`~digslam.agents.goals.GoalAgent` sized from ``env`` with the goal keywords of
    its sidecar, its observation space checked against the goal observations that agent makes.

    Args:
        path: A ``.zip`` saved by ``digslam train`` (or SB3's ``PPO.save``).
        env: The (low-level) environment the model will act in.
        opt: How the messages name the model (the command line passes ``"--model"``).

    Raises:
        ModelError: no such file, stable-baselines3 (or sb3-contrib) missing, not a PPO model, or trained on
            other observations than ``env`` gives.
    """
    path = Path(path)
    if not path.is_file():
        what = "is a folder" if path.is_dir() else "does not exist"
        raise ModelError(f"{opt} {path}: {what}; give a .zip saved by `digslam train` "
                         f"(or leave {opt} out for the shipped policy)")  # fmt: skip
    meta = model_meta(path)
    goal_id = goal_env_id(meta)
    algo: type[BaseAlgorithm]
    try:
        if goal_id is not None:
            from sb3_contrib import MaskablePPO

            algo = MaskablePPO
        else:
            from stable_baselines3 import PPO

            algo = PPO
    except ImportError:
        raise ModelError(f"{opt} needs stable-baselines3{', sb3-contrib' if goal_id else ''} and torch; "
                         'install the train extra: pip install "digslam[train]"') from None  # fmt: skip
    from digslam.agents.learning.vec_env import pin_threads

    pin_threads(1)
    kind = f"MaskablePPO model of {goal_id}" if goal_id else "PPO model"
    try:
        model = algo.load(path, device="cpu")
    except Exception as exc:  # noqa: BLE001 - any failure to read the file is the file's
        raise ModelError(f"{opt} {path}: not a {kind} saved by `digslam train` "
                         f"({type(exc).__name__}: {_first_line(exc)})") from None  # fmt: skip
    if goal_id is not None:
        return _goal_agent(model, path, env, meta, opt)
    try:
        policy = as_policy(model)
    except ValueError as exc:
        raise ModelError(f"{opt} {path}: {_first_line(exc)}") from None
    if model.observation_space != env.observation_space:
        raise ModelError(f"{opt} {path}: trained on observations {model.observation_space}, but the "
                         f"environment gives {env.observation_space}; pass the environment keywords it was "
                         f"trained with in {path.with_suffix('.json')}")  # fmt: skip
    return policy


def _goal_agent(
    model: BaseAlgorithm, path: Path, env: gym.Env, meta: dict[str, Any], opt: str
) -> PolicyPredictor:
    """``model`` (a goal-level ``MaskablePPO``) inside a ``GoalAgent`` on ``env``, checked."""
    goals = _goals()
    goal_kw, _ = goals.split_goal_kwargs(meta.get("env_kwargs", {}))
    goal_kw.pop("max_steps", None)  # the episode's length is the env's (its horizon, which the sidecar set)
    try:
        agent = goals.GoalAgent.from_env(env, model, **goal_kw)
        want = agent.goal_observation_space
    except (ValueError, TypeError, KeyError) as exc:
        raise ModelError(f"{opt} {path}: cannot act in this environment ({_first_line(exc)})") from None
    if model.observation_space != want:
        raise ModelError(f"{opt} {path}: trained on goal observations {model.observation_space}, but the "
                         f"environment gives {want}; pass the environment keywords it was trained with "
                         f"in {path.with_suffix('.json')}")  # fmt: skip
    return agent


__all__ = ["CHOOSER", "DATA", "DEFAULT_ENV", "GOALS", "LEADERBOARD", "LOWLEVEL", "PRETRAINED",
           "TRAINING_ONLY", "ModelError",
           "as_policy", "best_agent", "goal_env_id", "leaderboard_record", "load_ppo", "model_env_kwargs",
           "model_meta"]  # fmt: skip
