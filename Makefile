# hippomaze: `make demo` and `make test` set themselves up on a fresh machine.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
DOCS_STAMP := $(VENV)/.installed-docs

.PHONY: demo test test-slow install lint docs clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

# torch==2.13.0 first: it is the local CPU build; a bare torch requirement would pull CUDA wheels.
$(STAMP): $(PY) pyproject.toml
	$(PY) -m pip install --quiet torch==2.13.0
	$(PY) -m pip install --quiet -e ".[baselines,ray,dev,video,bench]"
	touch $(STAMP)

install: $(STAMP)

# The docs extra, on top of what `make test` installs.
$(DOCS_STAMP): $(STAMP)
	$(PY) -m pip install --quiet -e ".[docs]"
	touch $(DOCS_STAMP)

demo: $(STAMP)
	$(VENV)/bin/hippomaze dmtp --maze open --trials 5 --runs 4 --seed 0 --agent hippo --out demo_out --overwrite

test: $(STAMP)
	$(PY) -m pytest -q

test-slow: $(STAMP)
	$(PY) -m pytest -q -m slow

# ruff on everything; mypy on the packages (and baselines/), its settings in pyproject.toml.
lint: $(STAMP)
	$(VENV)/bin/ruff check hippo_env hippo_agent hippomaze baselines benchmarks tests
	$(VENV)/bin/ruff format --check hippo_env hippo_agent hippomaze baselines benchmarks tests
	$(VENV)/bin/mypy

docs: $(DOCS_STAMP)
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict

clean:
	rm -rf $(VENV) demo_out .pytest_cache site
