"""The rendered book as a reader meets it.

The book is built ONCE per test session (the ``book`` fixture of ``conftest.py``:
``tools.build_book.build``, every chapter executed, ``-n -W --keep-going``) into
``_build/`` of the repository, or into ``$ORRC_BOOK_OUT/_build`` when that variable is
set; tests/test_chapters.py checks the executed notebooks of the same build. Then

* without a browser: the build succeeded; no page loads a script, stylesheet, image
  or frame from the network (MathJax 3 is shipped in ``_static/mathjax``); no Thebe;
  every chapter has a valid ``.ipynb`` download holding the chapter's code cells;
  the execution-times page lists every chapter; no page is heavier than 3 MB;
* in headless Chromium (Playwright driving the SYSTEM Chromium, never a downloaded
  one): every page of ``_toc.yml`` opens from ``file://`` without console errors or
  network requests, its math is typeset, its images have loaded, no cell shows an
  error, and every frame slider changes its figure and its text alternative. Screenshots at 1366 px
  and 390 px go to ``_build/screenshots/<page>-1366.jpg`` / ``-390.jpg`` (JPEG: a tall page
  encodes in a third of the time of a PNG, and reads as well); at both widths the
  axe-core audit finds no serious or critical violation (reports in ``_build/screenshots/axe/``)
  and every element that runs past the text column sits in a box that scrolls, shows a cue and
  takes keyboard focus. Every image has a text alternative; the execution table's
  status marks need no emoji font.

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

from conftest import BOOK_HTML as HTML, BOOK_OUT, PUBLISHED_HTML, SHOTS, tree_fingerprint
from tools.sphinx_offline import portable_source
from tools.toc import notebook_pages, toc_pages

ROOT = Path(__file__).resolve().parents[1]
MAX_PAGE_BYTES = 3_000_000
WIDTHS = (1366, 390)

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
    assert book["rc"] == 0, ("jupyter-book build failed (a cell error or a Sphinx warning; "
                             "run `make book` to see it)")
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


def _code_cells_in_myst(text: str) -> list[str]:
    """The sources of the ```{code-cell} blocks of a MyST notebook, read with a regex (not jupytext)."""
    cells = []
    for m in re.finditer(r"^(`{3,})\{code-cell\}[^\n]*\n(.*?)^\1[ \t]*$", text, re.S | re.M):
        body = m.group(2)
        lines = body.split("\n")
        if lines and lines[0].startswith("---"):  # YAML options block
            end = lines.index("---", 1)
            lines = lines[end + 1:]
        else:
            while lines and lines[0].startswith(":") and ":" in lines[0][1:]:
                lines = lines[1:]  # short-form options (:tags: [...])
        cells.append("\n".join(lines).strip())
    return cells


@pytest.mark.parametrize("page", NOTEBOOKS, ids=page_id)
def test_every_chapter_offers_its_ipynb(book, page):
    import nbformat

    nb_path = HTML / "_sources" / f"{page}.ipynb"
    assert nb_path.is_file(), f"no .ipynb download for {page}"
    nb = nbformat.read(nb_path, as_version=4)
    nbformat.validate(nb)
    code = [c.source.strip() for c in nb.cells if c.cell_type == "code"]
    expected = [portable_source(c) for c in _code_cells_in_myst((ROOT / f"{page}.md").read_text(encoding="utf-8"))]
    assert expected, f"{page} has no code cells?"
    assert code == expected, f"{page}.ipynb does not hold the chapter's code cells"
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


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_pages_stay_light(book, page):
    size = (HTML / f"{page}.html").stat().st_size
    assert size < MAX_PAGE_BYTES, f"{page}.html is {size / 1e6:.1f} MB (frames too heavy?)"


# ---------------------------------------------------------------- the browser

AXE = ROOT / "_build" / "axe" / "node_modules" / "axe-core" / "axe.min.js"   # `make test` installs it
AXE_IMPACTS = ("serious", "critical")   # the audit fails a page on these


