"""Sphinx extension of digslam's documentation: the API reference and the gallery, generated at build time.

* :func:`public_modules` lists the public modules (no ``_`` in their path) of ``digslam.observer``,
  ``digslam.envs`` and ``digslam.agents`` that declare ``__all__``; :func:`targets` gives every name of
  those ``__all__`` its one documented home (the module that defines it), so a name re-exported by a
  package is documented once and linked from the package's table.
* :func:`write_api` writes ``api/<package>.rst``, one page per folder (its modules as sections);
* :func:`write_gallery` writes ``gallery/<example>.rst`` for each script of ``examples/``, showing the
  pictures cached in ``gallery/images/`` by ``docs/make_gallery.py`` (the build does not run the examples).

The generated pages are rewritten at every build (``builder-inited``) and are not kept in git.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import logging
import pkgutil
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

DOCS = Path(__file__).resolve().parent.parent
REPO = DOCS.parent
TOPS = ("digslam.observer", "digslam.envs", "digslam.agents")
_NUM = r"(?:[A-B]|\d+)(?:\.\d+)?"  # 2.12, A.8
FIGURE = re.compile(rf"\b(?:Fig(?:ure)?s?\.?|Tables?)\s+{_NUM}(?:\s*(?:[–,-]|and)\s*{_NUM}\b)*")


def public_modules() -> list[ModuleType]:
    """The public modules of the three packages that declare ``__all__``, and every public folder."""
    out: list[ModuleType] = []
    for top in TOPS:
        pkg = importlib.import_module(top)
        names = [top] + sorted(i.name for i in pkgutil.walk_packages(pkg.__path__, top + "."))
        for name in names:
            if any(part.startswith("_") for part in name.split(".")):
                continue
            mod = importlib.import_module(name)
            if getattr(mod, "__all__", None) is not None or is_package(mod):
                out.append(mod)
    return out


def is_package(mod: ModuleType) -> bool:
    return hasattr(mod, "__path__")


def names(mod: ModuleType) -> list[str]:
    """The public names of ``mod``: its ``__all__`` (a folder without one has none of its own)."""
    return list(getattr(mod, "__all__", []))


@dataclass(frozen=True)
class Target:
    """Where a public name is documented: ``path`` (``module.name``) and the autodoc directive for it."""

    path: str
    kind: str  # "module", "class", "function" or "data"

    @property
    def module(self) -> str:
        return self.path if self.kind == "module" else self.path.rsplit(".", 1)[0]


def _assigned(mod: ModuleType, name: str) -> bool:
    """Whether ``mod``'s source binds ``name`` at top level by assignment (where a constant is defined)."""
    try:
        tree = ast.parse(inspect.getsource(mod))
    except (OSError, TypeError):
        return False
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == name for t in node.targets
        ):
            return True
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and node.target.id == name:
            return True
    return False


def targets(mods: list[ModuleType] | None = None) -> dict[tuple[str, str], Target]:
    """``(module, name) -> Target`` for every name of every public ``__all__``."""
    mods = public_modules() if mods is None else mods
    listed = {m.__name__: set(names(m)) for m in mods}
    listers: dict[int, list[str]] = {}
    for m in mods:
        for name in names(m):
            listers.setdefault(id(getattr(m, name)), []).append(m.__name__)
    out: dict[tuple[str, str], Target] = {}
    for m in mods:
        for name in names(m):
            obj = getattr(m, name)
            if inspect.ismodule(obj):
                out[m.__name__, name] = Target(obj.__name__, "module")
                continue
            kind = "class" if inspect.isclass(obj) else "function" if callable(obj) else "data"
            home, qual = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
            if (
                kind != "data"
                and home in listed
                and qual == name
                and qual in listed[home]
                and getattr(sys.modules[home], qual, None) is obj
            ):
                out[m.__name__, name] = Target(f"{home}.{qual}", kind)
                continue
            # a constant, an alias or a name defined in a private module: the lister that assigns it, else
            # the deepest module listing it under this name
            if kind != "data" and getattr(obj, "__qualname__", None) != name:
                kind = "data"  # an alias (a type alias, another name for a function): documented as a name
            cands = [h for h in listers[id(obj)] if name in listed[h]]
            owner = next((h for h in cands if _assigned(sys.modules[h], name)), None)
            if owner is None:
                owner = max(cands, key=lambda h: (not is_package(sys.modules[h]), h.count(".")))
            out[m.__name__, name] = Target(f"{owner}.{name}", kind)
    return out


def page_of(module: str, mods_by_name: dict[str, ModuleType]) -> str:
    """The API page (folder package) that holds ``module``'s section."""
    mod = mods_by_name[module]
    return module if is_package(mod) else module.rsplit(".", 1)[0]


def api_pages(mods: list[ModuleType] | None = None) -> dict[str, list[ModuleType]]:
    """``page -> modules``: one API page per folder package, holding the folder's modules in order."""
    mods = public_modules() if mods is None else mods
    by_name = {m.__name__: m for m in mods}
    pages: dict[str, list[ModuleType]] = {}
    for m in mods:
        pages.setdefault(page_of(m.__name__, by_name), []).append(m)
    return pages


