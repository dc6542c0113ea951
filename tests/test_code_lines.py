"""No code line of a chapter is longer than 88 characters: at 1366 px the book's code
column shows about 95 characters, and a longer line is cut off at the right edge (it scrolls, but
the reader does not see that it goes on). Counted in the chapters' MyST sources: every line of a
``{code-cell}`` and of a fenced code block, hidden cells included (a reader opens them in the
``.ipynb`` download and in JupyterLab)."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from tools.toc import toc_pages

ROOT = Path(__file__).resolve().parents[1]
MAX_CHARS = 88
FENCE = re.compile(r"^(`{3,}|~{3,})(.*)$")


def code_lines(text: str) -> list[tuple[int, str]]:
    """(line number, line) of every line inside a fenced block (```{code-cell}, ```python, ...),
    the fences, a code cell's option lines (``:tags:``) and a YAML option block left out."""
    out, fence, options = [], None, False
    for n, line in enumerate(text.split("\n"), 1):
        m = FENCE.match(line.strip())
        if fence is None:
            if m and m.group(2).strip() and not m.group(2).strip().startswith("{") or \
                    m and m.group(2).strip().startswith(("{code-cell}", "{code-block}", "{code}")):
                fence, options = m.group(1), m.group(2).strip().startswith("{")
            continue
        if line.strip() == fence:
            fence = None
            continue
        if options and (line.startswith(":") or line.strip() == "---"):
            continue
        options = False
        out.append((n, line))
    return out


def test_code_lines_are_found():
    text = "x\n```{code-cell} ipython3\n:tags: [remove-cell]\n\na = 1\n```\n```python\nb = 2\n```\n```{note}\nno\n```\n"
    assert code_lines(text) == [(4, ""), (5, "a = 1"), (8, "b = 2")]


@pytest.mark.parametrize("page", [p for p in toc_pages(ROOT) if (ROOT / f"{p}.md").is_file()],
                         ids=lambda p: Path(p).name)
def test_no_code_line_is_longer_than_88_characters(page):
    text = (ROOT / f"{page}.md").read_text(encoding="utf-8")
    long = [(n, len(line)) for n, line in code_lines(text) if len(line) > MAX_CHARS]
    assert not long, (f"{page}.md: {len(long)} code lines over {MAX_CHARS} characters "
                      f"(line: length) {dict(long[:12])}")
