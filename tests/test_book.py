"""The rendered book as a reader meets it.

The book is built ONCE per test session (the ``book`` fixture of ``conftest.py``:
``tools.build_book.build``, every chapter executed, ``-n -W --keep-going``) into
``_build/`` of the repository, or into ``$ORRC_BOOK_OUT/_build`` when that variable is
set; tests/test_chapters.py checks the executed notebooks of the same build. Then

* without a browser: the build succeeded; no page loads a script, stylesheet, image
  or frame from the network (MathJax 3 is shipped in ``_static/mathjax``); no Thebe;
  every chapter has a valid ``.ipynb`` download holding the code cells the page shows, with
  the pinned requirements and the ``orrc`` wheel it installs from beside it and linked from the page;
  the execution-times page lists every chapter; no page is heavier than 3 MB;
* in headless Chromium (Playwright driving the SYSTEM Chromium, never a downloaded
  one): every page of ``_toc.yml`` opens from ``file://`` without console errors or
  network requests, its math is typeset, its images have loaded, no cell shows an
  error, and every frame slider changes its figure and its text alternative. Screenshots at 1366 px
  and 390 px go to ``_build/screenshots/<page>-1366.jpg`` / ``-390.jpg`` (JPEG: a tall page
  encodes in a third of the time of a PNG, and reads as well); the axe-core audit finds no
  serious or critical violation (report in ``_build/screenshots/axe/``; run once, at 1366 px:
  the document and the styles it reads are those of both widths, and what the width changes is
  checked at both, below), and at both widths every element that runs past the text column sits
  in a box that scrolls, shows a cue and takes keyboard focus. Every image has a text alternative; the execution table's
  status marks need no emoji font.

The pages are checked in the background as soon as the book is built, in one Chromium (Playwright's
async API), one page per core at a time (:data:`PARALLEL_PAGES`); each page's test reads its result.

No Chromium: the browser tests are skipped with a message saying how to enable them,
except when ``CI`` is set, where a missing browser is a failure.
"""
from __future__ import annotations

import ast
import html.parser
import os
import re
from pathlib import Path

import pytest

from conftest import BOOK_HTML as HTML, BOOK_LOG, BOOK_OUT, HOW_TO_ENABLE, PUBLISHED_HTML, SHOTS, after, background, find_chromium, tree_fingerprint
from tools.download import portable_source
from tools.toc import notebook_pages, toc_pages

ROOT = Path(__file__).resolve().parents[1]
MAX_PAGE_BYTES = 3_000_000
WIDTHS = (1366, 390)
SHOT_PART = 60_000   # px of page per screenshot (a JPEG holds at most 65,535 px)

pytestmark = pytest.mark.slow


# ---------------------------------------------------------------- helpers

PAGES = toc_pages(ROOT)
NOTEBOOKS = notebook_pages(ROOT)


def page_id(page: str) -> str:
    """A page's name for its screenshots and reports: ``book/lemma1`` -> ``lemma1``, an API page
    ``book/api/comparison`` -> ``api-comparison`` (the comparison chapter keeps ``comparison``)."""
    parts = Path(page).parts
    return "-".join(parts[1:] if parts[0] == "book" else parts)


class _Assets(html.parser.HTMLParser):
    """Collect every URL a page makes the browser fetch, and the inline script bodies."""

    def __init__(self):
        super().__init__()
        self.fetched: list[tuple[str, str]] = []
        self.inline_scripts: list[str] = []
        self._in_script = False

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag in ("script", "img", "iframe", "source", "audio", "video", "embed") and a.get("src"):
            self.fetched.append((tag, a["src"]))
        if tag == "link" and a.get("href"):
            rel = (a.get("rel") or "").lower()
            if any(r in rel for r in ("stylesheet", "preload", "modulepreload", "icon", "prefetch")):
                self.fetched.append((tag, a["href"]))
        self._in_script = tag == "script" and not a.get("src")
        if self._in_script:
            self.inline_scripts.append("")

    def handle_endtag(self, tag):
        if tag == "script":
            self._in_script = False

    def handle_data(self, data):
        if self._in_script:
            self.inline_scripts[-1] += data


def parse(page: str) -> _Assets:
    p = _Assets()
    p.feed((HTML / f"{page}.html").read_text(encoding="utf-8"))
    return p


def is_remote(url: str) -> bool:
    return bool(re.match(r"^(https?:)?//", url.strip(), re.I))


# ---------------------------------------------------------------- the build (once: the `book` fixture of conftest.py)

def test_book_builds_without_warnings_or_cell_errors(book):
    if book["rc"] != 0:
        lines = BOOK_LOG.read_text(encoding="utf-8", errors="replace").splitlines() if BOOK_LOG.is_file() else []
        why = [ln for ln in lines if re.search(r"WARNING|ERROR|Error|Traceback|not cached", ln)
               and "IPKernelApp" not in ln][:20]
        pytest.fail(f"jupyter-book build failed (a cell error or a Sphinx warning); {BOOK_LOG}:\n"
                    + "\n".join(why + ["..."] + lines[-15:]))
    for page in PAGES:
        assert (HTML / f"{page}.html").is_file(), f"{page}.html was not written"


