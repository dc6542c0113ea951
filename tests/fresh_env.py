"""Fresh virtual environments for the checks that must not lean on the project's ``.venv``.

Coursework handed to a grader (an autograder zip) and a chapter downloaded as ``.ipynb`` must
work from their own files, installed from the package registry. A test proves it by building a
virtual environment from those files alone, with the machine's base Python (no
``--system-site-packages``, nothing from ``.venv``), and running in it.

Such an environment takes a minute or more to build, so it is built **once, keyed by what it is
built from**, and shared: :func:`fresh_env` hashes the requirement lines, the bytes of every
local file they name (a wheel, a requirements file) and the Python version, and keeps the
environment in ``_build/fresh-envs/<name>-<key>``. Every test of one run (and of later runs,
while nothing changes) that asks for the same requirements gets the same environment; a file
lock makes concurrent requests (tests in background threads, two pytest processes) wait for one
build instead of racing. A build that fails leaves nothing behind that a later call would take
for a finished environment.

:func:`orrc_wheel` builds the project's wheel once per package content, for environments (and
autograder zips) that install ``orrc`` itself. :func:`reader_env` is the environment a chapter's
download installs (``requirements-reader.txt`` and the wheel): the test build executes every
chapter in its kernel.
"""
from __future__ import annotations

import fcntl
import hashlib
import os
import shutil
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENVS = Path(os.environ.get("ORRC_BOOK_OUT", ROOT)) / "_build" / "fresh-envs"
DONE = ".orrc-fresh-env-complete"   # written last: an environment without it is incomplete
#: uv (pinned in requirements.txt, beside this Python) installs the registry's packages
UV = str(Path(sys.executable).parent / "uv")


def base_python() -> str:
    """The machine's Python, not the project's ``.venv`` (``sys._base_executable`` inside a venv)."""
    return getattr(sys, "_base_executable", None) or sys.executable


@contextmanager
def _locked(path: Path):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _local_files(lines: list[str], base: Path) -> list[Path]:
    """The local files that requirement lines name: ``-r other.txt``, a path to a wheel or sdist,
    ``name @ file:///...``."""
    found = []
    for line in lines:
        words = line.replace("file://", " ").replace("@", " ").split()
        for i, word in enumerate(words):
            if word in ("-r", "--requirement", "-c", "--constraint") and i + 1 < len(words):
                word = words[i + 1]
            candidate = Path(word) if Path(word).is_absolute() else base / word
            if candidate.is_file():
                found.append(candidate)
    return found


def env_key(lines: list[str], base: Path = ROOT, python: str | None = None) -> str:
    """What an environment is built from, hashed: the Python version, the requirement lines and
    the content of each local file they name."""
    python = python or base_python()
    version = subprocess.run([python, "-c", "import sys; print(sys.version)"], capture_output=True,
                             text=True, check=True).stdout.strip()
    h = hashlib.sha256(version.encode() + b"\0")
    for line in lines:
        h.update(line.strip().encode() + b"\0")
    for f in _local_files(lines, base):
        h.update(f.read_bytes())
    return h.hexdigest()[:16]


def fresh_env(name: str, requirements: list[str] | str | Path, *, base: Path | None = None,
              python: str | None = None, timeout: float = 900, compile_bytecode: bool = True) -> Path:
    """The Python executable of a fresh virtual environment with ``requirements`` installed.

    ``requirements``: a requirements file, or a list of lines as pip takes them on its command
    line or in a requirements file (``numpy==2.4.6``, ``-r reqs.txt``, ``path/to/orrc.whl``).
    Relative paths are taken relative to ``base`` (the requirements file's folder, else the
    repository). The environment is built with the machine's base Python, its packages from the
    package registry only (uv's download cache may serve them) and checked with ``pip check``, once
    per key (:func:`env_key`), and reused. ``compile_bytecode``: every installed module compiled to
    bytecode, as pip does; without it, what a process of the environment imports is compiled where
    it runs, and kept only where ``PYTHONDONTWRITEBYTECODE`` is not set for it.
    """
    if isinstance(requirements, (str, Path)):
        req_file = Path(requirements).resolve()
        base = base or req_file.parent
        lines = [f"-r {req_file}"]
    else:
        lines = [str(x) for x in requirements]
    base = Path(base or ROOT).resolve()
    python = python or base_python()
    target = ENVS / f"{name}-{env_key(lines, base, python)}"
    exe = target / "bin" / "python"
    with _locked(ENVS / f".{target.name}.lock"):
        if (target / DONE).is_file():
            return exe
        shutil.rmtree(target, ignore_errors=True)
        subprocess.run([python, "-m", "venv", str(target)], check=True, timeout=timeout)
        req = target / "requirements.txt"
        req.write_text("\n".join(lines) + "\n", encoding="utf-8")
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PIP_REQUIRE_VIRTUALENV")}
        # uv installs what pip would from the same pinned lines (relative paths from ``base``, as pip
        # takes them), downloading in parallel: seconds instead of a minute; and compiles them to
        # bytecode as pip does (else, where PYTHONDONTWRITEBYTECODE is set, every kernel of the
        # environment compiles what it imports again). ``pip check`` then holds the result to pip's
        # own idea of a consistent environment, the one a reader's ``pip install`` gives.
        install = [UV, "pip", "install", "--quiet", *(["--compile-bytecode"] if compile_bytecode else []),
                   "--python", str(exe), "-r", str(req)]
        for cmd in (install,
                    [str(exe), "-m", "pip", "--no-input", "--disable-pip-version-check", "check"]):
            run = subprocess.run(cmd, cwd=base, env=env, capture_output=True, text=True, timeout=timeout)
            if run.returncode != 0:
                shutil.rmtree(target, ignore_errors=True)
                raise RuntimeError(f"building the fresh environment {name!r} failed ({Path(cmd[0]).name} "
                                   f"{cmd[1] if cmd[1] != '-m' else cmd[-1]}, exit {run.returncode}):\n"
                                   f"{run.stdout[-3000:]}\n{run.stderr[-3000:]}")
        (target / DONE).write_text("\n".join(lines) + "\n", encoding="utf-8")
    return exe


