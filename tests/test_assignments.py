"""The graded assignments: otter-grader builds them, their autograders grade
anywhere, their solutions get full marks, and each plausible wrong submission loses points in
its own question only.

One session fixture (``graded``, in conftest.py: it starts when the tests are collected and
runs beside the rest of the suite) builds every assignment of ``assignments/`` (``tools.assignments``: jupytext
to .ipynb, ``otter assign``, the orrc wheel and the pinned requirements put in the autograder zip)
and grades, with the otter of a fresh environment built from the autograder zip alone
(``tests/fresh_env.py``), the solution notebook, the blank student notebook, and each plausible
wrong submission ``tests/fixtures/assignments/NAME_wrong*.md`` (its answer cells filled into the
student notebook, as a student fills them in; its front matter names the one question it gets
wrong). These are the checks ``make assignments`` prints, and more.
Graded solutions stay out of the book: ``assignments/`` is excluded from it, and no solution
line or hidden test of an assignment is in the built HTML.
"""
from __future__ import annotations

import json
import multiprocessing
import os
import re
import shutil
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pytest
import yaml

from conftest import BOOK_OUT, after, background
from tools import assignments, grading

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = ROOT / "tests" / "fixtures" / "assignments"
NAMES = assignments.names()


def wrong_submissions(name: str, gaming: bool = False) -> dict[str, dict]:
    """The plausible wrong submissions of an assignment: {label: front matter} (label as graded);
    with ``gaming``, the submissions that try to pass without the understanding a question tests
    (front matter ``gaming: true`` and ``loses``, the points each question must lose)."""
    out = {}
    for p in sorted(FIXTURES.glob(f"{name}_wrong*.md")):
        front = yaml.safe_load(p.read_text(encoding="utf-8").split("---")[1])
        if bool(front["orrc_wrong"].get("gaming")) == gaming:
            out[p.stem[len(name) + 1:]] = front["orrc_wrong"]
    return out


def test_assignments_cover_every_part_of_the_paper():
    """Each of the paper's three algorithms (and Theorems 1 and 2, Lemmas 3-5, the comparison and
    the forecasts beyond the paper) is assessed, and a nonlinear system is among them."""
    assert len(NAMES) >= 7, NAMES
    chapters = {ch for n in NAMES for ch in assignments.read_assignment(assignments.SOURCES / n / f"{n}.md")["chapters"]}
    for part in ("book/preview_rhc", "book/theorem1", "book/unknown_systems", "book/lemma3_4", "book/theorem2",
                 "book/minmax", "book/comparison", "book/forecasts"):
        assert part in chapters, f"no assignment goes with {part}"
    sources = [(assignments.SOURCES / n / f"{n}.md").read_text(encoding="utf-8") for n in NAMES]
    assert any("orrc.ParametricSystem(" in s or "orrc.NonlinearSystem(" in s for s in sources), \
        "no assignment works on a nonlinear system"


@pytest.mark.parametrize("name", NAMES)
def test_every_assignment_asks_for_a_prediction_a_derivation_and_an_explanation(name):
    qs = assignments.read_assignment(assignments.SOURCES / name / f"{name}.md")["questions"]
    kinds = {k for q in qs for k in ("predict", "derivation", "verify") if k in q["name"]}
    assert kinds == {"predict", "derivation", "verify"}, f"{name}: questions {[q['name'] for q in qs]}"
    assert "predict" in qs[0]["name"], f"{name}: the prediction is asked before any cell can reveal it"
    assert any(t["hidden"] for t in qs[0]["tests"]), f"{name}: the prediction is graded by a hidden test"
    verify = next(q for q in qs if "verify" in q["name"])
    assert any(t["hidden"] for t in verify["tests"]), f"{name}: the verification is graded"
    assert any(q["manual"] and q["manual_points"] > 0 for q in qs), f"{name}: no written question graded by hand"


@pytest.mark.parametrize("name", NAMES)
def test_every_assignment_has_a_plausible_wrong_submission_of_one_question(name):
    wrong = wrong_submissions(name)
    questions = {q["name"] for q in assignments.read_assignment(assignments.SOURCES / name / f"{name}.md")["questions"]}
    assert wrong, f"tests/fixtures/assignments/{name}_wrong.md is missing"
    for label, front in wrong.items():
        assert front["question"] in questions, f"{name}_{label}: names no question of {name}"


