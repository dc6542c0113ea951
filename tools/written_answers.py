"""The written answers of a submission, for grading by hand: read from the notebook, and one PDF
per submission.

A written question of an assignment (``manual: true`` in its source) reaches the student as a
markdown prompt between otter's ``<!-- BEGIN QUESTION -->`` and ``<!-- END QUESTION -->``
comments, followed by the answer cells the student types into (tagged ``otter_answer_cell``).
:func:`read` returns, for each written question, its prompt, its points (the prompt's
"(N points, graded by hand)") and the student's answer; :func:`write_pdf` puts them on A4 pages
(matplotlib, no LaTeX or browser needed), under a header with the student, the assignment and
the code-graded score, so that the lecturer grades the written part beside the rest (or uploads
the PDFs to Gradescope, one per student).

Examples
--------
>>> import nbformat
>>> nb = nbformat.v4.new_notebook()
>>> nb.cells = [nbformat.v4.new_markdown_cell("<!-- BEGIN QUESTION -->\\n\\n**Question 6 (2 points, graded by hand).** Why?"),
...             nbformat.v4.new_markdown_cell("Because.", metadata={"tags": ["otter_answer_cell"]}),
...             nbformat.v4.new_markdown_cell("<!-- END QUESTION -->")]
>>> [(q["points"], q["answer"]) for q in read(nb)]
[(2.0, 'Because.')]
"""
from __future__ import annotations

import re
import textwrap
from pathlib import Path

BLANK = "_Type your answer here, replacing this text._"
_POINTS = re.compile(r"\((\d+(?:\.\d+)?) points?, graded by hand\)")


def read(nb) -> list[dict]:
    """The written questions of a notebook: ``[{"prompt", "points", "answer"}]`` in order (an
    answer left as otter's placeholder is empty)."""
    out, current = [], None
    for cell in nb.cells:
        src = cell.get("source", "")
        if cell.get("cell_type") == "markdown" and "<!-- BEGIN QUESTION -->" in src:
            prompt = src.replace("<!-- BEGIN QUESTION -->", "").replace("<!-- END QUESTION -->", "").strip()
            m = _POINTS.search(prompt)
            current = {"prompt": prompt, "points": float(m.group(1)) if m else 0.0, "answer": ""}
            out.append(current)
        elif current is not None and "otter_answer_cell" in cell.get("metadata", {}).get("tags", []):
            text = src.strip()
            current["answer"] = "\n\n".join(a for a in (current["answer"], "" if text == BLANK else text) if a)
        if "<!-- END QUESTION -->" in src:
            current = None
    return [q for q in out if q["points"] > 0]


def _lines(text: str, width: int) -> list[str]:
    out = []
    for para in text.split("\n"):
        out += textwrap.wrap(para, width) or [""]
    return out


def text_pdf(dest: Path, body: list[tuple[str, str]], per_page: int = 60) -> Path:
    """A4 pages of text lines, each ``(text, "bold", "normal" or "code")``, as one PDF (matplotlib)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.backends.backend_pdf import PdfPages
    from matplotlib.figure import Figure

    dest = Path(dest)
    dest.parent.mkdir(parents=True, exist_ok=True)
    with PdfPages(dest) as pdf:
        for start in range(0, max(len(body), 1), per_page):
            fig = Figure(figsize=(8.27, 11.69))
            for i, (text, weight) in enumerate(body[start:start + per_page]):
                fig.text(0.07, 0.95 - i * 0.015, text, fontsize=9, weight="normal" if weight == "code" else weight,
                         family="DejaVu Sans Mono" if weight == "code" else "DejaVu Sans", parse_math=False, va="top")
            pdf.savefig(fig)
    return dest


def solution_pdf(dest: Path, solution) -> Path:
    """The solutions of an assignment as a PDF: every markdown and code cell of its clean
    solution notebook (see :func:`tools.assignments.clean_solution`), in order."""
    body = []
    for cell in solution.cells:
        kind = "code" if cell.cell_type == "code" else "normal"
        for ln in cell.source.split("\n") if kind == "code" else _lines(cell.source, 95):
            body.append((ln, kind))
        body.append(("", "normal"))
    return text_pdf(dest, body)


def write_pdf(dest: Path, student: str, assignment: str, score: str, questions: list[dict],
              note: str = "") -> Path:
    """One PDF of a submission's written answers (A4 pages), under a header naming the student,
    the assignment and the code-graded ``score``; a blank line to write the points of each."""
    body = [(f"{assignment}: written answers of {student}", "bold"), (f"Code-graded score: {score}", "normal")]
    if note:
        body += [(ln, "normal") for ln in _lines(f"Note: {note}", 95)]
    for q in questions:
        body += [("", "normal")] + [(ln, "bold") for ln in _lines(q["prompt"], 95)]
        body += [("", "normal")] + [(ln, "normal") for ln in _lines(q["answer"] or "(no answer)", 95)]
        body += [("", "normal"), (f"Points: ____ / {q['points']:g}", "bold")]
    return text_pdf(dest, body)
