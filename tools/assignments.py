"""Build and grade the graded assignments (``make assignments``).

Each assignment is one source notebook, ``assignments/NAME/NAME.md`` (jupytext MyST), holding the
questions, their solutions and their tests in otter-grader 7's assign format (raw cells
``# BEGIN QUESTION`` ... ``# END QUESTION``, ``# BEGIN SOLUTION`` markers, exception-based tests in
``# BEGIN TESTS`` blocks, hidden ones with ``hidden: true``). Its front matter says which chapters
it needs and how long a student takes (``orrc_assignment: {chapters: [...], minutes: N}``).

For every assignment, :func:`build` converts the source to ``.ipynb`` (jupytext; otter assign
reads notebooks), makes its autograder self-contained (:func:`self_contained`: the orrc wheel and the
pinned requirements of :mod:`tools.autograder_env` in its config) and runs ``otter assign`` into
``_build/assignments/NAME/``: ``student/`` (what students get: ``NAME.ipynb``, solutions and
hidden tests removed, the orrc wheel and ``requirements.txt``, the pinned list to set up from,
see :func:`write_student_requirements`), ``solution/`` (for the lecturer: the solution notebook
without markers or tests, :func:`clean_solution`, and it as a PDF) and ``autograder/`` (the
solution notebook and the autograder zip); ``otter assign`` runs no notebook (``run_tests:
false``). :func:`grade_built` then grades every notebook as ``otter run`` does (locally, no
container; by default with this environment's otter and kernel, or with another interpreter's,
e.g. a fresh environment built from the zip alone), all in one process per interpreter
(:func:`tools.grading.grade_many`), so that each notebook is executed once. Questions marked
``manual: true`` are written answers graded by hand (no tests; their points in the question's
config). :func:`main` grades each
solution notebook and each untouched student notebook and prints one line per assignment,

    NAME: solution P/P points, blank Q/P points

and exits non-zero when a solution gets less than full marks or a blank notebook gets full marks.
"""
from __future__ import annotations

import argparse
import ast
import contextlib
import io
import json
import multiprocessing
import os
import re
import shutil
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import yaml

from tools import autograder_env, grading_prelude, handout_leaks, written_answers
from tools.grading import grade_many

ROOT = Path(__file__).resolve().parents[1]
SOURCES = ROOT / "assignments"
OUT = ROOT / "_build" / "assignments"
_CONFIG_DOC = re.compile(r'^\s*(?:[\w.]+\s*=\s*)?"""\s*#\s*BEGIN\s+TEST\s+CONFIG(?P<yaml>.*?)"""\s*#\s*END\s+TEST\s+CONFIG',
                         re.S | re.I)


def names(root: Path = SOURCES) -> list[str]:
    """The assignments: every folder of ``assignments/`` holding a source notebook of its own name."""
    return sorted(p.name for p in Path(root).iterdir() if p.is_dir() and (p / f"{p.name}.md").is_file())


def _raw_header(cell) -> tuple[str, dict]:
    """(``BEGIN QUESTION`` etc., its YAML) for an otter boundary raw cell, else ("", {})."""
    if cell.cell_type != "raw":
        return "", {}
    first, _, rest = cell.source.strip().partition("\n")
    m = re.match(r"#\s+((?:begin|end)\s+\w+|assignment\s+config)\s*$", first.strip(), re.I)
    if not m:
        return "", {}
    return " ".join(m.group(1).upper().split()), (yaml.safe_load(rest) or {})


