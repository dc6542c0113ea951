"""Build the solution-free edition of the book into ``_build/student/html`` (``make book-student``).

No solution text reaches Sphinx, so none can reach the output (pages, ``_sources``, ``.ipynb``
downloads, the search index, the executed notebooks): the book's sources are copied into
``_build/student/source``, every solution of every page is removed from the copy by
:func:`tools.solutions.strip_solutions` (both forms of the fixed format; a malformed one stops
the build), and Jupyter Book builds the copy. The exercises and everything else stay.
(sphinx-exercise's ``hide_solutions`` is not used: it leaves the text in ``_sources`` and fails
on gated solutions.)

Executing once, not twice. When the normal build (``make book``, or the test session's build)
is fresh -- its stamp ``_build/orrc-build.json`` has the digest of the current sources and the
run size asked for here -- its executed notebooks are reused: the normal build keeps them in its
Jupyter cache ``_build/.jupyter_cache`` (see tools/build_book.py); for each chapter the code
cells outside the solutions, with their outputs, are put into the student build's own cache
under the hash of the stripped chapter, so MyST-NB (``execute_notebooks: cache``) finds every
chapter executed and runs no kernel. A chapter in which a
code cell outside the solutions follows a solution's code cell is not reused (its outputs
might depend on the solution having run) and is executed without its solutions instead, as is
every chapter when there is no fresh normal build.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import sys
import time
from pathlib import Path

import yaml

from tools.build_book import CACHE, ROOT, build, inputs_digest, is_quick, read_stamp
from tools.solutions import FormatError, parse, strip_solutions
from tools.toc import notebook_pages

COPIED = ("_config.yml", "_toc.yml", "book", "tools", "benchmarks/results.json")  # the benchmarks page reads the last
TITLE_SUFFIX = " (student edition)"
#: pages for instructors only: not copied, not in the copy's table of contents, links to them unlinked
INSTRUCTOR_PAGES = ("book/instructors",)
_INSTRUCTOR_BLOCK = re.compile(r"<!--\s*instructor-only\b.*?-->.*?<!--\s*/instructor-only\s*-->\n?", re.S)
_STUDENT_TEXT = re.compile(r"<!--\s*student-edition:[^\n]*\n(.*?)-->\n?", re.S)


def for_students(text: str) -> str:
    """A page's text for the student edition: its ``<!-- instructor-only -->`` ...
    ``<!-- /instructor-only -->`` blocks dropped, the text of its ``<!-- student-edition: ...`` comments
    shown, and every reference to an instructor-only page turned into plain words."""
    text = _STUDENT_TEXT.sub(lambda m: m.group(1), _INSTRUCTOR_BLOCK.sub("", text))
    for page in INSTRUCTOR_PAGES:
        label = page.rsplit("/", 1)[-1]
        text = re.sub(rf"\{{(?:ref|doc)\}}`(?:([^`<]*?)\s*<)?/?(?:{re.escape(page)}|{re.escape(label)})>?`",
                      lambda m: (m.group(1) or "the instructor's guide").strip(), text)
    return text


def _without_instructor_pages(entries: list) -> list:
    """The entries of a toc list without the instructor pages; a part or a chapter's sections left
    empty are dropped (an empty list is malformed for Jupyter Book)."""
    out = []
    for e in entries:
        if e.get("file") in INSTRUCTOR_PAGES:
            continue
        kept = {k: (_without_instructor_pages(v) if k in ("chapters", "sections") else v) for k, v in e.items()}
        kept = {k: v for k, v in kept.items() if not (k in ("chapters", "sections") and v == [])}
        if "file" in kept or kept.get("chapters"):
            out.append(kept)
    return out


def _student_toc(toc_path: Path) -> None:
    toc = yaml.safe_load(toc_path.read_text(encoding="utf-8"))
    for key in ("chapters", "parts"):
        if key in toc:
            toc[key] = _without_instructor_pages(toc[key])
    toc_path.write_text(yaml.safe_dump(toc, sort_keys=False), encoding="utf-8")


def stripped_copy(dest: Path, root: Path = ROOT) -> dict[str, int]:
    """Copy the book's sources to ``dest`` with every solution removed and without the pages for
    instructors (:func:`for_students`); returns solutions removed per page."""
    if dest.exists():
        shutil.rmtree(dest)
    dest.mkdir(parents=True)
    for name in COPIED:
        src = root / name
        if src.is_dir():
            shutil.copytree(src, dest / name, ignore=shutil.ignore_patterns("__pycache__", "*.ipynb", ".ipynb_checkpoints"))
        else:
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / name)
    for page in INSTRUCTOR_PAGES:
        (dest / f"{page}.md").unlink(missing_ok=True)
    _student_toc(dest / "_toc.yml")
    removed = {}
    for md in sorted((dest / "book").rglob("*.md")):
        text = for_students(md.read_text(encoding="utf-8"))
        n = len(parse(text, str(md.relative_to(dest))).solutions)
        md.write_text(strip_solutions(text, str(md.relative_to(dest))), encoding="utf-8")
        removed[md.relative_to(dest).with_suffix("").as_posix()] = n
    return removed


def _student_config(dest: Path, cache: Path | None, root: Path = ROOT) -> None:
    """The copy's _config.yml: the edition in the title, the cache to read, and the assignments
    folder of the original (read by the instructor's guide; never copied)."""
    cfg_path = dest / "_config.yml"
    cfg = yaml.safe_load(cfg_path.read_text(encoding="utf-8"))
    cfg["title"] = str(cfg.get("title", "")) + TITLE_SUFFIX
    cfg.setdefault("sphinx", {}).setdefault("config", {})["coursework_assignments"] = str(Path(root) / "assignments")
    if cache is not None:
        cfg.setdefault("execute", {})
        cfg["execute"]["execute_notebooks"] = "cache"
        cfg["execute"]["cache"] = str(cache)
    cfg_path.write_text(yaml.safe_dump(cfg, sort_keys=False, allow_unicode=True), encoding="utf-8")


def _md_config(dest: Path):
    from myst_parser.config.main import MdParserConfig

    cfg = yaml.safe_load((dest / "_config.yml").read_text(encoding="utf-8"))
    return MdParserConfig(enable_extensions=set(cfg.get("parse", {}).get("myst_enable_extensions", [])))


def reusable_notebooks(dest: Path, normal_cache: Path, root: Path = ROOT):
    """For each chapter, the stripped notebook (as MyST-NB reads the copy in ``dest``) with the outputs
    its code cells got in the normal build, read from that build's Jupyter cache ``normal_cache``
    (where the glue outputs are kept; ``jupyter_execute/`` has them removed). Chapters that cannot
    be reused are left out, with the reason. Returns ({page: (notebook, seconds)}, {page: reason})."""
    from jupyter_cache import get_cache
    from myst_nb.core.read import read_myst_markdown_notebook

    md_config = _md_config(dest)
    cache = get_cache(str(normal_cache))
    out, skipped = {}, {}
    for page in notebook_pages(root):
        full = parse(root / f"{page}.md")
        nb_full = read_myst_markdown_notebook(full.path.read_text(encoding="utf-8"), md_config, add_source_map=True,
                                              path=root / f"{page}.md")
        try:
            record = cache.match_cache_notebook(nb_full)
        except KeyError:
            skipped[page] = "not in the normal build's cache (a stale build?)"
            continue
        ex_code = [c for c in cache.get_cache_bundle(record.pk).nb.cells if c.cell_type == "code"]
        # which code cells of the full chapter sit inside a solution, in order
        in_solution = [any(s.start < f.start < s.end for s in full.solutions)
                       for f in full.fences if f.directive == "code-cell"]
        if len(in_solution) != len(ex_code):
            skipped[page] = f"{len(ex_code)} executed code cells, {len(in_solution)} in the source"
            continue
        first = next((i for i, s in enumerate(in_solution) if s), None)
        if first is not None and not all(in_solution[first:]):
            skipped[page] = "a code cell outside the solutions follows a solution's code"
            continue
        text = (dest / f"{page}.md").read_text(encoding="utf-8")
        nb = read_myst_markdown_notebook(text, md_config, add_source_map=True, path=dest / f"{page}.md")
        kept = [c for c, sol in zip(ex_code, in_solution) if not sol]
        code = [c for c in nb.cells if c.cell_type == "code"]
        if [c.source for c in code] != [c.source for c in kept]:
            skipped[page] = "the stripped chapter's code cells are not the executed ones outside the solutions"
            continue
        for cell, done in zip(code, kept):
            cell.outputs = done.get("outputs", [])
            cell.execution_count = done.get("execution_count")
        out[page] = (nb, record.data.get("execution_seconds"))
    return out, skipped


def fill_cache(cache_dir: Path, dest: Path, notebooks: dict) -> None:
    """Put the reused notebooks into a fresh Jupyter cache at ``cache_dir`` (with their run times)."""
    from jupyter_cache import get_cache
    from jupyter_cache.base import CacheBundleIn

    if cache_dir.exists():
        shutil.rmtree(cache_dir)
    cache = get_cache(str(cache_dir))
    for page, (nb, seconds) in notebooks.items():
        data = {"execution_seconds": seconds} if seconds is not None else {}
        cache.cache_notebook_bundle(CacheBundleIn(nb, str(dest / f"{page}.md"), data=data),
                                    check_validity=False, overwrite=True)


def executed_in_build(cache_dir: Path) -> int:
    """How many notebooks the student build had to execute (MyST-NB stages each one it runs)."""
    from jupyter_cache import get_cache

    return len(get_cache(str(cache_dir)).list_project_records())


def build_student(out: Path = ROOT, quick: bool | None = None, reuse: bool = True, root: Path = ROOT) -> dict:
    """Build the solution-free edition into ``out/_build/student`` (``html/`` inside it).

    ``quick``: the run size (default: ``ORRC_QUICK`` of the environment). ``reuse``: reuse a fresh
    normal build in ``out/_build`` (see the module's docstring). Returns a report: the exit code,
    seconds, solutions removed per page, chapters reused and executed.
    """
    quick = is_quick(os.environ) if quick is None else quick
    t0 = time.perf_counter()
    base = Path(out) / "_build" / "student"
    source = base / "source"
    cache_dir = base / "jupyter_cache"
    removed = stripped_copy(source, root)
    stamp = read_stamp(out) if reuse else None
    notebooks, skipped = {}, {}
    if stamp and stamp.get("digest") == inputs_digest(root) and bool(stamp.get("quick")) == quick:
        notebooks, skipped = reusable_notebooks(source, Path(out) / "_build" / CACHE, root)
        why = None
    else:
        why = ("no fresh normal build (its stamp does not match the sources or the run size)" if reuse
               else "reuse switched off")
    fill_cache(cache_dir, source, notebooks)
    _student_config(source, cache_dir, root)
    rc = build(source, extra_env={"ORRC_QUICK": "1" if quick else "0"}, source=source, cache=cache_dir)
    html = base / "html"
    if html.exists():
        shutil.rmtree(html)
    if rc == 0:
        shutil.move(str(source / "_build" / "html"), str(html))
    report = {"rc": rc, "seconds": time.perf_counter() - t0, "removed": removed, "reused": sorted(notebooks),
              "not_reused": skipped if why is None else {p: why for p in notebook_pages(root)},
              "executed": executed_in_build(cache_dir), "html": str(html), "quick": quick}
    (base / "report.json").write_text(json.dumps(report, indent=1))
    return report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--no-reuse", action="store_true", help="execute the chapters even if a fresh normal build exists")
    args = ap.parse_args(argv)
    try:
        r = build_student(reuse=not args.no_reuse)
    except FormatError as exc:  # a solution the stripper cannot read would leak: stop, naming it
        print(f"student edition not built: {exc}", file=sys.stderr)
        return 2
    total = sum(r["removed"].values())
    print(f"student edition: {total} solutions removed from {sum(1 for v in r['removed'].values() if v)} pages; "
          f"{len(r['reused'])} chapters reused from the normal build, {r['executed']} executed; "
          f"{r['seconds']:.0f} s; " + (f"open {r['html']}/index.html" if r["rc"] == 0 else f"FAILED (exit {r['rc']})"))
    for page, why in r["not_reused"].items():
        print(f"  not reused: {page}: {why}")
    return r["rc"]


if __name__ == "__main__":
    sys.exit(main())
