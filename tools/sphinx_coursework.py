"""A small Sphinx extension for the instructor's guide (``book/instructors.md``), loaded by ``_config.yml``.

Every number the guide gives about a chapter or an assignment is computed when the book is
built, never typed:

* ``{chapter}`book/lemma1``` -- a link to the chapter (its title), or, with ``Title <book/x>``,
  the title and "(in preparation)" while ``book/x`` is not yet a page of the book: a chapter
  being written elsewhere becomes a link by itself once it is in ``_toc.yml``;
* ``{runtime}`book/lemma1``` -- how long the chapter took to execute in this build (MyST-NB's
  execution data, the numbers of the execution-times page), "—" for a page not in the book;
* ``{readtime}`book/lemma1``` -- reading time: the words of the chapter outside its code cells
  at :data:`WORDS_PER_MINUTE`, rounded up to 5 minutes;
* ``{assignment-guide} NAME`` -- what ``assignments/NAME/NAME.md`` says about itself (chapters
  needed, as paths or ``Title <path>``, and the expected student time, from its metadata) and
  what its autograder checks: its questions, with the points, and the public and hidden tests
  with the message each shows when it fails (read by :func:`tools.assignments.read_assignment`). The folder is
  ``coursework_assignments`` (config value, relative to the book's root), so the
  solution-free edition, built from a copy without the assignments, reads the original.
"""
from __future__ import annotations

import math
import re
import sys
from pathlib import Path

from docutils import nodes
from sphinx.addnodes import pending_xref
from sphinx.application import Sphinx
from sphinx.transforms.post_transforms import SphinxPostTransform
from sphinx.util.docutils import SphinxDirective

# tools/ is loaded as a local extension folder; its siblings are imported as the package ``tools``
if str(Path(__file__).resolve().parents[1]) not in sys.path:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

WORDS_PER_MINUTE = 60  # careful reading of mathematical prose, with the formulas followed
_TARGET = re.compile(r"^(?:(?P<title>.*?)\s*<(?P<target>[^<>]+)>|(?P<bare>[^<>]+))$")


class coursework_ref(nodes.Inline, nodes.TextElement):
    """Placeholder for a chapter link, run time or reading time, resolved once every page is read."""


def _role(kind):
    def role(name, rawtext, text, lineno, inliner, options=None, content=None):
        m = _TARGET.match(text.strip())
        target = (m.group("target") or m.group("bare")).strip().lstrip("/") if m else text.strip()
        title = (m.group("title") or "").strip() if m else ""
        node = coursework_ref(rawtext, "", kind=kind, target=re.sub(r"\.(md|ipynb)$", "", target), title=title)
        return [node], []
    return role


def _words(path: Path) -> int:
    """Words of a MyST page outside its front matter and code cells (the prose a reader reads)."""
    from tools.solutions import fences

    lines = path.read_text(encoding="utf-8").split("\n")
    drop = set()
    if lines and lines[0].strip() == "---":
        drop.update(range(0, next((i for i in range(1, len(lines)) if lines[i].strip() == "---"), 0) + 1))
    for f in fences(lines):
        if f.directive in ("code-cell", "raw-cell"):
            drop.update(range(f.start, f.end + 1))
    text = " ".join(ln for i, ln in enumerate(lines) if i not in drop)
    return len(re.findall(r"[A-Za-z][A-Za-z'-]*", text))


def reading_minutes(path: Path) -> int:
    return max(5, 5 * math.ceil(_words(path) / WORDS_PER_MINUTE / 5))


def _runtime(env, docname: str):
    from myst_nb.sphinx_ import NbMetadataCollector

    if docname not in env.all_docs:
        return None
    data = NbMetadataCollector.get_exec_data(env, docname)
    return None if not data or data.get("runtime") is None else float(data["runtime"])


def _format_seconds(s: float) -> str:
    return f"{s:.0f} s" if s >= 10 else f"{s:.1f} s"


