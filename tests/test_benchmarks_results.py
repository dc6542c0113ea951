"""The benchmarks' results file: what ``make bench`` writes is what the book's benchmarks page reads.

The page (book/benchmarks.md, ``tools/sphinx_benchmarks.py``) is built from the committed
``benchmarks/results.json``; these tests check that the file is a full run with the machine and the
versions, that a run writes such a file, and that the page's reader turns it into a table and figures.
"""
import json

import pytest

from benchmarks import run
from benchmarks.common import fmt_time, parse_time
from tools import sphinx_benchmarks as page


@pytest.mark.parametrize("seconds", [3.2e-7, 7.72e-5, 0.101, 0.999, 1.0, 42.5])
def test_parse_time_reads_what_fmt_time_writes(seconds):
    text = fmt_time(seconds) + " (wall)"
    assert parse_time(text) == pytest.approx(seconds, rel=5e-3)


@pytest.mark.parametrize("text", ["skipped", "—", "Σc 1.189", "", "dyn. regret 0.27"])
def test_parse_time_finds_no_time_where_there_is_none(text):
    assert parse_time(text) is None


def test_a_run_writes_the_results_file_the_page_reads(tmp_path):
    out = tmp_path / "results.json"
    assert run.main(["--quick", "--only", "lq", "--results", str(out)]) == 0
    doc = page.load(out)
    assert doc["quick"] is True and doc["failures"] == []
    assert doc["machine"]["cores"] >= 1 and doc["machine"]["blas_threads"]
    assert {"python", "orrc", "numpy", "scipy", "casadi", "python-control"} <= set(doc["versions"])
    assert doc["rows"] and all(r["module"] == "lq" for r in doc["rows"])
    timed = [r for r in doc["rows"] if r["orrc_seconds"] is not None]
    assert timed and all(r["orrc_seconds"] > 0 for r in timed)
    fig = page.figure("lq", doc["rows"])
    assert fig is not None and len(fig.axes[0].patches) >= len(timed)


def test_a_quick_run_leaves_the_committed_results_alone(monkeypatch, tmp_path):
    target = tmp_path / "results.json"
    monkeypatch.setattr(run, "RESULTS", target)
    assert run.main(["--quick", "--only", "lq"]) == 0
    assert not target.exists()


def test_the_committed_results_are_a_full_run_with_versions_and_machine():
    doc = page.load(run.RESULTS)
    assert doc["quick"] is False, "benchmarks/results.json must come from a full `make bench`"
    assert doc["machine"]["cpu"] and doc["machine"]["load_average"]["start"] is not None
    modules = {r["module"] for r in doc["rows"]}
    assert modules <= set(run.MODULES) and modules
    assert set(page.TITLES) == set(run.MODULES), "every benchmark needs a title on the page"
    for r in doc["rows"]:
        assert r["orrc_seconds"] == parse_time(r["orrc"]) and r["peer_seconds"] == parse_time(r["peer"])


def test_a_missing_results_file_is_a_clear_error(tmp_path):
    with pytest.raises(page.BenchmarksError, match="make bench"):
        page.load(tmp_path / "nothing.json")
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"rows": []}))
    with pytest.raises(page.BenchmarksError, match="date"):
        page.load(bad)