@pytest.mark.slow
def test_gaming_submissions_lose_the_points_in_question(graded):
    """A wrapper of the package function a question asks for, a difference quotient of the
    package's gamma_c, numpy's comparisons replaced by ``lambda *a, **k: True``, a verification
    typed in: each loses the points of the questions it games (and no other point)."""
    seen = 0
    for name in NAMES:
        for label, front in wrong_submissions(name, gaming=True).items():
            seen += 1
            got = graded[name]["grades"][label]["questions"]
            for q, (score, pts, _) in got.items():
                if q in front["loses"]:
                    assert score <= pts - front["loses"][q], f"{name}_{label}: {q} gets {score:g}/{pts:g}"
                else:
                    assert score == pts, f"{name}_{label}: {q} loses points ({score:g}/{pts:g}) it does not game"
    assert seen >= 5


@pytest.mark.slow
def test_graded_in_a_fresh_environment_built_from_the_zip_alone(graded):
    """The grading otter ran in a virtual environment built from the zip's environment.yml alone
    (pip from the registry, the zip's own orrc wheel), not in the project's .venv."""
    import subprocess

    for name, r in graded.items():
        exe = Path(r["python"])
        assert "fresh-envs" in exe.parts and ROOT / ".venv" not in exe.parents, f"{name} graded by {exe}"
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
        where = subprocess.run([str(exe), "-c", "import orrc, otter; print(orrc.__file__)"], capture_output=True,
                               text=True, check=True, cwd=Path(r["paths"]["student"]).parent, env=env).stdout.strip()
        assert "site-packages" in where and not where.startswith(str(ROOT / "orrc")), where


@pytest.mark.slow
def test_autograder_zips_carry_their_environment(graded):
    """Each zip declares, in otter's environment.yml, the Python tested here and pinned pip lines
    only, and carries the orrc wheel it names in files/."""
    import zipfile

    for name, r in graded.items():
        with zipfile.ZipFile(r["paths"]["autograder"]) as zf:
            env = yaml.safe_load(zf.read("environment.yml"))
            files = set(zf.namelist())
        pip = next(d["pip"] for d in env["dependencies"] if isinstance(d, dict))
        assert f"python={sys.version_info.major}.{sys.version_info.minor}" in env["dependencies"]
        wheels = [p for p in pip if p.endswith(".whl")]
        assert len(wheels) == 1 and wheels[0] in files, (name, wheels)
        assert all("==" in p for p in pip if p not in wheels), [p for p in pip if "==" not in p and p not in wheels]
        assert any(p.startswith("otter-grader[grading]==") for p in pip) and any(p.startswith("numpy==") for p in pip)


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_solution_gets_full_marks_and_blank_does_not(graded, name):
    r = graded[name]
    sol, blank = r["grades"]["solution"], r["grades"]["blank"]
    assert sol["points"] > 0 and sol["score"] == sol["points"], assignments.summary([r])[0]
    assert blank["points"] == sol["points"]
    assert blank["score"] <= 0.25 * blank["points"], f"{name}: the untouched student notebook gets {blank['score']:g}"
    assert re.fullmatch(rf"{name}: solution ([\d.]+)/\1 points, blank [\d.]+/\1 points", assignments.line(r))


