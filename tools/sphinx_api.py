"""The book's API reference: one page per public module of ``orrc``, generated from the docstrings.

Loaded by ``_config.yml`` (``sphinx: local_extensions: {sphinx_api: tools}``) next to Sphinx's
``autodoc``, ``autosummary`` and ``napoleon``. It adds

1. the directive ``orrc-module``: ``.. orrc-module:: orrc.costs`` documents the module's public
   names (its ``__all__``, else the public names it defines) with autodoc, each name once in the
   whole reference: a name that a package above it exports (``orrc.QuadraticCost`` is
   ``orrc.costs.QuadraticCost``) is documented on that package's page and only linked from here
   (autodoc records the defining path as the canonical name, so both spellings resolve);
2. the docstring convention of ``orrc`` for napoleon: the package writes its Parameters and
   Attributes entries as ``name : what it is`` (a description, not a type, after the colon);
   :func:`entries_without_types` turns each into ``name`` with the description below it, so
   napoleon renders the text as the entry's description instead of as cross-referenced types.

:data:`MODULES` is the list of pages (``book/api/<module>.md``) and :func:`documented_at` says where
each public name is documented; ``tests/test_api_reference.py`` checks both against the built HTML.
"""
from __future__ import annotations

import functools
import importlib
import inspect
import re
import types

from docutils import nodes
from docutils.parsers.rst import Directive
from docutils.statemachine import StringList
from sphinx.util.nodes import nested_parse_with_titles

#: the modules with a page of their own, in the reference's order: the top-level package, its
#: public modules and subpackages, and the plotting modules that ``orrc.viz`` exports
MODULES = (
    "orrc", "orrc.systems", "orrc.parametric", "orrc.costs", "orrc.disturbances", "orrc.forecasts", "orrc.examples",
    "orrc.controllers", "orrc.simulate", "orrc.metrics", "orrc.sweep", "orrc.config",
    "orrc.theory", "orrc.checks", "orrc.certify", "orrc.estimation", "orrc.solvers", "orrc.tradeoff",
    "orrc.comparison", "orrc.viz", "orrc.viz.figures", "orrc.viz.describe", "orrc.viz.plots", "orrc.viz.theory_plots",
    "orrc.viz.comparison_plots", "orrc.viz.unknown_plots", "orrc.viz.minmax_plots",
)


def public_names(modname: str) -> list[str]:
    """The public names of a module: its ``__all__`` (modules left out: they have pages or are
    implementation), else every name without a leading underscore that it defines."""
    mod = importlib.import_module(modname)
    names = getattr(mod, "__all__", None)
    if names is None:
        names = [n for n, v in vars(mod).items() if not n.startswith("_")
                 and getattr(v, "__module__", None) == modname and (inspect.isclass(v) or inspect.isfunction(v))]
    return [n for n in names if not isinstance(getattr(mod, n), types.ModuleType)]


def submodules(modname: str) -> list[str]:
    """The public modules inside the package ``modname`` (none for a plain module) that have no
    page of their own: their docstrings are shown on the package's page."""
    import pkgutil

    mod = importlib.import_module(modname)
    if not hasattr(mod, "__path__"):
        return []
    return [f"{modname}.{info.name}" for info in pkgutil.iter_modules(mod.__path__)
            if not info.name.startswith("_") and f"{modname}.{info.name}" not in MODULES]


def documented_at(modname: str, name: str) -> str:
    """The module whose page documents ``modname.name``: the first page of :data:`MODULES` above
    ``modname`` (``orrc`` before ``orrc.viz`` before ``orrc.viz.plots``) that exports the same object."""
    obj = getattr(importlib.import_module(modname), name)
    parts = modname.split(".")
    for i in range(1, len(parts)):
        parent = ".".join(parts[:i])
        if parent in MODULES and name in public_names(parent) and getattr(importlib.import_module(parent), name) is obj:
            return parent
    return modname


_SECTION = re.compile(r"^(\s*)(Parameters|Attributes|Other Parameters|Keyword Arguments)\s*$")
_ENTRY = re.compile(r"^(\s*)([*\w][\w, *]*?)\s+:\s+(\S.*)$")


def entries_without_types(lines: list[str]) -> list[str]:
    """``name : description`` entries of the Parameters/Attributes sections rewritten as ``name``
    with the description indented below (continuation lines keep their place); a paragraph after
    the entries (at their indent, no entry) gets two blank lines before it, which end the section
    for napoleon; other lines as given."""
    out, section, indent, kind = [], False, "", ""
    for i, line in enumerate(lines):
        m = _SECTION.match(line)
        if m and i + 1 < len(lines) and set(lines[i + 1].strip()) == {"-"}:
            section, indent, kind = True, m.group(1), m.group(2)
            out.append(line)
            continue
        if section and line.strip() and not line.startswith(indent + " ") and not set(line.strip()) == {"-"} \
                and not _ENTRY.match(line):
            section = False   # a line at the section's indent that is no entry: the section ended,
            while out and not out[-1].strip():   # which napoleon sees only after two blank lines
                out.pop()
            out += ["", ""]
        e = _ENTRY.match(line) if section else None
        if e and e.group(1) == indent:   # "a, b" as one name (napoleon's variables take no list)
            names = e.group(2) if kind == "Parameters" else re.sub(r",\s*", ",", e.group(2))
            out += [f"{indent}{names}", f"{indent}    {e.group(3)}"]
        else:
            out.append(line)
    return out


