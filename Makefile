# The two commands of the README: `make book` and `make test`; for courses, `make book-student`
# (the book without solutions) and `make assignments` (graded assignments, built and graded).
# All create .venv from requirements.txt (pinned) on first use.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: book test bench test-kernels clean book-student assignments

$(STAMP): requirements.txt pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -r requirements.txt
	$(PY) -m pip install --quiet --no-deps -e .
	touch $(STAMP)

book: $(STAMP)
	set -eo pipefail; $(PY) -m tools.build_book

# the solution-free edition, into _build/student/html (reuses a fresh `make book`'s executed chapters)
book-student: $(STAMP)
	set -eo pipefail; $(PY) -m tools.build_student

# every assignment's student notebook and autograder (_build/assignments/NAME/dist), solutions and
# blank notebooks graded with otter run; fails when a solution loses a point or a blank one gets full marks
assignments: $(STAMP)
	set -eo pipefail; $(PY) -m tools.assignments

test: $(STAMP)
	set -eo pipefail; ORRC_QUICK=1 $(PY) -m pytest -q tests

bench: $(STAMP)
	set -eo pipefail; $(PY) -m benchmarks.run

# a local check, not called by `make test` or CI: the fast suite once per OpenBLAS kernel
test-kernels: $(STAMP)
	set -eo pipefail; $(PY) -m tools.test_kernels

clean:
	rm -rf _build .pytest_cache
