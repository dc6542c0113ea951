"""Build the book: execute every chapter (forced) and write the HTML.

Two builds, two folders, never mixed:

* the **published book**, ``python -m tools.build_book`` (what ``make book`` runs): every
  chapter at full size, into ``_build/html``. ``ORRC_QUICK`` is removed from the
  environment first, so a reader never sees the shortened test run;
* the **test build** (the ``book`` fixture of ``tests/conftest.py``): the chapters at the
  test size (``ORRC_QUICK=1``), into a folder of its own (``_build/test/_build/html``).
  :func:`build` refuses to write a test-size build into ``_build/html``.

Every build sets ``ORRC_BOOK_BUILD=1`` in the environment of the chapters' kernels: the explicit
signal (``orrc.config.book_build()``) that a chapter runs for the HTML book, so that
``orrc.viz.explore`` renders its static frames (a live notebook shows only the widget) and progress
bars stay silent.

Any cell error or Sphinx warning fails the build (``-n -W --keep-going``). Every page is
rebuilt and every chapter re-executed on every call (``--all`` with the forced
execution of ``_config.yml``): Sphinx's incremental build only sees changes to the
chapter sources, so without it a change in ``orrc/`` would leave stale outputs.

``_config.yml`` executes in MyST-NB's "cache" mode, and the cache (``_build/.jupyter_cache``)
is emptied here before every build, so every chapter is executed as with "force" and the
executed notebooks, with their glue outputs, are kept. The chapters are executed into the
emptied cache first, one per core (:mod:`tools.execute_chapters`); the build reads them from it. A build that succeeds leaves a stamp,
``_build/orrc-build.json``: the digest of every input (:func:`inputs_digest`) and the run size
(``ORRC_QUICK``). The solution-free edition (``tools/build_student.py``) reuses the cached
notebooks only when the stamp matches the sources and the size it is asked for.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

from tools.execute_chapters import write_executed

ROOT = Path(__file__).resolve().parents[1]
PUBLISHED_HTML = ROOT / "_build" / "html"
TEST_OUT = ROOT / "_build" / "test"  # jupyter-book's --path-output for the test build
STAMP = "orrc-build.json"
CACHE = ".jupyter_cache"  # MyST-NB's default place, beside html/
BUILD_SIGNAL = "ORRC_BOOK_BUILD"  # read by orrc.config.book_build(): explorers render static frames, no progress bars
INPUTS = ("_config.yml", "_toc.yml", "book/**/*", "orrc/**/*.py")


def inputs_digest(root: Path = ROOT) -> str:
    """SHA-256 over the path and content of every file the executed chapters depend on: the book's
    sources and configuration and the package (not tools/, which only renders; not hidden folders
    such as the ``.ipynb_checkpoints`` JupyterLab writes beside an open chapter)."""
    h = hashlib.sha256()
    files = sorted({p for pattern in INPUTS for p in Path(root).glob(pattern)
                    if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".ipynb"
                    and not any(part.startswith(".") for part in p.relative_to(root).parts)})
    for p in files:
        h.update(p.relative_to(root).as_posix().encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()


def is_quick(env: dict) -> bool:
    return env.get("ORRC_QUICK", "").strip().lower() in ("1", "true", "yes")


def html_dir(out: Path) -> Path:
    """Where a build with ``--path-output out`` writes its HTML (jupyter-book appends ``_build/html``)."""
    return Path(out) / "_build" / "html"


def kernel_for(python: Path, folder: Path) -> Path:
    """A Jupyter data folder in ``folder`` whose kernel ``python3`` (the name every chapter asks for)
    runs ``python`` with nothing of this checkout on its path; put first on ``JUPYTER_PATH``, it
    takes the place of the build environment's own kernel. The kernel writes the bytecode of the
    modules it imports into that environment (``PYTHONDONTWRITEBYTECODE`` emptied), so that only
    the first chapter compiles them."""
    spec = Path(folder) / "kernels" / "python3"
    spec.mkdir(parents=True, exist_ok=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [str(python), "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "Python 3 (orrc)", "language": "python",
        "env": {"PYTHONPATH": "", "PYTHONDONTWRITEBYTECODE": ""}}, indent=1))
    return Path(folder)


def build(out: Path = ROOT, extra_env: dict | None = None, source: Path = ROOT,
          kernel_python: Path | None = None, cache: Path | None = None, log: Path | None = None,
          run=subprocess.call) -> int:
    """Build the book in ``source`` into ``out/_build``; return jupyter-book's exit code.

    ``kernel_python``: the Python whose kernel executes the chapters (default: this environment's),
    e.g. that of a fresh environment built from what a chapter's download installs; each chapter
    runs in a temporary folder (``run_in_temp`` in ``_config.yml``) either way.

    ``log``: a file for everything the build prints (default: this process's output). ``run``:
    what runs each command, with :func:`subprocess.call`'s signature (a check passes its own
    instead of patching the module that other threads use).

    ``cache``: a Jupyter cache that already holds the executed chapters, the one ``_config.yml``
    names (the solution-free edition's, filled from the normal build): nothing is executed first,
    and MyST-NB runs only a chapter it does not find there. By default the build's own cache
    (``out/_build/.jupyter_cache``) is emptied and every chapter executed into it first.

    A test-size build (``ORRC_QUICK`` set in the environment or in ``extra_env``) into the
    published folder ``_build/html`` is refused (ValueError): that folder holds the full book only.
    """
    import shutil

    env = dict(os.environ)
    env.setdefault("MPLBACKEND", "Agg")
    env.update(extra_env or {})
    env[BUILD_SIGNAL] = "1"   # the chapters run for the HTML book, not in a live notebook (orrc.config.book_build)
    if is_quick(env) and html_dir(out).resolve() == PUBLISHED_HTML.resolve():
        raise ValueError(f"a test-size build (ORRC_QUICK={env['ORRC_QUICK']!r}) must not be written to "
                         f"{PUBLISHED_HTML}, which holds the full book; build it into {TEST_OUT} instead")
    if kernel_python is not None:
        data = kernel_for(kernel_python, Path(out) / "_build" / "kernel")
        env["JUPYTER_PATH"] = os.pathsep.join(p for p in (str(data), env.get("JUPYTER_PATH", "")) if p)
    stamp = Path(out) / "_build" / STAMP
    stamp.unlink(missing_ok=True)
    digest = inputs_digest(source)
    with open(log, "w", encoding="utf-8") if log is not None else contextlib.nullcontext() as out_file:
        streams = {"stdout": out_file, "stderr": subprocess.STDOUT} if out_file else {}
        if cache is None:
            cache = Path(out) / "_build" / CACHE
            shutil.rmtree(cache, ignore_errors=True)  # never a stale output
            # every chapter executed into the cache first, one per core (tools/execute_chapters.py): the
            # build then reads each from the cache instead of executing the chapters one after the other
            run([sys.executable, "-m", "tools.execute_chapters", str(cache)], cwd=source, env=env, **streams)
        cmd = [str(Path(sys.executable).parent / "jupyter-book"), "build", str(source), "--path-output", str(out),
               "--builder", "html", "--all", "-n", "-W", "--keep-going"]
        rc = run(cmd, cwd=source, env=env, **streams)
    write_executed(cache, Path(out) / "_build" / "jupyter_execute", source)
    if rc == 0:
        stamp.write_text(json.dumps({"digest": digest, "quick": is_quick(env)}, indent=1))
    return rc


def read_stamp(out: Path = ROOT) -> dict | None:
    """The stamp of the last successful build into ``out/_build`` (None when there is none)."""
    stamp = Path(out) / "_build" / STAMP
    try:
        return json.loads(stamp.read_text())
    except (OSError, ValueError):
        return None


def main() -> int:
    """The published book: full size (ORRC_QUICK removed), into ``_build/html``."""
    if os.environ.pop("ORRC_QUICK", None) is not None:
        print("tools.build_book: ORRC_QUICK ignored; the published book is built at full size", file=sys.stderr)
    return build(ROOT)


if __name__ == "__main__":
    sys.exit(main())