def test_the_test_build_has_a_folder_of_its_own(book):
    """The shortened test build never lands where readers look: ``_build/html`` is written
    only by ``make book`` (full size); the session's build went to ``_build/test``."""
    assert HTML.resolve() != PUBLISHED_HTML.resolve(), f"the test build writes to the published {PUBLISHED_HTML}"
    assert HTML.is_relative_to(BOOK_OUT) and (HTML / "index.html").is_file(), f"no test build in {HTML}"
    assert tree_fingerprint(PUBLISHED_HTML) == book["published"], (
        f"building the test book changed the published {PUBLISHED_HTML}")


def test_no_page_loads_anything_from_the_network(book):
    mathjax = HTML / "_static" / "mathjax" / "tex-svg.js"
    assert mathjax.is_file(), "MathJax was not shipped into _static/mathjax"
    head = mathjax.read_text(encoding="utf-8", errors="replace")[:400_000]
    assert re.search(r'VERSION="3\.\d+\.\d+"', head), "the shipped MathJax is not MathJax 3"
    pages_with_math = 0
    for page in PAGES:
        assets = parse(page)
        remote = [(tag, url) for tag, url in assets.fetched if is_remote(url)]
        assert not remote, f"{page}: loaded from the network: {remote}"
        srcs = [url for tag, url in assets.fetched if tag == "script"]
        for url in srcs:  # every local script exists in the build
            local = (HTML / Path(page).parent / url.split("?")[0]).resolve()
            assert local.is_file(), f"{page}: script {url} is missing from the build"
        mj = [u for u in srcs if "mathjax" in u.lower()]
        if mj:
            pages_with_math += 1
            assert all("_static/mathjax/tex-svg.js" in u for u in mj), f"{page}: MathJax from {mj}"
        bodies = "\n".join(assets.inline_scripts)
        assert "THEBE_JS_URL" not in bodies and "x-thebe-config" not in (HTML / f"{page}.html").read_text(), \
            f"{page}: Thebe is still configured"
        assert not re.search(r"require(\.min)?\.js|@jupyter-widgets/html-manager|embed-amd", bodies + " ".join(srcs)), \
            f"{page}: the page still loads require.js / the widget manager"
    assert pages_with_math >= 1, "no page loads MathJax at all: is math rendered?"


def _code_cells_in_myst(text: str) -> list[tuple[str, set[str]]]:
    """(source, tags) of the ```{code-cell} blocks of a MyST notebook, read with a regex (not jupytext)."""
    cells = []
    for m in re.finditer(r"^(`{3,})\{code-cell\}[^\n]*\n(.*?)^\1[ \t]*$", text, re.S | re.M):
        body = m.group(2)
        lines = body.split("\n")
        options = []
        if lines and lines[0].startswith("---"):  # YAML options block
            end = lines.index("---", 1)
            options, lines = lines[1:end], lines[end + 1:]
        else:
            while lines and lines[0].startswith(":") and ":" in lines[0][1:]:
                options, lines = options + [lines[0]], lines[1:]  # short-form options (:tags: [...])
        tags = set()
        for opt in options:
            found = re.match(r"^:?tags:\s*\[(.*)\]\s*$", opt.strip())
            if found:
                tags = {t.strip().strip("'\"") for t in found.group(1).split(",") if t.strip()}
        cells.append(("\n".join(lines).strip(), tags))
    return cells


@pytest.mark.parametrize("page", NOTEBOOKS, ids=page_id)
def test_every_chapter_offers_its_ipynb(book, page):
    import nbformat

    nb_path = HTML / "_sources" / f"{page}.ipynb"
    assert nb_path.is_file(), f"no .ipynb download for {page}"
    nb = nbformat.read(nb_path, as_version=4)
    nbformat.validate(nb)
    code = [c.source.strip() for c in nb.cells if c.cell_type == "code"]
    # the code cells the page shows (not the build's remove-cell ones), made portable
    expected = [portable_source(c).strip() for c, tags in _code_cells_in_myst((ROOT / f"{page}.md").read_text(encoding="utf-8"))
                if "remove-cell" not in tags]
    assert expected, f"{page} has no code cells?"
    assert code == expected, f"{page}.ipynb does not hold the code cells the page shows"
    # it runs wherever orrc is installed: no import of the book's build tools, and it says so first
    for c in code:
        tree = ast.parse("\n".join(line for line in c.splitlines() if not line.lstrip().startswith(("%", "!"))))
        imported = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        imported |= {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module}
        assert not {m for m in imported if m.split(".")[0] in ("myst_nb", "sphinx", "jupyter_book")}, \
            f"{page}.ipynb imports the book's build tools: {sorted(imported)}"
    first = nb.cells[0]
    assert first.cell_type == "markdown" and "orrc" in first.source and "pip install" in first.source, \
        f"{page}.ipynb does not start by saying where it runs"
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), "the download should be clean"
    assert nb.metadata["kernelspec"]["name"] == "python3"
    # the page's download menu links to it
    html_text = (HTML / f"{page}.html").read_text(encoding="utf-8")
    rel = os.path.relpath(nb_path, (HTML / page).parent).replace(os.sep, "/")
    assert f'href="{rel}"' in html_text, f"{page}.html has no link to {rel}"
    # and to the files its first cell installs from, beside it
    for f in [p for p in nb_path.parent.iterdir() if p.suffix in (".txt", ".whl")]:
        rel = os.path.relpath(f, (HTML / page).parent).replace(os.sep, "/")
        assert f'href="{rel}"' in html_text, f"{page}.html has no link to {rel}"
    assert {p.suffix for p in nb_path.parent.iterdir()} >= {".txt", ".whl"}, f"no requirements or wheel beside {nb_path}"


