"""The exercises and solutions of a chapter, in the book's one fixed format, and the chapter without them.

The format (common to every chapter; the solution-free edition strips exactly this):

* an exercise is a ``{exercise}`` directive with a ``:label:`` (backtick or colon fence);
* its solution is either a plain ``{solution} <label>`` directive (prose, no executed code), or
  sphinx-exercise's gated pair, whose code cells execute::

      ```{solution-start} <label>
      :class: dropdown
      ```
      prose, {glue:text}`...` roles
      ```{code-cell} ipython3
      ...
      ```
      ```{solution-end}
      ```

  both with ``:class: dropdown``.

Fences follow CommonMark (as markdown-it, under MyST, reads them): a fence of three or more
backticks or colons ends at the first line holding only the same character at least as many
times; everything in between is its body (which is why a solution holding a ```` ```python ````
block opens with four backticks). :func:`parse` reads a chapter with exactly these rules and
raises :class:`FormatError` (naming the file and the line) on anything it cannot read as the
format: an unclosed fence, a ``solution-start`` without its ``solution-end`` (or the reverse,
or nested), a solution for a label no exercise has, two solutions for one exercise, a solution
without ``:class: dropdown``, an exercise without a label. :func:`strip_solutions` returns the
chapter's text with every solution (both forms, the gated one from its start fence to the end
of its end fence, code cells included) removed and everything else unchanged.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

_OPEN = re.compile(r"^(?P<indent> {0,3})(?P<fence>`{3,}|:{3,})(?P<info>.*)$")
_DIRECTIVE = re.compile(r"^\{(?P<name>[\w:-]+)\}\s*(?P<arg>.*?)\s*$")
_OPTION = re.compile(r"^:(?P<key>[\w-]+):\s*(?P<value>.*?)\s*$")


class FormatError(ValueError):
    """A chapter's exercises or solutions are not in the book's fixed format."""


@dataclass
class Fence:
    """One fenced block at the top level of a chapter: lines [start, end] (0-based, inclusive)."""

    start: int
    end: int
    directive: str | None  # e.g. "exercise", "solution", "code-cell"; None for a plain ``` block
    argument: str
    options: dict
    body: list[str]  # the lines between the option block and the closing fence


@dataclass
class Solution:
    label: str  # the exercise it solves
    kind: str  # "plain" or "gated"
    start: int
    end: int  # inclusive: the closing fence of the directive (plain) or of solution-end (gated)
    prose: list[str] = field(default_factory=list)  # the text lines of the solution (no fences)
    code: list[str] = field(default_factory=list)  # the source of each executed code cell
    code_in_prose: list[str] = field(default_factory=list)  # fenced code that is shown, not executed


@dataclass
class Exercise:
    label: str
    start: int
    end: int
    statement: list[str]


@dataclass
class Chapter:
    path: Path
    lines: list[str]
    fences: list[Fence]
    exercises: list[Exercise]
    solutions: list[Solution]

    def solution_for(self, label: str) -> Solution | None:
        return next((s for s in self.solutions if s.label == label), None)


def _options_and_body(lines: list[str]) -> tuple[dict, list[str]]:
    """MyST directive options, as ``:key: value`` lines or a ``---`` YAML block, then the body."""
    opts: dict = {}
    if lines and lines[0].strip() == "---":
        try:
            close = next(i for i in range(1, len(lines)) if lines[i].strip() == "---")
        except StopIteration:
            return opts, lines
        import yaml

        opts = yaml.safe_load("\n".join(lines[1:close])) or {}
        return (opts if isinstance(opts, dict) else {}), lines[close + 1:]
    i = 0
    while i < len(lines):
        m = _OPTION.match(lines[i].strip()) if lines[i].startswith(":") else None
        if not m:
            break
        opts[m.group("key")] = m.group("value")
        i += 1
    return opts, lines[i:]


def _front_matter_end(lines: list[str]) -> int:
    """Index of the first line after a jupytext/YAML front matter (0 when there is none)."""
    if lines and lines[0].strip() == "---":
        for i in range(1, len(lines)):
            if lines[i].strip() == "---":
                return i + 1
    return 0


def fences(lines: list[str], where: str = "<text>") -> list[Fence]:
    """The top-level fenced blocks of a MyST document, with CommonMark's closing rule."""
    out: list[Fence] = []
    i = _front_matter_end(lines)
    while i < len(lines):
        m = _OPEN.match(lines[i])
        if not m or (m.group("fence")[0] == "`" and "`" in m.group("info")):
            i += 1
            continue
        char, size = m.group("fence")[0], len(m.group("fence"))
        close = re.compile(r"^ {0,3}" + re.escape(char) + "{" + str(size) + r",}\s*$")
        j = next((k for k in range(i + 1, len(lines)) if close.match(lines[k])), None)
        if j is None:
            raise FormatError(f"{where}:{i + 1}: the fence {m.group('fence')}{m.group('info')} is never closed")
        d = _DIRECTIVE.match(m.group("info").strip())
        opts, body = _options_and_body(lines[i + 1:j]) if d else ({}, lines[i + 1:j])
        out.append(Fence(i, j, d.group("name") if d else None, d.group("arg") if d else m.group("info").strip(),
                         opts, body))
        i = j + 1
    return out


