# rvfem: two commands for a fresh machine.
#   make run    create .venv if missing, install rvfem, run the main job on the default case
#   make test   create .venv if missing, install rvfem with the dev extra, run the test suite on
#               parallel workers (TEST_WORKERS, default one per core; TEST_WORKERS=0 runs it in one process)
# Both are idempotent: the installation is redone only when pyproject.toml changes.

PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin

# The main job: arguments of the `rvfem` command that `make run` executes.
MAIN_JOB ?= run cases/rv40e_fanholes.toml -o results/rv40e_fanholes --overwrite

# rvfem's modules compiled to bytecode (only those changed since): an editable install does not
# compile them, and where PYTHONDONTWRITEBYTECODE is set (as in many containers) every Python
# process of a run (the main one, the P2 model's, the render worker's) would compile them again,
# about 0.2 s of processor time each (benchmarks/README.md, "Start-up").
BYTECODE = $(BIN)/python -m compileall -q rvfem

# Parallel pytest workers of `make test` (pytest-xdist's -n: a number, auto = one per core, 0 = none).
TEST_WORKERS ?= auto

.PHONY: run test install install-dev help

help:
	@echo "make run    - install (if needed) and run: rvfem $(MAIN_JOB)"
	@echo "make test   - install with the dev extra (if needed) and run pytest on $(TEST_WORKERS) workers"

run: $(VENV)/.installed
	@$(BYTECODE)
	$(BIN)/rvfem $(MAIN_JOB)

test: $(VENV)/.installed-dev
	@$(BYTECODE)
	$(BIN)/python -m pytest -n $(TEST_WORKERS)

install: $(VENV)/.installed

install-dev: $(VENV)/.installed-dev

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(VENV)/.installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --progress-bar off -e .
	-.ci/ensure-gmsh-libs $(BIN)/python
	touch $@

$(VENV)/.installed-dev: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --progress-bar off -e '.[dev]'
	-.ci/ensure-gmsh-libs $(BIN)/python
	touch $@ $(VENV)/.installed
