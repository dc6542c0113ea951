"""The chapters as live notebooks in JupyterLab, driven in Chromium as a student uses them.

``make lab``'s JupyterLab (requirements-lab.txt, in ``.venv``; ``make test`` installs it) is started
once for this module, on a free localhost port with a token, with ``make lab``'s configuration
(tools/jupyter_lab_config.py) over a copy of ``book/`` (so that the edits below never touch the
repository), kernels at the test size (ORRC_QUICK=1). Chromium (the session's one, conftest.py)
opens chapters from it:

* a chapter opens unmodified and closes without asking to save;
* Run All completes without an error; the prose shows the numbers (``{eval}`glued(...)```
  evaluated by jupyterlab-myst), no glue key or expression; no claim note on the chapter's
  own values; solutions are folded with their code cells, no empty box where they end;
* a what-if edit (the first experiment's preview length M = 5 changed to M = 1, in the page that ran
  the chapter) runs to the end, with a note under each claim that no longer holds.

One chapter, the shortest run: every chapter is executed by the session's book build; here the
live front end is under test (the numbers in the prose, the folds, the notes), which one chapter
shows as well as several.

Screenshots: ``_build/screenshots/lab-*.png``.
"""
from __future__ import annotations

import json
import os
import re
import secrets
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from conftest import ROOT, SHOTS

pytestmark = [pytest.mark.browser, pytest.mark.slow]

