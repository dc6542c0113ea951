"""The shape of a chapter, measured: the words of its main path and of its whole page, its
from-scratch comparison, its main figure and where "Reading the paper critically" stands.

A chapter teaches first and checks after (the book's appendix on how it is built says why):
the question and a first experiment, the idea, the statement, the computation from scratch, the
same with ``orrc`` shown equal, an explorer, the proof sketch, "Reading the paper critically",
exercises. Two sizes are counted:

* the **main path**: the words of the Markdown prose a reader follows, without display or inline
  math, code, dropdowns (directives with ``:class: dropdown``, solutions) and the sections headed
  "Going deeper ...", "Reading the paper critically", "Exercises" and "References";
* the **page**: every word a reader of the rendered page can see: all the Markdown (math aside),
  the code of every cell not tagged ``remove-cell`` or ``remove-input``, and the text outputs of
  the executed notebook (streams and plain-text results that are not the caption of an image).

Used by ``tests/test_teaching_shape.py`` and by ``python -m tools.run_chapter``.
"""
from __future__ import annotations

import re

#: about 2,000 words of main path and 4,500 of page: "about" is these limits
MAIN_PATH_MAX = 2100
PAGE_MAX = 4700
#: the line a chapter prints when it compares its from-scratch computation with orrc's
SCRATCH_LINE = re.compile(r"largest difference, from scratch vs orrc: (\S+)")
SCRATCH_TOLERANCE = 1e-8
CRITICAL = "Reading the paper critically"
#: headings whose sections are not on the main path (compared case-insensitively, by prefix)
OFF_PATH = ("going deeper", CRITICAL.lower(), "exercises", "references")
#: headings that may follow "Reading the paper critically"
AFTER_CRITICAL = ("exercises", "references")
HIDDEN_TAGS = {"remove-cell", "remove-input"}

_WORD = re.compile(r"[A-Za-z0-9][A-Za-z0-9'’\-]*")
_FENCE = re.compile(r"^(\s*)(`{3,}|:{3,})\s*(\{[^}]*\})?(.*)$")
_HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*$")
_ROLE = re.compile(r"\{[\w:.-]+\}`([^`]*)`")
_DISPLAY_MATH = re.compile(r"\$\$.*?\$\$", re.S)
_INLINE_MATH = re.compile(r"(?<!\\)\$[^$\n]+?\$")
_INLINE_CODE = re.compile(r"`[^`\n]*`")
_COMMENT = re.compile(r"<!--.*?-->", re.S)
_LABEL = re.compile(r"^\s*\([\w:-]+\)=\s*$", re.M)
_OPTION = re.compile(r"^\s*:[\w-]+:.*$", re.M)


def words(text: str) -> int:
    """The number of words of ``text`` (tokens that start with a letter or a digit)."""
    return len(_WORD.findall(text))


def _role_text(match: re.Match) -> str:
    """What a role shows: its title (``{ref}`the title <label>``` shows "the title"), its target
    otherwise; a glued number counts as one word."""
    body = match.group(1)
    if "glued(" in body:
        return "0"
    return re.sub(r"<[^>]*>", "", body) if "<" in body else body


def prose(text: str) -> str:
    """Markdown without what is not prose: comments, labels, directive options, math and code."""
    text = _COMMENT.sub(" ", text)
    text = _LABEL.sub(" ", text)
    text = _OPTION.sub(" ", text)
    text = _DISPLAY_MATH.sub(" ", text)
    text = _ROLE.sub(_role_text, text)
    text = _INLINE_MATH.sub(" ", text)
    text = _INLINE_CODE.sub(" ", text)
    return text