_ROLE = re.compile(r":(?:py:)?(func|class|meth|attr|data|obj|mod|exc):`(~?)([\w.]+)`")


def absolute_roles(lines: list[str], name: str, obj) -> list[str]:
    """Python roles whose target is relative to where the docstring was written (``:data:`glued```
    in :mod:`orrc.viz.notebook`, shown in the reference as ``orrc.viz.glue``) given the absolute
    target, the text kept: the documented object's class and defining module, then the packages
    above that module, are tried in turn; a target that resolves as written is left alone."""
    home = obj.__name__ if inspect.ismodule(obj) else getattr(obj, "__module__", None) or ""
    parent = name.rpartition(".")[0]
    scopes = ([parent] if parent and inspect.isclass(resolve(parent)) else [])
    scopes += [".".join(home.split(".")[:i]) for i in range(home.count(".") + 1, 0, -1)]

    def fix(m):
        role, tilde, target = m.groups()
        if resolve(target) is not MISSING and target.startswith("orrc"):
            return m.group(0)
        for scope in scopes:
            if scope and resolve(f"{scope}.{target}") is not MISSING:
                shown = target.rpartition(".")[2] if tilde else target
                return f":py:{role}:`{shown} <{scope}.{target}>`"
        return m.group(0)

    return [_ROLE.sub(fix, line) for line in lines]


def implicit_attributes(lines: list[str]) -> list[str]:
    """A class docstring that lists its attributes as ``name : what it is`` lines after a blank line,
    without a section header, gets the header ``Attributes`` before the first of them (napoleon
    renders them as the class's variables); a docstring with sections of its own is left alone."""
    for i, line in enumerate(lines):
        if _SECTION.match(line) or (i + 1 < len(lines) and line.strip() and set(lines[i + 1].strip()) == {"-"}):
            return lines
        e = _ENTRY.match(line)
        if e and not e.group(1) and i > 0 and not lines[i - 1].strip():
            return lines[:i] + ["Attributes", "----------"] + lines[i:]
    return lines


def inline_colon(lines: list[str]) -> bool:
    """True when the first line of an attribute's or property's docstring holds a colon outside
    code (``(K, feedforward) of the fast path: u = ...``), which napoleon would read as
    ``type: description``: such docstrings bypass napoleon (:func:`_restore_docstring`)."""
    first = re.sub(r"`[^`]*`", "", lines[0]) if lines else ""
    return bool(re.search(r"(?<!:):(?!:)", first))


_BYPASS: dict = {}


_CODE = re.compile(r"(``.+?``|:[\w:]+:`[^`]*`|`[^`]*`)")


def literal_bars(lines: list[str]) -> list[str]:
    """``|x|`` (an absolute value, a norm) is reStructuredText's substitution syntax: every bar
    outside code and roles is escaped, so that it shows as written."""
    return ["".join(part if i % 2 else part.replace("|", "\\|") for i, part in enumerate(_CODE.split(line)))
            for line in lines]


def _process_docstring(app, what, name, obj, options, lines) -> None:
    fixed = literal_bars(absolute_roles(lines, name, obj))
    if what in ("class", "exception"):
        fixed = implicit_attributes(fixed)
    lines[:] = entries_without_types(fixed)
    if what in ("attribute", "property", "data") and inline_colon(lines):
        _BYPASS[(what, name)] = list(lines)


def _restore_docstring(app, what, name, obj, options, lines) -> None:
    """After napoleon: an attribute docstring with a colon in its first line, as it was before."""
    kept = _BYPASS.pop((what, name), None)
    if kept is not None:
        lines[:] = kept


def _no_index(modname: str) -> list[str]:
    """``:no-index:`` for a module that its package shadows with a function of the same name
    (``orrc.sweep`` is the function :func:`orrc.sweep`; its module's page has no index entry)."""
    parent, _, name = modname.rpartition(".")
    shadowed = parent and not inspect.ismodule(getattr(importlib.import_module(parent), name, None))
    return ["   :no-index:"] if shadowed else []


