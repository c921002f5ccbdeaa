# hippomaze: `make demo` and `make test` set themselves up on a fresh machine.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test test-slow install lint clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

# torch==2.13.0 first: it is the local CPU build; a bare torch requirement would pull CUDA wheels.
$(STAMP): $(PY) pyproject.toml
	$(PY) -m pip install --quiet torch==2.13.0
	$(PY) -m pip install --quiet -e ".[baselines,ray,dev,video,bench]"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/hippomaze dmtp --maze open --trials 5 --runs 4 --seed 0 --agent hippo --out demo_out --overwrite

test: $(STAMP)
	$(PY) -m pytest -q

test-slow: $(STAMP)
	$(PY) -m pytest -q -m slow

lint: $(STAMP)
	$(VENV)/bin/ruff check hippo_env hippo_agent hippomaze baselines benchmarks tests
	$(VENV)/bin/ruff format --check hippo_env hippo_agent hippomaze baselines benchmarks tests

clean:
	rm -rf $(VENV) demo_out .pytest_cache
