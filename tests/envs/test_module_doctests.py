"""The docstring examples of the envs modules that are not kernels (those are run by ``sim/test_kernels.py``)
nor the certified-coverage modules (``dig_coverage/test_env.py``)."""

from __future__ import annotations

import doctest
import importlib

import pytest


@pytest.mark.parametrize("name", ["observation", "splits", "stack", "sim.generators", "sim.robot"])
def test_module_doctests(name: str) -> None:
    mod = importlib.import_module(f"digslam.envs.{name}")
    res = doctest.testmod(mod, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert res.attempted > 0 and res.failed == 0