JUPYTER_LAB = Path(sys.executable).parent / "jupyter-lab"
RUN_ALL_TIMEOUT = 300_000   # ms, one chapter at the test size on a busy 2-core machine
EXPRESSIONS_TIMEOUT = 10_000   # ms, the last Markdown cells' expressions after the last code cell ran
CHAPTERS = ["book/problem"]   # the shortest run
# a reader's what-if edit: the first experiment's preview, M = 5 -> M = 1; the preview controller
# then no longer cancels most of a burst, which the text claims for M = 5
WHAT_IF = ("book/problem", r"T, M = 200, 5", "T, M = 200, 1",
           "the preview controller cancels most of a burst")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """``make lab``'s JupyterLab over a copy of book/: {"url", "token", "root", "log"}."""
    if not JUPYTER_LAB.is_file():
        msg = f"JupyterLab is not installed in {JUPYTER_LAB.parent}: `make .venv/.lab-installed` (make test does it)"
        if os.environ.get("CI"):
            pytest.fail(msg)
        pytest.skip(msg)
    home = tmp_path_factory.mktemp("lab")
    root = home / "root"
    shutil.copytree(ROOT / "book", root / "book")
    settings = home / "settings" / "@jupyterlab" / "notebook-extension"
    settings.mkdir(parents=True)
    # no settings of the test's own: make lab's overrides (tools/jupyterlab-overrides.json, in the
    # environment's share/jupyter/lab/settings) decide, as they do for a reader: no windowing, so
    # Run All shows every number whatever was on screen
    overrides = Path(sys.prefix) / "share" / "jupyter" / "lab" / "settings" / "overrides.json"
    tracker = json.loads(overrides.read_text())["@jupyterlab/notebook-extension:tracker"]
    assert tracker["windowingMode"] == "none", f"make lab's {overrides} leaves windowing on"
    token, port = secrets.token_hex(16), _free_port()
    env = {k: v for k, v in os.environ.items() if k not in ("ORRC_BOOK_BUILD", "JUPYTER_CONFIG_DIR")}
    env.update(ORRC_QUICK="1", JUPYTER_CONFIG_DIR=str(home / "config"), JUPYTER_RUNTIME_DIR=str(home / "runtime"),
               JUPYTERLAB_WORKSPACES_DIR=str(home / "workspaces"), JUPYTERLAB_SETTINGS_DIR=str(home / "settings"),
               MPLBACKEND="module://matplotlib_inline.backend_inline")
    cmd = [str(JUPYTER_LAB), "--no-browser", f"--config={ROOT / 'tools' / 'jupyter_lab_config.py'}",
           f"--ServerApp.root_dir={root}", f"--port={port}", "--ServerApp.port_retries=0",
           "--ServerApp.ip=127.0.0.1", f"--IdentityProvider.token={token}"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        cmd.append("--allow-root")   # a container
    log = open(home / "server.log", "w")
    proc = subprocess.Popen(cmd, cwd=root, env=env, stdout=log, stderr=subprocess.STDOUT)
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 120
        while True:
            try:
                with urllib.request.urlopen(f"{url}/api/status?token={token}", timeout=5) as r:
                    if r.status == 200:
                        break
            except OSError:
                pass
            if proc.poll() is not None or time.monotonic() > deadline:
                log.flush()
                pytest.fail(f"JupyterLab did not start:\n{(home / 'server.log').read_text()[-3000:]}")
            time.sleep(0.5)
        yield {"url": url, "token": token, "root": root, "log": home / "server.log"}
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        log.close()


def open_chapter(chromium, lab, chapter: str):
    """A fresh page (and JupyterLab workspace) with ``chapter`` open, its kernel idle."""
    ctx = chromium.new_context(viewport={"width": 1366, "height": 900}, device_scale_factor=1)
    page = ctx.new_page()
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    workspace = f"t{secrets.token_hex(4)}"
    page.goto(f"{lab['url']}/lab/workspaces/{workspace}/tree/{chapter}.md?token={lab['token']}&reset")
    page.wait_for_selector(".jp-Notebook .jp-Cell", timeout=120_000)
    page.wait_for_function("() => /\\| Idle/.test(document.querySelector('.jp-StatusBar-Widget, #jp-main-statusbar')"
                           "?.innerText || '')", timeout=120_000)
    page.wait_for_timeout(1500)   # the kernel's info has reached the notebook's metadata
    return ctx, page, errors


def settle(page, condition: str, arg=None, timeout: float = 5_000) -> None:
    """Wait until ``condition`` (a function of ``arg``) holds in the page, at most ``timeout`` ms, and go
    on either way: what follows reads the page and reports what is wrong."""
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    try:
        page.wait_for_function(condition, arg=arg, timeout=timeout)
    except PlaywrightTimeout:
        pass


def dirty(page) -> int:
    return page.locator(".lm-DockPanel .lm-TabBar-tab.jp-mod-dirty").count()


def run_all(page) -> float:
    """Run All from the Run menu; seconds until every cell has run and the kernel is idle."""
    t0 = time.perf_counter()
    page.click(".lm-MenuBar-itemLabel:text-is('Run')")
    page.click(".lm-Menu-itemLabel:text-is('Run All Cells')")
    page.wait_for_function(
        """() => { const prompts = [...document.querySelectorAll('.jp-CodeCell .jp-InputArea-prompt')];
                   const ind = document.querySelector('.jp-Notebook-ExecutionIndicator');
                   return prompts.length && prompts.every(p => /\\[\\d+\\]/.test(p.textContent))
                          && ind && ind.dataset.status === 'idle' }""", timeout=RUN_ALL_TIMEOUT)
    # the last Markdown cells' expressions: evaluated once no cell's prose shows one unevaluated (one
    # that stays so is reported by the test that reads the prose)
    settle(page, """() => ![...document.querySelectorAll('.jp-Notebook .jp-MarkdownCell')]
        .some(c => /glued\\(|\\{glue:text\\}|\\{eval\\}/.test((c.querySelector('.myst') || c).innerText))""",
           timeout=EXPRESSIONS_TIMEOUT)
    return time.perf_counter() - t0


def page_state(page) -> dict:
    """What a reader sees: the rendered prose, the errors and claim notes in the outputs, and the
    solutions (closed ones, their code cells shown or not, empty boxes)."""
    return page.evaluate(r"""() => {
        const cells = [...document.querySelectorAll('.jp-Notebook .jp-Cell')];
        const prose = cells.filter(c => c.classList.contains('jp-MarkdownCell'))
                           .map(c => (c.querySelector('.myst') || c).innerText).join('\n');
        const outputs = [...document.querySelectorAll('.jp-OutputArea-output')];
        const errors = outputs.filter(o => o.dataset.mimeType === 'application/vnd.jupyter.stderr'
                                           && /Error|Traceback/.test(o.innerText)).map(o => o.innerText.slice(0, 300));
        const notes = outputs.map(o => o.innerText).filter(t => t.includes('no longer holds'));
        let shownSolutionCode = 0, closedSolutions = 0;
        cells.forEach((c, i) => {
            const last = c.querySelector('.myst > details.myst-exercise:last-child');
            if (!last || last.open) return;
            closedSolutions += 1;
            for (let j = i + 1; j < cells.length && cells[j].classList.contains('jp-CodeCell'); j++)
                if (cells[j].offsetHeight > 0) shownSolutionCode += 1;
        });
        const emptyBoxes = [...document.querySelectorAll('.jp-Notebook aside.myst-exercise')]
            .filter(a => a.offsetHeight > 0 && !a.innerText.trim()).length;
        const visibleHidden = cells.filter(c => c.classList.contains('jp-CodeCell')
            && c.querySelector('.jp-InputArea-editor') && /orrc\.config\.size\(/.test(c.innerText)).length;
        return {prose, errors, notes, closedSolutions, shownSolutionCode, emptyBoxes, visibleHidden,
                expressions: cells.filter(c => c.classList.contains('jp-MarkdownCell'))
                                  .map(c => c.querySelectorAll('.myst span:not([class])').length).reduce((a, b) => a + b, 0)};
    }""")


GLUE_KEY = re.compile(r"glued\(|\{glue:text\}|\{eval\}")


@pytest.mark.parametrize("chapter", ["book/preface"])
def test_an_untouched_chapter_opens_unmodified_and_closes_without_asking(chromium, lab, chapter):
    ctx, page, errors = open_chapter(chromium, lab, chapter)
    try:
        assert dirty(page) == 0, f"{chapter} is marked modified after its kernel started"
        page.wait_for_timeout(3000)
        assert dirty(page) == 0, f"{chapter} became modified while idle"
        page.locator(".lm-DockPanel .lm-TabBar-tab").first.hover()
        page.locator(".lm-DockPanel .lm-TabBar-tab .lm-TabBar-tabCloseIcon").first.click()
        name = chapter.split("/")[-1] + ".md"
        # closed, or a dialog asks something (either is what the test reads next)
        settle(page, "(name) => ![...document.querySelectorAll('.lm-DockPanel .lm-TabBar-tab')]"
                     ".some(t => t.innerText.includes(name)) || !!document.querySelector('.jp-Dialog')", name)
        dialogs = page.locator(".jp-Dialog").count()
        SHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SHOTS / f"lab-close-{chapter.split('/')[-1]}.png"))
        assert dialogs == 0, f"closing the untouched {chapter} asked something (a save dialog)"
        assert page.locator(".lm-DockPanel .lm-TabBar-tab", has_text=name).count() == 0, f"{name} is still open"
    finally:
        ctx.close()


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_run_all_shows_the_numbers_and_folds_the_solutions_and_a_what_if_runs_to_the_end(chromium, lab, chapter):
    """Run All on the chapter as it is; then, in the chapter of the what-if (in the same page, so
    its first run is not repeated), the edit and Run All again."""
    ctx, page, errors = open_chapter(chromium, lab, chapter)
    name = chapter.split("/")[-1]
    try:
        assert dirty(page) == 0, f"{chapter} is marked modified after its kernel started"
        before = page_state(page)
        assert before["closedSolutions"] >= 1 and before["shownSolutionCode"] == 0, \
            f"{chapter}: the code cells of a closed solution are shown: {before['shownSolutionCode']}"
        assert before["emptyBoxes"] == 0, f"{chapter}: {before['emptyBoxes']} empty boxes (solution ends)"
        assert before["visibleHidden"] == 0, f"{chapter}: a size switch is open in the notebook"
        seconds = run_all(page)
        after = page_state(page)
        SHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SHOTS / f"lab-{name}.png"))
        assert not after["errors"], f"{chapter}: errors after Run All: {after['errors'][:3]}"
        keys = sorted(set(GLUE_KEY.findall(after["prose"])))
        shown = [m.group(0) for m in re.finditer(r".{40}glued\(.{30}", after["prose"])][:3]
        assert not keys, f"{chapter}: after Run All the prose still shows {keys}: {shown}"
        assert not after["notes"], f"{chapter}: a claim of the text fails on the chapter's own values: {after['notes']}"
        assert after["shownSolutionCode"] == 0 and after["emptyBoxes"] == 0
        assert not errors, f"{chapter}: page errors {errors[:3]}"
        print(f"{chapter}: Run All {seconds:.0f} s")
        if chapter == WHAT_IF[0]:
            what_if(page)
    finally:
        ctx.close()


