"""The architecture's rules, checked on the source (``tests/architecture.py`` reads it with ``ast``).

The rules are written in the folders' docstrings (``digslam.observer.core`` holds the kernel rules); these
tests fail when the code stops following them.
"""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest
from architecture import (
    REPO,
    cycles,
    docstring_references,
    graph,
    import_dotted,
    known_names,
    private_reaches,
    resolves,
    scan,
    third_party,
    unexplained_ignores,
)

MODS = scan()

#: What each concept folder may import (its docstring's "May import"); a folder may always import itself.
ALLOWED: dict[str, set[str]] = {
    "observer.cache": set(),
    "observer.core": set(),
    "observer.record": set(),
    "observer.expr": {"observer.core"},
    "observer.sets": {"observer.core", "observer.expr"},
    "observer.paving": {"observer.core", "observer.sets"},
    "observer.polar": {"observer.core", "observer.expr", "observer.sets"},
    "observer.thick": {"observer.core", "observer.expr", "observer.sets", "observer.paving"},
    "observer.tube": {"observer.core"},
    "observer.slam": {"observer.core", "observer.record", "observer.expr", "observer.sets", "observer.paving", "observer.polar",
                      "observer.thick", "observer.tube"},
    "observer.online": {"observer.core", "observer.record", "observer.slam", "observer.thick", "observer.tube"},
    "envs.sim": {"observer.core", "observer.record", "envs"},
    "envs.explore": {"observer.core", "observer.record", "envs.sim", "envs"},
    "envs.dig_coverage": {"observer.core", "observer.record", "observer.slam", "observer.thick", "observer.online", "envs.sim",
                          "envs.explore", "envs"},
    "agents.common": set(),
    "agents.baselines": {"observer.core", "envs"},
    "agents.learning": {"observer.core", "envs", "agents.common", "agents.baselines", "agents.evaluation",
                        "agents.goals"},
    "agents.evaluation": {"observer.core", "observer.thick", "envs", "agents.common", "envs.sim", "envs.explore",
                          "envs.dig_coverage", "agents.baselines", "agents.learning"},
    "agents.goals": {"envs", "agents.common", "agents.baselines"},
    "agents.prediction": {"observer.core", "envs", "agents.common", "envs.dig_coverage", "agents.baselines", "agents.evaluation",
                          "agents.goals", "agents.learning"},
}  # fmt: skip
FOLDERS = sorted(m.name for m in MODS.values() if m.is_package and m.name.count(".") == 1)


def test_every_concept_folder_is_listed_and_documented() -> None:
    assert set(FOLDERS) - {"agents.cli"} == set(ALLOWED), "a new folder needs its rules here and a docstring"
    for name in FOLDERS:
        doc = ast.get_docstring(MODS[name].tree) or ""
        assert "Lives here" in doc and "May import" in doc, (
            f"{name}/__init__.py: say what lives there and what it may import"
        )


def test_no_folder_holds_more_than_15_modules() -> None:
    for name in FOLDERS:
        n = sum(1 for m in MODS.values() if m.folder == name and not m.is_package)
        assert n <= 15, f"{name}: {n} modules"


def test_folders_import_only_what_their_docstring_allows() -> None:
    bad = []
    for m in MODS.values():
        folder = ".".join(m.folder.split(".")[:2])  # a subfolder follows its concept folder's rules
        if folder not in ALLOWED:
            continue
        for target, _, line, _ in m.imports:
            tfolder = ".".join((MODS[target].folder if target in MODS else target).split(".")[:2])
            if tfolder == folder or tfolder.startswith(folder + "."):
                continue
            if tfolder not in ALLOWED[folder]:
                bad.append(f"{m.path.relative_to(REPO)}:{line} imports {target}")
    assert not bad, "\n".join(bad)


def test_no_import_cycle_including_imports_inside_functions() -> None:
    assert cycles(graph(MODS)) == []


def test_no_private_name_is_imported_across_modules() -> None:
    bad = [f"{m.path.relative_to(REPO)}:{line} imports {name} from {target}"
           for m in MODS.values() for target, name, line, _ in m.imports
           if name and name.startswith("_") and target != m.name]  # fmt: skip
    assert not bad, "\n".join(bad)