def _failed(output: str, question: str) -> set[int]:
    """Which test cases of a question failed (otter numbers them in order: "q - 2 result: ❌ ...")."""
    return {int(i) for i in re.findall(rf"{re.escape(question)} - (\d+) result:\s*\n\s*❌", output)}


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_one_wrong_question_costs_its_own_points_only(graded, name):
    """Each question is graded on its own: a submission whose only mistake is in one question loses
    points there, and every other question gets full marks."""
    for label, front in wrong_submissions(name).items():
        got = graded[name]["grades"][label]["questions"]
        for q, (score, pts, _) in got.items():
            if q == front["question"]:
                assert score < pts, f"{name}_{label}: its wrong {q} gets full marks"
            else:
                assert score == pts, f"{name}_{label}: {q} loses points ({score:g}/{pts:g}) for a mistake in {front['question']}"


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_wrong_submissions_fail_a_hidden_test_and_a_public_one_where_fair(graded, name):
    """A hidden test always catches a plausible wrong submission; a public test too where the fixture
    says it is fair to point at it, with the message that says what to check."""
    meta = assignments.read_assignment(assignments.SOURCES / name / f"{name}.md")
    tests = {q["name"]: q["tests"] for q in meta["questions"]}
    for label, front in wrong_submissions(name).items():
        q = front["question"]
        output = graded[name]["grades"][label]["questions"][q][2]
        failed = [tests[q][i - 1] for i in sorted(_failed(output, q))]
        assert any(t["hidden"] for t in failed), f"{name}_{label}: no hidden test of {q} fails"
        public = [t for t in failed if not t["hidden"]]
        if front.get("public_test_catches_it"):
            assert public, f"{name}_{label}: no public test of {q} catches it"
            assert all(t["checks"] in output for t in public)


#: the assignment whose notebooks are graded once more, one ``otter run`` each, to compare with the
#: session's gradings (all in one process): the one whose notebooks cost the least to grade
SINGLE = "a5_minmax"


@pytest.fixture(scope="module")
def single_runs(graded):
    return background("single_runs")


@after("graded", "single_runs")
def grade_one_by_one(graded):
    """Every notebook of SINGLE graded by its own ``otter run`` (tools.grading.grade), by the
    interpreter that graded the session's batch, each in a folder of its own."""
    r = graded[SINGLE]
    work = Path(tempfile.mkdtemp(prefix="orrc-single-runs-"))
    try:
        return {label: grading.grade(nb, r["paths"]["autograder"], work / label, r["python"])
                for label, nb in r["submissions"].items()}
    finally:
        shutil.rmtree(work, ignore_errors=True)


@pytest.mark.slow
def test_one_process_grades_as_one_otter_run_per_notebook(graded, single_runs):
    """The session grades all notebooks in one process per environment (tools.grading, otter
    imported once); each notebook gets the points per question, and fails the test cases, that its
    own ``otter run`` gives it."""
    batch = graded[SINGLE]["grades"]
    assert set(single_runs) == set(batch) and {"solution", "blank", "wrong"} <= set(batch)
    scores = set()
    for label, single in single_runs.items():
        got = batch[label]["questions"]
        assert list(got) == list(single["questions"]), label
        for q, (score, pts, output) in single["questions"].items():
            assert got[q][:2] == (score, pts), f"{SINGLE} {label} {q}: batch {got[q][:2]}, otter run {(score, pts)}"
            assert _failed(got[q][2], q) == _failed(output, q), f"{SINGLE} {label} {q}"
        scores.add((single["score"] == single["points"], single["score"] == 0))
    assert scores >= {(True, False), (False, False)}, scores   # a full mark and a wrong question among them


@pytest.mark.slow
def test_student_notebooks_end_with_the_export_cell(graded):
    import nbformat

    for name, r in graded.items():
        nb = nbformat.read(r["paths"]["student"], as_version=4)
        last = [c for c in nb.cells if c.cell_type == "code"][-1]
        assert "grader.export(" in last.source, f"{name}: the last code cell is not otter's export cell"


@pytest.mark.slow
def test_the_report_and_its_exit_code(graded):
    text, rc = assignments.summary(list(graded.values()))
    assert rc == 0 and len(text.splitlines()) == len(NAMES)
    bad = dict(graded[NAMES[0]], grades={**graded[NAMES[0]]["grades"], "solution": graded[NAMES[0]]["grades"]["wrong"]})
    assert assignments.summary([bad])[1] == 1, "a solution below full marks must fail make assignments"
    full = dict(graded[NAMES[0]], grades={**graded[NAMES[0]]["grades"], "blank": graded[NAMES[0]]["grades"]["solution"]})
    assert assignments.summary([full])[1] == 1, "a blank notebook at full marks must fail make assignments"


