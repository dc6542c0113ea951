"""The repository's files speak of the project, not of how it was made: no tracked file (except the
changelog, whose subject is the history) names a work ticket or a round of work."""
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# a ticket number after "issue", a round of work by number or by name: the ways the history of the
# work crept into files
HISTORY = re.compile(r"issue [0-9]|round (one|two|three|four|five)|rounds? [0-9]")
EXEMPT = {"CHANGELOG.md"}


def tracked_files() -> list[Path]:
    out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    return [ROOT / name for name in out.decode().split("\0") if name and name not in EXEMPT]


def test_the_pattern_finds_what_it_is_meant_to_find():
    # the samples are assembled here, so that this file does not match its own pattern
    for text in ("after issue" + " 22's fourth round", "since round" + " two", "rounds" + " 3 and 4", "(issue" + " 9)"):
        assert HISTORY.search(text), text
    for text in ("an issue with the solver", "rounded to 3 digits", "round-off of 1e-16"):
        assert not HISTORY.search(text), text


def test_no_tracked_file_tells_the_history_of_its_making():
    files = tracked_files()
    assert len(files) > 50, "git ls-files found too few files: is this a git checkout?"
    hits = []
    for path in files:
        try:
            text = path.read_text(encoding="utf-8")
        except (UnicodeDecodeError, FileNotFoundError, IsADirectoryError):
            continue  # binary files, and files deleted but not yet committed
        for n, line in enumerate(text.splitlines(), 1):
            if HISTORY.search(line):
                hits.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()[:100]}")
    assert not hits, "development history in tracked files:\n" + "\n".join(hits)