def package_digest(root: Path = ROOT) -> str:
    """SHA-256 of what goes into the project's wheel: ``pyproject.toml`` and ``orrc/**/*.py``."""
    h = hashlib.sha256()
    files = [root / "pyproject.toml", root / "README.md"] + sorted((root / "orrc").rglob("*.py"))
    for f in files:
        if "__pycache__" not in f.parts:
            h.update(f.relative_to(root).as_posix().encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()[:16]


def orrc_wheel(root: Path = ROOT) -> Path:
    """The project's wheel (``orrc-<version>-py3-none-any.whl``), built once per package content
    into ``_build/fresh-envs/wheels/<digest>/``."""
    out = ENVS / "wheels" / package_digest(root)
    with _locked(ENVS / ".wheel.lock"):
        wheels = sorted(out.glob("orrc-*.whl"))
        if wheels:
            return wheels[0]
        tmp = out.with_name(out.name + ".tmp")
        shutil.rmtree(tmp, ignore_errors=True)
        subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                        "--disable-pip-version-check", "--quiet", "-w", str(tmp), str(root)],
                       check=True, capture_output=True, text=True)
        shutil.rmtree(out, ignore_errors=True)
        tmp.rename(out)
        return sorted(out.glob("orrc-*.whl"))[0]


def with_wheels(python: Path, wheels: list[Path], timeout: float = 300) -> Path:
    """``python``'s environment with ``wheels`` installed on top, without their dependencies, once
    per content of the wheels; ``pip check`` then confirms that every requirement of every installed
    distribution (the wheels' included) is met by what the environment already has.

    This keeps an environment keyed by its pinned dependencies only: a change of the project
    reinstalls its wheel in seconds instead of rebuilding the whole environment. The result is the
    environment one ``pip install`` of the dependencies and the wheels together gives, since the
    wheels' requirements are all met by the pinned versions (else ``pip check`` fails)."""
    target = Path(python).parent.parent
    h = hashlib.sha256()
    for wheel in wheels:
        h.update(Path(wheel).name.encode() + b"\0" + Path(wheel).read_bytes())
    digest, marker = h.hexdigest()[:16], target / ".orrc-wheels-installed"
    with _locked(ENVS / f".{target.name}.lock"):
        if marker.is_file() and marker.read_text(encoding="utf-8") == digest:
            return python
        marker.unlink(missing_ok=True)
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
        pip = [str(python), "-m", "pip", "--no-input", "--disable-pip-version-check"]
        for args in (["install", "--quiet", "--no-deps", "--force-reinstall", *map(str, wheels)], ["check"]):
            run = subprocess.run(pip + args, env=env, capture_output=True, text=True, timeout=timeout)
            if run.returncode != 0:
                raise RuntimeError(f"pip {args[0]} in {target.name} failed (exit {run.returncode}):\n"
                                   f"{run.stdout[-3000:]}\n{run.stderr[-3000:]}")
        marker.write_text(digest, encoding="utf-8")
    return python


def autograder_env(zip_path: Path, name: str = "autograder") -> Path:
    """The Python of a fresh environment built from an otter autograder zip alone: the ``pip:``
    list of its ``environment.yml`` (as otter's ``setup.sh`` installs it in the grading image),
    installed from the zip's unpacked files (its ``files/`` holds the wheels it names). The
    environment is keyed by the list's registry requirements; the zip's own wheels (``orrc``) go
    on top with :func:`with_wheels`, so a change of the package does not rebuild it."""
    import tempfile
    import zipfile

    import yaml

    with tempfile.TemporaryDirectory() as tmp:
        with zipfile.ZipFile(zip_path) as zf:
            zf.extractall(tmp)
        env = yaml.safe_load((Path(tmp) / "environment.yml").read_text(encoding="utf-8"))
        pip = next(d["pip"] for d in env["dependencies"] if isinstance(d, dict) and "pip" in d)
        wheels = [w for w in _local_files(pip, Path(tmp)) if w.suffix == ".whl"]
        registry = [line for line in pip if not _local_files([line], Path(tmp))]
        assert len(registry) + len(wheels) == len(pip), f"unexpected lines in {zip_path.name}'s pip list: {pip}"
        return with_wheels(fresh_env(name, registry, base=Path(tmp)), wheels)


READER_REQUIREMENTS = "requirements-reader.txt"


def reader_requirements(root: Path = ROOT) -> list[str]:
    """The pinned registry lines of ``requirements-reader.txt``: what a chapter's download installs
    besides the orrc wheel (tools/sphinx_offline.py writes the file beside every download, with the
    wheel's line added)."""
    text = (Path(root) / READER_REQUIREMENTS).read_text(encoding="utf-8")
    return [line.strip() for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")]


def reader_env(root: Path = ROOT) -> Path:
    """The Python of the environment a reader builds from a chapter's download: the pinned lines of
    ``requirements-reader.txt`` (keyed by them, :func:`fresh_env`) and the project's wheel on top.
    Its packages are not compiled to bytecode when installed (a third of a minute before the book's
    build can start): the chapters' kernels write the bytecode of what they import
    (``tools.build_book.kernel_for``), once."""
    return with_wheels(fresh_env("reader", reader_requirements(root), compile_bytecode=False), [orrc_wheel(root)])