def _code_fences_in(body: list[str]) -> list[str]:
    """Fenced code blocks (```python, ```{code} ...) inside a directive's body: shown, never executed."""
    shown = []
    for f in fences(body):
        if f.directive in (None, "code", "code-block", "sourcecode") and not (f.directive is None and f.argument == ""
                                                                           and not f.body):
            shown.append("\n".join(f.body))
    return shown


def parse(path_or_text, name: str | None = None) -> Chapter:
    """Read a chapter (a path, or its text with ``name`` for messages) in the fixed format."""
    if isinstance(path_or_text, Path):
        path, text = path_or_text, path_or_text.read_text(encoding="utf-8")
    else:
        path, text = Path(name or "<text>"), str(path_or_text)
    where = str(path)
    lines = text.split("\n")
    blocks = fences(lines, where)
    exercises: list[Exercise] = []
    solutions: list[Solution] = []
    gated: Solution | None = None
    for f in blocks:
        if f.directive in ("exercise", "exercise-start"):
            if gated:
                raise FormatError(f"{where}:{f.start + 1}: an exercise inside the solution of {gated.label!r}")
            label = str(f.options.get("label", "")).strip()
            if not label:
                raise FormatError(f"{where}:{f.start + 1}: an {{{f.directive}}} without a :label:")
            exercises.append(Exercise(label, f.start, f.end, f.body))
        elif f.directive in ("solution", "solution-start"):
            if gated:
                raise FormatError(f"{where}:{f.start + 1}: a solution inside the solution of {gated.label!r} "
                                  f"(started at line {gated.start + 1}; missing its solution-end?)")
            if not f.argument:
                raise FormatError(f"{where}:{f.start + 1}: {{{f.directive}}} needs the exercise's label as argument")
            if "dropdown" not in str(f.options.get("class", "")).split():
                raise FormatError(f"{where}:{f.start + 1}: the solution of {f.argument!r} needs :class: dropdown")
            sol = Solution(f.argument, "plain" if f.directive == "solution" else "gated", f.start, f.end)
            if f.directive == "solution":
                sol.prose = [ln for ln in f.body]
                sol.code_in_prose = _code_fences_in(f.body)
                solutions.append(sol)
            else:
                if f.body and any(ln.strip() for ln in f.body):
                    raise FormatError(f"{where}:{f.start + 1}: solution-start takes no content; write the solution "
                                      "after its closing fence")
                gated = sol
                prose_from = f.end + 1
        elif f.directive == "solution-end":
            if not gated:
                raise FormatError(f"{where}:{f.start + 1}: solution-end without a solution-start")
            gated.prose.extend(lines[prose_from:f.start])
            gated.end = f.end
            solutions.append(gated)
            gated = None
        elif gated is not None:
            gated.prose.extend(lines[prose_from:f.start])
            prose_from = f.end + 1
            if f.directive == "code-cell":
                gated.code.append("\n".join(f.body).strip("\n"))
            else:
                gated.code_in_prose.extend(_code_fences_in(lines[f.start:f.end + 1]))
    if gated:
        raise FormatError(f"{where}:{gated.start + 1}: solution-start {gated.label!r} has no solution-end")
    labels = [e.label for e in exercises]
    for lab in {x for x in labels if labels.count(x) > 1}:
        raise FormatError(f"{where}: two exercises with the label {lab!r}")
    seen: set[str] = set()
    for s in solutions:
        if s.label not in labels:
            raise FormatError(f"{where}:{s.start + 1}: a solution for {s.label!r}, which no exercise has "
                              f"(exercises: {labels})")
        if s.label in seen:
            raise FormatError(f"{where}:{s.start + 1}: a second solution for {s.label!r}")
        seen.add(s.label)
    # the prose of a solution is what remains once its fences' own lines are gone
    for s in solutions:
        s.prose = [ln for ln in s.prose if ln.strip() and ln.strip() != "+++" and not ln.startswith("+++ ")]
    return Chapter(path, lines, blocks, exercises, solutions)


def strip_solutions(text: str, name: str = "<text>") -> str:
    """The chapter's text without its solutions (both forms), everything else unchanged."""
    ch = parse(text, name)
    drop = set()
    for s in ch.solutions:
        drop.update(range(s.start, s.end + 1))
    return "\n".join(ln for i, ln in enumerate(ch.lines) if i not in drop)
