"""A static map of the package, read from the source with ``ast`` (nothing is imported): which modules exist,
what each imports (at module level and inside functions), and which functions are numba kernels.

Used by ``tests/test_architecture.py`` to check the rules written in the folders' docstrings.
"""

from __future__ import annotations

import ast
import importlib
import re
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGES = ("observer", "envs", "agents")


@dataclass
class Module:
    name: str  # dotted, without the "digslam." prefix, e.g. "observer.sets.paver"
    path: Path
    is_package: bool
    tree: ast.Module
    kernels: set[str] = field(default_factory=set)
    # (target module, imported name or None, line, inside a function)
    imports: list[tuple[str, str | None, int, bool]] = field(default_factory=list)

    @property
    def folder(self) -> str:
        return self.name if self.is_package else self.name.rsplit(".", 1)[0]


def import_dotted(path: str) -> object | None:
    """The object a dotted ``digslam....`` path names (its longest importable prefix, then attributes), or
    None when no prefix imports; an attribute that is missing raises ``AttributeError``."""
    parts = path.split(".")
    for cut in range(len(parts), 1, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ModuleNotFoundError:
            continue
        for attr in parts[cut:]:
            obj = getattr(obj, attr)
        return obj
    return None


def _is_kernel(fn: ast.FunctionDef) -> bool:
    for d in fn.decorator_list:
        target = d.func if isinstance(d, ast.Call) else d
        name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
        if name in ("njit", "jit", "vectorize", "guvectorize"):
            return True
    return False


def _resolve(mod: Module, node: ast.ImportFrom) -> str | None:
    if node.level:
        base = mod.name.split(".") if mod.is_package else mod.name.split(".")[:-1]
        base = base[: len(base) - (node.level - 1)]
        return ".".join(base + ([node.module] if node.module else []))
    if node.module and node.module.startswith("digslam."):
        return node.module[len("digslam.") :]
    return None


def scan() -> dict[str, Module]:
    mods: dict[str, Module] = {}
    for pkg in PACKAGES:
        for path in sorted((REPO / pkg).rglob("*.py")):
            if "__pycache__" in path.parts:
                continue
            parts = list(path.relative_to(REPO).with_suffix("").parts)
            is_pkg = parts[-1] == "__init__"
            if is_pkg:
                parts = parts[:-1]
            mods[".".join(parts)] = Module(".".join(parts), path, is_pkg, ast.parse(path.read_text()))
    for m in mods.values():
        m.kernels = {n.name for n in m.tree.body if isinstance(n, ast.FunctionDef) and _is_kernel(n)}
        funcs = [n for n in ast.walk(m.tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]
        nested = {id(x) for f in funcs for x in ast.walk(f) if x is not f}
        for node in ast.walk(m.tree):
            inside = id(node) in nested
            if isinstance(node, ast.ImportFrom):
                target = _resolve(m, node)
                if target is None:
                    continue
                for a in node.names:
                    sub = f"{target}.{a.name}"
                    if sub in mods:
                        m.imports.append((sub, None, node.lineno, inside))
                    else:
                        m.imports.append((target, a.name, node.lineno, inside))
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.startswith("digslam."):
                        m.imports.append((a.name[len("digslam.") :], None, node.lineno, inside))
    return mods


def third_party(mod: Module) -> set[str]:
    """Top-level names of the non-digslam modules ``mod`` imports (anywhere in the file)."""
    out = set()
    for node in ast.walk(mod.tree):
        if isinstance(node, ast.Import):
            out |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
            out.add(node.module.split(".")[0])
    return out - {"digslam"}


def graph(mods: dict[str, Module]) -> dict[str, set[str]]:
    """Module -> modules it imports (a package's ``__init__`` counts as the package's module)."""
    g: dict[str, set[str]] = {name: set() for name in mods}
    for m in mods.values():
        for target, _, _, _ in m.imports:
            if target in mods and target != m.name and not m.name.startswith(target + "."):
                g[m.name].add(target)
    return g


def cycles(g: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in g[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(g):
        if v not in index:
            visit(v)
    return out


#: Names through which code reaches the env that a wrapper wraps (``self.env``, ``env.unwrapped``...).
ENV_NAMES = frozenset({"env", "unwrapped", "raw"})


def private_reaches(mod: Module) -> list[tuple[int, str]]:
    """``(line, text)`` of each private attribute (``_x``, not ``__x__``) read or called through a wrapped env:
    an expression such as ``self.env._step(...)`` or ``env.unwrapped._spec`` whose chain of names passes
    through ``env``, ``unwrapped`` or ``raw``."""
    out = []
    for node in ast.walk(mod.tree):
        if not isinstance(node, ast.Attribute):
            continue
        name = node.attr
        if not name.startswith("_") or (name.startswith("__") and name.endswith("__")):
            continue
        chain, v = [], node.value
        while isinstance(v, ast.Attribute):
            chain.append(v.attr)
            v = v.value
        if isinstance(v, ast.Name):
            chain.append(v.id)
        if ENV_NAMES & set(chain):
            out.append((node.lineno, ast.unparse(node)))
    return sorted(out)


#: A Sphinx cross-reference: its role, its text and its explicit target (``text <target>``).
ROLE = re.compile(r":(mod|class|func|meth|data|attr|exc|obj):`~?([^`<]*?)(?:\s*<([^>]+)>)?`")
TYPE_IGNORE = re.compile(r"#\s*type:\s*ignore\b(\[[^\]]*\])?(.*)$")


def unexplained_ignores(path: Path) -> list[tuple[int, str]]:
    """``(line, text)`` of each ``# type: ignore`` without an error code and a reason: a comment after it on
    its line (``# type: ignore[override]  # gymnasium declares spec a property``), or a comment line just
    above it."""
    lines = path.read_text().splitlines()
    out = []
    for i, line in enumerate(lines):
        m = TYPE_IGNORE.search(line)
        if m is None:
            continue
        code, rest = m.group(1), m.group(2)
        above = lines[i - 1].strip() if i else ""
        reason = bool(re.match(r"\s*#\s*\S", rest)) or (above.startswith("#") and len(above) > 2)
        if not code or not reason:
            out.append((i + 1, line.strip()))
    return out


def docstring_references(mods: dict[str, Module]) -> list[tuple[Module, int, str, str]]:
    """``(module, line, role, target)`` of each Sphinx cross-reference to digslam in the source
    (``:mod:`digslam.envs.sim```, ``:func:`~.carving.srac```...)."""
    out = []
    for m in mods.values():
        text = m.path.read_text()
        for r in ROLE.finditer(text):
            target = (r.group(3) or r.group(2)).strip().lstrip("~")
            if re.fullmatch(r"\.?[A-Za-z_][\w.]*", target) and (target.startswith((".", "digslam."))):
                out.append((m, text[: r.start()].count("\n") + 1, r.group(1), target))
    return out


def known_names(mods: dict[str, Module]) -> tuple[set[str], set[str]]:
    """The full names of every digslam module and of every name defined or imported at the top of one (and
    of the members of its classes): ``(modules, names)``, each with the ``digslam.`` prefix. Imports every
    module."""
    import inspect

    modules, names = set(), set()
    for m in mods.values():
        full = f"digslam.{m.name}"
        modules.add(full)
        names.add(full)
        mod = importlib.import_module(full)
        for k, v in vars(mod).items():
            names.add(f"{full}.{k}")
            if inspect.isclass(v):
                members = [*vars(v), *getattr(v, "__annotations__", {}), *getattr(v, "_fields", ())]
                names.update(f"{full}.{k}.{a}" for a in members)
    return modules, names


def resolves(role: str, target: str, modules: set[str], names: set[str]) -> bool:
    """Whether Sphinx can resolve ``target``: a name that starts with ``.`` resolves to any object whose full
    name ends with it; a ``:mod:`` names a module."""
    pool = modules if role == "mod" else names
    if target.startswith("."):
        return any(n.endswith(target) for n in pool)
    return target in pool
