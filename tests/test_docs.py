"""The documentation: every public name has a page, every internal link resolves, the README stays a front door.

The fast tests read the sources of ``docs/`` and the API pages the build would generate
(``docs/_ext/digslam_docs.py``); the full ``sphinx-build -W`` (about a minute of CPU, longer on a busy
machine) is marked ``expensive`` and also runs as a step of ``.ci/run``.
"""

from __future__ import annotations

import importlib
import re
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
DOCS = REPO / "docs"
sys.path.insert(0, str(DOCS / "_ext"))

import digslam_docs  # noqa: E402
from architecture import import_dotted  # noqa: E402

LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^(```|~~~).*?^\1", re.S | re.M)
DIRECTIVE = re.compile(r"^\.\. (automodule|autoclass|autofunction|autodata):: (\S+)", re.M)


def pages() -> list[Path]:
    """The hand-written pages of the documentation (the generated ones are rewritten at each build)."""
    return sorted(p for p in DOCS.rglob("*.md") if "_build" not in p.parts)


def without_code(text: str) -> str:
    """``text`` without its code blocks and inline code (``[J]([x])`` is no link)."""
    return re.sub(r"`[^`\n]*`", "", FENCE.sub("", text))


def slug(heading: str) -> str:
    """MyST's (GitHub's) anchor of a heading."""
    text = re.sub(r"[`*_]", "", heading.strip().lower())
    return re.sub(r"\s", "-", re.sub(r"[^\w\s-]", "", text))


def anchors(path: Path) -> set[str]:
    if path.suffix != ".md":
        return set()
    return {slug(h) for h in re.findall(r"^#{1,6} (.+)$", without_code(path.read_text()), re.M)}


@pytest.fixture(scope="module")
def generated(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """The API pages the build would write: ``page -> text``."""
    out = tmp_path_factory.mktemp("api")
    digslam_docs.write_api(out)
    return {p.stem: p.read_text() for p in out.glob("*.rst")}


def generated_docnames() -> set[str]:
    api = {f"api/{p}" for p in digslam_docs.api_pages()} | {"api/index"}
    gallery = {f"gallery/{p.stem}" for p in digslam_docs.examples()} | {"gallery/index"}
    return api | gallery


# --- every public name has a page ----------------------------------------------------------------------
def test_every_public_name_is_documented_once(generated: dict[str, str]) -> None:
    documented: dict[str, str] = {}
    for page, text in generated.items():
        for _, path in DIRECTIVE.findall(text):
            assert path not in documented, f"{path} documented on {documented[path]} and {page}"
            documented[path] = page
    mods = digslam_docs.public_modules()
    targets = digslam_docs.targets(mods)
    assert sum(len(digslam_docs.names(m)) for m in mods) == len(targets) > 500
    for (module, name), target in targets.items():
        assert target.path in documented, f"{module}.{name}: no page documents {target.path}"
        obj = getattr(importlib.import_module(module), name)
        home = importlib.import_module(target.module)
        same = importlib.import_module(target.path) if target.kind == "module" else getattr(home, name)
        assert same is obj, f"{module}.{name} is documented as {target.path}, another object"


def test_every_public_module_has_a_section(generated: dict[str, str]) -> None:
    text = "\n".join(generated.values())
    for mod in digslam_docs.public_modules():
        assert f".. automodule:: {mod.__name__}\n" in text, mod.__name__
    for top in digslam_docs.TOPS:  # the top packages' tables list every one of their names
        table = generated[top]
        for name in digslam_docs.names(importlib.import_module(top)):
            assert f":`{name} <" in table, f"{top}.{name} missing from its table"


# --- every internal link resolves ----------------------------------------------------------------------
def resolve(source: Path, target: str) -> str | None:
    """Why the link ``target`` of ``source`` does not resolve, or None."""
    if re.match(r"^[a-z]+:", target) or target.startswith("#") and source.suffix != ".md":
        return None  # an URL
    ref, _, anchor = target.partition("#")
    if not ref:
        path = source
    else:
        path = (source.parent / ref).resolve()
        if not path.exists():
            docname = path.relative_to(DOCS.resolve()).as_posix() if DOCS.resolve() in path.parents else None
            if docname is not None and docname.removesuffix(".rst") in generated_docnames():
                return None if not anchor else f"{target}: anchor into a generated page"
            if path.with_suffix(".md").exists():
                path = path.with_suffix(".md")
            else:
                return f"{target}: no such file"
    if anchor and anchor not in anchors(path):
        return f"{target}: no heading with anchor {anchor!r} in {path.name}"
    return None


def test_every_internal_link_of_the_pages_resolves() -> None:
    broken = []
    for page in pages() + [REPO / "README.md", REPO / "CHANGELOG.md"]:
        for target in LINK.findall(without_code(page.read_text())):
            why = resolve(page, target)
            if why:
                broken.append(f"{page.relative_to(REPO)}: {why}")
    assert not broken, "\n".join(broken)


def test_every_page_is_in_a_toctree() -> None:
    listed = set()
    for page in pages():
        for block in re.findall(r"```\{toctree\}(.*?)```", page.read_text(), re.S):
            for line in block.splitlines():
                if line.strip() and not line.strip().startswith(":"):
                    listed.add((page.parent / line.strip()).resolve().relative_to(DOCS.resolve()).as_posix())
    missing = [p for p in pages() if p.name != "index.md" or p.parent != DOCS]
    missing = [p for p in missing if p.relative_to(DOCS).with_suffix("").as_posix() not in listed]
    assert not missing, f"pages in no toctree: {missing}"
    assert {"api/index", "gallery/index"} <= listed


@pytest.mark.filterwarnings("ignore::DeprecationWarning")  # layout.md names the old paths of 0.1
def test_every_dotted_path_in_the_pages_imports() -> None:
    text = "\n".join(p.read_text() for p in pages())
    for path in sorted(set(re.findall(r"\bdigslam\.(?:observer|envs|agents)(?:\.[a-z_]+)+", text))):
        if import_dotted(path) is None:
            pytest.fail(f"{path} does not import")


def test_every_python_block_of_the_pages_compiles() -> None:
    for page in pages() + [REPO / "README.md"]:
        for i, block in enumerate(re.findall(r"^```python\n(.*?)^```", page.read_text(), re.S | re.M)):
            compile(block, f"{page.name}, python block {i + 1}", "exec")


# --- the gallery -----------------------------------------------------------------------------------------
def test_every_example_has_a_cached_picture_and_a_thesis_reference() -> None:
    images = DOCS / "gallery" / "images"
    for example in digslam_docs.examples():
        assert list(images.glob(f"{example.stem}__*.png")), f"{example.stem}: run docs/make_gallery.py"
    total = sum(p.stat().st_size for p in images.glob("*.png"))
    assert total < 6e6, f"gallery pictures take {total / 1e6:.1f} MB"
    refs = {p.stem: digslam_docs.thesis_figures(digslam_docs.example_doc(p)) for p in digslam_docs.examples()}
    assert refs["ex2_7_ring"] == "Figure 2.12"
    assert sum(bool(r) for r in refs.values()) >= len(refs) - 3, refs


# --- the README ------------------------------------------------------------------------------------------
def test_readme_is_a_front_door_and_ci_installs_what_it_says() -> None:
    readme = (REPO / "README.md").read_text()
    assert len(readme.splitlines()) <= 200
    assert (REPO / "docs" / "_static" / "demo_frame.png").exists()
    assert readme.index("CUDA") < readme.index("pip install torch==2.13.0 && ")
    main_job, tests = re.findall(
        r"^pip install torch==2\.13\.0 && pip install \"(\.\[[a-z,]+\])\"", readme, re.M
    )
    assert main_job == ".[sim,viz,train]" and tests == ".[sim,viz,train,dev,docs]"
    ci = (REPO / ".ci" / "run").read_text()
    assert f'python -m pip install -q "{tests}"' in ci and "python -m pytest -q" in ci


# --- the full build --------------------------------------------------------------------------------------
class _Links(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.hrefs: list[str] = []
        self.ids: set[str] = set()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        d = dict(attrs)
        if d.get("id"):
            self.ids.add(d["id"] or "")
        if tag == "a" and d.get("href"):
            self.hrefs.append(d["href"] or "")
        if tag == "span" and "problematic" in (d.get("class") or "") and self.hrefs:
            self.hrefs.pop()  # a docstring's markup slip, listed in docstring_warnings.txt
        if tag in ("img", "script") and d.get("src"):
            self.hrefs.append(d["src"] or "")


@pytest.mark.expensive
def test_the_docs_build_with_warnings_as_errors(tmp_path: Path) -> None:
    from sphinx.cmd.build import build_main
    from sphinx.util.inventory import InventoryFile

    out = tmp_path / "html"
    assert build_main(["-W", "-q", "-b", "html", str(DOCS), str(out)]) == 0
    with open(out / "objects.inv", "rb") as f:
        inv = InventoryFile.load(f, "", lambda base, uri: uri)
    names = {name for group in inv.values() for name in group} if isinstance(inv, dict) else set(inv)
    missing = {t.path for t in digslam_docs.targets().values()} - names
    assert not missing, sorted(missing)[:20]
    parsed = {}
    for html in out.rglob("*.html"):
        p = _Links()
        p.feed(html.read_text(encoding="utf-8"))
        parsed[html.resolve()] = p
    broken = []
    for html, p in parsed.items():
        for href in p.hrefs:
            if re.match(r"^[a-z]+:", href) or href.startswith("//"):
                continue
            ref, _, anchor = href.partition("#")
            ref = ref.partition("?")[0]  # a cache-busting query of a static file
            target = (html.parent / ref).resolve() if ref else html
            if not target.exists():
                broken.append(f"{html.name}: {href}")
            elif anchor and target in parsed and anchor not in parsed[target].ids:
                broken.append(f"{html.name}: {href} (no id {anchor})")
    assert not broken, broken[:20]
