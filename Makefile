# flexsat — the two entry points: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test bench lint clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/flexsat modal --out out/modal
	$(BIN)/flexsat openloop --out out/openloop
	$(BIN)/flexsat slew --out out/slew
	@echo "Study of the nominal case written to out/: modal/ (modes), openloop/ (open-loop validation), slew/ (ASMC slew, R1-R3)"

test: $(STAMP)
	$(BIN)/ruff check src tests bench examples
	$(BIN)/python -m pytest -q

bench: $(STAMP)
	$(BIN)/python bench/bench_dynamics.py
	$(BIN)/python bench/bench_openloop.py
	$(BIN)/python bench/bench_slew.py
	$(BIN)/python bench/bench_campaigns.py

lint: $(STAMP)
	$(BIN)/ruff check src tests bench examples

clean:
	rm -rf $(VENV) out build *.egg-info src/*.egg-info .pytest_cache .ruff_cache .hypothesis
