"""The book's API reference (issue 24): every public name of ``orrc`` has an entry, every public
module a page, each entry shows its signature and its docstring's sections rendered.

The reference is generated at build time from the docstrings (tools/sphinx_api.py); the HTML
checks read the session's one build (the ``book`` fixture); the docstring conventions are checked
without a build.
"""
from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
import types
from pathlib import Path

import pytest

import orrc
from conftest import BOOK_HTML as HTML
from tools.sphinx_api import (MISSING, MODULES, documented_at, entries_without_types, implicit_attributes,
                              public_names, resolve)
from tools.toc import teaching_chapters, toc_pages

ROOT = Path(__file__).resolve().parents[1]

# the packages whose __all__ is the public API (orrc and its subpackages)
PACKAGES = ["orrc"] + [f"orrc.{m.name}" for m in pkgutil.iter_modules(orrc.__path__) if m.ispkg
                       and not m.name.startswith("_")]


def page_of(module: str) -> str:
    return "book/api/" + ("orrc" if module == "orrc" else module.removeprefix("orrc.").replace(".", "_"))


def public_modules() -> list[str]:
    """Every module of orrc without a leading underscore in its path, subpackages' modules included."""
    names = []
    for info in pkgutil.walk_packages(orrc.__path__, "orrc."):
        if not any(part.startswith("_") for part in info.name.split(".")):
            names.append(info.name)
    return names


# ---------------------------------------------------------------- without a build

def test_every_package_has_a_page():
    assert set(PACKAGES) <= set(MODULES), f"packages without a page: {sorted(set(PACKAGES) - set(MODULES))}"
    pages = toc_pages(ROOT)
    for module in MODULES:
        assert page_of(module) in pages, f"{module}: {page_of(module)} is not in _toc.yml"
        text = (ROOT / f"{page_of(module)}.md").read_text(encoding="utf-8")
        assert f"{{orrc-module}} {module}" in text, f"{page_of(module)}.md does not document {module}"
    last_chapter = max(pages.index(c) for c in teaching_chapters(ROOT))
    assert pages.index("book/api/index") > last_chapter, "the reference comes after the chapters"


def test_every_public_name_is_documented_once_where_it_is_exported_highest():
    for package in PACKAGES:
        for name in public_names(package):
            home = documented_at(package, name)
            assert home in MODULES and name in public_names(home)
            assert getattr(importlib.import_module(home), name) is getattr(importlib.import_module(package), name)
    assert documented_at("orrc.controllers", "PreviewRHC") == "orrc"        # orrc.PreviewRHC
    assert documented_at("orrc.controllers", "FailureLadder") == "orrc.controllers"


def test_parameter_entries_lose_their_description_as_type():
    doc = ["Run it.", "", "Parameters", "----------", "system, cost : the model and the stage-cost family.",
           "M : preview horizon (M >= 1); the controller sees", "    w and c M steps ahead.", "",
           "Solver failures follow the ladder: a retry, then IPOPT."]
    out = entries_without_types(doc)
    assert out[4:8] == ["system, cost", "    the model and the stage-cost family.", "M",
                        "    preview horizon (M >= 1); the controller sees"]
    # the paragraph after the entries ends the section for napoleon (two blank lines before it)
    assert out[-3:] == ["", "", "Solver failures follow the ladder: a retry, then IPOPT."]
    attrs = implicit_attributes(["The result.", "", "x : (T+1, n) states", "u : (T, m) inputs"])
    assert attrs[2:4] == ["Attributes", "----------"]
    assert implicit_attributes(doc) == doc, "a docstring with sections of its own keeps them"
    assert resolve("orrc.controllers.preview.PreviewRHC") is orrc.PreviewRHC
    assert resolve("orrc.no_such_name") is MISSING


# ---------------------------------------------------------------- the built reference

@pytest.fixture(scope="module")
def inventory(book):
    from sphinx.util.inventory import InventoryFile

    assert book["rc"] == 0, "the book did not build"
    with open(HTML / "objects.inv", "rb") as f:
        inv = InventoryFile.load(f, "", lambda base, uri: uri)
    return {kind[3:]: entries for kind, entries in inv.items() if kind.startswith("py:")}


