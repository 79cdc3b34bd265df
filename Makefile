# The two commands of the README (`make report`, `make test`) do their own set-up on a
# fresh machine: they build .venv from requirements.lock, the exact dependency set (with
# hashes) the suite last passed on. Only `make lock` and `make upgrade` ever re-resolve it.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
LOCK := requirements.lock
# the one command that produces the lock (uv is pinned in the lock itself, extra "dev")
UV_COMPILE = $(BIN)/uv pip compile pyproject.toml --all-extras --generate-hashes \
	--universal --python-version 3.11 --quiet -o $(LOCK)

.PHONY: test report docs install lint typecheck bench lock upgrade test-lowest clean

$(STAMP): $(LOCK) pyproject.toml
	rm -rf $(VENV)
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --require-hashes --no-deps -r $(LOCK)
	$(BIN)/python -m pip install --quiet --no-deps -e .
	$(BIN)/python -m pip check
	touch $(STAMP)

install: $(STAMP)

test: $(STAMP)
	$(BIN)/python -m pytest -q

report: $(STAMP)
	$(BIN)/labbrdf validate --out reports/validation --overwrite

# The documentation site, warnings as errors (every cross-reference to labbrdf must resolve);
# open build/docs/index.html.
docs: $(STAMP)
	rm -rf docs/generated build/docs
	$(BIN)/sphinx-build -E -W --keep-going -q -b html docs build/docs

lint: $(STAMP)
	$(BIN)/ruff check labbrdf tests benchmarks
	$(BIN)/mypy labbrdf

typecheck: $(STAMP)
	$(BIN)/mypy labbrdf

bench: $(STAMP)
	for f in benchmarks/bench_*.py; do $(BIN)/python $$f; done

# Re-resolve the lock after editing pyproject.toml, keeping every pin that still fits.
lock: $(STAMP)
	$(UV_COMPILE)

# Re-resolve the lock to the newest versions pyproject.toml allows, rebuild .venv from it
# and run both README commands: a new release that changes our numbers is seen here first.
upgrade: $(STAMP)
	$(UV_COMPILE) --upgrade
	$(MAKE) test report

# The suite at the lower bounds of pyproject.toml (direct dependencies at their minimum).
# Deprecation warnings are not errors here: old releases paired with new indirect
# dependencies warn inside their own code (matplotlib 3.9 with pyparsing 3.3); the
# deprecation check runs on the lock, where it belongs.
test-lowest: $(STAMP)
	$(BIN)/uv pip compile pyproject.toml --all-extras --resolution lowest-direct \
		--python-version 3.11 --quiet -o .venv-lowest.txt
	rm -rf .venv-lowest && $(PYTHON) -m venv .venv-lowest
	.venv-lowest/bin/python -m pip install --quiet --no-deps -r .venv-lowest.txt
	.venv-lowest/bin/python -m pip install --quiet --no-deps -e .
	.venv-lowest/bin/python -m pytest -q -p no:cacheprovider \
		-W "ignore::DeprecationWarning" -W "ignore::FutureWarning"

clean:
	rm -rf $(VENV) .venv-lowest .venv-lowest.txt build docs/generated *.egg-info