def _summary(obj: object) -> str:
    doc = (
        inspect.getdoc(obj) if not isinstance(obj, (int, float, str, tuple, dict, list, frozenset)) else None
    )
    line = (doc or "").strip().split("\n\n")[0].replace("\n", " ")
    return line


def _heading(text: str, char: str) -> str:
    return f"{text}\n{char * len(text)}\n"


def _table(mod: ModuleType, tg: dict[tuple[str, str], Target]) -> list[str]:
    lines = [".. list-table::", "   :widths: 30 70", ""]
    for name in sorted(names(mod), key=str.lower):
        t = tg[mod.__name__, name]
        role = "mod" if t.kind == "module" else "obj"
        summary = _summary(getattr(mod, name)) if t.kind != "module" else ""
        summary = summary if len(summary) < 160 else summary[:157].rsplit(" ", 1)[0] + " …"
        lines += [f"   * - :py:{role}:`{name} <{t.path}>`", f"     - {_escape(summary)}"]
    return lines + [""]


def _escape(text: str) -> str:
    """A one-line summary made safe inside a table cell (inline markup cut mid-way would warn)."""
    if text.count("``") % 2 or text.count("`") % 2 or text.count("*") % 2:
        return ""
    return text


def write_api(out: Path) -> int:
    """Write the API pages into ``out``; return how many."""
    mods = public_modules()
    by_name = {m.__name__: m for m in mods}
    tg = targets(mods)
    homed: dict[str, list[Target]] = {}
    for t in set(tg.values()):
        if t.kind != "module":
            homed.setdefault(t.module, []).append(t)
    pages = api_pages(mods)
    out.mkdir(parents=True, exist_ok=True)
    for old in out.glob("*.rst"):
        old.unlink()
    for page, members in pages.items():
        pkg = by_name[page]
        lines = [_heading(page, "="), f".. automodule:: {page}", "   :no-members:", ""]
        if names(pkg):
            lines += [".. rubric:: Public names", ""] + _table(pkg, tg)
        lines += _entries(page, homed)
        for m in members:
            if m is pkg:
                continue
            lines += [_heading(m.__name__, "-"), f".. automodule:: {m.__name__}", "   :no-members:", ""]
            reexported = sorted(n for n in m.__all__ if tg[m.__name__, n].module != m.__name__)
            if reexported:
                links = ", ".join(f":py:obj:`{n} <{tg[m.__name__, n].path}>`" for n in reexported)
                lines += [f"Also exported here: {links}.", ""]
            lines += _entries(m.__name__, homed)
        (out / f"{page}.rst").write_text("\n".join(lines), encoding="utf-8")
    tops = [p for p in pages if p in TOPS]
    index = [
        _heading("API reference", "="),
        "Generated from the docstrings of every name in the ``__all__`` of",
        "each public module. One page per folder; a package's table links each of its names to the",
        "module that defines it.",
        "",
        ".. toctree::",
        "   :maxdepth: 1",
        "",
    ]
    for top in tops:
        index.append(f"   {top}")
        index += [f"   {p}" for p in pages if p.startswith(top + ".")]
    (out / "index.rst").write_text("\n".join(index) + "\n", encoding="utf-8")
    return len(pages) + 1


def _entries(module: str, homed: dict[str, list[Target]]) -> list[str]:
    lines: list[str] = []
    for t in sorted(homed.get(module, []), key=lambda t: t.path.lower()):
        directive = {"class": "autoclass", "function": "autofunction", "data": "autodata"}[t.kind]
        lines += [f".. {directive}:: {t.path}"]
        if t.kind == "class":
            lines += ["   :members:", "   :show-inheritance:"]
        if t.kind == "data":
            lines += ["   :no-value:"]
        lines += [""]
    return lines


# --- gallery -------------------------------------------------------------------------------------------
def examples() -> list[Path]:
    return sorted(p for p in (REPO / "examples").glob("*.py") if not p.name.startswith("_"))


def example_doc(path: Path) -> str:
    return ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""


def thesis_figures(doc: str) -> str:
    """The thesis figures (and tables) named in the first paragraph of an example's docstring."""
    found = FIGURE.findall(doc.split("\n\n")[0])
    return ", ".join(dict.fromkeys(f.strip() for f in found))


