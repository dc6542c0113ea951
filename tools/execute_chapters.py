"""Execute the book's chapters into MyST-NB's cache, as many at a time as there are cores.

MyST-NB executes a chapter when Sphinx reads it, one chapter after the other. Before a build,
:func:`execute` runs every chapter of ``_toc.yml`` that is a notebook through jupyter-cache's
parallel executor (``temp-parallel``: each in a temporary folder, as ``run_in_temp`` in
``_config.yml``; one kernel per core), reading each chapter with MyST-NB's own reader, and keeps
the executed notebooks in the cache. The build then finds each chapter in the cache (matched by its
code cells) and executes nothing again; a chapter whose run failed is not cached, so the build
executes it and reports its error as it always does.

Run by :func:`tools.build_book.build` as ``python -m tools.execute_chapters CACHE``, in the
environment of the build's kernels (``ORRC_BOOK_BUILD``, ``ORRC_QUICK``, ``JUPYTER_PATH``).

MyST-NB writes a chapter it found in the cache to ``_build/jupyter_execute/<page>.ipynb`` without
the cached outputs (it writes the notebook it read, not the one it merged); after the build
:func:`write_executed` writes each chapter there as the cache holds it, outputs included, as a
chapter executed during the build would be.
"""
from __future__ import annotations

import logging
import sys
from pathlib import Path

import nbformat
import yaml
from jupyter_cache import get_cache
from jupyter_cache.executors import load_executor
from myst_nb.core.read import myst_nb_reader_plugin

from tools.toc import ROOT, notebook_pages

#: how MyST-NB reads a chapter (its jupyter-cache reader plugin), so that the build matches it
READER = {"name": "myst_nb_md", "type": "plugin"}


def cell_timeout(root: Path = ROOT) -> int:
    """The seconds a cell may run: ``execute.timeout`` of ``_config.yml``, as the build uses it."""
    config = yaml.safe_load((Path(root) / "_config.yml").read_text(encoding="utf-8"))
    return int(config.get("execute", {}).get("timeout", 30))


def execute(cache_dir: Path, root: Path = ROOT) -> dict:
    """Execute every notebook page of ``_toc.yml`` under ``root`` into the jupyter-cache at
    ``cache_dir``; returns {"succeeded", "failed"}: the chapters' paths."""
    cache = get_cache(str(cache_dir))
    for page in notebook_pages(root):
        cache.add_nb_to_project(str(Path(root) / f"{page}.md"), read_data=READER)
    logger = logging.getLogger("orrc.execute_chapters")
    result = load_executor("temp-parallel", cache, logger=logger).run_and_cache(
        timeout=cell_timeout(root), allow_errors=False)
    return {"succeeded": list(result.succeeded), "failed": list(result.excepted) + list(result.errored)}


def write_executed(cache_dir: Path, folder: Path, root: Path = ROOT) -> list[str]:
    """Write every notebook page that the cache at ``cache_dir`` holds to ``folder/<page>.ipynb``
    with its cached outputs (read with MyST-NB's reader, merged with the cache's match); returns
    the pages written."""
    cache = get_cache(str(cache_dir))
    written = []
    for page in notebook_pages(root):
        nb = myst_nb_reader_plugin(str(Path(root) / f"{page}.md"))
        try:
            _, merged = cache.merge_match_into_notebook(nb)
        except KeyError:        # not in the cache (its run failed): the build reported it
            continue
        target = Path(folder) / f"{page}.ipynb"
        target.parent.mkdir(parents=True, exist_ok=True)
        nbformat.write(merged, target)
        written.append(page)
    return written


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        print("usage: python -m tools.execute_chapters CACHE_DIR", file=sys.stderr)
        return 2
    result = execute(Path(args[0]))
    print(f"tools.execute_chapters: {len(result['succeeded'])} chapters executed into the cache"
          + (f"; not cached (the build runs them again and reports why): {result['failed']}"
             if result["failed"] else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