@pytest.mark.slow
def test_student_notebooks_hold_no_solution(graded):
    for name, r in graded.items():
        student = r["paths"]["student"]
        text = student.read_text(encoding="utf-8")
        assert "BEGIN SOLUTION" not in text and "BEGIN TESTS" not in text
        meta = assignments.read_assignment(assignments.SOURCES / name / f"{name}.md")
        for q in meta["questions"]:
            for t in q["tests"]:
                assert (f"def {t['name']}(" in text) == (not t["hidden"]), f"{name}: {t['name']}"


def test_a_solution_outside_a_solution_block_is_refused(tmp_path):
    """A solution cell left outside a BEGIN/END SOLUTION block would reach the students: the build stops."""
    src = assignments.SOURCES / NAMES[0] / f"{NAMES[0]}.md"
    text = src.read_text(encoding="utf-8")
    first = text.index("```{raw-cell}\n# BEGIN SOLUTION\n```\n")
    text = text[:first] + text[first:].replace("```{raw-cell}\n# BEGIN SOLUTION\n```\n", "", 1).replace(
        "```{raw-cell}\n# END SOLUTION\n```\n", "", 1)
    (tmp_path / NAMES[0]).mkdir()
    (tmp_path / NAMES[0] / f"{NAMES[0]}.md").write_text(text, encoding="utf-8")
    wheel = tmp_path / "orrc-0.0.0-py3-none-any.whl"   # packed, never installed: no need to build one
    wheel.write_bytes(b"")
    # in a process of its own, as make assignments builds: a build parses Python (ast), which one
    # interpreter must not do in two threads at once, and the session's background threads may
    with ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn")) as proc:
        with pytest.raises(RuntimeError, match="still holds solution"):
            proc.submit(assignments.build, NAMES[0], tmp_path / "out", tmp_path, wheel).result()


def test_no_assignment_runs_its_tests_when_built():
    """otter assign executes no notebook (``run_tests: false``): each solution is executed once, when
    the gradings grade it (and get it full marks, test_solution_gets_full_marks_and_blank_does_not)."""
    import jupytext

    for name in NAMES:
        nb = jupytext.read(assignments.SOURCES / name / f"{name}.md", fmt="md:myst")
        config = next(conf for head, conf in map(assignments._raw_header, nb.cells) if head == "ASSIGNMENT CONFIG")
        assert config.get("run_tests") is False, f"{name}: otter assign would run the tests on the solution"


def test_assignments_are_excluded_from_the_book():
    cfg = yaml.safe_load((ROOT / "_config.yml").read_text(encoding="utf-8"))
    assert "assignments" in cfg["exclude_patterns"]


@pytest.mark.slow
def test_no_assignment_solution_in_the_built_book(book, tmp_path):
    assert book["rc"] == 0
    lines = []
    for name in NAMES:
        master = assignments.to_ipynb(assignments.SOURCES / name / f"{name}.md", tmp_path / f"{name}.ipynb")
        lines += [ln for ln in assignments._solution_text(master) if len(ln) >= 12]
    book_sources = "\n".join(p.read_text(encoding="utf-8") for p in (ROOT / "book").rglob("*.md"))
    lines = [ln for ln in lines if ln not in book_sources]  # what the book itself also says is no leak
    assert len(lines) > 20
    html = BOOK_OUT / "_build" / "html"
    files = [p for p in html.rglob("*") if p.is_file() and p.suffix in (".html", ".js", ".txt", ".md", ".ipynb", ".json")]
    for p in files:
        text = p.read_text(encoding="utf-8", errors="replace")
        hits = [ln for ln in lines if ln in text]
        assert not hits, f"{p.relative_to(html)} holds assignment solution text: {hits[:2]}"