def write_gallery(out: Path) -> int:
    """Write one page per example and the gallery's index into ``out``; return how many pages."""
    images = out / "images"
    for old in out.glob("*.rst"):
        old.unlink()
    cards = []
    for path in examples():
        name = path.stem
        doc = example_doc(path)
        lead, _, rest = doc.partition("\n\n")
        pics = sorted(images.glob(f"{name}__*.png"))
        figs = thesis_figures(doc)
        lines = [_heading(f"{name}.py", "="), lead.strip(), ""]
        thesis = figs if figs else "none (an illustration of the library)"
        lines += [
            f"**Thesis figure:** {thesis}. **Run:** ``python examples/{name}.py`` (writes into ``out/``)",
            "",
        ]
        if not pics:
            lines += [
                ".. note::",
                "   No picture cached yet: run ``python docs/make_gallery.py " + name + "``.",
                "",
            ]
        for pic in pics:
            lines += [f".. image:: images/{pic.name}", f"   :alt: figure of {name}", ""]
        lines += [
            rest.strip(),
            "",
            ".. rubric:: Source",
            "",
            f".. literalinclude:: ../../examples/{name}.py",
            "   :language: python",
            "",
        ]
        (out / f"{name}.rst").write_text("\n".join(lines), encoding="utf-8")
        cards.append((name, figs, pics[0].name if pics else None))
    idx = (
        [
            _heading("Gallery", "="),
            "Each script of ``examples/`` reproduces a figure of the thesis; its page shows the picture, the",
            "setting and the source. The pictures are cached in ``docs/gallery/images/``: the documentation",
            "build does not run the examples (that takes many minutes on 2 cores);",
            "``python docs/make_gallery.py`` runs them all again and refreshes the pictures.",
            "",
            ".. toctree::",
            "   :hidden:",
            "",
        ]
        + [f"   {n}" for n, _, _ in cards]
        + ["", ".. container:: gallery-grid", ""]
    )
    for name, figs, pic in cards:
        idx += ["   .. container:: gallery-card", ""]
        if pic:
            idx += [
                f"      .. image:: images/{pic}",
                f"         :alt: {name}",
                f"         :target: {name}.html",
                "",
            ]
        idx += [f"      :doc:`{name}`", ""]
        if figs:
            idx += [f"      {figs}", ""]
    (out / "index.rst").write_text("\n".join(idx) + "\n", encoding="utf-8")
    return len(cards) + 1


def write_observation(out: Path) -> Path:
    """The observation's table from its schema (:mod:`digslam.envs.observation`), included by
    ``environments.md``: the docs never restate the layout by hand."""
    from digslam.envs.observation import markdown_table

    out.mkdir(parents=True, exist_ok=True)
    path = out / "observation.inc"
    path.write_text(markdown_table() + "\n", encoding="utf-8")
    return path


def _generate(app: object) -> None:
    write_api(DOCS / "api")
    write_gallery(DOCS / "gallery")
    write_observation(DOCS / "_generated")


def _drop_type_docstring(app, what, name, obj, options, lines):  # noqa: ANN001 (Sphinx's event signature)
    """A constant or alias without a ``#:`` comment would show its type's docstring (``int``, ``ndarray``)."""
    if what not in ("data", "attribute") or not lines:
        return
    kind = obj if inspect.isclass(obj) else type(obj)
    if kind.__module__.startswith("digslam"):
        return
    first = (inspect.getdoc(kind) or "").strip().splitlines()[:1]
    if lines[0].startswith(f"{kind.__name__}(") or [lines[0].strip()] == first:
        lines.clear()


class DocstringMarkup(logging.Filter):
    """Keep markup warnings from the package's docstrings out of the ``-W`` gate; list them in a file.

    The docstrings belong to the code; their few reST slips (an indented line, a cut table, an ambiguous
    relative ``:mod:``) are listed in ``<outdir>/docstring_warnings.txt`` for their owners, while every
    warning of the documentation's own pages still fails the build.
    """

    def __init__(self) -> None:
        super().__init__()
        self.found: list[str] = []

    def filter(self, record: logging.LogRecord) -> bool:
        loc = getattr(record, "location", None)
        if loc is not None and not isinstance(loc, str):
            from sphinx.util.logging import get_node_location

            loc = get_node_location(loc)
        # a docstring of the package, wherever it is installed (the source tree, or site-packages in CI)
        in_docstring = bool(loc) and ":docstring of digslam." in loc and "/docs/" not in loc
        if in_docstring or (loc or "").startswith(str(DOCS / "api")):  # api/ pages hold only docstrings
            self.found.append(f"{loc}: {record.getMessage()}")
            return False
        return True


def _write_docstring_warnings(app, exc) -> None:  # noqa: ANN001 (Sphinx's event signature)
    flt = app.digslam_docstring_filter
    (Path(app.outdir) / "docstring_warnings.txt").write_text("".join(f"{w}\n" for w in flt.found))


def setup(app):  # noqa: ANN001, ANN201 (Sphinx's extension hook)
    app.connect("builder-inited", _generate)
    app.connect("autodoc-process-docstring", _drop_type_docstring)
    app.connect("build-finished", _write_docstring_warnings)
    flt = DocstringMarkup()
    app.digslam_docstring_filter = flt
    for name in (
        "sphinx.sphinx.util.docutils",
        "sphinx.sphinx.domains.python",
        "sphinx.sphinx.domains.std",
        "sphinx.sphinx.transforms.post_transforms",
    ):
        logging.getLogger(name).addFilter(flt)
    return {"parallel_read_safe": False, "parallel_write_safe": True}