def read_assignment(path: Path) -> dict:
    """What an assignment source says about itself: title, chapters (pages of the book; an entry
    ``Title <page>`` names a page not yet written), minutes, questions and tests.

    Each test: its function name, points, whether it is hidden, and ``checks``, the message it
    shows when it fails (its ``failure_message``). Raises ValueError on a question without tests,
    a test without points or a failure message, or metadata missing from the front matter.
    """
    import jupytext

    nb = jupytext.read(path, fmt="md:myst")
    meta = nb.metadata.get("orrc_assignment")
    if not isinstance(meta, dict) or not meta.get("chapters") or not meta.get("minutes"):
        raise ValueError(f"{path}: the front matter needs orrc_assignment: {{chapters: [...], minutes: N}}")
    title = next((re.sub(r"^#\s+", "", c.source.strip().split("\n")[0]) for c in nb.cells
                  if c.cell_type == "markdown" and c.source.lstrip().startswith("# ")), path.stem)
    questions, q, in_tests = [], None, False
    for cell in nb.cells:
        head, conf = _raw_header(cell)
        if head == "BEGIN QUESTION":
            q = {"name": conf["name"], "tests": [], "manual": bool(conf.get("manual")),
                 "manual_points": float(conf.get("points") or 0) if conf.get("manual") else 0.0}
            questions.append(q)
        elif head == "BEGIN TESTS":
            in_tests = True
        elif head == "END TESTS":
            in_tests = False
        elif head == "END QUESTION":
            q = None
        elif in_tests and q is not None and cell.cell_type == "code":
            m = _CONFIG_DOC.match(cell.source)
            conf = yaml.safe_load(m.group("yaml")) if m else {}
            fn = next(n.name for n in ast.parse(cell.source).body if isinstance(n, ast.FunctionDef))
            if not conf.get("points") or not conf.get("failure_message"):
                raise ValueError(f"{path}: test {fn} of {q['name']} needs points and a failure_message")
            if '"' in str(conf["failure_message"]) or "\\" in str(conf["failure_message"]):
                raise ValueError(f"{path}: the failure_message of {fn} holds a double quote or a backslash, "
                                 "which break the test file otter assign writes")
            q["tests"].append({"name": fn, "points": float(conf["points"]), "hidden": bool(conf.get("hidden")),
                               "checks": str(conf["failure_message"])})
    for q in questions:
        if not q["tests"] and not q["manual"]:
            raise ValueError(f"{path}: question {q['name']} has no tests")
        if q["manual"] and not q["manual_points"]:
            raise ValueError(f"{path}: the manual question {q['name']} needs its points")
    chapters, titles = [], {}
    for entry in meta["chapters"]:  # a page of the book, or "Title <page>" for one not written yet
        m = re.fullmatch(r"\s*(?:(.*?)\s*<([^<>]+)>|([^<>]+?))\s*", str(entry))
        page = (m.group(2) or m.group(3)).strip()
        chapters.append(page)
        titles[page] = (m.group(1) or "").strip()
    return {"name": path.stem, "title": title, "chapters": chapters, "chapter_titles": titles,
            "minutes": int(meta["minutes"]),
            "questions": questions, "points": sum(t["points"] for q in questions for t in q["tests"]),
            "manual_points": sum(q["manual_points"] for q in questions)}


def to_ipynb(md: Path, dest: Path) -> Path:
    """Convert a jupytext MyST notebook to ``.ipynb`` (no outputs)."""
    import jupytext

    dest.parent.mkdir(parents=True, exist_ok=True)
    nb = jupytext.read(md, fmt="md:myst")
    nb.metadata.pop("jupytext", None)
    jupytext.write(nb, dest, fmt="ipynb")
    return dest


def _solution_text(master: Path) -> list[str]:
    """The solution lines of a master notebook (inside in-cell BEGIN/END SOLUTION markers, or ending
    in ``# SOLUTION``, whose right-hand side otter replaces) and the names of its hidden tests."""
    import nbformat

    found, inside = [], False
    for cell in nbformat.read(master, as_version=4).cells:
        if cell.cell_type != "code":
            continue
        m = _CONFIG_DOC.match(cell.source)
        if m and (yaml.safe_load(m.group("yaml")) or {}).get("hidden"):
            found += [f"def {n.name}(" for n in ast.parse(cell.source).body if isinstance(n, ast.FunctionDef)]
            continue
        for ln in cell.source.split("\n"):
            text = ln.strip()
            if re.match(r"#\s*BEGIN\s+SOLUTION", text, re.I):
                inside = True
            elif re.match(r"#\s*END\s+SOLUTION", text, re.I):
                inside = False
            elif re.search(r"#\s*SOLUTION\s*$", text):
                rhs = re.sub(r"#\s*SOLUTION\s*$", "", text).partition("=")[2].strip() or text
                found.append(rhs)
            elif inside and len(text) >= 8 and not text.startswith("#"):
                found.append(text)
    return found


def leaked_solutions(master: Path, student: Path) -> list[str]:
    """Solution lines or hidden-test names of ``master`` that are still in the ``student`` notebook."""
    import nbformat

    nb = nbformat.read(student, as_version=4)  # its code cells and its metadata (the public tests)
    text = "\n".join(c.source for c in nb.cells if c.cell_type == "code") + json.dumps(nb.metadata)
    return [ln for ln in _solution_text(master) if ln in text]