class OrrcModule(Directive):
    """``.. orrc-module:: orrc.x``: autodoc of the module's own public names, links to the others."""

    required_arguments = 1

    def run(self):
        modname = self.arguments[0]
        names = public_names(modname)
        own = [n for n in names if documented_at(modname, n) == modname]
        elsewhere = [(n, documented_at(modname, n)) for n in names if n not in own]
        rst = [f".. automodule:: {modname}", *_no_index(modname), ""]
        if own:
            rst += [".. autosummary::", "   :nosignatures:", ""] + [f"   {n}" for n in own] + [""]
            for n in own:
                kind = "autoclass" if inspect.isclass(getattr(importlib.import_module(modname), n)) else "autofunction"
                if kind == "autoclass":
                    rst += [f".. autoclass:: {modname}.{n}", "   :members:", "   :show-inheritance:", ""]
                elif callable(getattr(importlib.import_module(modname), n)):
                    rst += [f".. autofunction:: {modname}.{n}", ""]
                else:
                    rst += [f".. autodata:: {modname}.{n}", ""]
        subs = submodules(modname)
        if subs:
            rst += [".. rubric:: Its modules", ""]
            for sub in subs:   # their docstrings: what each module holds (and targets for :mod: links)
                rst += [f".. automodule:: {sub}", *_no_index(sub), ""]
        if elsewhere:
            links = ", ".join(f":py:obj:`{parent}.{n}`" for n, parent in elsewhere)
            rst += [f"Also exported here, documented where a package above exports them: {links}.", ""]
        # the pages are MyST Markdown, autodoc writes reStructuredText: parse it as such
        fence = "`" * 6
        text = [f"{fence}{{eval-rst}}", *rst, fence]
        node = nodes.section()
        node.document = self.state.document
        nested_parse_with_titles(self.state, StringList(text, source=f"<orrc-module {modname}>"), node)
        return node.children


MISSING = object()


@functools.lru_cache(maxsize=None)
def resolve(dotted: str):
    """The Python object a dotted name ``orrc.x.y.Z.attr`` names (:data:`MISSING` when it names nothing);
    remembered for the build (a name that names nothing costs a search of the path per attempt)."""
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for attr in parts[i:]:
            if not hasattr(obj, attr):
                return MISSING
            obj = getattr(obj, attr)
        return obj
    return MISSING


def _linkable(obj) -> bool:
    """Objects with an identity of their own (a number or a string could be many names' value)."""
    return inspect.ismodule(obj) or inspect.isclass(obj) or inspect.isroutine(obj) or isinstance(obj, property)


def _documented(env) -> dict:
    """id(object) -> (name, entry) of every documented Python object, from the py domain's objects."""
    objects = env.get_domain("py").objects
    key = len(objects)
    cache = getattr(env, "_orrc_documented", None)
    if cache is None or cache[0] != key:
        table = {}
        for name, entry in objects.items():
            if entry.aliased:
                continue
            obj = resolve(name)
            if obj is not MISSING and _linkable(obj):
                table.setdefault(id(obj), (name, entry, obj))
        cache = env._orrc_documented = (key, table)
    return cache[1]


def _missing_reference(app, env, node, contnode):
    """A Python reference that names an ``orrc`` object under another of its import paths (relative
    to the module or class it is written in, ``orrc.controllers.Observation`` for ``orrc.Observation``,
    a submodule's function by its package's name) links to the object's entry; one that names an
    existing ``orrc`` object without an entry (an implementation detail) stays code text without a
    link. Anything else (a name that exists nowhere) is left to Sphinx's warning."""
    from sphinx.util.nodes import make_refnode

    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip(".~")
    mod, cls = node.get("py:module"), node.get("py:class")
    candidates = [f"{mod}.{cls}.{target}" if mod and cls else None, f"{mod}.{target}" if mod else None, target]
    for name in filter(None, candidates):
        if not name.startswith("orrc"):
            continue
        obj = resolve(name)
        if obj is MISSING:
            continue
        hit = _documented(env).get(id(obj)) if _linkable(obj) else None
        if hit is not None and hit[2] is obj:
            _, entry, _ = hit
            return make_refnode(app.builder, node["refdoc"], entry.docname, entry.node_id, contnode, hit[0])
        return contnode
    return None


#: abbreviations after which autosummary's one-line summary must not stop ("x_{t+1} = ... (Eq." is no
#: sentence): the paper's equations, sections and figures are cited this way in every docstring
ABBREVIATIONS = ("Eq.", "Eqs.", "Sec.", "Fig.", "Alg.", "cf.", "resp.", "vs.")


def setup(app):
    from sphinx.ext import autosummary

    autosummary.WELL_KNOWN_ABBREVIATIONS = tuple(dict.fromkeys(autosummary.WELL_KNOWN_ABBREVIATIONS + ABBREVIATIONS))
    app.connect("autodoc-process-docstring", _process_docstring, priority=400)  # before napoleon (500)
    app.connect("autodoc-process-docstring", _restore_docstring, priority=600)  # after napoleon
    app.connect("missing-reference", _missing_reference)
    app.add_directive("orrc-module", OrrcModule)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
