"""The one config base: frozen, validated dataclasses built from mappings that reject unknown keys.

Every configuration of the project (the environments', the observers', training and sweeps) is a frozen
dataclass declared with :func:`config_dataclass` and deriving from :class:`Config`:

* the constructor and :meth:`Config.from_dict` reject an unknown key with a ``ValueError`` (never a
  ``TypeError``) that names it and lists the known keys;
* :meth:`Config.replace` copies with some fields changed, :meth:`Config.to_dict` gives plain data that
  :meth:`Config.from_dict` reads back;
* ``__post_init__`` checks the values with the checkers below, each naming the offending field
  (``"<field>: <what is wrong>"``);
* :meth:`Config.from_file` reads a ``.toml`` or ``.json`` file (:func:`read_config_file`, the one reader of
  configuration files) and :meth:`Config.override` applies ``key=value`` strings from a command line
  (:func:`apply_overrides`, values parsed as TOML literals by :func:`parse_value`); every error is one line
  naming the file or the key.

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
>>> Demo().override(["n=4"]).n, parse_value("{map_size = 40}"), parse_value("plain words")
(4, {'map_size': 40}, 'plain words')
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import json
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

if TYPE_CHECKING:  # type checkers only (typing has it from Python 3.11): never imported at run time
    from typing_extensions import dataclass_transform
else:

    def dataclass_transform(**_: object) -> Callable[[Any], Any]:
        return lambda f: f


C = TypeVar("C", bound="Config")


def reject_unknown(cls: type, keys: Iterable[str]) -> None:
    """Raise ``ValueError`` naming the keys of ``keys`` that are no field of the dataclass ``cls``.

    The message lists the known keys: ``"<Class>: unknown key(s) ['x']; known: ['a', 'b']"``.
    """
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(keys) - known)
    if unknown:
        raise ValueError(f"{cls.__name__}: unknown key(s) {unknown}; known: {sorted(known)}")


@dataclass_transform(frozen_default=True)
def config_dataclass(cls: type[C]) -> type[C]:
    """``@dataclass(frozen=True)`` whose constructor raises ``ValueError`` (not ``TypeError``) on unknown
    keyword arguments, naming them (see :func:`reject_unknown`)."""
    cls = dataclasses.dataclass(frozen=True)(cls)
    # mypy forbids reading __init__ off a class; the dataclass's generated one is what is wrapped here
    init: Callable[..., None] = cls.__init__  # type: ignore[misc]

    @functools.wraps(init)
    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        reject_unknown(type(self), kwargs)
        init(self, *args, **kwargs)

    # the checked constructor replaces the generated one (mypy forbids assigning a method)
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
        # a mixin: every Config is a dataclass (config_dataclass), which mypy cannot see on the base
        return dataclasses.replace(self, **kwargs)  # type: ignore[type-var]

    def to_dict(self) -> dict[str, Any]:
        """The fields as plain data (nested configs become dicts); ``from_dict`` reads it back."""
        # a mixin: every Config is a dataclass (config_dataclass), which mypy cannot see on the base
        return dataclasses.asdict(self)  # type: ignore[call-overload, no-any-return]

    @classmethod
    def from_file(cls: type[C], path: str | Path, overrides: Iterable[str] = ()) -> C:
        """Build from the table of a ``.toml`` or ``.json`` file (:func:`read_config_file`), then apply the
        ``key=value`` strings of ``overrides`` (:meth:`override`); ``ValueError`` in one line naming the file
        or the key."""
        return cls.from_dict(read_config_file(path)).override(overrides)

    def override(self: C, overrides: Iterable[str]) -> C:
        """Copy with ``key=value`` strings applied (:func:`apply_overrides`): values are TOML literals, else
        plain strings; ``head.sub=value`` sets one entry of a field that holds a table (a dict). No
        overrides: this config itself."""
        overrides = list(overrides)
        if not overrides:
            return self
        # a mixin: every Config is a dataclass (config_dataclass), which mypy cannot see on the base
        fields = dataclasses.fields(self)  # type: ignore[arg-type]
        tables = [f.name for f in fields if isinstance(getattr(self, f.name), dict)]
        return type(self).from_dict(apply_overrides(self.to_dict(), overrides, dotted=tables))


def toml_module() -> ModuleType:
    """The TOML reader: the standard library's ``tomllib`` (Python 3.11+), else its backport ``tomli``."""
    try:
        return importlib.import_module("tomllib")
    except ModuleNotFoundError:  # Python 3.10: the same API under the backport's name
        return importlib.import_module("tomli")


def read_config_file(path: str | Path) -> dict[str, Any]:
    """The table of settings in a ``.toml`` or ``.json`` file.

    Raises:
        ValueError: no such file, another suffix, unreadable text or a file that holds no table, in one
            line that starts with ``path:`` and names the file.
    """
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"path: no configuration file {str(p)!r}")
    if p.suffix not in (".json", ".toml"):
        raise ValueError(f"path: configuration must be .toml or .json, got {str(p)!r}")
    try:
        text = p.read_text()
        data = json.loads(text) if p.suffix == ".json" else toml_module().loads(text)
    except (OSError, UnicodeDecodeError, ValueError) as exc:  # TOMLDecodeError, JSONDecodeError
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ValueError(f"path: cannot read {str(p)!r} as {p.suffix[1:].upper()} ({first})") from None
    if not isinstance(data, dict):
        raise ValueError(f"path: {str(p)!r} must hold a table of settings, got {type(data).__name__}")
    return data


def parse_value(raw: str) -> Any:
    """A TOML literal (``3``, ``1e-4``, ``true``, ``"x"``, ``{map_size = 40}``), or the raw string."""
    toml = toml_module()
    try:
        return toml.loads(f"v = {raw}")["v"]
    except toml.TOMLDecodeError:
        return raw


def parse_assignment(item: str, option: str = "overrides") -> tuple[str, Any]:
    """``(key, value)`` of one ``key=value`` string, the value parsed by :func:`parse_value`.

    Raises:
        ValueError: no ``=`` or an empty key, naming ``option`` (the command-line option or argument).
    """
    key, sep, raw = item.partition("=")
    if not sep or not key.strip():
        raise ValueError(f"{option}: expected KEY=VALUE, got {item!r}")
    return key.strip(), parse_value(raw.strip())


def apply_overrides(data: Mapping[str, Any], overrides: Iterable[str],
                    dotted: Sequence[str] = ()) -> dict[str, Any]:  # fmt: skip
    """``data`` with ``key=value`` strings applied (values parsed by :func:`parse_value`); ``head.sub=value``
    sets one entry of a table field named in ``dotted``.

    Raises:
        ValueError: a string without ``=``, a key not in ``data``, or a dotted key on a field not in
            ``dotted``, naming the key.
    """
    out = dict(data)
    for item in overrides:
        key, value = parse_assignment(item)
        head, _, sub = key.partition(".")
        if head not in out:
            raise ValueError(f"{head}: unknown key; known: {sorted(out)}")
        if sub:
            if head not in dotted:
                raise ValueError(f"{key}: only {' and '.join(dotted)} takes dotted keys" if dotted
                                 else f"{key}: no key takes dotted keys")  # fmt: skip
            out[head] = {**out[head], sub: value}
        else:
            out[head] = value
    return out


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
    "apply_overrides",
    "parse_assignment",
    "check",
    "check_choice",
    "check_finite_nonneg",
    "check_finite_pos",
    "check_in",
    "check_int",
    "config_dataclass",
    "is_int",
    "is_number",
    "parse_value",
    "read_config_file",
    "reject_unknown",
    "toml_module",
]
