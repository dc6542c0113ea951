"""What an autograder zip needs to grade anywhere: ``orrc`` as a wheel and the pinned requirements.

otter-grader's autograder zip (``otter assign`` -> ``otter generate``) declares the grading
environment in its own format: ``environment.yml`` (a conda environment ``otter-env`` with a
Python version and a ``pip:`` list) and ``setup.sh``, which otter's grading image and hosted
autograders run to build it; the files listed in the assignment's ``files`` sit in the zip's
``files/`` folder, where ``setup.sh`` (conda runs pip from the folder of ``environment.yml``)
and the notebook under grading find them. :func:`grading_requirements` gives the ``pip:`` list: the
closure of what grading imports (otter-grader with its ``grading`` extra, ``orrc``'s
dependencies, and the libraries the assignments' tests use), each pinned as in the project's
``requirements.txt``, plus ``files/<the orrc wheel>``; the assignment's config is told to use
that list alone (``overwrite_requirements``), so nothing unpinned enters the zip.

The same list builds a plain virtual environment from the zip alone (``pip install`` of the
``pip:`` list of its ``environment.yml``, run from the unpacked zip): that is how the tests check
that an autograder grades outside this repository.
"""
from __future__ import annotations

import importlib.metadata as md
import os
import re
import subprocess
import sys
import tomllib
from functools import lru_cache
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]
#: what grading imports besides orrc's declared dependencies: otter itself (its grading extra runs
#: the notebook) and the libraries orrc imports where a computation needs them (orrc.certify, the
#: min-max controller, the figures a notebook draws)
GRADING_ROOTS = ("otter-grader[grading]", "cvxpy", "clarabel", "matplotlib")
WHEEL_FOLDER = "files"   # otter puts an assignment's files in the zip's files/ folder


def pins(path: Path = ROOT / "requirements.txt") -> dict[str, str]:
    """``{canonical name: version}`` of every ``name==version`` line of a requirements file."""
    out = {}
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        m = re.match(r"^\s*([A-Za-z0-9_.-]+)(\[[^\]]*\])?\s*==\s*([^\s;#]+)", line)
        if m:
            out[canonicalize_name(m.group(1))] = m.group(3)
    return out


def _closure(roots: list[str]) -> dict[str, set[str]]:
    """Every distribution ``roots`` need, as installed here: {canonical name: extras asked for}."""
    need: dict[str, set[str]] = {}
    todo = [Requirement(r) for r in roots]
    while todo:
        req = todo.pop()
        name = canonicalize_name(req.name)
        extras = set(req.extras)
        if name in need and extras <= need[name]:
            continue
        need.setdefault(name, set()).update(extras)
        for line in md.distribution(name).requires or []:
            sub = Requirement(line)
            if sub.marker is None or any(sub.marker.evaluate({"extra": e}) for e in (need[name] | {""})):
                todo.append(sub)
    return need


def grading_requirements(wheel_name: str, root: Path = ROOT) -> list[str]:
    """The ``pip:`` lines of an autograder's environment: the pinned closure of what grading
    imports (``name[extras]==version``, versions from ``requirements.txt``) and the orrc wheel."""
    return list(_pinned_closure(Path(root))) + [f"{WHEEL_FOLDER}/{wheel_name}"]


@lru_cache(maxsize=4)
def _pinned_closure(root: Path) -> tuple[str, ...]:
    """The registry lines of :func:`grading_requirements`, computed once per process (every
    assignment's build asks twice; the installed metadata does not change meanwhile)."""
    project = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    need = _closure(list(project["dependencies"]) + list(GRADING_ROOTS))
    pinned = pins(root / "requirements.txt")
    lines = []
    for name, extras in sorted(need.items()):
        version = pinned.get(name) or md.version(name)
        lines.append(f"{name}{'[' + ','.join(sorted(extras)) + ']' if extras else ''}=={version}")
    return tuple(lines)


def python_version() -> str:
    """The Python the pins are tested with (``major.minor``), which the grading image installs."""
    return f"{sys.version_info.major}.{sys.version_info.minor}"


def build_wheel(dest: Path, root: Path = ROOT) -> Path:
    """The project's wheel, built into ``dest`` (no dependencies bundled; the pins bring them), with fixed
    timestamps, so that the same sources give the same bytes (and a fresh environment keyed by them is reused)."""
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, SOURCE_DATE_EPOCH="315532800")  # 1980: the same bytes for the same sources
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                    "--disable-pip-version-check", "--quiet", "-w", str(dest), str(root)],
                   check=True, capture_output=True, text=True, env=env)
    return sorted(dest.glob("orrc-*.whl"))[-1]