def own_their_tools(master: Path) -> None:
    """Give every test of ``master`` the grading prelude (:mod:`tools.grading_prelude`): its own
    numpy and orrc, its own tolerances, package functions forbidden while a student's is graded."""
    import nbformat

    nb = nbformat.read(master, as_version=4)
    for cell in nb.cells:
        if cell.cell_type == "code" and _CONFIG_DOC.match(cell.source):
            cell.source = grading_prelude.with_prelude(cell.source)
    nbformat.write(nb, master)


def self_contained(master: Path, wheel: Path) -> None:
    """Make the autograder of ``master`` grade anywhere: its assignment config gets the orrc wheel
    (``files``: in the zip's ``files/`` and beside the student notebook), the pinned requirements
    grading imports in place of otter's default list, and the Python they are tested with
    (see :mod:`tools.autograder_env`)."""
    import nbformat

    shutil.copy2(wheel, master.parent / wheel.name)
    nb = nbformat.read(master, as_version=4)
    cell = next(c for c in nb.cells if _raw_header(c)[0] == "ASSIGNMENT CONFIG")
    conf = _raw_header(cell)[1]
    conf.update(requirements=autograder_env.grading_requirements(wheel.name), overwrite_requirements=True,
                files=sorted(set(conf.get("files", [])) | {wheel.name}), python_version=autograder_env.python_version())
    cell.source = "# ASSIGNMENT CONFIG\n" + yaml.safe_dump(conf, sort_keys=False)
    nbformat.write(nb, master)


STUDENT_REQUIREMENTS = "requirements.txt"
_STUDENT_SETUP = """\
# Everything this assignment's notebook needs, pinned, for Python {python}. From this folder:
#   python{python} -m venv .venv
#   .venv/bin/pip install -r requirements.txt
# then open the notebook with JupyterLab (.venv/bin/pip install jupyterlab), VS Code or any
# Jupyter front end, choosing this environment's kernel. On a JupyterHub or on Colab, upload this
# folder's files and run  %pip install -r requirements.txt  in a cell before the first one.
"""


def wheel_name(folder: Path) -> str:
    """The name of the one orrc wheel in ``folder``."""
    wheels = sorted(Path(folder).glob("orrc-*.whl"))
    if len(wheels) != 1:
        raise RuntimeError(f"{folder}: {len(wheels)} orrc wheels (one expected)")
    return wheels[0].name


def write_student_requirements(folder: Path, wheel: str) -> Path:
    """The handout's ``requirements.txt``: the pinned list the autograder grades with (same
    versions, so a student's results are the grader's) and the orrc wheel beside it."""
    lines = [ln for ln in autograder_env.grading_requirements(wheel) if not ln.endswith(".whl")]
    path = Path(folder) / STUDENT_REQUIREMENTS
    path.write_text(_STUDENT_SETUP.format(python=autograder_env.python_version()) + "\n".join(lines + [wheel]) + "\n",
                    encoding="utf-8")
    return path


def clean_solution(solution: Path, dest: Path):
    """The solution notebook for the lecturer: otter's, without its solution markers, question
    comments, otter cells (``grader.check``, the export cell) and tests; written to ``dest``."""
    import nbformat

    nb = nbformat.read(solution, as_version=4)
    cells = []
    for cell in nb.cells:
        if cell.cell_type == "raw" or (cell.cell_type == "code" and ("grader." in cell.source or "otter" in cell.source)):
            continue
        src = re.sub(r"\n?[ \t]*#\s*(BEGIN|END) SOLUTION( NO PROMPT)?[ \t]*(?=\n|$)", "", cell.source)
        src = re.sub(r"[ \t]*#\s*SOLUTION\s*$", "", src, flags=re.M)
        src = re.sub(r"<!--\s*(BEGIN|END) QUESTION\s*-->\s*", "", src).strip()
        if src:
            cell.source = src
            cell.metadata.pop("tags", None)
            cells.append(cell)
    nb.cells = cells
    nb.metadata.pop("otter", None)
    dest.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, dest)
    return nb


def otter_assign(master: Path, dist: Path) -> None:
    """``otter assign MASTER DIST`` (what the command calls, with its defaults), in this process: a
    process that builds several assignments imports otter once. It runs no notebook (the
    assignments' configs say ``run_tests: false``: the solution is graded once, afterwards, by
    :func:`tools.grading.grade_many`). Like every build step that parses Python (``ast``), call it from one thread
    of a process at a time (see :func:`run_all`). Raises RuntimeError with otter's output."""
    from otter.assign import main as assign

    said = io.StringIO()
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            assign(str(Path(master).resolve()), str(Path(dist).resolve()))
    except Exception as exc:  # noqa: BLE001 -- whatever otter raises, the build stops with its message
        raise RuntimeError(f"otter assign failed for {Path(master).stem}: {type(exc).__name__}: {exc}\n"
                           f"{said.getvalue()[-3000:]}") from exc


