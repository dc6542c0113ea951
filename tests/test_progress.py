"""orrc.progress: a progress bar where a reader watches (a live kernel, a terminal), nothing in the
book's build (ORRC_BOOK_BUILD=1): the executed chapters keep no progress output and no stderr."""
import importlib

import orrc

progress_module = importlib.import_module("orrc._progress")


def test_in_the_book_build_the_loop_is_returned_unchanged(monkeypatch):
    monkeypatch.setenv("ORRC_BOOK_BUILD", "1")
    monkeypatch.setattr(progress_module.sys.stderr, "isatty", lambda: True, raising=False)
    items = [1, 2, 3]
    assert not progress_module.watched()
    assert orrc.progress(items, desc="x") is items


def test_where_a_reader_watches_it_is_a_tqdm_bar_over_the_same_items(monkeypatch):
    from tqdm.auto import tqdm

    monkeypatch.delenv("ORRC_BOOK_BUILD", raising=False)
    monkeypatch.setattr(progress_module, "watched", lambda: True)
    bar = orrc.progress({"a": 1, "b": 2}.items(), desc="runs", delay=0)
    assert isinstance(bar, tqdm) and bar.total == 2 and bar.desc == "runs"
    assert list(bar) == [("a", 1), ("b", 2)]


def in_a_kernel_live_and_built(code: str) -> tuple[list, list]:
    """The messages of ``code`` run in a real kernel as a live notebook, then with ORRC_BOOK_BUILD=1."""
    from benchmarks.widgets import ROOT, Kernel, kernel_env

    k = Kernel(ROOT / "book", kernel_env(quick=False))
    try:
        return k.run(code), k.run("import os; os.environ['ORRC_BOOK_BUILD'] = '1'\n" + code)
    finally:
        k.close()


def test_in_a_kernel_a_widget_bar_and_in_the_build_nothing():
    """A real kernel: without the build signal the bar is a widget (tqdm.auto in a notebook), and
    nothing goes to stderr; with ORRC_BOOK_BUILD=1 the cell outputs only what it prints itself."""
    code = "import orrc\nprint(sum(orrc.progress(range(5), desc='runs', delay=0)))"
    live, built = in_a_kernel_live_and_built(code)
    for msgs in (live, built):
        assert [m["content"]["text"] for m in msgs if m["msg_type"] == "stream"] == ["10\n"]
    assert any("application/vnd.jupyter.widget-view+json" in m["content"].get("data", {})
               for m in live if m["msg_type"] == "display_data")
    assert not [m for m in built if m["msg_type"] in ("display_data", "update_display_data")]


def test_a_long_call_shows_one_status_line_in_a_kernel_and_nothing_in_the_build():
    """orrc._progress.working: a status line while the block runs, emptied when it was quick,
    "done in ... s" when it took longer than ``delay``; in the build nothing at all."""
    code = ("import time\nfrom orrc._progress import working\n"
            "with working('solving', delay=0.2):\n    time.sleep(0.4)\n"
            "with working('quick', delay=5):\n    pass\nprint('after')")
    live, built = in_a_kernel_live_and_built(code)
    shown = [m["content"]["data"]["text/plain"] for m in live if m["msg_type"] == "display_data"]
    updated = [m["content"]["data"]["text/plain"] for m in live if m["msg_type"] == "update_display_data"]
    assert shown == ["\u23f3 solving \u2026", "\u23f3 quick \u2026"]
    assert updated[0].startswith("solving: done in 0.") and updated[1] == ""
    assert [m["content"]["text"] for m in built if m["msg_type"] == "stream"] == ["after\n"]
    assert not [m for m in built if m["msg_type"] in ("display_data", "update_display_data")]

