# The two commands of the README: `make book` and `make test`.
# Both create .venv from requirements.txt (pinned) on first use.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: book test bench test-kernels clean

$(STAMP): requirements.txt pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -r requirements.txt
	$(PY) -m pip install --quiet --no-deps -e .
	touch $(STAMP)

book: $(STAMP)
	set -eo pipefail; $(PY) -m tools.build_book

test: $(STAMP)
	set -eo pipefail; ORRC_QUICK=1 $(PY) -m pytest -q tests

bench: $(STAMP)
	set -eo pipefail; $(PY) -m benchmarks.run

# a local check, not called by `make test` or CI: the fast suite once per OpenBLAS kernel
test-kernels: $(STAMP)
	set -eo pipefail; $(PY) -m tools.test_kernels

clean:
	rm -rf _build .pytest_cache