def test_every_exercise_has_time_and_difficulty_in_the_guide():
    """The guide's table tags every exercise of the book (kind, time, difficulty), and the syllabus
    sets every assignment."""
    from tools.toc import toc_pages

    guide = (ROOT / "book" / "instructors.md").read_text(encoding="utf-8")
    rows = dict(re.findall(r"^\| \{ref\}`(ex-[\w-]+)` \| ([^|]+\| \d+ min \| ★+) \|$", guide, re.M))
    labels = [m for p in toc_pages(ROOT) if p != "book/instructors" and (ROOT / f"{p}.md").is_file()
              for m in re.findall(r"^:label: (ex-[\w-]+)$", (ROOT / f"{p}.md").read_text(encoding="utf-8"), re.M)]
    assert labels, "no exercise found"
    missing = [lb for lb in labels if lb not in rows]
    assert not missing, f"exercises without time and difficulty in the guide's table: {missing}"
    syllabus = guide[guide.index("## Syllabus"):guide.index("## The exercises")]
    assert all(re.search(rf"\| {i}\b|\b{i}; exam|, and {i}|\b{i} \|", syllabus) for i in range(1, len(NAMES) + 1))


def json_text(outputs) -> str:
    """What a cell's outputs show, as one string."""
    return json.dumps([dict(o) for o in outputs])


def _handout_of(master: Path, dest: Path) -> Path:
    """A stand-in for otter's student notebook: the master without its solution regions, in-cell
    solution blocks and hidden tests (what otter removes), the rest as it is."""
    import nbformat

    from tools import handout_leaks

    nb = nbformat.read(master, as_version=4)
    cells, region = [], False
    for cell in nb.cells:
        if cell.cell_type == "raw":
            region = {"BEGIN SOLUTION": True, "END SOLUTION": False}.get(handout_leaks._raw_head(cell), region)
            continue
        if cell.cell_type == "code" and "hidden: true" in cell.source:
            continue
        if region and cell.cell_type == "markdown":
            continue
        if cell.cell_type == "code":
            kept, inside = [], False
            for ln in cell.source.split("\n"):
                if re.match(r"\s*#\s*BEGIN\s+SOLUTION", ln):
                    inside = True
                elif re.match(r"\s*#\s*END\s+SOLUTION", ln):
                    inside = False
                elif not inside:
                    kept.append(re.sub(r"=.*#\s*SOLUTION\s*$", "= ...", ln) if "=" in ln
                                else re.sub(r"\S.*#\s*SOLUTION\s*$", "...", ln))
            cell.source = "\n".join(kept)
        cells.append(cell)
    nb.cells = cells
    nbformat.write(nb, dest)
    return dest


@pytest.mark.parametrize("name", NAMES)
def test_the_leak_check_sees_a_planted_leak(tmp_path, name):
    """The build's leak check (tools.handout_leaks) passes a handout without solutions and fails
    one with a sentence of a written solution, a solution comment, a number of a solution, or a
    line of a hidden test planted anywhere in it (a markdown cell, a code cell, the metadata)."""
    import nbformat

    from tools import handout_leaks

    master = assignments.to_ipynb(assignments.SOURCES / name / f"{name}.md", tmp_path / "master.ipynb")
    clean = _handout_of(master, tmp_path / "clean.ipynb")
    assert handout_leaks.leaks(master, clean) == []
    secrets = handout_leaks.secrets(master)
    assert secrets["prose"] and secrets["code"] and secrets["tests"], secrets
    plants = {"prose": ("markdown", secrets["prose"][-1]),
              "comment": ("code", next(c for c in secrets["code"] if c.startswith("#"))),
              "code": ("code", secrets["code"][0]),
              "test": ("metadata", secrets["tests"][0])}
    if secrets["numbers"]:
        plants["number"] = ("markdown", f"You should find about {secrets['numbers'][0]}.")
    for kind, (where, text) in plants.items():
        nb = nbformat.read(clean, as_version=4)
        if where == "markdown":
            nb.cells.append(nbformat.v4.new_markdown_cell(f"Hint: {text}"))
        elif where == "code":
            nb.cells[3].source += f"\n{text}"
        else:
            nb.metadata["otter"] = {"tests": {"q": text}}
        planted = tmp_path / f"planted_{kind}.ipynb"
        nbformat.write(nb, planted)
        assert handout_leaks.leaks(master, planted), f"{name}: a planted {kind} ({text[:60]!r}) is not caught"