def test_kernels_are_defined_only_in_jit_files() -> None:
    bad = [m.name for m in MODS.values() if m.kernels and not m.name.endswith("_jit")]
    assert not bad, f"move these kernels into a <topic>_jit.py file: {bad}"


def test_a_kernel_file_calls_only_its_own_folder_and_the_core() -> None:
    bad = []
    for m in MODS.values():
        if not m.name.endswith("_jit"):
            continue
        for target, name, line, _ in m.imports:
            src = MODS.get(target)
            if src is None or name is None or name not in src.kernels:
                continue
            if src.folder not in (m.folder, "observer.core"):
                bad.append(f"{m.path.relative_to(REPO)}:{line} calls {target}.{name}")
    assert not bad, "\n".join(bad)


def test_the_kernel_rule_test_catches_a_cross_folder_call(tmp_path: Path) -> None:
    """The checker itself: a kernel file that imports a kernel of another non-core folder is reported."""
    from architecture import Module

    src = Module("observer.online.dig_jit", tmp_path / "a.py", False, ast.parse(""), kernels={"window"})
    bad = Module("envs.sim.x_jit", tmp_path / "b.py", False, ast.parse(""),
                 imports=[("observer.online.dig_jit", "window", 1, False)])  # fmt: skip
    offenders = [name for _, name, _, _ in bad.imports
                 if name in src.kernels and src.folder not in (bad.folder, "observer.core")]  # fmt: skip
    assert offenders == ["window"]


def test_observer_needs_only_numpy_scipy_numba() -> None:
    allowed = {"numpy", "scipy", "numba", "matplotlib", "mpmath"}  # matplotlib: paving.draw, on use only
    allowed |= {"typing_extensions"}  # core.config, under TYPE_CHECKING only (never imported at run time)
    allowed |= {
        "rosbags"
    }  # record.bag: inside its functions only (the [ros] extra; a test imports without it)
    stdlib = set(__import__("sys").stdlib_module_names)
    for m in MODS.values():
        if m.name.startswith("observer"):
            extra = third_party(m) - allowed - stdlib
            assert not extra, f"{m.name} imports {extra}"


# --- documented paths --------------------------------------------------------------------------------
README = (REPO / "README.md").read_text()
DOCUMENTED = sorted(set(re.findall(r"\bdigslam\.(?:observer|envs|agents)(?:\.[a-z_]+)+", README)))


@pytest.mark.parametrize("pkg", ["digslam.observer", "digslam.envs", "digslam.agents"])
def test_every_listed_name_imports(pkg: str) -> None:
    mod = importlib.import_module(pkg)
    for name in mod.__all__:
        assert getattr(mod, name) is not None, f"{pkg}.{name}"


@pytest.mark.parametrize("path", DOCUMENTED)
def test_every_path_in_the_readme_imports(path: str) -> None:
    if import_dotted(path) is None:
        pytest.fail(f"{path} does not import")


def test_no_alias_finder_is_installed() -> None:
    """Old module paths end: no import finder of digslam answers a name with a module at another path."""
    import sys

    import digslam.agents
    import digslam.envs
    import digslam.observer  # noqa: F401

    finders = [type(f).__module__ + "." + type(f).__qualname__ for f in sys.meta_path]
    assert not [f for f in finders if f.startswith("digslam")], finders
    for pkg in ("digslam.observer", "digslam.envs", "digslam.agents"):
        assert not hasattr(importlib.import_module(pkg), "MOVED"), pkg
    with pytest.raises(ImportError):
        importlib.import_module("digslam.observer.online_jit")  # a 0.1 path


