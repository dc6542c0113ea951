"""A chapter as a plain Jupyter notebook that shows what the book's page shows.

The book's chapters are MyST notebooks: their Markdown quotes computed numbers as
``{eval}`glued("key", "fmt")```, refers to theorems, equations, sections and papers with
roles (``{prf:ref}``, ``{eq}``, ``{ref}``, ``{numref}``, ``{cite:t}``, ``{py:func}``, ...) and
sets statements in directives (```` ```{prf:lemma} ````). Only JupyterLab with jupyterlab-myst
reads them; Jupyter Notebook 7, JupyterLab without extensions, VS Code and Colab show them raw.

:func:`reader_notebook` turns a chapter into what every front end reads, from what the book's
build knows (:class:`Resolved`: the executed chapter's glued values, the numbers and titles
Sphinx gave to every label, the bibliography):

* every role becomes text: a quoted number its value, formatted as the HTML formats it; a
  reference the text the HTML shows ("Lemma 2", "(3)", a section's title); a citation
  "Author (year)" or "(Author, year)"; an API name inline code;
* every directive becomes Markdown: a statement a bold title and its body, a display
  equation with a label its number (``\\tag``), the bibliography the list of the works cited;
  labels ``(name)=`` and comments ``% ...`` are dropped;
* the code cells are the ones the reader sees on the page: a cell tagged ``remove-cell`` (the
  build's checks of the text's claims, its glued numbers, its size switches) is left out, and
  the names ``claim``, ``glue`` and ``glued`` leave the visible imports.

Code blocks in the Markdown are copied as they are.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Callable

import nbformat

HIDDEN = "remove-cell"
BUILD_NAMES = ("claim", "glue", "glued")

# a role, or inline code (left as it is): read left to right, so a role's backticks never pair with code's
ROLE = re.compile(r"\{(?P<role>[A-Za-z][\w:.+-]*)\}`(?P<text>[^`]+)`|(?P<code>`[^`]+`)")
EXPLICIT = re.compile(r"^(?P<title>.*?)\s*<(?P<target>[^<>]+)>\s*$", re.S)
FENCE = re.compile(r"^(?P<indent>\s*)(?P<fence>`{3,}|:{3,}|~{3,})\s*(?P<info>.*)$")
DIRECTIVE = re.compile(r"^\{(?P<name>[\w:.+-]+)\}\s*(?P<arg>.*)$")
OPTION = re.compile(r"^\s*:(?P<key>[\w-]+):\s*(?P<value>.*)$")
TARGET = re.compile(r"^\s*\((?P<label>[^()\s]+)\)=\s*$")
COMMENT = re.compile(r"^\s*%")
LABELLED_MATH = re.compile(r"\$\$[ \t]*\((?P<label>[^()\s]+)\)")
GLUED = re.compile(r"""^\s*glued\(\s*(["'])(?P<key>[^"']+)\1\s*(?:,\s*(["'])(?P<fmt>[^"']*)\3\s*)?\)\s*$""")

#: directives whose title is the name's last part, capitalised (``prf:lemma`` -> "Lemma")
ADMONITIONS = {"note", "tip", "hint", "important", "warning", "caution", "attention", "danger",
               "error", "seealso", "admonition", "dropdown", "topic", "sidebar", "margin"}


@dataclass
class Resolved:
    """What the book's build knows about one chapter, for :func:`reader_notebook`.

    Attributes
    ----------
    glued : dict
        ``key -> text/plain`` of each value the executed chapter glued.
    xref : callable
        ``xref(role, target, title)``: the text the HTML shows for a reference (``role`` one of
        ``ref``, ``numref``, ``eq``, ``doc``, ``prf:ref``, ...), or None when unknown.
    number : callable
        ``number(kind, label)``: the number Sphinx gave a numbered directive or equation
        (``kind`` ``"displaymath"`` for an equation, else the directive's name), or "".
    cite : callable
        ``cite(keys, textual)``: "Author (year)" (``textual``) or "(Author, year; ...)".
    bibliography : callable
        ``bibliography(keys)``: a Markdown list of the works with these keys.
    """

    glued: dict = field(default_factory=dict)
    xref: Callable[[str, str, str | None], str | None] = lambda role, target, title: None
    number: Callable[[str, str], str] = lambda kind, label: ""
    cite: Callable[[list[str], bool], str] = lambda keys, textual: ", ".join(keys)
    bibliography: Callable[[list[str]], str] = lambda keys: "\n".join(f"* {k}" for k in keys)


class UnresolvedError(ValueError):
    """A role or directive of the chapter that the build's data cannot turn into text."""


def format_glued(text_plain: str, fmt: str) -> str:
    """A glued value's ``text/plain`` formatted with ``fmt`` as the book's ``{glue:text}`` does
    (the value's literal, then ``format(value, fmt)``; the bare text when ``fmt`` is empty)."""
    from ast import literal_eval

    try:
        value = literal_eval(text_plain)
    except (SyntaxError, ValueError):
        value = text_plain
    if not fmt:
        return str(value)
    kind = fmt[-1]
    if kind == "s":
        value = str(value)
    elif kind in "bcdoxX":
        value = int(value)
    elif kind in "eEfFgGn%":
        value = float(value)
    return format(value, fmt)


def _split_explicit(text: str) -> tuple[str | None, str]:
    m = EXPLICIT.match(text)
    if m and m.group("title").strip():
        return " ".join(m.group("title").split()), m.group("target").strip()
    return None, " ".join(text.split())


class _Renderer:
    def __init__(self, resolved: Resolved, keyprefix: str):
        self.r = resolved
        self.keyprefix = keyprefix
        self.cited: list[str] = []
        self.exercises = 0
        self.exercise_numbers: dict[str, int] = {}

    # ------------------------------------------------------------------ roles
    def role(self, m: re.Match) -> str:
        if m.group("code"):
            return m.group("code")
        role, text = m.group("role"), m.group("text")
        if role == "eval":
            g = GLUED.match(text)
            if g is None:
                raise UnresolvedError(f"inline expression {text!r} is not glued(\"key\", \"fmt\")")
            key, fmt = g.group("key"), g.group("fmt") or ""
            if key not in self.r.glued:
                raise UnresolvedError(f"the executed chapter glued no value {key!r}")
            return format_glued(self.r.glued[key], fmt)
        if role.startswith("cite"):
            keys = [self._bibkey(k) for k in text.split(",") if k.strip()]
            self.cited += [k for k in keys if k not in self.cited]
            return self.r.cite(keys, role in ("cite:t", "cite:ts", "cite:ct", "cite:cts"))
        if role == "math":
            return f"${text}$"
        title, target = _split_explicit(text)
        if role.startswith("py:") or role in ("func", "class", "meth", "mod", "attr", "obj", "data"):
            shown = title or target.lstrip("~").rsplit(".", 1)[-1] if target.startswith("~") else title or target
            if title is None and role.endswith(("func", "meth")):
                shown += "()"
            return f"`{shown}`"
        if role in ("ref", "numref", "eq", "doc", "prf:ref", "term", "any") or ":" in role:
            resolved = self.r.xref(role, target, title)
            if resolved is not None:   # a section's or page's title in italics, as a link's text reads
                return f"*{resolved}*" if role in ("ref", "doc") and title is None else resolved
            if title is not None:
                return title
            raise UnresolvedError(f"{{{role}}}`{text}`: no such target in the book")
        return title or target        # abbr, sub, download, ...: their text

    def inline(self, text: str) -> str:
        text = ROLE.sub(self.role, text)
        return LABELLED_MATH.sub(self._tag, text)

    def _tag(self, m: re.Match) -> str:
        number = self.r.number("displaymath", m.group("label"))
        return f"\\tag{{{number}}}\n$$" if number else "$$"

    def _bibkey(self, key: str) -> str:
        key = key.strip()
        return key[len(self.keyprefix):] if self.keyprefix and key.startswith(self.keyprefix) else key

    # ------------------------------------------------------------------ blocks
    def blocks(self, lines: list[str]) -> list[str]:
        out: list[str] = []
        para: list[str] = []

        def flush():
            if para:
                out.extend(self.inline("\n".join(para)).split("\n"))
                para.clear()

        i = 0
        while i < len(lines):
            line = lines[i]
            fence = FENCE.match(line)
            if fence:
                char, n = fence.group("fence")[0], len(fence.group("fence"))
                close = re.compile(rf"^\s*{re.escape(char)}{{{n},}}\s*$")
                j = i + 1
                while j < len(lines) and not close.match(lines[j]):
                    j += 1
                body = lines[i + 1:j]
                flush()
                d = DIRECTIVE.match(fence.group("info").strip())
                if d:
                    out.extend(self.directive(d.group("name"), d.group("arg").strip(), body))
                else:
                    out.extend(lines[i:j + 1])   # a code block, as it is
                i = j + 1
                continue
            if TARGET.match(line) or COMMENT.match(line):
                i += 1
                continue
            para.append(line)
            i += 1
        flush()
        return out

    def directive(self, name: str, arg: str, body: list[str]) -> list[str]:
        options: dict[str, str] = {}
        if body and body[0].strip() == "---" and "---" in [b.strip() for b in body[1:]]:
            end = 1 + [b.strip() for b in body[1:]].index("---")
            for opt in body[1:end]:
                if ":" in opt:
                    k, v = opt.split(":", 1)
                    options[k.strip()] = v.strip()
            body = body[end + 1:]
        else:
            while body and OPTION.match(body[0]):
                m = OPTION.match(body[0])
                options[m.group("key")] = m.group("value").strip()
                body = body[1:]
        label = options.get("label", "")
        inner = self.blocks(body)
        kind = name.split(":")[-1]
        if name in ("bibliography",):
            if options.get("keyprefix") is not None and not self.keyprefix:
                self.keyprefix = options["keyprefix"]
            return [self.r.bibliography(self.cited)] if self.cited else []
        if name in ("math",):
            tag = self.r.number("displaymath", label) if label else ""
            return ["$$", *inner, *([f"\\tag{{{tag}}}"] if tag else []), "$$"]
        if name in ("solution-end",):
            return []
        if name in ("exercise", "exercise-start"):
            self.exercises += 1
            number = self.r.number("exercise", label) or str(self.exercises)
            if label:
                self.exercise_numbers[label] = int(number) if number.isdigit() else self.exercises
            head = f"**Exercise {number}**" + (f" ({self.inline(arg)})" if arg else "")
            return [head, "", *inner]
        if name in ("solution", "solution-start"):
            target = arg.split()[0] if arg else ""
            number = self.exercise_numbers.get(target) or self.r.number("exercise", target)
            return [f"**Solution to Exercise {number}**" if number else "**Solution**", "", *inner]
        if name.startswith("prf:"):
            title = kind.capitalize()
            if kind != "proof" and "nonumber" not in options and label:
                number = self.r.number(kind, label)
                title += f" {number}" if number else ""
            head = f"**{title}.**" if kind == "proof" else f"**{title}**"
            head += f" ({self.inline(arg)})" if arg else ""
            return [head, "", *inner, *(["", "$\\blacksquare$"] if kind == "proof" else [])]
        if kind in ADMONITIONS or name in ADMONITIONS:
            title = self.inline(arg) if arg and name in ("admonition", "dropdown", "topic", "sidebar") else kind.capitalize()
            return ["> **" + title + "**", ">", *[f"> {x}" if x.strip() else ">" for x in inner]]
        # any other directive: its name and argument as a title, then its body
        head = f"**{kind.replace('-', ' ').capitalize()}**" + (f" ({self.inline(arg)})" if arg else "")
        return [head, "", *inner] if inner else ([head] if arg else [])


def _keyprefix(markdown: str) -> str:
    m = re.search(r"^\s*:keyprefix:\s*(\S+)\s*$", markdown, re.M)
    return m.group(1) if m else ""


def portable_source(code: str) -> str:
    """A visible code cell as the download holds it: ``claim``, ``glue`` and ``glued`` (the
    build's names) left out of its ``from orrc.viz import ...`` / ``from myst_nb import ...``
    lines (a line left with nothing to import, and a comment that only explained them, goes)."""
    lines = []
    for line in code.split("\n"):
        m = re.match(r"^(\s*)from (orrc\.viz|myst_nb) import ([\w, ]+?)\s*(#.*)?$", line)
        if m:
            names = [n.strip() for n in m.group(3).split(",") if n.strip()]
            kept = [n for n in names if n not in BUILD_NAMES]
            if kept != names:
                if not kept:
                    continue
                line = f"{m.group(1)}from {m.group(2)} import {', '.join(kept)}"
        lines.append(line)
    return "\n".join(lines)


#: the roles that a front end reading one notebook, with no bibliography, cannot resolve (JupyterLab
#: with jupyterlab-myst): citations, references to other pages' targets, API names
LAB_ROLES = re.compile(r"^(cite(:\w+)?|ref|numref|doc|eq|prf:ref|py:\w+)$")


def role_texts(nb: nbformat.NotebookNode, resolved: Resolved) -> dict[str, str]:
    """``{role as written: the text the HTML shows}`` for every citation, reference and API role
    (:data:`LAB_ROLES`) in the Markdown cells of the chapter ``nb``, outside code blocks; a role that
    ``resolved`` cannot turn into text is left out. ``make lab`` shows these texts
    (tools/lab_contents.py)."""
    markdown = "\n".join(c.source for c in nb.cells if c.cell_type == "markdown")
    renderer = _Renderer(resolved, _keyprefix(markdown))
    out = {}
    for m in ROLE.finditer(CODE_BLOCK.sub("", markdown)):
        if m.group("role") and LAB_ROLES.match(m.group("role")) and m.group(0) not in out:
            try:
                out[m.group(0)] = renderer.role(m)
            except UnresolvedError:
                continue
    return out


def reader_cells(nb: nbformat.NotebookNode) -> list[nbformat.NotebookNode]:
    """The cells a reader sees on the page, in order: Markdown, and the code cells not tagged
    ``remove-cell``."""
    return [c for c in nb.cells if c.cell_type != "code" or HIDDEN not in c.metadata.get("tags", [])]


def reader_notebook(nb: nbformat.NotebookNode, resolved: Resolved) -> nbformat.NotebookNode:
    """The chapter ``nb`` (read from its MyST source, no outputs) as a plain notebook: Markdown
    with every role and directive turned into text (see the module's docstring), the code cells a
    reader sees, their sources made portable (:func:`portable_source`). Raises
    :class:`UnresolvedError` naming the first role that ``resolved`` cannot turn into text."""
    markdown = "\n".join(c.source for c in nb.cells if c.cell_type == "markdown")
    renderer = _Renderer(resolved, _keyprefix(markdown))
    cells = []
    for cell in reader_cells(nb):
        if cell.cell_type == "markdown":
            text = "\n".join(renderer.blocks(cell.source.split("\n"))).strip("\n")
            text = re.sub(r"\n{3,}", "\n\n", text)
            if text.strip():
                cells.append(nbformat.v4.new_markdown_cell(text))
        elif cell.cell_type == "code":
            tags = [t for t in cell.metadata.get("tags", []) if t.startswith(("hide-", "remove-output"))]
            new = nbformat.v4.new_code_cell(portable_source(cell.source))
            if tags:
                new.metadata["tags"] = tags
            cells.append(new)
        else:
            cells.append(cell)
    out = nbformat.v4.new_notebook(cells=cells, metadata=dict(nb.metadata))
    out.metadata.pop("jupytext", None)
    return out


RAW_ROLES = re.compile(r"^(eval|prf:[\w-]+|cite(:\w+)?|numref|eq|ref|py:\w+|doc)$")
RAW_DIRECTIVE = re.compile(r"^\s*(`{3,}|:{3,})\{[\w:.+-]+\}", re.M)


CODE_BLOCK = re.compile(r"^(\s*)(`{3,}|~{3,})(?![^\n]*\{)[^\n]*\n.*?^\1\2\s*$", re.M | re.S)


def raw_markup(nb: nbformat.NotebookNode) -> list[str]:
    """Every MyST role or directive left in the Markdown cells of ``nb`` (with 20 characters
    around it), outside code blocks and inline code: what a front end without jupyterlab-myst
    would show raw."""
    found = []
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            text = CODE_BLOCK.sub("", cell.source)
            spots = [m for m in ROLE.finditer(text) if m.group("role") and RAW_ROLES.match(m.group("role"))]
            spots += list(RAW_DIRECTIVE.finditer(text))
            for m in spots:
                found.append(text[max(0, m.start() - 20):m.end() + 20].replace("\n", " "))
    return found