def build(name: str, out: Path = OUT, root: Path = SOURCES, wheel: Path | None = None) -> dict:
    """``otter assign`` one assignment into ``out/NAME``: paths of the student and solution notebooks
    and of the autograder zip. ``wheel``: the orrc wheel to put in the autograder (built if None)."""
    dest = Path(out) / name
    if dest.exists():
        shutil.rmtree(dest)
    master = to_ipynb(Path(root) / name / f"{name}.md", dest / "master" / f"{name}.ipynb")
    own_their_tools(master)
    self_contained(master, wheel or autograder_env.build_wheel(dest / "wheel"))
    otter_assign(master, dest / "dist")
    zips = sorted((dest / "dist" / "autograder").glob(f"{name}-autograder_*.zip"))
    if len(zips) != 1:
        raise RuntimeError(f"otter assign wrote {len(zips)} autograder zips for {name}")
    leaks = leaked_solutions(master, dest / "dist" / "student" / f"{name}.ipynb")
    leaks += handout_leaks.leaks(master, dest / "dist" / "student" / f"{name}.ipynb")
    if leaks:
        raise RuntimeError(f"{name}: the student notebook still holds solution or hidden-test text "
                           f"(a solution outside a BEGIN/END SOLUTION block, a sentence or number of a "
                           f"solution or hidden test in the handout's text?): {leaks[:3]}")
    shutil.rmtree(dest / "master")  # the master holds the hidden tests and solutions: keep only otter's output
    write_student_requirements(dest / "dist" / "student", wheel_name(dest / "dist" / "student"))
    solution = clean_solution(dest / "dist" / "autograder" / f"{name}.ipynb", dest / "dist" / "solution" / f"{name}.ipynb")
    written_answers.solution_pdf(dest / "dist" / "solution" / f"{name}-solutions.pdf", solution)
    return {"student": dest / "dist" / "student" / f"{name}.ipynb",
            "solution": dest / "dist" / "autograder" / f"{name}.ipynb", "autograder": zips[0],
            "clean_solution": dest / "dist" / "solution" / f"{name}.ipynb",
            "solutions_pdf": dest / "dist" / "solution" / f"{name}-solutions.pdf"}


def fill_in(student: Path, answers: Path, dest: Path) -> Path:
    """A submission: the ``student`` notebook with its answer cells (otter's ``otter_answer_cell``)
    replaced, in order, by the code cells of the jupytext notebook ``answers``, as a student fills
    them in. The two counts must agree."""
    import jupytext
    import nbformat

    nb = nbformat.read(student, as_version=4)
    slots = [c for c in nb.cells if c.cell_type == "code" and "otter_answer_cell" in c.metadata.get("tags", [])]
    code = [c.source for c in jupytext.read(answers, fmt="md:myst").cells if c.cell_type == "code"]
    if len(code) != len(slots):
        raise ValueError(f"{answers}: {len(code)} answer cells for the {len(slots)} of {student.name}")
    for cell, src in zip(slots, code):
        cell.source = src
    dest.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, dest)
    return dest


def build_submissions(name: str, out: Path = OUT, root: Path = SOURCES, extra: dict | None = None,
                      wheel: Path | None = None) -> dict:
    """Build one assignment and make the notebooks to grade: its solution, its blank student
    notebook, and each submission made from ``extra`` ({label: answers}, see :func:`fill_in`; e.g. a
    plausible wrong one). Returns {"name", "paths", "submissions": {label: notebook}, "seconds"}."""
    t0 = time.perf_counter()
    paths = build(name, out, root, wheel)
    subs = {"solution": paths["solution"], "blank": paths["student"]}
    for label, answers in (extra or {}).items():
        subs[label] = fill_in(paths["student"], answers, Path(out) / name / "submissions" / f"{label}.ipynb")
    return {"name": name, "paths": paths, "submissions": subs, "seconds": time.perf_counter() - t0}


def _notebooks(built: dict, out: Path) -> list[tuple[str, tuple[Path, Path, Path]]]:
    """(label, (notebook, autograder, working folder)) for every notebook of ``built`` to grade."""
    return [(label, (nb, built["paths"]["autograder"], Path(out) / built["name"] / "graded" / label))
            for label, nb in built["submissions"].items()]


