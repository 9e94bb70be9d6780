"""The one config base: frozen, validated dataclasses built from mappings that reject unknown keys.

Every configuration of the project (the environments', the observers', training and sweeps) is a frozen
dataclass declared with :func:`config_dataclass` and deriving from :class:`Config`:

* the constructor and :meth:`Config.from_dict` reject an unknown key with a ``ValueError`` (never a
  ``TypeError``) that names it and lists the known keys;
* :meth:`Config.replace` copies with some fields changed, :meth:`Config.to_dict` gives plain data that
  :meth:`Config.from_dict` reads back;
* ``__post_init__`` checks the values with the checkers below, each naming the offending field
  (``"<field>: <what is wrong>"``).

>>> @config_dataclass
... class Demo(Config):
...     n: int = 1
...     def __post_init__(self) -> None:
...         check_int("n", self.n, 1)
>>> Demo.from_dict({"n": 2}).replace(n=3).to_dict()
{'n': 3}
>>> Demo(m=2)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: Demo: unknown key(s) ['m']; known: ['n']
>>> Demo(n=0)
Traceback (most recent call last):
...
ValueError: n: must be an integer >= 1, got 0
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable, Iterable, Mapping
from typing import Any, TypeVar

import numpy as np

C = TypeVar("C", bound="Config")


def reject_unknown(cls: type, keys: Iterable[str]) -> None:
    """Raise ``ValueError`` naming the keys of ``keys`` that are no field of the dataclass ``cls``.

    The message lists the known keys: ``"<Class>: unknown key(s) ['x']; known: ['a', 'b']"``.
    """
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(keys) - known)
    if unknown:
        raise ValueError(f"{cls.__name__}: unknown key(s) {unknown}; known: {sorted(known)}")


def config_dataclass(cls: type[C]) -> type[C]:
    """``@dataclass(frozen=True)`` whose constructor raises ``ValueError`` (not ``TypeError``) on unknown
    keyword arguments, naming them (see :func:`reject_unknown`)."""
    cls = dataclasses.dataclass(frozen=True)(cls)
    init: Callable[..., None] = cls.__init__  # type: ignore[misc]

    @functools.wraps(init)
    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        reject_unknown(type(self), kwargs)
        init(self, *args, **kwargs)

    cls.__init__ = __init__  # type: ignore[method-assign]
    return cls


class Config:
    """Mixin of the configs: construction from a mapping, copies with changes, plain data.

    Use it with :func:`config_dataclass` (the methods need a dataclass).
    """

    @classmethod
    def from_dict(cls: type[C], data: Mapping[str, Any] | None = None, **kwargs: Any) -> C:
        """Build from ``data`` and keyword overrides; an unknown key raises ``ValueError`` naming it."""
        merged = {**(data or {}), **kwargs}
        reject_unknown(cls, merged)
        return cls(**merged)

    def replace(self: C, **kwargs: Any) -> C:
        """Copy with some fields changed (unknown keys raise ``ValueError``; the copy is checked anew)."""
        reject_unknown(type(self), kwargs)
        return dataclasses.replace(self, **kwargs)  # type: ignore[type-var]

    def to_dict(self) -> dict[str, Any]:
        """The fields as plain data (nested configs become dicts); ``from_dict`` reads it back."""
        return dataclasses.asdict(self)  # type: ignore[call-overload, no-any-return]


def check(cond: bool, name: str, msg: str) -> None:
    """Raise ``ValueError("<name>: <msg>")`` unless ``cond``."""
    if not cond:
        raise ValueError(f"{name}: {msg}")


def is_number(v: Any) -> bool:
    """True for a real number (Python or numpy), False for a bool."""
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))


def is_int(v: Any) -> bool:
    """True for an integer (Python or numpy), False for a bool."""
    return isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))


def check_finite_nonneg(name: str, v: Any) -> None:
    """``v`` must be a finite number >= 0."""
    check(is_number(v) and math.isfinite(v) and v >= 0, name, f"must be finite and >= 0, got {v!r}")


def check_finite_pos(name: str, v: Any) -> None:
    """``v`` must be a finite number > 0."""
    check(is_number(v) and math.isfinite(v) and v > 0, name, f"must be finite and > 0, got {v!r}")


def check_int(name: str, v: Any, minimum: int = 0, note: str = "") -> None:
    """``v`` must be an integer (not a bool) >= ``minimum``; ``note`` is appended to the bound in the
    message (``"must be an integer >= 0 (outliers per step), got -1"``)."""
    check(is_int(v) and v >= minimum, name, f"must be an integer >= {minimum}{note}, got {v!r}")


def check_in(name: str, v: Any, lo: float, hi: float, lo_open: bool = False, hi_open: bool = False) -> None:
    """``v`` must be a number in the interval from ``lo`` to ``hi`` (closed unless ``lo_open``/``hi_open``),
    e.g. ``"must be in (0, 1], got 1.5"``."""
    ok = is_number(v) and (lo < v if lo_open else lo <= v) and (v < hi if hi_open else v <= hi)
    bounds = f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"
    check(ok, name, f"must be in {bounds}, got {v!r}")


def check_choice(name: str, v: Any, choices: Iterable[Any]) -> None:
    """``v`` must be one of ``choices`` (a tuple in the message)."""
    options = tuple(choices)
    check(v in options, name, f"must be one of {options}, got {v!r}")


__all__ = [
    "Config",
    "check",
    "check_choice",
    "check_finite_nonneg",
    "check_finite_pos",
    "check_in",
    "check_int",
    "config_dataclass",
    "is_int",
    "is_number",
    "reject_unknown",
]
