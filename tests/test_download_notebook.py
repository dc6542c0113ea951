"""A chapter's download shows its text as the page does in any Jupyter front end (tools/download.py).

On a small chapter and a stand-in for what the book's build knows (the glued values, the
references' texts, the numbers, the bibliography): every role and directive becomes plain
Markdown, the code cells are the ones the page shows, and what cannot be resolved is named.
The chapters' own downloads are checked on the session's build (tests/test_downloads.py).
"""
import jupytext
import pytest

from tools.download import Resolved, UnresolvedError, portable_source, raw_markup, reader_notebook

CHAPTER = """---
jupytext:
  text_representation:
    extension: .md
    format_name: myst
kernelspec:
  display_name: Python 3
  language: python
  name: python3
---

(sec-start)=
# A chapter

% a comment for the authors
As {cite:t}`x-smith2020` showed {cite:p}`x-smith2020,x-doe2019`, the gap is
{eval}`glued("gap", ".1f")` (see {prf:ref}`lem-a`, {prf:ref}`the lemma <lem-a>`, {eq}`eq-a`,
{ref}`sec-start`, {numref}`fig-a` and {py:func}`orrc.simulate`, {py:class}`Plan <orrc.solvers.Plan>`).

```{prf:lemma} A bound
:label: lem-a

$$
x \\le {eval}`glued("gap")`
$$ (eq-a)
```

```{prf:proof}
Immediate.
```

```{code-cell} ipython3
from orrc.viz import claim, glue, glued, plots   # numbers computed here, quoted in the text
T = 200
```

```{code-cell} ipython3
:tags: [remove-cell]

T = orrc.config.size(T, 20)
glue("gap", 1.25)
claim(True, "it holds")
```

```{code-cell} ipython3
:tags: [hide-input]

print("{eval}`kept as code`")
```

```{note}
A note with `{ref}` written as code.
```

```{exercise}
:label: ex-a

Do it.
```

```{solution-start} ex-a
:class: dropdown
```

Done, {eval}`glued("gap", ".0f")`.

```{solution-end}
```

```{bibliography}
:filter: docname in docnames
:keyprefix: x-
```
"""


def resolved(**changes):
    refs = {("prf:ref", "lem-a", None): "Lemma 3", ("prf:ref", "lem-a", "the lemma"): "the lemma",
            ("eq", "eq-a", None): "(2)", ("ref", "sec-start", None): "A chapter",
            ("numref", "fig-a", None): "Fig. 4"}
    numbers = {("displaymath", "eq-a"): "2", ("lemma", "lem-a"): "3"}
    base = dict(glued={"gap": "1.2500001"},
                xref=lambda role, target, title: refs.get((role, target, title)),
                number=lambda kind, label: numbers.get((kind, label), ""),
                cite=lambda keys, textual: ("Smith (2020)" if textual else f"(cited: {'; '.join(keys)})"),
                bibliography=lambda keys: "**References**\n\n" + "\n".join(f"* {k}" for k in keys))
    base.update(changes)
    return Resolved(**base)


def download(**changes):
    return reader_notebook(jupytext.reads(CHAPTER, fmt="md:myst"), resolved(**changes))


def test_every_role_and_directive_becomes_text():
    nb = download()
    md = "\n\n".join(c.source for c in nb.cells if c.cell_type == "markdown")
    assert raw_markup(nb) == [], raw_markup(nb)
    for shown in ("As Smith (2020) showed (cited: smith2020; doe2019)", "the gap is\n1.3 (see Lemma 3, the lemma, (2),",
                  "*A chapter*, Fig. 4 and `orrc.simulate()`, `Plan`", "**Lemma 3** (A bound)", "\\tag{2}\n$$",
                  "x \\le 1.2500001", "**Proof.**", "**Exercise 1**", "**Solution to Exercise 1**", "Done, 1.",
                  "> **Note**", "`{ref}` written as code", "**References**\n\n* smith2020\n* doe2019"):
        assert shown in md, f"{shown!r} not in the Markdown:\n{md}"
    assert "(sec-start)=" not in md and "a comment for the authors" not in md


def test_the_code_cells_are_the_ones_the_page_shows():
    code = [c for c in download().cells if c.cell_type == "code"]
    assert [c.source for c in code] == ["from orrc.viz import plots\nT = 200", 'print("{eval}`kept as code`")']
    assert code[1].metadata["tags"] == ["hide-input"]
    assert portable_source("from orrc.viz import claim, glue, glued\nx = 1") == "x = 1"
    assert portable_source("from myst_nb import glue\nx = 1") == "x = 1"


def test_what_the_build_does_not_know_is_named():
    with pytest.raises(UnresolvedError, match="glued no value 'gap'"):
        download(glued={})
    with pytest.raises(UnresolvedError, match=r"\{eq\}`eq-a`: no such target"):
        download(xref=lambda role, target, title: None if role == "eq" else "x")


def test_raw_markup_finds_what_a_plain_front_end_shows_raw():
    nb = jupytext.reads(CHAPTER, fmt="md:myst")
    found = raw_markup(nb)
    assert any("{eval}`" in f for f in found) and any("{prf:ref}`" in f for f in found)
    assert any("{cite:t}`" in f for f in found) and any("{numref}`" in f for f in found)