def test_what_you_should_see_and_reasoning_stay_in_the_solutions():
    """The results a question leads to, and the reasoning of a prediction, are solution text."""
    from tools import handout_leaks

    for name in NAMES:
        text = (assignments.SOURCES / name / f"{name}.md").read_text(encoding="utf-8")
        last = text[text.rindex("# END QUESTION"):]
        assert not last.split("```", 1)[1].strip(), f"{name}: text after the last question reaches students"
        assert "my reasoning" not in text, name
    assert handout_leaks.significant_digits("0.595") == 3 and handout_leaks.significant_digits("400") == 1
    assert handout_leaks.numbers("slope 0.595 at T = 400, seed 2024") == {"0.595", "2024"}


@pytest.mark.slow
def test_a_student_sets_up_from_the_handout_alone(graded, tmp_path):
    """The handout's requirements.txt installs, in a fresh environment, what runs the notebook and
    its public tests: the same pinned list the autograder grades with (so the environment the
    gradings built is the one a student's file gives, reused here), and the wheel beside it."""
    import subprocess
    import zipfile

    import nbformat

    from fresh_env import fresh_env, with_wheels

    r = graded[NAMES[0]]
    handout = Path(r["paths"]["student"]).parent
    lines = [ln.strip() for ln in (handout / "requirements.txt").read_text(encoding="utf-8").splitlines()
             if ln.strip() and not ln.startswith("#")]
    wheels = [ln for ln in lines if ln.endswith(".whl")]
    assert len(wheels) == 1 and (handout / wheels[0]).is_file(), lines
    registry = [ln for ln in lines if ln not in wheels]
    assert all("==" in ln for ln in registry), [ln for ln in registry if "==" not in ln]
    with zipfile.ZipFile(r["paths"]["autograder"]) as zf:
        pip = next(d["pip"] for d in yaml.safe_load(zf.read("environment.yml"))["dependencies"] if isinstance(d, dict))
    assert registry == [p for p in pip if not p.endswith(".whl")], "the student's pins are the grader's"
    exe = with_wheels(fresh_env("autograder", registry, base=handout), [handout / wheels[0]])
    work = tmp_path / "handout"
    shutil.copytree(handout, work)
    shutil.copy(Path(r["paths"]["student"]).parents[2] / "submissions" / "wrong.ipynb", work / f"{NAMES[0]}.ipynb")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    run = subprocess.run([str(exe), "-c", "import nbformat, nbclient, sys; nb = nbformat.read(sys.argv[1], 4); "
                          "nbclient.NotebookClient(nb, kernel_name='python3', timeout=600, "
                          "resources={'metadata': {'path': sys.argv[2]}}).execute(); nbformat.write(nb, sys.argv[1])",
                          str(work / f"{NAMES[0]}.ipynb"), str(work)], cwd=work, env=env, capture_output=True,
                         text=True, timeout=900)
    assert run.returncode == 0, run.stderr[-3000:]
    nb = nbformat.read(work / f"{NAMES[0]}.ipynb", as_version=4)
    checks = {c.source.split('"')[1]: json_text(c.outputs) for c in nb.cells
              if c.cell_type == "code" and c.source.startswith("grader.check(")}
    assert "passed" in checks["q2_derivation"] and "failed" not in checks["q2_derivation"].lower(), checks
    assert "failed" in checks["q1_plan"].lower(), "the public tests point at the wrong Question 1"


@pytest.mark.slow
def test_the_lecturer_gets_a_clean_solution_and_its_pdf(graded):
    """The solution notebook without markers, otter cells or tests, and a PDF of it, per assignment."""
    import nbformat

    for name, r in graded.items():
        nb = nbformat.read(r["paths"]["clean_solution"], as_version=4)
        code = "\n".join(c.source for c in nb.cells if c.cell_type == "code")
        text = "\n".join(c.source for c in nb.cells)
        assert "SOLUTION" not in text and "BEGIN QUESTION" not in text and "grader.check" not in code, name
        assert "def test_" not in text and "otter" not in nb.metadata, name
        sol = assignments.read_assignment(assignments.SOURCES / name / f"{name}.md")
        assert text.count("graded by hand") == sum(q["manual"] for q in sol["questions"]), name
        pdf = Path(r["paths"]["solutions_pdf"])
        assert pdf.read_bytes()[:5] == b"%PDF-" and pdf.stat().st_size > 5000, name
