"""Run the docstring examples of every observer module (set operations are documented by example)."""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import numpy as np
import pytest

import digslam.observer as observer

MODULES = sorted(
    m.name.removeprefix("digslam.observer.")
    for m in pkgutil.walk_packages(observer.__path__, "digslam.observer.")
    if not m.name.rsplit(".", 1)[-1].startswith("_")
)


@pytest.mark.parametrize("name", MODULES)
def test_module_doctests(name: str) -> None:
    mod = importlib.import_module(f"digslam.observer.{name}")
    globs = {**vars(observer), "np": np}
    res = doctest.testmod(mod, extraglobs=globs, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert res.failed == 0, f"{res.failed} doctest failures in digslam.observer.{name}"
