"""Extra candidate features computed outside the goal package, named by an entry point.

A goal env (:class:`~.env.GoalSelectionEnv`, ``candidate_features="module:name"``) and the
:class:`~.agent.GoalAgent` that replays it may append ``k`` features to every candidate's
:data:`~.candidates.FEATURES`, computed by an object of another package: the map predictor's gains,
:data:`digslam.agents.prediction.features.ENTRY_POINT`. It is named by its entry point, as gymnasium names
an env's class, so that this package never imports the predictor's (dependencies point from the
predictor to the goals) and a model's sidecar names it in JSON.

The object, ``name()`` for a class or a function, has ``names`` (its ``k`` feature names) and is called as
``extra(driver, view, candidates)`` to give ``(n, k)`` float32 features in ``[-1, 1]``, zero on the padding.
It reads what a candidate's own features read (the observation, the driver's memory), never ground truth.
One object is built per entry point and process (:func:`resolve`).
"""

from __future__ import annotations

import functools
import importlib
from typing import Any, Protocol, cast

import numpy as np

from digslam.agents.baselines.policy import View
from digslam.agents.goals.candidates import Candidates
from digslam.agents.goals.driver import GoalDriver


class CandidateFeatures(Protocol):
    """What an entry point of ``candidate_features`` builds (module docstring)."""

    names: tuple[str, ...]

    def __call__(self, driver: GoalDriver, view: View, candidates: Candidates) -> np.ndarray: ...


@functools.lru_cache(maxsize=8)
def resolve(entry_point: str) -> CandidateFeatures:
    """The object of ``entry_point`` (``"package.module:name"``), built once per process.

    Raises:
        ValueError: a malformed name, a module or attribute that is not there, an object that cannot be
            built with no arguments, or one without ``names`` and a call, each in one line.
    """
    mod, sep, attr = str(entry_point).partition(":")
    if not (sep and mod and attr):
        raise ValueError(f"candidate_features: expected 'package.module:name', got {entry_point!r}")
    try:
        obj: Any = getattr(importlib.import_module(mod), attr)
    except (ImportError, AttributeError) as exc:
        raise ValueError(f"candidate_features: cannot load {entry_point!r} ({exc})") from None
    if not callable(obj):
        raise ValueError(f"candidate_features: {entry_point!r} is not callable (a class or a function)")
    try:
        extra = obj()
    except Exception as exc:  # noqa: BLE001 - whatever the named object raises, the user gets one line
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ValueError(f"candidate_features: {entry_point!r} could not be built with no arguments "
                         f"({first})") from None  # fmt: skip
    names = getattr(extra, "names", None)
    if not callable(extra) or not names or not all(isinstance(n, str) for n in names):
        raise ValueError(f"candidate_features: {entry_point!r} builds no features (names and a call)")
    return cast(CandidateFeatures, extra)


def n_extra(entry_point: str | None) -> int:
    """Features the entry point adds (0 for None)."""
    return 0 if entry_point is None else len(resolve(entry_point).names)


def with_extra(entry_point: str | None, driver: GoalDriver, view: View, c: Candidates) -> np.ndarray:
    """``c.features`` with the entry point's features appended (a copy; ``c.features`` alone for None)."""
    if entry_point is None:
        return c.features.copy()
    extra = np.asarray(resolve(entry_point)(driver, view, c), np.float32)
    want = (len(c.mask), n_extra(entry_point))
    if extra.shape != want:
        raise ValueError(f"candidate_features: {entry_point!r} gave shape {extra.shape}, expected {want}")
    extra = np.where(c.mask[:, None], np.clip(extra, -1.0, 1.0), 0.0).astype(np.float32)
    return np.concatenate([c.features, extra], axis=1)


__all__ = ["CandidateFeatures", "n_extra", "resolve", "with_extra"]