def what_if(page):
    """The first experiment's preview length changed from M = 5 to M = 1 and Run All: the chapter
    runs to the end, and the claim "the preview controller cancels most of a burst" shows its note."""
    chapter, pattern, replacement, statement = WHAT_IF
    source = (ROOT / f"{chapter}.md").read_text(encoding="utf-8")
    assert re.search(pattern, source), f"{chapter} has no line {pattern!r} any more: update WHAT_IF"
    found = page.locator(".jp-CodeCell .cm-content").filter(has_text=re.compile(pattern))
    assert found.count() == 1, f"{chapter}: {found.count()} cells match {pattern!r}"
    editor = found.element_handle()   # the same cell after its text changes
    old = editor.inner_text()
    editor.click()
    page.keyboard.press("Control+a")
    page.keyboard.insert_text(re.sub(pattern, replacement, old))
    page.keyboard.press("Escape")
    assert replacement in editor.inner_text()
    seconds = run_all(page)
    state = page_state(page)
    note = page.locator(".jp-OutputArea-output", has_text="no longer holds").first
    if note.count():
        note.scroll_into_view_if_needed()
    SHOTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(SHOTS / "lab-what-if.png"))
    assert not state["errors"], f"{chapter} with {replacement}: errors {state['errors'][:3]}"
    assert any(statement in n for n in state["notes"]), \
        f"{chapter} with {replacement}: no note that {statement!r} no longer holds; notes: {state['notes']}"
    assert all("expected after changing a parameter" in n for n in state["notes"])
    print(f"{chapter} with {replacement}: Run All {seconds:.0f} s, {len(state['notes'])} notes")


def test_the_server_and_its_kernels_start_quietly(lab):
    """After the chapters above ran: no kernel warned "running over TCP without encryption" (the
    kernels use IPC), no websocket ping warning, and no page's connection was closed for a ping
    timeout (the what-if's page stays open past one ping interval; tools/jupyter_lab_config.py)."""
    log = lab["log"].read_text(encoding="utf-8", errors="replace")
    assert "Kernel started" in log
    noisy = [line[:160] for line in log.splitlines()
             if "without encryption" in line or "websocket_ping_timeout" in line or "ping timeout" in line]
    assert not noisy, f"warnings at the start of the server or a kernel: {noisy}"
