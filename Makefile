# pinarms — the two commands a user needs: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.pinarms-installed

.PHONY: install demo demo-quick readme-table test browser urdf bench clean docs-pictures

# Create .venv if missing and install the project with its test and benchmark extras, then compile
# every numba kernel into numba's disk cache (`pinarms warm`: minutes the first time, a few seconds
# once they are cached), so that no later process compiles them on first use.
# Idempotent: re-runs pip only when pyproject.toml changed.
install: $(STAMP)
	$(VENV)/bin/pinarms warm

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[test,bench]"
	touch $(STAMP)

# Debian's chromium for the browser tests (never a downloaded browser build).
browser:
	@if [ -x /usr/bin/chromium ]; then :; \
	elif [ "$$(id -u)" = "0" ] && command -v apt-get >/dev/null; then \
		echo "installing Debian's chromium for the browser tests"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null; \
	else echo "note: /usr/bin/chromium missing and cannot apt-get install it: browser tests will be skipped"; fi

demo: install
	$(VENV)/bin/pinarms demo --out demo-output

demo-quick: install
	$(VENV)/bin/pinarms demo --quick --out demo-output

# The full demo, and its paper-vs-pinarms table written into README.md (between its markers).
readme-table: install
	$(VENV)/bin/pinarms demo --out demo-output --readme README.md

# The whole suite in parallel: pytest-xdist with one worker per core (CI has 2). Each test file is an
# xdist group (tests/conftest.py), so a file runs in one worker and its module fixtures are built
# once; the longest files start first. Tests run at the same time as others: a test writes only
# under tmp_path, binds only port 0 (any free port), changes the environment only through
# monkeypatch, and never writes into the repository (rules in tests/README.md).
# `make test PYTEST_WORKERS=0` runs it in one process. pytest's exit code is kept (.ci/run fails on 5).
PYTEST_WORKERS ?= 2
test: install browser
	$(PY) -m pytest -q -n $(PYTEST_WORKERS) --dist loadgroup --no-loadscope-reorder tests

# The pictures of README.md and docs/ (viewer pages in headless Chromium, plots), from the tests that check them.
docs-pictures: install browser
	PINARMS_DOCS_PICTURES=1 $(PY) -m pytest -q tests/viz/test_browser.py tests/viz/test_plots.py

# Regenerate urdf/*.urdf and urdf/cells/*.urdf from robots/xacro/ (arms and cells).
urdf: install
	$(VENV)/bin/pinarms urdf build

bench: install
	for f in benchmarks/*.py; do echo "== $$f"; $(PY) $$f || exit 1; done

clean:
	rm -rf $(VENV) demo-output .pytest_cache build *.egg-info