def test_execution_times_page_lists_every_chapter(book):
    assert PAGES[-1].endswith("execution"), "the execution-times page should be the last entry of _toc.yml"
    text = (HTML / f"{PAGES[-1]}.html").read_text(encoding="utf-8")
    table = text[text.index("<table"):text.index("</table>")]
    rows = re.findall(r"<tr.*?</tr>", table, re.S)[1:]
    assert len(rows) == len(NOTEBOOKS), f"{len(rows)} rows for {len(NOTEBOOKS)} chapters"
    for page in NOTEBOOKS:
        row = next((r for r in rows if f'href="{Path(page).name}.html"' in r), None)
        assert row is not None, f"{page} missing from the execution table"
        cells = [re.sub(r"<.*?>", "", c).strip() for c in re.findall(r"<td.*?</td>", row, re.S)]
        seconds = float(cells[3])
        assert 0 < seconds < 600, f"{page}: run time {seconds}"
        assert cells[4] == "passed", f"{page}: status {cells[4]}"
    # the status marks need no emoji font: an inline SVG and a word (tools/sphinx_a11y.py)
    assert not re.search("[\U0001F000-\U0001FAFF\u2705\u274C]", text), "an emoji glyph is left on the page"
    assert text.count('class="orrc-status-mark"') == len(NOTEBOOKS)


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_every_image_has_a_text_alternative(book, page):
    """No image announced as just "figure": each figure's alt says what it shows (orrc.viz.describe);
    an image without one must be marked decorative (alt="")."""
    text = (HTML / f"{page}.html").read_text(encoding="utf-8")
    imgs = re.findall(r"<img\b[^>]*>", text)
    missing = [i[:120] for i in imgs if not re.search(r'\balt="', i)]
    assert not missing, f"{page}: images without an alt attribute: {missing[:3]}"
    fixed = [i[:120] for i in imgs if re.search(r'\balt="(figure|image|plot)?"', i, re.I) and "orrc-img" in i]
    assert not fixed, f"{page}: figures without a description of what they show: {fixed[:3]}"


@pytest.mark.parametrize("page", NOTEBOOKS, ids=page_id)
def test_interactive_figures_are_static_frames_in_the_html(book, page):
    source = (ROOT / f"{page}.md").read_text(encoding="utf-8")
    text = (HTML / f"{page}.html").read_text(encoding="utf-8")
    assert "application/vnd.jupyter.widget-view+json" not in text, f"{page}: a dead live widget is shown"
    assert "application/vnd.jupyter.widget-state+json" not in text, f"{page}: unused widget state embedded"
    if "explore(" in source:
        assert 'class="orrc-frames"' in text, f"{page} calls explore() but shows no static frames"


def uncaptioned_pictures(html_text: str) -> list[str]:
    """The pictures of a page's text that are not a numbered figure with a caption: every image,
    inline SVG and block of explorer frames (``div.orrc-frames``, counted once with its images)
    whose nearest ``<figure>`` has no ``<figcaption>`` with a figure number and a caption text.
    Left out: the icons of the page's widgets (the octicons of a dropdown). Returns one short
    description per picture."""
    from bs4 import BeautifulSoup

    soup = BeautifulSoup(html_text, "html.parser")
    article = soup.find("article", class_="bd-article")
    assert article is not None, "no article element (the theme changed?)"
    found = []
    for el in article.find_all(["img", "svg"]) + article.find_all("div", class_="orrc-frames"):
        if el.name != "div" and el.find_parent("div", class_="orrc-frames") is not None:
            continue   # a frame of an explorer: the block of frames is the picture
        if "sd-octicon" in (el.get("class") or []):
            continue
        fig = el.find_parent("figure")
        cap = fig.find("figcaption") if fig is not None else None
        number = cap.find(class_="caption-number") if cap is not None else None
        text = cap.find(class_="caption-text") if cap is not None else None
        if number is None or text is None or not text.get_text(strip=True):
            section = el.find_parent("section")
            what = (el.get("alt") or (el.find("img") or {}).get("alt") or el.name)[:80] if el.name != "svg" else "svg"
            found.append(f"{el.name}.{'.'.join(el.get('class') or [])} in #{section.get('id') if section else '?'}: {what}")
    return found


