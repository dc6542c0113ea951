"""The solution-free edition (``make book-student``, tools/build_student.py) holds no solution text.

Built once per session at the test size, after the session's normal build (the ``book`` fixture),
whose executed chapters it reuses. Then:

* every solution's distinctive text -- its code lines and runs of plain words of its prose,
  extracted from the chapter sources (tools/solutions.py), minus anything that also occurs
  outside the solutions -- is searched for in every file of the student output tree (pages,
  ``_sources``, ``.ipynb`` downloads, the search index, the executed notebooks, the stripped
  sources): no hit. The same search finds every solution in the normal edition, and in its
  rendered page, so the search is able to see what it looks for;
* the search index holds none of the words that occur only in solutions (stemmed as Sphinx
  stems them), while the normal edition's index holds them;
* every exercise is still there: its anchor and its statement, on its page.
"""
from __future__ import annotations

import html
import json
import re
from functools import lru_cache
from pathlib import Path

import pytest

from conftest import BOOK_OUT, after, background
from tools.build_book import CACHE
from tools.build_student import INSTRUCTOR_PAGES, for_students, stripped_copy
from tools.solutions import parse, strip_solutions
from tools.toc import notebook_pages, toc_pages

ROOT = Path(__file__).resolve().parents[1]
NORMAL = BOOK_OUT / "_build"
STUDENT = BOOK_OUT / "_build" / "student"
PAGES = toc_pages(ROOT)
SOURCES = {p: parse(ROOT / f"{p}.md") for p in PAGES if (ROOT / f"{p}.md").is_file()}
SOLUTIONS = [(p, s) for p, ch in SOURCES.items() for s in ch.solutions]

pytestmark = pytest.mark.slow


# ---------------------------------------------------------------- text as a reader (or a crawler) sees it

_DASHES = str.maketrans({"\u2013": "-", "\u2014": "-", "\u2018": "'", "\u2019": "'", "\u201c": '"', "\u201d": '"',
                         "\u00a0": " "})


def normal_form(text: str) -> str:
    """Whitespace collapsed, typographic quotes and dashes made plain (Sphinx's smartquotes), … as ..."""
    text = text.translate(_DASHES).replace("\u2026", "...").replace("---", "-").replace("--", "-")
    return re.sub(r"\s+", " ", text)


def _strings(obj):
    if isinstance(obj, str):
        yield obj
    elif isinstance(obj, dict):
        for k, v in obj.items():
            yield from _strings(k)
            yield from _strings(v)
    elif isinstance(obj, list):
        for v in obj:
            yield from _strings(v)


#: a picture's base64 payload (a figure in a page's ``data:`` URI or a notebook's output): no text in
#: it can be read, and it is two fifths of the bytes of the trees searched. Never begun right after a
#: backslash, so that a JSON escape (``\n``) stays whole
_BASE64 = re.compile(r"(?<!\\)[A-Za-z0-9+/]{256,}={0,2}")


def views(path: Path) -> list[str]:
    """The file's text as stored, and as what it says: an HTML page's text without tags and entities,
    a JSON file's (notebook's, search index's) strings decoded; without pictures' base64 payloads."""
    raw = _BASE64.sub("", path.read_text(encoding="utf-8", errors="replace"))
    out = [raw]
    if path.suffix in (".html", ".htm", ".xml"):
        out.append(html.unescape(re.sub(r"<[^>]+>", "", raw)))
    if path.suffix in (".ipynb", ".json", ".js"):
        body = raw[raw.find("{"): raw.rfind("}") + 1] if path.suffix == ".js" else raw
        try:
            out.append("\n".join(_strings(json.loads(body))))
        except ValueError:
            pass
    return [normal_form(v) for v in out]


TEXT_SUFFIXES = {".html", ".htm", ".js", ".json", ".ipynb", ".md", ".txt", ".xml", ".css", ".py", ".yml", ".yaml", ".bib"}


def tree_texts(root: Path) -> dict[Path, list[str]]:
    return {p: views(p) for p in sorted(root.rglob("*")) if p.is_file() and p.suffix in TEXT_SUFFIXES}


# ---------------------------------------------------------------- what a solution says

_MATH = re.compile(r"\$\$.*?\$\$|\$[^$]*\$", re.S)
_ROLE = re.compile(r"\{[\w:-]+\}`[^`]*`")
_CODE = re.compile(r"`[^`]*`")
_LINK = re.compile(r"\[([^\]]*)\]\([^)]*\)")


def prose_fragments(lines: list[str]) -> list[str]:
    """Runs of at least four plain words (20+ characters) between the markup of some prose."""
    text = " ".join(ln.strip() for ln in lines)
    text = _LINK.sub(r"\1", text)
    pieces = re.split(r"\$\$.*?\$\$|\$[^$]*\$|\{[\w:-]+\}`[^`]*`|`[^`]*`|[*_]{1,2}|\||<[^>]*>", text)
    out = []
    for piece in pieces:
        piece = normal_form(piece).strip(" ,;:.()")
        if len(piece.split()) >= 4 and len(piece) >= 20:
            out.append(piece)
    return out