def grade_built(built: list[dict], out: Path = OUT, python=None, workers: int = 2) -> list[dict]:
    """Grade every notebook of every assignment of ``built`` (:func:`build_submissions` results)
    with :func:`grade_many`: one process per grading interpreter for all the assignments it grades,
    ``workers`` notebooks at a time. ``python(paths)``: the interpreter that grades an assignment
    (see :func:`tools.grading.grade`), given its built paths. Returns each of ``built`` with "grades"
    ({label: grade}) and "python" added, "seconds" the build's and its gradings' time."""
    exes = [python(b["paths"]) if python else None for b in built]
    grades: list[dict] = [{} for _ in built]
    for exe in dict.fromkeys(exes):
        todo = [(i, label, item) for i, b in enumerate(built) if exes[i] == exe for label, item in _notebooks(b, out)]
        for (i, label, _), g in zip(todo, grade_many([item for _, _, item in todo], exe, workers)):
            grades[i][label] = g
    return [{**b, "grades": g, "python": exe or sys.executable,
             "seconds": b["seconds"] + sum(x["seconds"] for x in g.values())}
            for b, g, exe in zip(built, grades, exes)]


def grade_submissions(built: dict, out: Path = OUT, python=None) -> dict:
    """Grade every notebook of one assignment's ``built`` (:func:`build_submissions`, :func:`grade_built`)."""
    return grade_built([built], out, python)[0]


def build_and_grade(name: str, out: Path = OUT, root: Path = SOURCES, extra: dict | None = None,
                    wheel: Path | None = None, python=None) -> dict:
    """Build one assignment, then grade its solution notebook, its blank student notebook, and each
    submission made from ``extra`` (:func:`build_submissions`, :func:`grade_submissions`)."""
    return grade_submissions(build_submissions(name, out, root, extra, wheel), out, python)


def line(result: dict) -> str:
    s, b = result["grades"]["solution"], result["grades"]["blank"]
    return f"{result['name']}: solution {s['score']:g}/{s['points']:g} points, blank {b['score']:g}/{b['points']:g} points"


def ok(result: dict) -> bool:
    s, b = result["grades"]["solution"], result["grades"]["blank"]
    return s["points"] > 0 and s["score"] == s["points"] and b["score"] < b["points"]


def run_all(out: Path = OUT, root: Path = SOURCES, workers: int = 2, extra=None, python=None,
            on_built=None) -> list[dict]:
    """Build every assignment, then grade them all (:func:`grade_built`: ``workers`` notebooks at a
    time, in one process per grading interpreter; one orrc wheel for all);
    ``extra(name)`` gives more notebooks to grade, ``python`` the interpreter that grades (see
    :func:`build_and_grade`). ``on_built(built)`` is called with every assignment's
    :func:`build_submissions` result once all are built, before the first grading, so that work
    which needs the built notebooks only (not their grades) can start beside the gradings."""
    wheel = autograder_env.build_wheel(Path(out) / "_wheel")
    todo = names(root)
    # the builds in processes of their own: each parses notebooks with ``ast``, whose conversion to
    # Python objects is not safe in two threads of one interpreter at once (CPython 3.11 raises
    # "AST constructor recursion depth mismatch"), and the caller may be parsing in another thread
    with ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn")) as procs:
        built = list(procs.map(build_submissions, todo, [out] * len(todo), [root] * len(todo),
                               [extra(n) if extra else None for n in todo], [wheel] * len(todo)))
    if on_built is not None:
        on_built(built)
    return grade_built(built, out, python, workers)


def summary(results: list[dict]) -> tuple[str, int]:
    """The report of :func:`main`: one line per assignment (and, for a failure, what failed), and the
    exit code: 1 when a solution gets less than full marks or a blank notebook gets full marks."""
    out = []
    for r in results:
        out.append(line(r) + ("" if ok(r) else "   <-- FAILED"))
        if not ok(r):
            for q, (score, pts, output) in r["grades"]["solution"]["questions"].items():
                if score < pts:
                    out.append(f"  {r['name']} solution, {q}: {score:g}/{pts:g}\n{output}")
    return "\n".join(out), 1 if (not results or not all(ok(r) for r in results)) else 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Build every assignment's student notebook and autograder, "
                                             "grade the solutions and the blank notebooks.")
    ap.add_argument("--out", type=Path, default=OUT)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    results = run_all(args.out)
    text, rc = summary(results)
    print(text)
    print(f"{len(results)} assignments in {time.perf_counter() - t0:.0f} s; student notebooks in "
          f"{args.out}/NAME/dist/student/, autograders in {args.out}/NAME/dist/autograder/")
    return rc


if __name__ == "__main__":
    sys.exit(main())
