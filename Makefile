# Two entry points for users: `make run` (the default workflow) and `make test` (the suite).
# Both set up everything they need first and are cheap the second time.
SHELL := /bin/bash
VENV := .venv
PY := $(VENV)/bin/python
PY_STAMP := $(VENV)/.requirements-installed
ENGINE := $(VENV)/bin/dem_engine
ENGINE_BUILD := build/engine
ENGINE_SOURCES := $(shell find dem_engine/src dem_engine/CMakeLists.txt -type f 2>/dev/null)
CORES ?= all
SNAKEMAKE_ARGS ?=

.PHONY: setup sysdeps engine run test lint bench convergence discrepancy-matrix sequential-comparison docs clean

setup: $(PY_STAMP) sysdeps engine

# Python environment: rebuilt only when the pinned requirements change.
$(PY_STAMP): requirements.txt pyproject.toml
	@test -x $(PY) || python3 -m venv $(VENV)
	@echo "installing Python dependencies into $(VENV) (log: $(VENV)/pip.log)"
	@$(PY) -m pip install -r requirements.txt > $(VENV)/pip.log 2>&1 \
		|| { tail -30 $(VENV)/pip.log; exit 1; }
	@$(PY) -m pip install --no-deps --no-build-isolation -e . >> $(VENV)/pip.log 2>&1 \
		|| { tail -30 $(VENV)/pip.log; exit 1; }
	@touch $@

# Debian packages: off-screen pyvista rendering, LIGGGHTS 3.8 and OpenMPI.
sysdeps:
	@bash scripts/install_system_packages.sh

# The DEM engine: CMake Release build with OpenMP, installed into the venv.
engine: $(ENGINE)

$(ENGINE): $(ENGINE_SOURCES) | $(PY_STAMP)
	@$(VENV)/bin/cmake -S dem_engine -B $(ENGINE_BUILD) -DCMAKE_BUILD_TYPE=Release > /dev/null
	@$(VENV)/bin/cmake --build $(ENGINE_BUILD) -j 2
	@install -m 755 $(ENGINE_BUILD)/dem_engine $(ENGINE)

run: setup
	source $(VENV)/bin/activate && snakemake --cores $(CORES) --force-use-threads $(SNAKEMAKE_ARGS) \
		&& snakemake --report results/report.html $(SNAKEMAKE_ARGS)

test: setup
	source $(VENV)/bin/activate && pytest

lint: setup
	$(VENV)/bin/ruff check demcal scripts tests
	$(VENV)/bin/ruff format --check demcal scripts tests
	source $(VENV)/bin/activate && snakemake --lint

bench: setup
	source $(VENV)/bin/activate && python dem_engine/bench/run_bench.py

# Convergence study of the virtual tests at the quick profile (hours on 2 cores; resumable).
CONVERGENCE_ARGS ?=
convergence: setup
	source $(VENV)/bin/activate && python scripts/convergence_study.py --config config/config.yaml \
		--out results/convergence/quick $(CONVERGENCE_ARGS)

# Validation matrix of the discrepancy workflow: hidden effects x drawn truths, data from
# LIGGGHTS (MATRIX_PROFILE=config/config.yaml for the quick scale; resumable).
MATRIX_PROFILE ?= config/tiny.yaml
MATRIX_ARGS ?= --truths 10
discrepancy-matrix: setup
	source $(VENV)/bin/activate && python scripts/discrepancy_matrix.py --profile $(MATRIX_PROFILE) \
		--out results/matrix/$(basename $(notdir $(MATRIX_PROFILE))) $(MATRIX_ARGS)

# Sequential against one-shot calibration on two synthetic materials (LIGGGHTS truths, quick
# scale; resumable): docs/sequential.md.
COMPARISON_ARGS ?= --budgets 44 72 100
sequential-comparison: setup
	source $(VENV)/bin/activate && python scripts/sequential_comparison.py \
		--out results/sequential_comparison $(COMPARISON_ARGS)

# The configuration reference, generated from the schema (tests/unit/test_docs.py checks it).
docs: $(PY_STAMP)
	$(PY) -m demcal.core.config_reference --output docs/configuration.md

clean:
	rm -rf $(ENGINE_BUILD) .snakemake results