@pytest.mark.parametrize("page", NOTEBOOKS, ids=page_id)
def test_every_picture_is_a_numbered_figure_with_a_caption(book, page):
    """Every image, inline SVG and explorer (its static frames) of a chapter is a numbered figure
    with a caption (myst-nb's ``mystnb: figure:`` cell metadata, or ``{glue:figure}``), so the
    prose can refer to it and a reader knows what it shows."""
    text = (HTML / f"{page}.html").read_text(encoding="utf-8")
    bare = uncaptioned_pictures(text)
    assert not bare, f"{page}: {len(bare)} pictures without a figure number and a caption: {bare[:4]}"


def test_the_caption_check_sees_a_bare_picture():
    """The check above finds a picture outside a figure, a figure without a caption, and an explorer
    without one, and passes a numbered, captioned figure."""
    page = """<article class="bd-article">
      <section id="a"><figure id="fig-x"><img alt="a curve" src="x.png">
        <figcaption><p><span class="caption-number">Fig. 1 </span><span class="caption-text">A curve.</span></p></figcaption>
      </figure></section>
      <section id="b"><img alt="bare" src="y.png"></section>
      <section id="c"><figure><img alt="no caption" src="z.png"></figure></section>
      <section id="d"><div class="orrc-frames"><img class="orrc-frame" alt="frame" src="f.png"></div></section>
    </article>"""
    bare = uncaptioned_pictures(page)
    assert len(bare) == 3 and "#b" in bare[0] and "#c" in bare[1] and "div.orrc-frames in #d" in bare[2]


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_pages_stay_light(book, page):
    size = (HTML / f"{page}.html").stat().st_size
    assert size < MAX_PAGE_BYTES, f"{page}.html is {size / 1e6:.1f} MB (frames too heavy?)"


# ---------------------------------------------------------------- the browser

AXE = ROOT / "_build" / "axe" / "node_modules" / "axe-core" / "axe.min.js"   # `make test` installs it
AXE_IMPACTS = ("serious", "critical")   # the audit fails a page on these


async def axe_audit(pg, page: str, width: int) -> list[dict]:
    """Run axe-core (pinned, tools/axe/package-lock.json) on the open page; save its report to
    ``_build/screenshots/axe/<page>-<width>.json``; return the serious and critical violations."""
    import json

    # preload: false, else axe-core fetches the stylesheets again (refused from file://: console errors)
    if not await pg.evaluate("() => !!window.axe"):
        await pg.add_script_tag(path=str(AXE))
    result = await pg.evaluate("""() => axe.run(document, {resultTypes: ['violations'], preload: false}).then(r => ({
        version: r.testEngine.version, url: r.url,
        violations: r.violations.map(v => ({id: v.id, impact: v.impact, help: v.help, helpUrl: v.helpUrl,
            nodes: v.nodes.map(n => ({target: n.target, html: n.html.slice(0, 300), summary: n.failureSummary}))}))
    }))""")
    out = SHOTS / "axe"
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{page_id(page)}-{width}.json").write_text(json.dumps(result, indent=1, ensure_ascii=False))
    return [v for v in result["violations"] if v["impact"] in AXE_IMPACTS]


# every element of the text (math, code, tables, paragraphs) that runs past the text column at this
# width must sit in a box that scrolls sideways (overflow-x auto or scroll), shows the cue (class
# orrc-overflows and a shadow on the side with more) and takes keyboard focus: the nearest ancestor
# (or itself) that clips it; reaching the column itself means content cut off without a cue
_OVERFLOWING = """() => {
  const column = document.querySelector('#main-content article') || document.querySelector('#main-content');
  const edge = column.getBoundingClientRect();
  const boxes = [];
  column.querySelectorAll('div.math, mjx-container, pre, table, p, code, img, svg').forEach(e => {
    const r = e.getBoundingClientRect();
    if (r.width === 0 || (r.right <= edge.right + 1 && r.left >= edge.left - 1)) { return; }
    // the nearest ancestor that cuts it off: one that clips (overflow applies to block boxes only,
    // never to an inline element) and that the element runs past
    const clips = b => getComputedStyle(b).overflowX !== 'visible' && getComputedStyle(b).display !== 'inline';
    const past = b => { const q = b.getBoundingClientRect(); return r.right > q.right + 1 || r.left < q.left - 1; };
    let box = e.parentElement;
    while (box !== column && !(clips(box) && past(box))) { box = box.parentElement; }
    if (!boxes.includes(box)) { boxes.push(box); }
  });
  return boxes.map(b => { const s = getComputedStyle(b); return {
    html: b === column ? 'the text column itself' : b.outerHTML.slice(0, 100), overflowX: s.overflowX,
    cue: b.classList.contains('orrc-overflows'), shadow: s.boxShadow, tabindex: b.getAttribute('tabindex'),
    label: b.getAttribute('aria-label')}; });
}"""


