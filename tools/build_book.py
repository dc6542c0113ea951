"""Build the book: execute every chapter (forced) and write the HTML to _build/html.

Run as ``python -m tools.build_book`` (this is what ``make book`` does). Any cell
error or Sphinx warning fails the build (``-n -W --keep-going``). Every page is
rebuilt and every chapter re-executed on every call (``--all`` with the forced
execution of ``_config.yml``): Sphinx's incremental build only sees changes to the
chapter sources, so without it a change in ``orrc/`` would leave stale outputs.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def build(out: Path = ROOT, extra_env: dict | None = None) -> int:
    import os

    env = dict(os.environ)
    env.setdefault("MPLBACKEND", "Agg")
    env.update(extra_env or {})
    cmd = [str(Path(sys.executable).parent / "jupyter-book"), "build", str(ROOT), "--path-output", str(out),
           "--builder", "html", "--all", "-n", "-W", "--keep-going"]
    return subprocess.call(cmd, cwd=ROOT, env=env)


if __name__ == "__main__":
    sys.exit(build())