def code_fragments(sources: list[str]) -> list[str]:
    out = []
    for src in sources:
        for ln in src.split("\n"):
            ln = normal_form(ln).strip()
            if len(ln) >= 16 and re.search(r"[A-Za-z]", ln) and not ln.startswith("#"):
                out.append(ln)
    return out


@lru_cache(maxsize=None)
def legit_text() -> str:
    """Everything the student edition may show: every page's source for students (without its
    solutions and its instructor-only blocks); not the instructor's guide, which it leaves out."""
    return normal_form("\n".join(strip_solutions(for_students((ROOT / f"{p}.md").read_text(encoding="utf-8")), p)
                                  for p in SOURCES if p not in INSTRUCTOR_PAGES))


def package_text() -> str:
    """The package's source: the API reference renders its docstrings, so their words are in the index."""
    return "\n".join(f.read_text(encoding="utf-8") for f in sorted((ROOT / "orrc").rglob("*.py")))


def distinctive(solution) -> list[str]:
    frags = prose_fragments(solution.prose) + code_fragments(solution.code + solution.code_in_prose)
    return sorted({f for f in frags if f not in legit_text()})


def _hits(fragments, texts):
    return [f for f in fragments if any(f in t for t in texts)]


# ---------------------------------------------------------------- the builds

@after("book", "student_book")
def build_the_student_edition(book):
    from tools.build_student import build_student

    assert book["rc"] == 0, "the normal build failed"
    return build_student(BOOK_OUT, quick=True)


@pytest.fixture(scope="session")
def student_book(book):
    """The solution-free edition, built once per session (test size), reusing the session's normal
    build (in the background as soon as the book is built, ``conftest.after``)."""
    return background("student_book")


@pytest.fixture(scope="session")
def student_tree(student_book):
    assert student_book["rc"] == 0, "the student edition did not build (see the build output)"
    return tree_texts(STUDENT)


@pytest.fixture(scope="session")
def normal_tree(book):
    texts = tree_texts(NORMAL / "html")
    texts.update(tree_texts(NORMAL / "jupyter_execute"))
    return texts


# ---------------------------------------------------------------- the tests

def test_the_student_edition_builds_apart_and_reuses_the_executed_chapters(student_book):
    r = student_book
    assert r["rc"] == 0
    assert Path(r["html"]) == STUDENT / "html" and (STUDENT / "html" / "index.html").is_file()
    assert not (NORMAL / "html" / "student").exists()
    chapters = set(notebook_pages(ROOT))
    assert set(r["reused"]) | set(r["not_reused"]) == chapters
    for page, why in r["not_reused"].items():  # only a chapter whose outputs could depend on a solution is re-run
        assert "follows a solution" in why, f"{page} was not reused: {why}"
    assert r["executed"] == len(r["not_reused"]), "a reused chapter was executed again"
    # nor executed before the Sphinx build into a cache of its own (a normal build's first step)
    assert not (STUDENT / "source" / "_build" / CACHE).exists(), "the student build executed the chapters first"
    executed = {p.relative_to(STUDENT / "source" / "_build" / "jupyter_execute").with_suffix("").as_posix()
                for p in (STUDENT / "source" / "_build" / "jupyter_execute").rglob("*.ipynb")}
    assert chapters <= executed, f"executed notebooks missing from the student build: {sorted(chapters - executed)}"
    assert sum(r["removed"].values()) == len(SOLUTIONS)
    first = (STUDENT / "html" / f"{PAGES[0]}.html").read_text(encoding="utf-8")
    assert "(student edition)" in first and "(student edition)" not in (NORMAL / "html" / f"{PAGES[0]}.html").read_text()


def test_every_solution_is_checked_and_found_in_the_normal_edition(normal_tree):
    assert SOLUTIONS, "no solution in the book?"
    pages = {p: views(NORMAL / "html" / f"{p}.html") for p in SOURCES}
    texts = [t for ts in normal_tree.values() for t in ts]
    for page, sol in SOLUTIONS:
        frags = distinctive(sol)
        assert frags, f"{page}: the solution of {sol.label!r} has no distinctive text to search for"
        assert _hits(frags, texts), f"{page}: no text of the solution of {sol.label!r} found in the normal build"
        assert _hits(frags, pages[page]), f"{page}: the solution of {sol.label!r} is not found on its rendered page"