def test_every_folder_package_is_installed() -> None:
    """pyproject lists its packages one by one: a folder missing there imports from the checkout and not
    from an install (``pip install .``)."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib  # type: ignore[no-redef]
    listed = set(tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    for top in ("observer", "envs", "agents"):
        for init in (REPO / top).rglob("__init__.py"):
            rel = init.parent.relative_to(REPO).parts
            assert ".".join(("digslam", *rel)) in listed, f"pyproject.toml: add digslam.{'.'.join(rel)}"


# --- the house: shared contracts, wrappers, types, sizes --------------------------------------------------
def test_no_module_is_over_500_lines() -> None:
    big = {m.name: n for m in MODS.values() if (n := len(m.path.read_text().splitlines())) > 500}
    assert not big, f"one concept per module: split {big}"


def test_no_wrapper_reaches_a_private_name_of_the_env_it_wraps() -> None:
    """Wrappers use the public API of the env they wrap and ``info``: no ``self.env._step(...)``, no
    ``env.unwrapped._spec``."""
    bad = [
        f"{m.path.relative_to(REPO)}:{line} {text}"
        for m in MODS.values()
        for line, text in private_reaches(m)
    ]
    assert not bad, "\n".join(bad)


def test_the_private_reach_check_catches_a_private_call(tmp_path: Path) -> None:
    """The checker itself: a call of a private method through ``.env`` or ``.unwrapped`` is reported, one on
    ``self`` is not."""
    from architecture import Module

    code = "class W:\n    def step(self, a):\n        self._own()\n        return self.env._step(a, observe=False)\n" \
           "    def spec(self):\n        return self.env.unwrapped._spec\n"  # fmt: skip
    m = Module("envs.x", tmp_path / "x.py", False, ast.parse(code))
    assert [text for _, text in private_reaches(m)] == ["self.env._step", "self.env.unwrapped._spec"]


def test_mypy_checks_the_three_packages() -> None:
    """mypy checks ``digslam.observer``, ``digslam.envs`` and ``digslam.agents`` as one package (its path
    holds a link to each folder, so imports across them are checked, not taken as ``Any``), and CI runs it."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib  # type: ignore[no-redef]  # the same API under the backport's name
    cfg = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["mypy"]
    assert set(cfg["packages"]) == {f"digslam.{p}" for p in ("observer", "envs", "agents")}, cfg
    for top in ("observer", "envs", "agents"):
        link = REPO / cfg["mypy_path"] / "digslam" / top
        assert link.resolve() == (REPO / top).resolve(), f"{link} must link to {top}/"
    ci = (REPO / ".ci" / "run").read_text()
    assert re.search(r"^mypy\b", ci, re.M), ".ci/run runs mypy on pyproject's packages"


def test_every_type_ignore_has_a_code_and_a_reason() -> None:
    bad = [f"{m.path.relative_to(REPO)}:{line} {text}" for m in MODS.values()
           for line, text in unexplained_ignores(m.path)]  # fmt: skip
    assert not bad, "say why, after the ignore or on the line above:\n" + "\n".join(bad)


def test_every_docstring_reference_names_something_that_exists() -> None:
    """A ``:mod:``/``:func:``/``:class:``... reference to digslam names a module or an object that exists (a
    target that starts with ``.`` as Sphinx resolves it: any full name that ends with it)."""
    modules, names = known_names(MODS)
    bad = [f"{m.path.relative_to(REPO)}:{line} :{role}:`{target}`"
           for m, line, role, target in docstring_references(MODS)
           if not resolves(role, target, modules, names)]  # fmt: skip
    assert not bad, "\n".join(bad)


def test_the_layout_page_states_each_folders_imports() -> None:
    """``docs/layout.md`` lists every concept folder with what it may import, as :data:`ALLOWED` does."""
    text = (REPO / "docs" / "layout.md").read_text()
    rows = dict(re.findall(r"^\| `([a-z_/]+)` \|[^|]*\| ([^|]+) \|$", text, re.M))
    for folder, allowed in ALLOWED.items():
        row = rows.get(folder.replace(".", "/"))
        assert row is not None, f"docs/layout.md: add a row for {folder.replace('.', '/')}"
        stated = (
            set()
            if row.strip() == "nothing"
            else {s.replace("/", ".") for s in re.findall(r"`([a-z_/]+)`", row)}
        )
        assert stated == allowed, (
            f"docs/layout.md, {folder}: states {sorted(stated)}, the rule is {sorted(allowed)}"
        )