def _strip_blocks(markdown: str, *, main_path: bool) -> str:
    """The Markdown of a page with its off-path blocks removed (``main_path``) or with only math
    and code blocks removed (the whole page): fenced blocks are tracked by their fence."""
    out: list[str] = []
    stack: list[tuple[str, bool]] = []   # (fence, dropped) of the open fenced blocks
    in_solution = False                  # between {solution-start} and {solution-end}
    off_level = 0                        # the level of an off-path heading we are under (0: none)
    lines = markdown.splitlines()
    for i, line in enumerate(lines):
        fence = _FENCE.match(line)
        if stack and fence and fence.group(2).startswith(stack[-1][0][0]) \
                and len(fence.group(2)) >= len(stack[-1][0]) and not fence.group(3) and not fence.group(4).strip():
            stack.pop()
            continue
        if fence and fence.group(3):
            name = fence.group(3).strip("{}")
            if name == "solution-start":
                in_solution = True
            if name == "solution-end":
                in_solution = False
            options = "\n".join(lines[i + 1:i + 8])
            dropdown = ":class: dropdown" in options or name in ("dropdown", "solution")
            dropped = name in ("math", "code-cell", "code") or (main_path and dropdown)
            stack.append((fence.group(2), dropped))
            continue
        if fence and not fence.group(3) and fence.group(2).startswith("`"):
            stack.append((fence.group(2), True))   # a plain code block
            continue
        if any(d for _, d in stack) or (main_path and in_solution):
            continue
        heading = _HEADING.match(line) if not stack else None
        if heading and main_path:
            level, title = len(heading.group(1)), heading.group(2).lower()
            if off_level and level <= off_level:
                off_level = 0
            if not off_level and title.startswith(OFF_PATH):
                off_level = level
        if main_path and off_level:
            continue
        out.append(line)
    return "\n".join(out)


def markdown_of(nb) -> str:
    return "\n\n".join(c.source for c in nb.cells if c.cell_type == "markdown")


def main_path_words(nb) -> int:
    """The words of the main path of a notebook (a jupytext or executed notebook)."""
    return words(prose(_strip_blocks(markdown_of(nb), main_path=True)))


def is_hidden(cell) -> bool:
    return bool(set(cell.get("metadata", {}).get("tags", [])) & HIDDEN_TAGS)


def _output_text(out) -> str:
    if out.get("output_type") == "stream":
        return out.get("text", "")
    data = out.get("data", {})
    if any(k.startswith("image/") or k == "text/html" for k in data):
        return ""
    return data.get("text/plain", "") if isinstance(data.get("text/plain", ""), str) else "".join(data["text/plain"])


def page_words(executed) -> int:
    """The words a reader sees on the rendered page of an executed notebook."""
    n = words(prose(_strip_blocks(markdown_of(executed), main_path=False)))
    for cell in executed.cells:
        if cell.cell_type != "code" or is_hidden(cell):
            continue
        n += words(cell.source)
        tags = set(cell.get("metadata", {}).get("tags", []))
        if "remove-output" not in tags:
            n += sum(words(_output_text(o)) for o in cell.get("outputs", []))
    return n


def scratch_differences(executed) -> list[float]:
    """Every difference a page prints between its from-scratch computation and orrc's."""
    found = []
    for cell in executed.cells:
        for out in cell.get("outputs", []) if cell.cell_type == "code" else []:
            for m in SCRATCH_LINE.finditer(_output_text(out) if out.get("output_type") == "stream" else ""):
                try:
                    found.append(float(m.group(1)))
                except ValueError:
                    found.append(float("nan"))
    return found


def headings(nb) -> list[tuple[int, str]]:
    """The headings of a notebook's Markdown outside fenced blocks: (level, title)."""
    text = _strip_blocks(markdown_of(nb), main_path=False)
    return [(len(m.group(1)), m.group(2)) for m in map(_HEADING.match, text.splitlines()) if m]


def critical_section_problems(nb) -> list[str]:
    """Why the page's "Reading the paper critically" is missing or not at the end of its main
    path (only exercises and references may follow it); empty when it is where it belongs."""
    hs = headings(nb)
    at = [i for i, (_, t) in enumerate(hs) if t.strip().lower() == CRITICAL.lower()]
    if not at:
        return [f"no section headed {CRITICAL!r}"]
    level = hs[at[0]][0]
    after = [t for lv, t in hs[at[0] + 1:] if lv <= level and not t.lower().startswith(AFTER_CRITICAL)]
    return [f"{CRITICAL!r} is followed by {after}"] if after else []


def main_figure_cells(nb) -> list:
    """The visible code cells that draw with matplotlib and carry a numbered, captioned figure
    (myst-nb's ``mystnb: figure: {name, caption}`` cell metadata)."""
    found = []
    for cell in nb.cells:
        if cell.cell_type != "code" or is_hidden(cell):
            continue
        fig = cell.get("metadata", {}).get("mystnb", {}).get("figure", {})
        if fig.get("name") and fig.get("caption") and re.search(r"\bplt\.|\bax\w*\.", cell.source):
            found.append(cell)
    return found
