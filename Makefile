# Two set-up commands for a fresh machine: `make demo` and `make test`.
# Each creates .venv and installs the package (with its test extras) when it is not there;
# installing also compiles the simulator's numba kernels into their on-disk cache, so no
# first run pays that.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test test-slow browser lint lint-imports docs wheel-check clean

# The dependencies go in with uv (itself installed from PyPI by pip), 7x (cold cache) to
# 20x faster than pip (docs/results/speed.md, session 15); pip installs them when uv cannot
# be had. uv reads no pip configuration: a private index is given to it as UV_INDEX_URL /
# UV_EXTRA_INDEX_URL.
$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(INSTALL) -e '.[dev]'
	$(PRECOMPILE)
	touch $(STAMP)

# uv writes no bytecode: compile it (as pip does; a failure is not fatal there either) while
# numba compiles the simulator's kernels, one core each. Without it, every first import
# compiles, and a loky worker killed mid-import outlives its parent (test_reliability.py).
# The packages' own test folders (a third of the files, never imported here) are skipped.
PRECOMPILE = { $(BIN)/python -m compileall -q -j 0 -x '/tests?/' $(VENV)/lib >/dev/null 2>&1 || true; } & \
	pyc=$$!; $(BIN)/python -m suds_exp.sim.precompile; rc=$$?; wait $$pyc; exit $$rc

# `$(INSTALL) ARGS`: uv's `pip install ARGS` into the venv, else pip's
INSTALL = install() { \
	  { test -x $(BIN)/uv || $(BIN)/python -m pip install --quiet uv; } \
	  && $(BIN)/uv pip install --quiet --python $(BIN)/python "$$@" \
	  || { echo "uv unavailable: installing with pip"; \
	       $(BIN)/python -m pip install --quiet --upgrade pip \
	       && $(BIN)/python -m pip install --quiet "$$@"; }; }; install

demo: $(STAMP)
	$(BIN)/suds-exp demo

# two worker processes, each test file on one of them (its module fixtures built once);
# files in collection order (tests/conftest.py puts the slowest first), not by test count
test: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile --no-loadscope-reorder

# The slow suite screenshots the report with a headless browser; Debian's chromium is
# installed here (never in `make test`) when apt-get is usable, else that test skips.
test-slow: $(STAMP) browser
	$(BIN)/python -m pytest -q -m slow

browser:
	@command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 \
	  || (apt-get update -qq && apt-get install -y -qq chromium) \
	  || echo "no chromium installed: the report screenshot test will skip"

lint: $(STAMP)
	$(BIN)/ruff check .

# the layering contracts in pyproject.toml ([tool.importlinter])
lint-imports: $(STAMP)
	$(BIN)/lint-imports

# The documentation site (mkdocs.yml) into site/, warnings as errors, then every local link
# checked as a reader opening the files would follow it; needs the docs extra.
DOCS_STAMP := $(VENV)/.docs-installed
$(DOCS_STAMP): $(STAMP)
	$(INSTALL) -e '.[dev,docs]'
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict
	$(BIN)/python docs/hooks/check_site.py site

# build the sdist and wheel, install the wheel in a fresh venv outside the checkout and run
# a short quickstart from an empty folder (.ci/wheel_check.sh; run by .ci/run)
wheel-check: $(STAMP)
	PY=$(PY) bash .ci/wheel_check.sh

clean:
	rm -rf $(VENV) *.duckdb *.duckdb.lock reports/*/ sim-data site
