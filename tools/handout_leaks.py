"""What a handout must not hold: the solutions and hidden tests of an assignment, found in the
student notebook.

An assignment's master notebook (otter-grader's assign format, see :mod:`tools.assignments`)
holds its secrets in four places:

- the solution code: every line inside in-cell ``# BEGIN SOLUTION`` ... ``# END SOLUTION``
  blocks (comments included), the right-hand side of each line ending in ``# SOLUTION``, and
  every comment of a code cell inside a solution region (raw ``BEGIN SOLUTION`` cells) that
  lies outside such a block, except a prompt to the student (a comment starting ``# your``):
  otter keeps those lines, so one left there reaches the student;
- the written solutions: the markdown cells inside a solution region, sentence by sentence;
- the hidden tests: their code lines and failure messages;
- the numbers of all of these with three significant digits or more (a measured slope, a
  ratio), which give an answer away without a sentence around them.

:func:`leaks` lists every secret of the master that appears in the student notebook (its
markdown, its code and its metadata, where otter keeps the public tests); the build refuses a
student notebook with any. Lines of the grading prelude (:mod:`tools.grading_prelude`), which
public tests carry too, are not secrets.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import yaml

_CONFIG_DOC = re.compile(r'^\s*(?:[\w.]+\s*=\s*)?"""\s*#\s*BEGIN\s+TEST\s+CONFIG(?P<yaml>.*?)"""\s*#\s*END\s+TEST\s+CONFIG',
                         re.S | re.I)
_NUMBER = re.compile(r"(?<![\w.])\d+\.\d+(?:e[-+]?\d+)?(?!\w)|(?<![\w.])\d{3,}(?!\w|\.\d)", re.I)
_SENTENCE_END = re.compile(r"(?<=[.!?:;])\s+")
MIN_LINE = 8          # shorter code lines (``return U``) say nothing on their own
MIN_SENTENCE = 24     # shorter prose fragments ("so it is zero.") are not a solution


def significant_digits(number: str) -> int:
    """How many significant digits a numeral carries: ``0.595`` 3, ``400`` 1, ``2024`` 4."""
    mantissa = re.split(r"[eE]", number)[0].replace(".", "").lstrip("0")
    if "." not in number:
        mantissa = mantissa.rstrip("0")
    return len(mantissa)


def numbers(text: str, digits: int = 3) -> set[str]:
    """The numerals of ``text`` with at least ``digits`` significant digits."""
    return {n for n in _NUMBER.findall(text) if significant_digits(n) >= digits}


def normal(text: str) -> str:
    """``text`` with its whitespace runs made single spaces (a sentence may break across lines)."""
    return " ".join(text.split())


def _raw_head(cell) -> str:
    first = cell.source.strip().split("\n")[0].strip()
    m = re.match(r"#\s+((?:begin|end)\s+\w+)\s*$", first, re.I)
    return " ".join(m.group(1).upper().split()) if m else ""


def _prelude_lines() -> set[str]:
    from tools import grading_prelude

    return {ln.strip() for ln in grading_prelude.PRELUDE.splitlines() if ln.strip()}


def secrets(master: Path) -> dict[str, list[str]]:
    """The secrets of a master notebook, by kind: ``code``, ``prose``, ``tests``, ``numbers``."""
    import nbformat

    nb = nbformat.read(master, as_version=4)
    code, prose, tests = [], [], []
    region = False
    prelude = _prelude_lines()
    for cell in nb.cells:
        if cell.cell_type == "raw":
            head = _raw_head(cell)
            region = {"BEGIN SOLUTION": True, "END SOLUTION": False}.get(head, region)
            continue
        if cell.cell_type == "markdown":
            if region:
                prose += [s for s in _SENTENCE_END.split(normal(cell.source)) if len(s) >= MIN_SENTENCE]
            continue
        m = _CONFIG_DOC.match(cell.source)
        if m:
            conf = yaml.safe_load(m.group("yaml")) or {}
            if conf.get("hidden"):
                body = cell.source[m.end():]
                tests += [ln.strip() for ln in body.splitlines()
                          if len(ln.strip()) >= MIN_LINE and ln.strip() not in prelude]
                tests.append(normal(str(conf.get("failure_message", ""))))
            continue
        inside = False
        for ln in cell.source.split("\n"):
            text = ln.strip()
            if re.match(r"#\s*BEGIN\s+SOLUTION", text, re.I):
                inside = True
            elif re.match(r"#\s*END\s+SOLUTION", text, re.I):
                inside = False
            elif re.search(r"#\s*SOLUTION\s*$", text):
                line = re.sub(r"#\s*SOLUTION\s*$", "", text).strip()
                rhs = line.partition("=")[2].strip() if re.search(r"[^=!<>]=[^=]", line) else line
                if not re.fullmatch(r"""(["'])[^"']*\1""", rhs):   # one of the choices the question offers
                    code.append(rhs)
            elif inside and len(text) >= MIN_LINE:
                code.append(text)
            elif region and text.startswith("#") and not re.match(r"#\s*your\b", text, re.I) and len(text) >= MIN_LINE:
                code.append(text)
    public = _public_text(nb)
    # a hidden test's generic line that a public test (or the handout's own code) also holds, or a
    # line a question's statement quotes (a given call), is no secret
    tests = [t for t in tests if t and t not in public]
    code = [c for c in code if c not in public or c.startswith("#")]
    found = set()
    for text in code + prose + tests:
        found |= numbers(text)
    return {"code": code, "prose": prose, "tests": tests, "numbers": sorted(found)}


def _public_text(nb) -> str:
    """What the master shows on purpose: the questions' statements, its public tests, and the code
    lines otter keeps (outside in-cell solution blocks, not ending in ``# SOLUTION``)."""
    out, region = [], False
    for cell in nb.cells:
        if cell.cell_type == "raw":
            region = {"BEGIN SOLUTION": True, "END SOLUTION": False}.get(_raw_head(cell), region)
        if cell.cell_type == "markdown" and not region:
            out.append(cell.source)     # a question's statement (a code line it quotes)
        if cell.cell_type != "code":
            continue
        m = _CONFIG_DOC.match(cell.source)
        if m:
            if not (yaml.safe_load(m.group("yaml")) or {}).get("hidden"):
                out.append(cell.source[m.end():])
            continue
        inside = False
        for ln in cell.source.split("\n"):
            if re.match(r"\s*#\s*BEGIN\s+SOLUTION", ln, re.I):
                inside = True
            elif re.match(r"\s*#\s*END\s+SOLUTION", ln, re.I):
                inside = False
            elif not inside and not re.search(r"#\s*SOLUTION\s*$", ln):
                out.append(ln)
    return "\n".join(out)


def student_text(student: Path) -> str:
    """Everything a student notebook holds as text: every cell's source and its metadata."""
    import nbformat

    nb = nbformat.read(student, as_version=4)
    return "\n".join(c.source for c in nb.cells) + "\n" + json.dumps(nb.metadata)


def leaks(master: Path, student: Path) -> list[str]:
    """Every secret of ``master`` (see :func:`secrets`) that the ``student`` notebook holds."""
    text = student_text(student)
    flat = normal(text)
    s = secrets(master)
    found = [ln for ln in s["code"] + s["tests"] if ln in text or normal(ln) in flat]
    found += [p for p in s["prose"] if p in flat]
    shown = numbers(text)
    found += [f"the number {n}" for n in s["numbers"] if n in shown]
    return found
