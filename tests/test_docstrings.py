"""The public API's docstrings follow numpydoc, and their examples run as shown.

Every docstring example of every module of ``orrc`` runs as a doctest (what the API reference
shows is what the code prints), and every public name of ``orrc`` (``orrc.__all__``, and the public
names of the modules it exports, ``orrc.disturbances`` and ``orrc.examples``) has an Examples
section; a function also states what it returns (Returns, or Yields for a generator or a context
manager), and a class whose constructor takes arguments lists them (Parameters).
"""
from __future__ import annotations

import doctest
import importlib
import inspect
import pkgutil
import re
import types

import pytest

import orrc
import orrc.viz
from tools.sphinx_api import documented_at, public_names

#: names whose docstrings are written beside their module's other changes; emptied when those land
PENDING_DOCSTRINGS = {"MinMaxRHC"}

#: public modules beyond orrc.__all__ whose every public name is held to the same sections
COMPLETE_PACKAGES = ["orrc.config", "orrc.theory", "orrc.checks", "orrc.certify", "orrc.estimation",
                     "orrc.comparison", "orrc.tradeoff", "orrc.costs", "orrc.controllers", "orrc.controllers.gpc",
                     "orrc.controllers.hinf", "orrc.controllers.lifted", "orrc.solvers.lq", "orrc.solvers.game",
                     "orrc.solvers.condensed", "orrc.solvers.regret", "orrc.viz", "orrc.systems", "orrc.trajectory",
                     "orrc.viz.figures", "orrc.viz.legibility", "orrc.viz.narrow", "orrc.viz.describe", "orrc.viz.kernel",
                     "orrc.solvers.acceptance", "orrc.solvers.qp", "orrc.solvers.warm_sqp", "orrc.solvers.exchange",
                     *("orrc.viz.plots", "orrc.viz.rhc_plots", "orrc.viz.style", "orrc.viz.tables",
                       "orrc.viz.theory_plots", "orrc.viz.lemma1_plots", "orrc.viz.lemma2_plots",
                       "orrc.viz.theorem1_plots", "orrc.viz.comparison_plots", "orrc.viz.unknown_plots",
                       "orrc.viz.lemma34_plots", "orrc.viz.theorem2_plots", "orrc.viz.minmax_plots",
                       "orrc.viz.lemma6_plots")]
#: the figure modules of orrc.viz: every public function also lists its Parameters
PLOT_MODULES = [m for m in COMPLETE_PACKAGES if m.startswith("orrc.viz.") and m.endswith(("plots", "style", "tables"))]
#: modules of those packages whose docstrings do not have their sections yet
PENDING_MODULES = {"orrc.certify.minmax", "orrc.certify._lemma6_case", "orrc.certify._lemma6_recheck",
                   "orrc.controllers.minmax"}

FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def modules() -> list[str]:
    """Every module of orrc, private ones included (a public name may be defined in one)."""
    return ["orrc"] + [m.name for m in pkgutil.walk_packages(orrc.__path__, "orrc.")]


def doctests(module: str) -> list[doctest.DocTest]:
    """The docstring examples defined in ``module`` itself (not those of names it imports)."""
    mod = importlib.import_module(module)
    finder = doctest.DocTestFinder(exclude_empty=True)
    return [t for t in finder.find(mod, module) if t.examples]


WITH_EXAMPLES = [m for m in modules() if doctests(m)]


@pytest.mark.parametrize("module", WITH_EXAMPLES)
def test_docstring_examples_run_as_shown(module):
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    report = []
    for test in doctests(module):
        test.globs = dict(test.globs)
        out = []
        result = runner.run(test, out=out.append, clear_globs=True)
        if result.failed:
            report.append("".join(out))
    assert not report, "\n".join(report)


def public_api() -> dict[str, object]:
    """orrc.__all__ by name, a module replaced by its public names (``disturbances.uniform_ball``)."""
    names = {}
    for name in orrc.__all__:
        obj = getattr(orrc, name)
        if isinstance(obj, types.ModuleType):
            for sub in public_names(obj.__name__):
                names[f"{name}.{sub}"] = getattr(obj, sub)
        else:
            names[name] = obj
    return names


def sections(doc: str) -> set[str]:
    """The numpydoc section headers of a docstring (a title line underlined with dashes)."""
    lines = inspect.cleandoc(doc or "").splitlines()
    return {lines[i].strip() for i in range(len(lines) - 1)
            if lines[i].strip() and re.fullmatch(r"-{3,}", lines[i + 1].strip())}


def missing_sections(obj) -> list[str]:
    doc = inspect.getdoc(obj) or ""
    have = sections(doc)
    missing = [] if "Examples" in have else ["Examples"]
    if inspect.isclass(obj):
        if issubclass(obj, BaseException):   # exceptions and warnings: their message
            return missing
        params = [p for p in inspect.signature(obj).parameters.values()
                  if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
        if params and not ({"Parameters", "Attributes"} & have):   # a dataclass lists its fields
            missing.append("Parameters")
    elif callable(obj) and not ({"Returns", "Yields"} & have):
        missing.append("Returns")
    return missing


def test_every_public_name_has_its_numpydoc_sections():
    api = public_api()
    gaps = {name: missing_sections(obj) for name, obj in api.items() if name not in PENDING_DOCSTRINGS}
    gaps = {name: m for name, m in gaps.items() if m}
    assert not gaps, "public names without their docstring sections: " + "; ".join(
        f"{name} ({', '.join(m)})" for name, m in sorted(gaps.items()))


def test_every_name_of_the_documented_packages_has_its_numpydoc_sections():
    gaps = {}
    for package in COMPLETE_PACKAGES:
        module = importlib.import_module(package)
        for name in public_names(package):
            obj = getattr(module, name)
            if documented_at(package, name) != package or getattr(inspect.unwrap(obj), "__module__", "") in PENDING_MODULES:
                continue
            if not (inspect.isclass(obj) or inspect.isroutine(obj)):
                continue   # constants: described in their module's docstring
            missing = missing_sections(obj)
            if missing:
                gaps[f"{package}.{name}"] = missing
    assert not gaps, "public names without their docstring sections: " + "; ".join(
        f"{name} ({', '.join(m)})" for name, m in sorted(gaps.items()))


def test_every_figure_function_lists_its_parameters():
    gaps = []
    for package in PLOT_MODULES:
        module = importlib.import_module(package)
        for name in public_names(package):
            obj = getattr(module, name)
            if not (inspect.isclass(obj) or inspect.isroutine(obj)):
                continue
            params = [p for p in inspect.signature(obj).parameters.values()
                      if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
            if params and "Parameters" not in sections(inspect.getdoc(obj)):
                gaps.append(f"{package}.{name}")
    # every module of orrc.viz that draws figures is held to it
    drawing = {f"orrc.viz.{m.name}" for m in pkgutil.iter_modules(orrc.viz.__path__)
               if m.name.endswith("_plots") or m.name in ("plots", "style", "tables")}
    assert drawing <= set(PLOT_MODULES), f"figure modules left out: {sorted(drawing - set(PLOT_MODULES))}"
    assert not gaps, f"figure functions without a Parameters section: {gaps}"


def test_pending_names_are_public_names():
    assert PENDING_DOCSTRINGS <= set(public_api()), "a pending name is not public: drop it from the set"


def test_the_section_reader_reads_numpydoc():
    doc = '''Summary.

    Parameters
    ----------
    x : the input.

    Returns
    -------
    float
        Twice x.
    '''
    assert sections(doc) == {"Parameters", "Returns"}
    assert missing_sections(lambda x: 2 * x) == ["Examples", "Returns"]
