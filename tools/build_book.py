"""Build the book: execute every chapter (forced) and write the HTML.

Two builds, two folders, never mixed:

* the **published book**, ``python -m tools.build_book`` (what ``make book`` runs): every
  chapter at full size, into ``_build/html``. ``ORRC_QUICK`` is removed from the
  environment first, so a reader never sees the shortened test run;
* the **test build** (the ``book`` fixture of ``tests/conftest.py``): the chapters at the
  test size (``ORRC_QUICK=1``), into a folder of its own (``_build/test/_build/html``).
  :func:`build` refuses to write a test-size build into ``_build/html``.

Any cell error or Sphinx warning fails the build (``-n -W --keep-going``). Every page is
rebuilt and every chapter re-executed on every call (``--all`` with the forced
execution of ``_config.yml``): Sphinx's incremental build only sees changes to the
chapter sources, so without it a change in ``orrc/`` would leave stale outputs.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PUBLISHED_HTML = ROOT / "_build" / "html"
TEST_OUT = ROOT / "_build" / "test"  # jupyter-book's --path-output for the test build


def html_dir(out: Path) -> Path:
    """Where a build with ``--path-output out`` writes its HTML (jupyter-book appends ``_build/html``)."""
    return Path(out) / "_build" / "html"


def _quick(env: dict) -> bool:
    return env.get("ORRC_QUICK", "").strip().lower() in ("1", "true", "yes")


def build(out: Path = ROOT, extra_env: dict | None = None) -> int:
    """Run ``jupyter-book build`` into ``html_dir(out)``; returns its exit code.

    A test-size build (``ORRC_QUICK`` set in the environment or in ``extra_env``) into the
    published folder ``_build/html`` is refused (ValueError): that folder holds the full book only.
    """
    env = dict(os.environ)
    env.setdefault("MPLBACKEND", "Agg")
    env.update(extra_env or {})
    if _quick(env) and html_dir(out).resolve() == PUBLISHED_HTML.resolve():
        raise ValueError(f"a test-size build (ORRC_QUICK={env['ORRC_QUICK']!r}) must not be written to "
                         f"{PUBLISHED_HTML}, which holds the full book; build it into {TEST_OUT} instead")
    cmd = [str(Path(sys.executable).parent / "jupyter-book"), "build", str(ROOT), "--path-output", str(out),
           "--builder", "html", "--all", "-n", "-W", "--keep-going"]
    return subprocess.call(cmd, cwd=ROOT, env=env)


def main() -> int:
    """The published book: full size (ORRC_QUICK removed), into ``_build/html``."""
    if os.environ.pop("ORRC_QUICK", None) is not None:
        print("tools.build_book: ORRC_QUICK ignored; the published book is built at full size", file=sys.stderr)
    return build(ROOT)


if __name__ == "__main__":
    sys.exit(main())