def axe_audit(pg, page: str, width: int) -> list[dict]:
    """Run axe-core (pinned, tools/axe/package-lock.json) on the open page; save its report to
    ``_build/screenshots/axe/<page>-<width>.json``; return the serious and critical violations."""
    import json

    if not AXE.is_file():
        msg = f"axe-core is not installed ({AXE}); `make test` installs it (npm ci, tools/axe)"
        if os.environ.get("CI"):
            pytest.fail(msg)
        pytest.skip(msg)
    # preload: false, else axe-core fetches the stylesheets again (refused from file://: console errors)
    if not pg.evaluate("() => !!window.axe"):
        pg.add_script_tag(path=str(AXE))
    result = pg.evaluate("""() => axe.run(document, {resultTypes: ['violations'], preload: false}).then(r => ({
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
  column.querySelectorAll('div.math, mjx-container, pre, table, p, code, img').forEach(e => {
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


# the session's one Chromium: the `chromium` fixture of conftest.py (shared with tests/test_live_notebooks.py)


# every remote request is refused and recorded, so an offline failure shows up here too
def _open(chromium, page, width):
    ctx = chromium.new_context(viewport={"width": width, "height": 900}, device_scale_factor=1)
    events = {"errors": [], "remote": []}

    def on_route(route):
        url = route.request.url
        if url.startswith(("file:", "data:", "blob:")):
            route.continue_()
        else:
            events["remote"].append(url)
            route.abort()

    ctx.route("**/*", on_route)
    pg = ctx.new_page()
    pg.on("console", lambda m: events["errors"].append(f"console.{m.type}: {m.text}") if m.type == "error" else None)
    pg.on("pageerror", lambda e: events["errors"].append(f"page error: {e}"))
    pg.goto((HTML / f"{page}.html").as_uri(), wait_until="load")
    # MathJax typesets after load; wait for it where the page loads it
    if pg.evaluate("() => !!document.querySelector('script[src*=\"mathjax\"]')"):
        from playwright.sync_api import TimeoutError as PlaywrightTimeout

        try:
            pg.wait_for_function("() => window.MathJax && MathJax.startup && MathJax.startup.promise",
                                 timeout=30_000)
        except PlaywrightTimeout:
            ctx.close()
            raise AssertionError(f"{page}: MathJax never started (refused network requests: {events['remote']}; "
                                 f"errors: {events['errors']})") from None
        pg.evaluate("() => MathJax.startup.promise")
    pg.evaluate("""() => Promise.all(Array.from(document.images).map(img => {
        img.loading = 'eager';
        return img.complete ? null : new Promise(r => { img.onload = img.onerror = r; });
    }))""")
    return ctx, pg, events


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


@pytest.mark.browser
@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_page_in_a_real_browser(chromium, book, page):
    assert book["rc"] == 0, "the book did not build"
    ctx, pg, events = _open(chromium, page, WIDTHS[0])
    try:
        # math typeset: every math node became a MathJax container, no raw TeX left in the text
        untypeset = pg.evaluate("() => Array.from(document.querySelectorAll('span.math, div.math'))"
                                ".filter(e => !e.querySelector('mjx-container')).map(e => e.textContent.slice(0, 60))")
        assert not untypeset, f"{page}: math not typeset: {untypeset[:5]}"
        if pg.locator("span.math, div.math").count():
            assert pg.locator("mjx-container [data-mjx-error], mjx-merror").count() == 0, f"{page}: TeX errors"
        text = pg.evaluate(_TEXT_OUTSIDE_CODE)
        for raw in ("$$", "\\(", "\\[", "\\begin{"):
            assert raw not in text, f"{page}: raw TeX {raw!r} left in the rendered text"

        # every image has loaded
        broken = pg.evaluate("() => Array.from(document.images)"
                             ".filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src.slice(0, 80))")
        assert not broken, f"{page}: images not loaded: {broken}"

        # no cell shows an error
        assert pg.locator(".cell_output .output.traceback, .output.error").count() == 0, f"{page}: a cell error"
        for err in pg.locator(".cell_output .output.stderr").all_inner_texts():
            assert "Traceback" not in err and not re.search(r"\b\w*Error\b", err), f"{page}: stderr {err[:200]}"

        # screenshots at a laptop and a phone width
        SHOTS.mkdir(parents=True, exist_ok=True)
        for width in WIDTHS:  # taken before the sliders are touched, so the page is as a reader first sees it
            pg.set_viewport_size({"width": width, "height": 900})
            pg.evaluate("() => window.scrollTo(0, 0)")  # sticky sidebars are drawn where the page is scrolled
            # two animation frames: the new width laid out and painted before the picture
            pg.evaluate("() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
            # caret="initial": no text caret to hide on these pages, and hiding it (the default) restyles
            # the whole page twice, a stylesheet put in and taken out (0.1 to 0.4 s a screenshot of a tall page)
            pg.screenshot(path=str(SHOTS / f"{page_id(page)}-{width}.jpg"), full_page=True, quality=85,
                          caret="initial")
            # nothing makes the whole page scroll sideways (wide equations and tables scroll in their own box)
            overflow = pg.evaluate("() => document.documentElement.scrollWidth - document.documentElement.clientWidth")
            assert overflow <= 1, f"{page}: the page is {overflow}px wider than a {width}px screen"
            # every block wider than its box scrolls in it, with a visible cue, and takes keyboard focus
            pg.evaluate("() => window.orrcMarkOverflow && window.orrcMarkOverflow()")
            for box in pg.evaluate(_OVERFLOWING):
                assert box["overflowX"] in ("auto", "scroll"), f"{page} at {width} px: clipped, no scrolling: {box}"
                assert box["cue"] and box["shadow"] != "none", f"{page} at {width} px: scrolls without a cue: {box}"
                assert box["tabindex"] == "0" and box["label"], f"{page} at {width} px: not keyboard-scrollable: {box}"
            # the accessibility audit: no serious or critical violation (report beside the screenshots)
            bad = axe_audit(pg, page, width)
            assert not bad, f"{page} at {width} px: axe-core: " + "; ".join(
                f"{v['impact']} {v['id']} ({v['help']}): {[n['target'] for n in v['nodes'][:3]]}" for v in bad)
            # every figure legible: shown at >= 100 px per figure inch (its fonts of >= 9 pt at >= 12.5 px)
            # and inside the screen
            for fig in pg.evaluate(_SHOWN_IMAGES):
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
        for i in range(frames.count()):
            box = frames.nth(i)
            imgs = box.locator("img.orrc-frame")
            assert imgs.count() in (1, 2) and box.locator("input.orrc-slider").count() >= 1
            handles = [imgs.nth(k).element_handle() for k in range(imgs.count())]
            for j in range(box.locator("input.orrc-slider").count()):
                slider = box.locator("input.orrc-slider").nth(j)
                top = int(slider.get_attribute("max"))
                if top == 0:
                    continue
                before = [h.get_attribute("src") for h in handles]
                before_alt = [h.get_attribute("alt") for h in handles]
                before_label = box.locator("output").nth(j).inner_text()
                start = int(slider.input_value())
                slider.fill(str(top if start != top else 0))
                for h, src in zip(handles, before):
                    pg.wait_for_function("([el, s]) => el.src !== s", arg=[h, src], timeout=5_000)
                    assert pg.evaluate("(el) => el.naturalWidth > 0", h), f"{page}: new frame broken"
                assert box.locator("output").nth(j).inner_text() != before_label, f"{page}: label did not follow"
                # the text alternative follows the frame: the new frame's parameter value is in it
                name, label = slider.get_attribute("data-name"), box.locator("output").nth(j).inner_text()
                for h, alt in zip(handles, before_alt):
                    now = h.get_attribute("alt")
                    assert now != alt and f"{name} = {label}" in now, (
                        f"{page}: the image's text alternative did not follow the slider ({name} = {label}): {now[:120]}")
                slider.fill(str(start))  # and back
                for h, src in zip(handles, before):
                    pg.wait_for_function("([el, s]) => el.src === s", arg=[h, src], timeout=5_000)

        assert not events["remote"], f"{page}: requested from the network: {events['remote']}"
        assert not events["errors"], f"{page}: " + "\n".join(events["errors"])
    finally:
        ctx.close()


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
