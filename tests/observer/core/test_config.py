"""The config base: unknown keys named, copies, plain data, frozen fields, the shared checkers."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from digslam.observer.core.config import (
    Config,
    apply_overrides,
    check,
    check_choice,
    check_finite_nonneg,
    check_finite_pos,
    check_in,
    check_int,
    config_dataclass,
    is_int,
    is_number,
    parse_value,
    read_config_file,
)


@config_dataclass
class Inner(Config):
    a: int = 1

    def __post_init__(self) -> None:
        check_int("a", self.a, 1)


@config_dataclass
class Outer(Config):
    name: str = "x"
    rate: float = 0.5
    inner: Inner = dataclasses.field(default_factory=Inner)

    def __post_init__(self) -> None:
        if isinstance(self.inner, dict):
            object.__setattr__(self, "inner", Inner.from_dict(self.inner))
        check_in("rate", self.rate, 0.0, 1.0, lo_open=True)


def test_from_dict_rejects_unknown_keys_naming_them_and_the_known_ones():
    with pytest.raises(
        ValueError, match=r"Outer: unknown key\(s\) \['nmae', 'zz'\]; known: \['inner', 'name', 'rate'\]"
    ):
        Outer.from_dict({"nmae": "y", "zz": 1})
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['b'\]"):
        Outer.from_dict(inner={"b": 2})  # nested mappings are checked by the nested config
    assert Outer.from_dict({"name": "y"}, rate=0.25) == Outer(name="y", rate=0.25)
    assert Outer.from_dict() == Outer() == Outer.from_dict(None)


def test_constructor_raises_value_error_not_type_error():
    with pytest.raises(ValueError, match=r"Inner: unknown key\(s\) \['b'\]") as exc:
        Inner(b=2)  # type: ignore[call-arg]
    assert not isinstance(exc.value, TypeError)
    with pytest.raises(ValueError, match="a: must be an integer >= 1, got 0"):
        Inner(a=0)
    assert Inner(3).a == 3  # positional arguments still work


def test_replace_checks_keys_and_values():
    c = Outer()
    d = c.replace(rate=1.0, inner=Inner(a=2))
    assert (d.rate, d.inner.a, c.rate) == (1.0, 2, 0.5)
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['rte'\]"):
        c.replace(rte=1.0)
    with pytest.raises(ValueError, match=r"rate: must be in \(0, 1\], got 0.0"):
        c.replace(rate=0.0)


def test_to_dict_round_trip():
    c = Outer(name="z", rate=0.75, inner=Inner(a=4))
    d = c.to_dict()
    assert d == {"name": "z", "rate": 0.75, "inner": {"a": 4}}
    assert Outer.from_dict(d) == c
    d["inner"]["a"] = 5  # plain data: editing it leaves the config alone
    assert c.inner.a == 4


def test_frozen_fields_cannot_be_set():
    c = Outer()
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.rate = 0.1  # type: ignore[misc]
    assert hash(Inner(2)) == hash(Inner(2))


def test_checkers():
    check(True, "x", "never")
    with pytest.raises(ValueError, match="^x: bad$"):
        check(False, "x", "bad")
    check_finite_nonneg("v", 0)
    check_finite_nonneg("v", np.float64(2.0))
    for bad in (-1.0, float("inf"), float("nan"), "1", True):
        with pytest.raises(ValueError, match="v: must be finite and >= 0"):
            check_finite_nonneg("v", bad)
    check_finite_pos("v", 1e-9)
    with pytest.raises(ValueError, match="v: must be finite and > 0, got 0"):
        check_finite_pos("v", 0)
    check_int("n", np.int64(3), 1)
    for bad in (0, 1.0, True, "2"):
        with pytest.raises(ValueError, match="n: must be an integer >= 1"):
            check_int("n", bad, 1)
    with pytest.raises(ValueError, match=r"q: must be an integer >= 0 \(per step\), got -1"):
        check_int("q", -1, 0, " (per step)")
    check_in("b", -1, -1.0, 1.0)
    with pytest.raises(ValueError, match=r"b: must be in \[-1, 1\), got 1"):
        check_in("b", 1, -1.0, 1.0, hi_open=True)
    with pytest.raises(ValueError, match="b: must be in"):
        check_in("b", "0.5", 0.0, 1.0)
    check_choice("m", "a", ("a", "b"))
    with pytest.raises(ValueError, match=r"m: must be one of \('a', 'b'\), got 'c'"):
        check_choice("m", "c", ["a", "b"])
    assert is_int(np.int32(1)) and not is_int(True) and not is_int(1.0)
    assert is_number(np.float32(1)) and is_number(2) and not is_number(np.bool_(True)) and not is_number("1")


@config_dataclass
class Run(Config):
    steps: int = 1
    name: str = "run"
    options: dict = dataclasses.field(default_factory=dict)

    def __post_init__(self) -> None:
        check_int("steps", self.steps, 1)


def test_config_files_are_read_by_one_reader_with_one_line_errors(tmp_path):
    t = tmp_path / "c.toml"
    t.write_text("steps = 3\n[options]\nsize = 40\n")
    j = tmp_path / "c.json"
    j.write_text('{"steps": 4, "options": {"crop": 4.0}}')
    assert read_config_file(t) == {"steps": 3, "options": {"size": 40}}
    assert Run.from_file(j) == Run(steps=4, options={"crop": 4.0})
    assert Run.from_file(t, ["name=other", "options.crop=2.5"]) == Run(3, "other", {"size": 40, "crop": 2.5})
    bad = tmp_path / "bad.toml"
    bad.write_text("steps = = 3\n")
    lst = tmp_path / "list.json"
    lst.write_text("[1, 2]")
    for path, words in ((tmp_path / "missing.toml", "no configuration file"), (tmp_path / "c.yaml", "must be"),
                        (bad, "cannot read"), (lst, "table of settings")):  # fmt: skip
        if path.suffix == ".yaml":
            path.write_text("steps: 1")
        with pytest.raises(ValueError, match=f"^path: .*{words}") as exc:
            read_config_file(path)
        assert "\n" not in str(exc.value)
    with pytest.raises(ValueError, match=r"Run: unknown key\(s\) \['stpes'\]"):
        Run.from_dict(read_config_file(t) | {"stpes": 1})


def test_overrides_are_toml_literals_and_name_the_key():
    assert parse_value("1e-4") == 1e-4 and parse_value("true") is True and parse_value("plain") == "plain"
    assert parse_value("{a = 1}") == {"a": 1} and parse_value('"quoted"') == "quoted"
    assert apply_overrides({"a": 1, "t": {"x": 1}}, ["a=2", "t.y=3"], dotted=("t",)) == {
        "a": 2,
        "t": {"x": 1, "y": 3},
    }
    for item, key in (("b=1", "b"), ("a.x=1", "a.x"), ("noequals", "overrides")):
        with pytest.raises(ValueError, match=key.replace(".", r"\.")):
            apply_overrides({"a": 1}, [item])
    assert Run().override([]) == Run() and Run().override(["steps=5"]).steps == 5
    with pytest.raises(ValueError, match="steps: must be an integer >= 1"):
        Run().override(["steps=0"])
