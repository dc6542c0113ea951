# The three commands of the README: `make book`, `make test` and `make lab`; for courses,
# `make book-student` (the book without solutions) and `make assignments` (graded assignments,
# built and graded). All create .venv from requirements.txt (pinned) on first use.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
# uv (pinned in requirements.txt, from the package registry) installs the pinned requirements: the same
# packages pip would install, downloaded in parallel; `pip check` confirms the result. Like pip, it
# compiles them to bytecode as it installs them (--compile-bytecode): where PYTHONDONTWRITEBYTECODE
# is set, as in many containers, nothing else would, and every Python process the tests, the
# chapters and the gradings start would compile each module it imports again
UV := $(VENV)/bin/uv
UV_INSTALL := $(UV) pip install --quiet --compile-bytecode --python $(PY)
STAMP := $(VENV)/.installed
LAB_STAMP := $(VENV)/.lab-installed
LAB_SETTINGS := $(VENV)/share/jupyter/lab/settings
PORT ?= 8000
LAB_ARGS ?=
# axe-core (pinned in tools/axe/package-lock.json, from the npm registry) for the accessibility audit
# of the browser tests; installed into the build folder, never downloaded at run time
AXE_DIR := _build/axe
AXE := $(AXE_DIR)/node_modules/axe-core/axe.min.js

.PHONY: book test lab serve bench test-kernels clean book-student assignments

$(STAMP): requirements.txt pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check "$$(grep '^uv==' requirements.txt)"
	$(UV_INSTALL) -r requirements.txt
	$(PY) -m pip check --disable-pip-version-check
	PYTHONWARNINGS="ignore:Editable installation" $(PY) -m pip install --quiet --no-deps -e .   # no setuptools banner
	touch $(STAMP)

# the published book, at full size, into _build/html (ORRC_QUICK is ignored here; tools.build_book sets
# ORRC_BOOK_BUILD=1 for the chapters: static frames, no progress bars)
book: $(STAMP)
	set -eo pipefail; env -u ORRC_QUICK $(PY) -m tools.build_book

# the solution-free edition, into _build/student/html (reuses a fresh `make book`'s executed chapters)
book-student: $(STAMP)
	set -eo pipefail; $(PY) -m tools.build_student

# every assignment's student notebook and autograder (_build/assignments/NAME/dist), solutions and
# blank notebooks graded with otter run; fails when a solution loses a point or a blank one gets full marks
assignments: $(STAMP)
	set -eo pipefail; $(PY) -m tools.assignments

$(AXE): tools/axe/package.json tools/axe/package-lock.json
	mkdir -p $(AXE_DIR)
	cp tools/axe/package.json tools/axe/package-lock.json $(AXE_DIR)/
	npm ci --prefix $(AXE_DIR) --no-audit --no-fund --ignore-scripts --loglevel=error
	touch $(AXE)

# the whole suite; it builds its own, shortened, book into _build/test (never _build/html); with
# make lab's JupyterLab, which tests/test_live_notebooks.py drives in Chromium, and axe-core.
# It ends with the slowest tests, the background jobs and the critical path (tests/conftest.py).
test: $(STAMP) $(LAB_STAMP) $(AXE)
	set -eo pipefail; ORRC_QUICK=1 $(PY) -m pytest -q --durations=30 tests

# JupyterLab (pinned, requirements-lab.txt) in the same .venv, chapters open as notebooks
$(LAB_STAMP): $(STAMP) requirements-lab.txt tools/jupyterlab-overrides.json
	$(UV_INSTALL) -r requirements.txt -r requirements-lab.txt
	$(PY) -m pip check --disable-pip-version-check
	mkdir -p $(LAB_SETTINGS)
	cp tools/jupyterlab-overrides.json $(LAB_SETTINGS)/overrides.json
	touch $(LAB_STAMP)

# tools/jupyter_lab_config.py: chapters open unmodified (tools/lab_contents.py), kernels over IPC
lab: $(LAB_STAMP)
	$(VENV)/bin/jupyter lab --config=tools/jupyter_lab_config.py --ServerApp.root_dir=. $(LAB_ARGS) book/preface.md

# the built book over http on localhost (search shows snippets only over http)
serve:
	$(PY) -m http.server --directory _build/html --bind 127.0.0.1 $(PORT)

bench: $(STAMP)
	set -eo pipefail; $(PY) -m benchmarks.run

# a local check, not called by `make test` or CI: the fast suite once per OpenBLAS kernel
test-kernels: $(STAMP)
	set -eo pipefail; $(PY) -m tools.test_kernels

clean:
	rm -rf _build .pytest_cache