# blocks wider than the text column (whether or not they sit in a box that scrolls), and code or
# printed output wider than its own box: at a laptop's width no equation, table, code or output may
# be (they are written to fit: code and printed lines within 88 characters, which the column shows at
# 13 px); at a phone's no table may be (tables reflow; long equations, code and output scroll in
# their own box, with the cue checked below)
_WIDE_BLOCKS = """() => {
  const column = document.querySelector('#main-content article') || document.querySelector('#main-content');
  const width = column.getBoundingClientRect().width;
  const kind = e => e.tagName === 'TABLE' ? 'table' : (e.tagName === 'PRE' ? 'code' : 'equation');
  const found = [];
  column.querySelectorAll('div.math, mjx-container[display="true"], pre, table').forEach(e => {
    const w = Math.max(e.scrollWidth, e.getBoundingClientRect().width);
    const scrolls = e.tagName === 'PRE' && e.clientWidth > 0 && e.scrollWidth > e.clientWidth + 1;
    if (w > width + 1 || scrolls) {
      const line = e.textContent.split('\\n').reduce((a, b) => (b.length > a.length ? b : a), '');
      found.push({kind: kind(e), width: Math.round(w), html: e.outerHTML.slice(0, 120), line: line.slice(0, 100)});
    }
  });
  return found;
}"""


class Tab:
    """One tab of the session's Chromium that opens page after page: a browser context (its own
    cookies and storage) whose every remote request is refused and recorded, so an offline failure
    shows up here too, and the console errors and page errors of the page it shows. One tab serves
    many pages: its renderer process, and the scripts it has compiled (MathJax, the theme's), are
    reused, as in a reader's browser (a new context per page doubled the cost of opening one)."""

    @classmethod
    async def new(cls, chromium) -> "Tab":
        tab = cls()
        tab.events = {"errors": [], "remote": []}
        tab.ctx = await chromium.new_context(viewport={"width": WIDTHS[0], "height": 900}, device_scale_factor=1)

        async def on_route(route):
            url = route.request.url
            if url.startswith(("file:", "data:", "blob:")):
                await route.continue_()
            else:
                tab.events["remote"].append(url)
                await route.abort()

        await tab.ctx.route("**/*", on_route)
        tab.pg = await tab.ctx.new_page()
        tab.pg.on("console", lambda m: tab.events["errors"].append(f"console.{m.type}: {m.text}")
                  if m.type == "error" else None)
        tab.pg.on("pageerror", lambda e: tab.events["errors"].append(f"page error: {e}"))
        tab.cdp = await tab.ctx.new_cdp_session(tab.pg)
        return tab

    async def open(self, page: str, width: int):
        """Show ``page`` at ``width`` px, its math typeset and its images loaded; returns the page
        (Playwright's) and the events recorded since (remote requests, errors)."""
        pg, events = self.pg, self.events
        events["errors"].clear()
        events["remote"].clear()
        await pg.set_viewport_size({"width": width, "height": 900})
        await pg.goto((HTML / f"{page}.html").as_uri(), wait_until="load")
        # MathJax typesets after load; wait for it where the page loads it
        if await pg.evaluate("() => !!document.querySelector('script[src*=\"mathjax\"]')"):
            from playwright.async_api import TimeoutError as PlaywrightTimeout

            try:
                await pg.wait_for_function("() => window.MathJax && MathJax.startup && MathJax.startup.promise",
                                           timeout=30_000)
            except PlaywrightTimeout:
                raise AssertionError(f"{page}: MathJax never started (refused network requests: {events['remote']}; "
                                     f"errors: {events['errors']})") from None
            await pg.evaluate("() => MathJax.startup.promise")
        await pg.evaluate("""() => Promise.all(Array.from(document.images).map(img => {
            img.loading = 'eager';
            return img.complete ? null : new Promise(r => { img.onload = img.onerror = r; });
        }))""")
        return pg, events

    async def screenshot(self, path: Path, clip: dict) -> None:
        """A JPEG of the part ``clip`` (page coordinates, px) of the page as laid out now, to ``path``:
        Chromium's own capture beyond the viewport (the DevTools protocol), which neither resizes the
        page nor restyles it (Playwright's full-page screenshot hides the caret with a stylesheet put
        in and taken out: about a fifth more CPU on a tall page)."""
        import base64

        shot = await self.cdp.send("Page.captureScreenshot", {
            "format": "jpeg", "quality": 85, "captureBeyondViewport": True, "clip": {**clip, "scale": 1}})
        Path(path).write_bytes(base64.b64decode(shot["data"]))

    async def close(self):
        await self.ctx.close()


MIN_SHOWN_DPI = 99.5   # 100 px per figure inch, less a rounding of the layout

# every image of the page's content that is shown (display: none ones, the other rendering of a
# figure, have no box), with its natural and shown width and its right edge
_SHOWN_IMAGES = """() => Array.from((document.querySelector('main') || document.body).querySelectorAll('img'))
  .map(i => [i, i.getBoundingClientRect()]).filter(([i, r]) => r.width > 0)
  .map(([i, r]) => ({src: i.currentSrc || i.src, natural: i.naturalWidth, shown: r.width, right: r.right}))"""