@pytest.mark.slow
def test_every_public_name_has_an_entry(inventory):
    """Every name of orrc.__all__ and of each subpackage's __all__ has an entry in the reference
    that names the same object (the same object may be documented under the package that exports
    it highest: orrc.controllers.PreviewRHC is the entry orrc.PreviewRHC)."""
    entries = {name: (kind, uri) for kind, items in inventory.items() for name, (_, _, uri, _) in items.items()}
    by_object = {}
    for name, (kind, uri) in entries.items():
        obj = resolve(name)
        if obj is not MISSING and (inspect.isclass(obj) or inspect.isroutine(obj) or inspect.ismodule(obj)):
            by_object.setdefault(id(obj), []).append(name)
    missing = []
    for package in PACKAGES:
        module = importlib.import_module(package)
        for name in module.__all__:
            obj = getattr(module, name)
            if inspect.isclass(obj) or inspect.isroutine(obj) or isinstance(obj, types.ModuleType):
                found = f"{package}.{name}" in entries or id(obj) in by_object
            else:   # data (a constant): its entry under its documented name
                found = f"{documented_at(package, name)}.{name}" in entries
            if not found:
                missing.append(f"{package}.{name}")
    assert not missing, f"public names without an entry in the API reference: {missing}"


@pytest.mark.slow
def test_every_public_module_has_an_entry(inventory):
    modules = inventory.get("module", {})
    shadowed = [m for m in public_modules() if not inspect.ismodule(getattr(importlib.import_module(
        m.rpartition(".")[0]), m.rpartition(".")[2], None))]
    missing = [m for m in public_modules() if m not in modules and m not in shadowed]
    assert not missing, f"public modules without an entry: {missing}"
    for m in shadowed:   # orrc.sweep is also the function orrc.sweep: the module is shown on its page
        assert m in MODULES or m.rpartition(".")[0] in MODULES, f"{m} is shown nowhere"


@pytest.mark.slow
def test_entries_show_signature_parameters_and_returns(book):
    text = (HTML / "book/api/orrc.html").read_text(encoding="utf-8")
    entry = text[text.index('id="orrc.PreviewRHC"'):text.index('id="orrc.MinMaxRHC"')]
    assert 'class="sig-param"' in entry and "input_bounds" in entry, "PreviewRHC's signature is not shown"
    assert re.search(r"Parameters.*?input_bounds.*?the set U", entry, re.S), "PreviewRHC's parameters are not listed"
    assert "Eq. (3)" in entry, "PreviewRHC's entry does not name the paper's equation it solves"
    # no description rendered as a type (napoleon's "name : type" reading of "name : what it is")
    assert not re.search(r'class="classifier"|<em>\(the model', entry), "a description was rendered as a type"
    certify = (HTML / "book/api/certify.html").read_text(encoding="utf-8")
    fn = certify[certify.index('id="orrc.certify.worst_case_regret"'):]
    fn = fn[:fn.index("</dd>")]
    assert "worst_case_regret" in fn and 'class="sig-param"' in fn and "Regret" in fn
    for page in (ROOT / "book/api").glob("*.md"):
        html = (HTML / "book/api" / f"{page.stem}.html").read_text(encoding="utf-8")
        body = re.sub(r"<(pre|code|script|style)\b.*?</\1>", "", html, flags=re.S)
        assert not re.search(r"\n\s*-{4,}\s*\n|^\s*Parameters\s*$", re.sub(r"<[^>]+>", "", body), re.M), \
            f"{page.stem}: a numpydoc section header left unrendered"


@pytest.mark.slow
def test_the_reference_is_searchable(book):
    """The search box finds every public class and function by name (Sphinx's search index lists it)."""
    import json

    text = (HTML / "searchindex.js").read_text(encoding="utf-8")
    index = json.loads(text[text.index("(") + 1:text.rindex(")")])
    found = {f"{prefix}.{entry[4]}" if prefix else entry[4] for prefix, entries in index["objects"].items()
             for entry in entries}
    wanted = {f"{documented_at(p, n)}.{n}" for p in PACKAGES for n in public_names(p)
              if inspect.isclass(getattr(importlib.import_module(p), n))
              or inspect.isroutine(getattr(importlib.import_module(p), n))}
    assert "orrc.PreviewRHC" in wanted and "orrc.certify.worst_case_regret" in wanted
    assert not wanted - found, f"not in the search index: {sorted(wanted - found)}"
