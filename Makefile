# flexsat — the two entry points: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
DEV    := $(VENV)/.installed-dev

.PHONY: demo test bench lint clean chromium

# The demo installs what the study needs and nothing else (no test or lint tools).
$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e .
	touch $(STAMP)

# Tests, lint and benchmarks add the dev extra (pytest, hypothesis, ruff, playwright).
$(DEV): $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(DEV)

demo: $(STAMP)
	$(BIN)/flexsat study --quick --out out
	@echo "Report of the nominal study: $(CURDIR)/out/report.html"

# The report's browser test renders it in Debian's Chromium, installed here when missing
# (as root, or with sudo); if that fails the test says so and is skipped.
chromium:
	@command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 || { \
	  SUDO=$$([ "$$(id -u)" = 0 ] || echo sudo); \
	  echo "installing Chromium for the report's browser test..."; \
	  { $$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium || \
	    { $$SUDO apt-get update -q && $$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium; }; } >/dev/null 2>&1 || \
	  echo "Chromium could not be installed: the report's browser test will be skipped."; }

# The suite runs on TEST_WORKERS processes (pytest-xdist), a test file per process at a
# time so that module fixtures are computed once (docs/performance.md, "The test suite").
TEST_WORKERS ?= 2
test: $(DEV) chromium
	$(BIN)/ruff check src tests bench examples
	$(BIN)/ruff format --check src tests bench examples
	$(BIN)/python -m pytest -q -n $(TEST_WORKERS) --dist loadfile --durations=15
	$(MAKE) docs

# Every benchmark and the table of performance targets (docs/performance.md); the
# optional `bench` extra adds Basilisk, the peer flexsat is compared with.
bench: $(DEV)
	$(BIN)/python -m pip install --quiet -e '.[dev,bench]'
	$(BIN)/python bench/run_all.py

# The documentation site (docs/documentation.md): Sphinx builds it, every example of the
# gallery is executed, and a warning is an error (outputs: docs/.gitignore).
.PHONY: docs
DOCS_STAMP := $(VENV)/.docs-installed
$(DOCS_STAMP): pyproject.toml $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[docs]'
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	MPLBACKEND=Agg $(BIN)/python -m sphinx -W --keep-going -q docs docs/_build/html
	@echo "Documentation: $(CURDIR)/docs/_build/html/index.html"

lint: $(DEV)
	$(BIN)/ruff check src tests bench examples
	$(BIN)/ruff format --check src tests bench examples

clean:
	rm -rf $(VENV) out build *.egg-info src/*.egg-info .pytest_cache .ruff_cache .hypothesis