def image_bytes(src: str, page: str) -> bytes:
    """The bytes of an image of a page: a data: URI, or a file of the build."""
    import base64
    from urllib.parse import unquote, urlparse

    if src.startswith("data:"):
        return base64.b64decode(src.split(",", 1)[1])
    return Path(unquote(urlparse(src).path)).read_bytes()


def png_dpi(data: bytes) -> float | None:
    """The resolution a PNG declares (its pHYs chunk, pixels per metre), in dots per inch; None without one."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    i = 8
    while i + 8 <= len(data):
        n, kind = int.from_bytes(data[i:i + 4], "big"), data[i + 4:i + 8]
        if kind == b"pHYs":
            ppu, unit = int.from_bytes(data[i + 8:i + 12], "big"), data[i + 16]
            return ppu * 0.0254 if unit == 1 else None
        if kind == b"IDAT":
            return None
        i += 12 + n
    return None


_TEXT_OUTSIDE_CODE = """() => {
  const main = document.querySelector('main') || document.body;
  const copy = main.cloneNode(true);
  copy.querySelectorAll('pre, code, script, style, mjx-container, .cell_input, .highlight')
      .forEach(e => e.remove());
  return copy.innerText;
}"""


#: pages checked at once in the one Chromium of the page checks: one per core (the checks wait on
#: Chromium's rendering, screenshots and the audit, which use a core each)
PARALLEL_PAGES = max(1, os.cpu_count() or 1)


@after("book", "browser_pages")
def check_the_pages_in_the_browser(book) -> dict:
    """Every page of ``_toc.yml`` checked (:func:`check_page`) in one headless Chromium,
    PARALLEL_PAGES at a time (Playwright's async API, in the background thread of this job):
    ``{page: None or the first problem}``, or ``{"__skip__": why}`` without a browser."""
    import asyncio

    if book["rc"] != 0:
        return {"__skip__": "the book did not build"}
    path = find_chromium()
    if path is None:
        return {"__skip__": f"no Chromium found; {HOW_TO_ENABLE}"}
    if not AXE.is_file():
        return {"__skip__": f"axe-core is not installed ({AXE}); `make test` installs it (npm ci, tools/axe)"}
    from playwright.async_api import async_playwright

    async def run_all() -> dict:
        results: dict = {}
        async with async_playwright() as p:
            browser = await p.chromium.launch(executable_path=path, args=["--no-sandbox", "--disable-gpu"])
            tabs: asyncio.Queue = asyncio.Queue()   # one tab per page checked at once, each reused
            for _ in range(PARALLEL_PAGES):
                tabs.put_nowait(await Tab.new(browser))

            async def one(page):
                tab = await tabs.get()
                try:
                    await check_page(tab, page)
                    results[page] = None
                except AssertionError as exc:
                    results[page] = str(exc)
                except Exception as exc:   # noqa: BLE001 - a Playwright error fails that page's test
                    results[page] = f"{type(exc).__name__}: {exc}"
                    # the tab may be broken (a crashed renderer): the next page gets a new one
                    await tab.close()
                    tab = await Tab.new(browser)
                finally:
                    tabs.put_nowait(tab)

            # the longest pages first (a page's HTML size as its cost), so that the last page checked
            # is a short one and no tab is left working alone at the end
            size = {page: (HTML / f"{page}.html").stat().st_size if (HTML / f"{page}.html").is_file() else 0
                    for page in PAGES}
            longest_first = sorted(PAGES, key=lambda page: -size[page])
            try:
                await asyncio.gather(*(one(page) for page in longest_first))
            finally:
                await browser.close()
        return results

    return asyncio.run(run_all())


@pytest.fixture(scope="session")
def browser_pages(book):
    """Every page's browser check, run in the background once the book is built."""
    results = background("browser_pages")
    if "__skip__" in results:
        if os.environ.get("CI"):
            pytest.fail(f"CI is set but {results['__skip__']}")
        pytest.skip(results["__skip__"])
    return results


@pytest.mark.browser
@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_page_in_a_real_browser(browser_pages, book, page):
    assert book["rc"] == 0, "the book did not build"
    problem = browser_pages[page]
    assert problem is None, problem


async def check_page(tab: Tab, page: str) -> None:
    """Every check of a page in the browser (see the module's docstring), in ``tab``; raises
    AssertionError with the first problem."""
    pg, events = await tab.open(page, WIDTHS[0])
    # math typeset: every math node became a MathJax container, no raw TeX left in the text
    untypeset = await pg.evaluate("() => Array.from(document.querySelectorAll('span.math, div.math'))"
                            ".filter(e => !e.querySelector('mjx-container')).map(e => e.textContent.slice(0, 60))")
    assert not untypeset, f"{page}: math not typeset: {untypeset[:5]}"
    if await pg.locator("span.math, div.math").count():
        assert await pg.locator("mjx-container [data-mjx-error], mjx-merror").count() == 0, f"{page}: TeX errors"
    text = await pg.evaluate(_TEXT_OUTSIDE_CODE)
    for raw in ("$$", "\\(", "\\[", "\\begin{"):
        assert raw not in text, f"{page}: raw TeX {raw!r} left in the rendered text"

    # every image has loaded
    broken = await pg.evaluate("() => Array.from(document.images)"
                         ".filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src.slice(0, 80))")
    assert not broken, f"{page}: images not loaded: {broken}"

    # no cell shows an error
    assert await pg.locator(".cell_output .output.traceback, .output.error").count() == 0, f"{page}: a cell error"
    for err in await pg.locator(".cell_output .output.stderr").all_inner_texts():
        assert "Traceback" not in err and not re.search(r"\b\w*Error\b", err), f"{page}: stderr {err[:200]}"

    # screenshots at a laptop and a phone width
    SHOTS.mkdir(parents=True, exist_ok=True)
    for width in WIDTHS:  # taken before the sliders are touched, so the page is as a reader first sees it
        await pg.set_viewport_size({"width": width, "height": 900})
        await pg.evaluate("() => window.scrollTo(0, 0)")  # sticky sidebars are drawn where the page is scrolled
        # two animation frames: the new width laid out and painted before the picture
        await pg.evaluate("() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
        # a page taller than one JPEG holds (65,535 px; the API reference's longest pages on a phone)
        # is taken in parts, <page>-<width>-2.jpg and on, each checked not empty
        tall = await pg.evaluate("() => document.documentElement.scrollHeight")
        for part, top in enumerate(range(0, tall, SHOT_PART)):
            shot = SHOTS / (f"{page_id(page)}-{width}.jpg" if part == 0 else f"{page_id(page)}-{width}-{part + 1}.jpg")
            clip = {"x": 0, "y": top, "width": width, "height": min(SHOT_PART, tall - top)}
            await tab.screenshot(shot, clip)
            assert shot.stat().st_size > 0, f"{page} at {width} px: an empty screenshot ({shot.name}, page {tall} px tall)"
        # nothing makes the whole page scroll sideways (wide equations and tables scroll in their own box)
        overflow = await pg.evaluate("() => document.documentElement.scrollWidth - document.documentElement.clientWidth")
        assert overflow <= 1, f"{page}: the page is {overflow}px wider than a {width}px screen"
        # every block wider than its box scrolls in it, with a visible cue, and takes keyboard focus
        await pg.evaluate("() => window.orrcMarkOverflow && window.orrcMarkOverflow()")
        wide = await pg.evaluate(_WIDE_BLOCKS)
        too_wide = [b for b in wide if b["kind"] == "table" or width >= 1366]
        assert not too_wide, f"{page} at {width} px: wider than the text column ({len(too_wide)}): {too_wide[:3]}"
        for box in await pg.evaluate(_OVERFLOWING):
            assert box["overflowX"] in ("auto", "scroll"), f"{page} at {width} px: clipped, no scrolling: {box}"
            assert box["cue"] and box["shadow"] != "none", f"{page} at {width} px: scrolls without a cue: {box}"
            assert box["tabindex"] == "0" and box["label"], f"{page} at {width} px: not keyboard-scrollable: {box}"
        # at a laptop's width a name in the API reference's summary tables stays on one line
        if width == WIDTHS[0]:
            broken = await pg.evaluate("() => Array.from(document.querySelectorAll("
                                       "'table.autosummary td:first-child code'))"
                                       ".filter(c => c.getClientRects().length > 1).map(c => c.textContent)")
            assert not broken, f"{page} at {width} px: names broken across lines: {broken[:5]}"
        # the map of the results keeps its labels legible (9.5 pt drawn in a figure about 700 px wide:
        # at least 600 px shown, scrolling in its own box on a phone)
        maps = await pg.evaluate("() => Array.from(document.querySelectorAll('svg.orrc-results-map'))"
                                 ".map(s => s.getBoundingClientRect().width)")
        assert all(w >= 600 for w in maps), f"{page} at {width} px: the map of the results is shown {maps} px wide"
        # the accessibility audit: no serious or critical violation (report beside the screenshots).
        # Once a page: axe's cost is building its model of the whole document (a few seconds on a page
        # of 13,000 elements, whatever the rules), and the document, its roles, names and colours are
        # the same at both widths; what the width changes (boxes that scroll, their cue, focus and
        # label, nothing wider than the screen) is checked at both widths above.
        if width == WIDTHS[0]:
            bad = await axe_audit(pg, page, width)
            assert not bad, f"{page} at {width} px: axe-core: " + "; ".join(
                f"{v['impact']} {v['id']} ({v['help']}): {[n['target'] for n in v['nodes'][:3]]}" for v in bad)
        # every figure legible: shown at >= 100 px per figure inch (its fonts of >= 9 pt at >= 12.5 px)
        # and inside the screen
        for fig in await pg.evaluate(_SHOWN_IMAGES):
            dpi = png_dpi(image_bytes(fig["src"], page))
            assert dpi is not None, f"{page}: an image without a resolution (not a figure PNG?): {fig['src'][:60]}"
            shown = dpi * fig["shown"] / fig["natural"]
            assert shown >= MIN_SHOWN_DPI, (
                f"{page} at {width} px: a figure {fig['natural']} px wide ({fig['natural'] / dpi:.1f} in) is shown "
                f"{fig['shown']:.0f} px wide, {shown:.0f} px per inch (at least {MIN_SHOWN_DPI}): its 9 pt fonts "
                f"would be {9 / 72 * shown:.1f} px; draw it narrower or give it a narrow variant")
            assert fig["right"] <= width + 0.5, f"{page} at {width} px: a figure overflows to {fig['right']:.0f} px"

    # every frame slider flips its figure (both renderings, wide and narrow)
    frames = pg.locator("div.orrc-frames")
    for i in range(await frames.count()):
        box = frames.nth(i)
        imgs = box.locator("img.orrc-frame")
        assert await imgs.count() in (1, 2) and await box.locator("input.orrc-slider").count() >= 1
        handles = [await imgs.nth(k).element_handle() for k in range(await imgs.count())]
        for j in range(await box.locator("input.orrc-slider").count()):
            slider = box.locator("input.orrc-slider").nth(j)
            top = int(await slider.get_attribute("max"))
            if top == 0:
                continue
            before = [await h.get_attribute("src") for h in handles]
            before_alt = [await h.get_attribute("alt") for h in handles]
            before_label = await box.locator("output").nth(j).inner_text()
            start = int(await slider.input_value())
            await slider.fill(str(top if start != top else 0))
            for h, src in zip(handles, before):
                await pg.wait_for_function("([el, s]) => el.src !== s", arg=[h, src], timeout=5_000)
                assert await pg.evaluate("(el) => el.naturalWidth > 0", h), f"{page}: new frame broken"
            assert await box.locator("output").nth(j).inner_text() != before_label, f"{page}: label did not follow"
            # the text alternative follows the frame: the new frame's parameter value is in it
            name, label = await slider.get_attribute("data-name"), await box.locator("output").nth(j).inner_text()
            for h, alt in zip(handles, before_alt):
                now = await h.get_attribute("alt")
                assert now != alt and f"{name} = {label}" in now, (
                    f"{page}: the image's text alternative did not follow the slider ({name} = {label}): {now[:120]}")
            await slider.fill(str(start))  # and back
            for h, src in zip(handles, before):
                await pg.wait_for_function("([el, s]) => el.src === s", arg=[h, src], timeout=5_000)

    assert not events["remote"], f"{page}: requested from the network: {events['remote']}"
    assert not events["errors"], f"{page}: " + "\n".join(events["errors"])


# ---------------------------------------------------------------- search, served over http

@pytest.fixture(scope="module")
def served_book(book):
    """The test build served over http on a free localhost port (as `make serve` serves _build/html)."""
    import functools
    import http.server
    import threading

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args):
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Quiet, directory=str(HTML)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


@pytest.mark.browser
def test_search_shows_snippets_when_served_over_http(chromium, served_book):
    """Opened from disk the browser refuses the fetches behind the snippets; served over http
    (the README's `make serve`), the search page lists pages with a snippet of their text."""
    ctx = chromium.new_context(viewport={"width": 1366, "height": 900})
    remote = []

    def on_route(route):
        url = route.request.url
        if url.startswith((served_book, "data:", "blob:")):
            route.continue_()
        else:
            remote.append(url)
            route.abort()

    ctx.route("**/*", on_route)
    try:
        pg = ctx.new_page()
        pg.goto(f"{served_book}/search.html?q=attenuation", wait_until="load")
        pg.wait_for_function("() => document.querySelectorAll('ul.search li p.context').length > 0"
                             " && Array.from(document.querySelectorAll('ul.search li p.context'))"
                             ".some(p => p.textContent.trim().length > 20)", timeout=30_000)
        hits = pg.evaluate("() => Array.from(document.querySelectorAll('ul.search li')).map(li => "
                           "[li.querySelector('a').textContent, (li.querySelector('p.context') || {}).textContent || ''])")
        assert len(hits) >= 3, f"search for 'attenuation' found {hits}"
        with_snippet = [h for h in hits if "attenuation" in h[1].lower()]
        assert with_snippet, f"no snippet shows the searched word: {hits[:3]}"
        assert not remote, f"the search page requested from the network: {remote}"
    finally:
        ctx.close()


# ---------------------------------------------------------------- last: the published book

def test_the_session_left_the_published_book_untouched(book):
    """After everything above (the build, the browser, the screenshots), ``_build/html`` is as
    it was before the session: only `make book` writes it."""
    assert tree_fingerprint(PUBLISHED_HTML) == book["published"], f"the test session changed {PUBLISHED_HTML}"
