"""Finding a layer in a stack of environments: the one helper that agents and tools use.

Gymnasium builds an environment as a raw env under wrappers, each holding the next in ``.env``;
``env.unwrapped`` is the raw env. :func:`find_wrapper` walks that chain from the outside in and returns the
first layer of a given class, as stable-baselines3's ``unwrap_wrapper`` does. :func:`observer_of` finds the
:class:`~digslam.envs.dig_coverage.wrapper.GuaranteedObserver` layer of a certified-coverage env (its grid,
its filter, its configuration) and says in one line when there is none.

>>> import gymnasium as gym
>>> env = gym.wrappers.TimeLimit(gym.make("CartPole-v1").unwrapped, 10)
>>> find_wrapper(env, gym.wrappers.TimeLimit) is env, find_wrapper(env, gym.wrappers.RecordEpisodeStatistics)
(True, None)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, TypeVar

if TYPE_CHECKING:
    import gymnasium as gym

    from digslam.envs.dig_coverage.wrapper import GuaranteedObserver

L = TypeVar("L")
#: More layers than any stack here has: a chain that long is a loop.
MAX_DEPTH = 64


def find_wrapper(env: gym.Env, cls: type[L]) -> L | None:
    """The outermost layer of ``env`` (``env`` itself, then ``env.env``, ...) that is an instance of
    ``cls``, or None when no layer is."""
    e: object = env
    for _ in range(MAX_DEPTH):
        if isinstance(e, cls):
            return e
        e = getattr(e, "env", None)
        if e is None:
            return None
    return None


def observer_of(env: gym.Env) -> GuaranteedObserver:
    """The :class:`~digslam.envs.dig_coverage.wrapper.GuaranteedObserver` layer of ``env``.

    Raises:
        ValueError: ``env`` holds no such layer (it is not a certified-coverage environment).
    """
    from digslam.envs.dig_coverage.wrapper import GuaranteedObserver

    layer = find_wrapper(env, GuaranteedObserver)
    if layer is None:
        raise ValueError(
            f"env: {type(env).__name__} is not a certified-coverage environment (no GuaranteedObserver "
            "inside); make one with gym.make('digslam/DigCoverage-v0')"
        )
    return layer


__all__ = ["MAX_DEPTH", "find_wrapper", "observer_of"]