class ResolveCoursework(SphinxPostTransform):
    """Turn the placeholders into links and numbers (before references are resolved)."""

    default_priority = 8

    def run(self, **kwargs) -> None:
        env = self.env
        for node in list(self.document.findall(coursework_ref)):
            kind, target, title = node["kind"], node["target"], node["title"]
            present = target in env.all_docs
            if kind == "chapter":
                if present:
                    ref = pending_xref("", refdomain="std", reftype="doc", reftarget="/" + target,
                                       refdoc=env.docname, refexplicit=False, refwarn=True)  # the page's own title
                    ref += nodes.inline("", title or target)
                    new = ref
                else:
                    new = nodes.inline("", f"{title or target} (in preparation)")
            elif kind == "runtime":
                seconds = _runtime(env, target)
                new = nodes.Text("—" if seconds is None else _format_seconds(seconds))
            else:  # readtime
                path = Path(env.doc2path(target)) if present else None
                new = nodes.Text("—" if path is None or not path.is_file() else f"{reading_minutes(path)} min")
            node.replace_self(new)


class AssignmentGuide(SphinxDirective):
    """``{assignment-guide} NAME``: the chapters, time and autograder checks of one assignment."""

    required_arguments = 1
    has_content = False

    def run(self):
        from tools.assignments import read_assignment

        name = self.arguments[0].strip()
        folder = Path(self.config.coursework_assignments)
        if not folder.is_absolute():
            folder = Path(self.env.app.confdir) / folder
        src = folder / name / f"{name}.md"
        if not src.is_file():
            raise self.error(f"assignment-guide: no assignment source {src}")
        self.env.note_dependency(str(src))
        a = read_assignment(src)
        para = nodes.paragraph()
        para += nodes.strong(text="Chapters it needs: ")
        for i, ch in enumerate(a["chapters"]):
            if i:
                para += nodes.Text(", ")
            para += coursework_ref("", "", kind="chapter", target=ch, title=a["chapter_titles"].get(ch, ""))
        para += nodes.Text(". ")
        para += nodes.strong(text="Expected student time: ")
        para += nodes.Text(f"{a['minutes']} minutes. ")
        para += nodes.strong(text="Points: ")
        para += nodes.Text(f"{a['points']:g}, in {len(a['questions'])} questions "
                           f"({sum(len(q['tests']) for q in a['questions'])} tests, "
                           f"{sum(t['hidden'] for q in a['questions'] for t in q['tests'])} of them hidden)"
                           + (f", and {a['manual_points']:g} points graded by hand." if a["manual_points"] else "."))
        questions = nodes.bullet_list()
        for q in a["questions"]:
            item = nodes.list_item()
            head = nodes.paragraph()
            head += nodes.literal(text=q["name"])
            head += nodes.Text(f", {q['manual_points']:g} points, a written answer graded by hand" if q["manual"]
                               else f", {sum(t['points'] for t in q['tests']):g} points")
            item += head
            tests = nodes.bullet_list()
            for t in q["tests"]:
                entry = nodes.paragraph()
                entry += nodes.emphasis(text=f"{'hidden' if t['hidden'] else 'public'} test, {t['points']:g} "
                                             f"point{'s' if t['points'] != 1 else ''}")
                entry += nodes.Text(f"; its message when it fails: {t['checks']}")
                tests += nodes.list_item("", entry)
            item += tests
            questions += item
        return [para, questions]


def setup(app: Sphinx) -> dict:
    app.add_config_value("coursework_assignments", "assignments", "env")
    app.add_node(coursework_ref)
    for kind in ("chapter", "runtime", "readtime"):
        app.add_role(kind, _role(kind))
    app.add_directive("assignment-guide", AssignmentGuide)
    app.add_post_transform(ResolveCoursework)
    # the guide's run times come from every other page: rebuild it whenever anything is rebuilt
    app.connect("env-get-outdated", lambda app, env, added, changed, removed:
                [d for d in env.all_docs if d.endswith("instructors")] if (added or changed) else [])
    return {"version": "0.1", "parallel_read_safe": True, "parallel_write_safe": True}
