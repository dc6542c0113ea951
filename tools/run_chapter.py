"""Execute chapters one at a time and report their shape, without building the book.

    python -m tools.run_chapter book/lemma1.md [book/lemma2.md ...] [--full]

Each chapter runs top to bottom in a fresh kernel, at the test size (``ORRC_QUICK=1``) unless
``--full`` is given, with ``ORRC_BOOK_BUILD=1`` as in the book's build (explorers draw their
static frames). The executed notebook goes to ``_build/run_chapter/<name>.ipynb``. Printed per
chapter: the first error if any, the seconds it took, the words of the main path and of the page
(limits in :mod:`tools.teaching_shape`), the from-scratch differences it printed, whether its
main figure is drawn by visible code, and where "Reading the paper critically" stands.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import jupytext
import nbformat
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError

from tools import teaching_shape as shape

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "_build" / "run_chapter"


def execute(path: Path, full: bool = False, timeout: int = 600):
    """Execute the MyST notebook ``path``; return (executed notebook, error text or None, seconds)."""
    nb = jupytext.read(path)
    env_before = dict(os.environ)
    os.environ.setdefault("MPLBACKEND", "Agg")
    os.environ["ORRC_BOOK_BUILD"] = "1"
    if full:
        os.environ.pop("ORRC_QUICK", None)
    else:
        os.environ["ORRC_QUICK"] = "1"
    os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env_before.get("PYTHONPATH")]))
    t0 = time.perf_counter()
    error = None
    try:
        NotebookClient(nb, timeout=timeout, kernel_name="python3",
                       resources={"metadata": {"path": str(path.parent)}}).execute()
    except CellExecutionError as exc:
        error = str(exc).strip().splitlines()[-1] if str(exc).strip() else repr(exc)
    finally:
        os.environ.clear()
        os.environ.update(env_before)
    return nb, error, time.perf_counter() - t0


def report(path: Path, nb, error, seconds) -> bool:
    """Print the shape of an executed chapter; True when it is within every limit."""
    main, page = shape.main_path_words(nb), shape.page_words(nb)
    diffs = shape.scratch_differences(nb)
    critical = shape.critical_section_problems(nb)
    figures = shape.main_figure_cells(nb)
    ok = (error is None and main <= shape.MAIN_PATH_MAX and page <= shape.PAGE_MAX and diffs
          and all(d < shape.SCRATCH_TOLERANCE for d in diffs) and not critical and figures)
    print(f"{path}: {'ok' if ok else 'NOT YET'} ({seconds:.0f} s)")
    print(f"  error: {error or 'none'}")
    print(f"  main path: {main} words (at most {shape.MAIN_PATH_MAX}); page: {page} words (at most {shape.PAGE_MAX})")
    print(f"  from scratch vs orrc: {diffs or 'no line printed'} (each below {shape.SCRATCH_TOLERANCE:g})")
    print(f"  main figure by visible matplotlib code, numbered and captioned: {len(figures)} cell(s)")
    print(f"  '{shape.CRITICAL}': {'; '.join(critical) or 'at the end of the main path'}")
    return bool(ok)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("chapters", nargs="+", type=Path)
    parser.add_argument("--full", action="store_true", help="the full size (default: the test size)")
    args = parser.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    all_ok = True
    for path in args.chapters:
        nb, error, seconds = execute(path.resolve(), full=args.full)
        nbformat.write(nb, OUT / f"{path.stem}.ipynb")
        all_ok &= report(path, nb, error, seconds)
    return 0 if all_ok else 1


if __name__ == "__main__":
    sys.exit(main())