def test_no_solution_text_anywhere_in_the_student_edition(student_tree):
    assert any(p.suffix == ".ipynb" and "_sources" in p.parts for p in student_tree), "no .ipynb downloads?"
    assert any(p.name == "searchindex.js" for p in student_tree)
    assert any("jupyter_execute" in p.parts for p in student_tree), "no executed notebooks?"
    for page, sol in SOLUTIONS:
        frags = distinctive(sol)
        for path, texts in student_tree.items():
            hits = _hits(frags, texts)
            assert not hits, f"{path.relative_to(STUDENT)}: text of the solution of {sol.label!r} ({page}): {hits[:2]}"


def _index_terms(path: Path) -> set[str]:
    raw = path.read_text(encoding="utf-8")
    data = json.loads(raw[raw.find("{"): raw.rfind("}") + 1])
    return set(data["terms"]) | set(data.get("titleterms", {}))


def test_the_search_index_holds_no_word_only_solutions_use(student_book):
    from sphinx.search.en import SearchEnglish

    stem = SearchEnglish({}).stem
    legit = {stem(w.lower()) for w in re.findall(r"[A-Za-z]{3,}", legit_text() + package_text())}
    words = set()
    for _, sol in SOLUTIONS:
        words |= {stem(w.lower()) for w in re.findall(r"[A-Za-z]{6,}", " ".join(sol.prose))}
    only_in_solutions = words - legit
    normal, student = _index_terms(NORMAL / "html" / "searchindex.js"), _index_terms(STUDENT / "html" / "searchindex.js")
    assert only_in_solutions & normal, "the normal index should hold words that only solutions use"
    leaked = only_in_solutions & student
    assert not leaked, f"the student search index holds words only solutions use: {sorted(leaked)[:10]}"


@pytest.mark.parametrize("page", [p for p in SOURCES if SOURCES[p].exercises], ids=lambda p: Path(p).name)
def test_every_exercise_statement_is_still_there(student_book, page):
    text = (STUDENT / "html" / f"{page}.html").read_text(encoding="utf-8")
    plain = views(STUDENT / "html" / f"{page}.html")
    for ex in SOURCES[page].exercises:
        assert f'id="{ex.label}"' in text, f"{page}: the exercise {ex.label!r} is gone"
        frags = prose_fragments(ex.statement) or code_fragments(["\n".join(ex.statement)])
        assert frags and _hits(frags, plain), f"{page}: the statement of {ex.label!r} is gone"


def test_the_stripped_copy_keeps_every_page_but_the_solutions(tmp_path):
    removed = stripped_copy(tmp_path / "src")
    toc = (tmp_path / "src" / "_toc.yml").read_text(encoding="utf-8")
    for page in INSTRUCTOR_PAGES:
        assert not (tmp_path / "src" / f"{page}.md").exists() and page not in toc, f"{page} is for instructors only"
    for page, ch in SOURCES.items():
        if page in INSTRUCTOR_PAGES:
            continue
        copy = parse(tmp_path / "src" / f"{page}.md")
        assert copy.solutions == [] and [e.label for e in copy.exercises] == [e.label for e in ch.exercises]
        assert removed[page] == len(ch.solutions)


def guide_fragments() -> list[str]:
    """What only the instructor's guide says: its prose (runs of plain words no page for students
    has), and every message of every assignment test, which the guide lists."""
    from tools import assignments

    paragraphs = [para.split("\n") for page in INSTRUCTOR_PAGES
                  for para in (ROOT / f"{page}.md").read_text(encoding="utf-8").split("\n\n")
                  if not para.lstrip().startswith(("#", "|", "`", "(", ":"))]
    frags = [f for para in paragraphs for f in prose_fragments(para)]
    frags = [f for f in frags if f not in legit_text()]
    messages = [normal_form(t["checks"]) for n in assignments.names()
                for q in assignments.read_assignment(assignments.SOURCES / n / f"{n}.md")["questions"] for t in q["tests"]]
    return sorted(set(frags)) + messages


def test_no_instructor_guide_in_the_student_edition(student_tree):
    """The guide (its page, its links, its text, the assignments' test messages it lists) and the
    preface's words for instructors are not in the student edition."""
    frags = guide_fragments()
    assert len(frags) > 40
    dropped = [f for f in prose_fragments(["Their solutions sit in dropdowns right below them"]) if f not in legit_text()]
    assert dropped
    html = [(path, texts) for path, texts in student_tree.items() if (STUDENT / "html") in path.parents]
    assert len(html) > 20
    for path, texts in html:   # what is handed out (the build's own source copy holds the tools' code)
        assert "instructors" not in path.name, f"{path.relative_to(STUDENT)}: a page of the guide"
        hits = _hits(frags + dropped, texts)
        assert not hits, f"{path.relative_to(STUDENT)}: text for instructors: {hits[:2]}"
        if path.suffix == ".html":
            assert not any("instructors.html" in t for t in texts), f"{path.relative_to(STUDENT)}: links to the guide"
