# siloflow: the two commands a newcomer needs are `make run` and `make test`.
# Both install what is missing first (Debian packages, then the Python package) and are idempotent.

PYTHON   ?= python3
CONFIG   ?= config/config.yaml
CORES    ?= 2
SUDO     := $(shell [ "$$(id -u)" = "0" ] || echo sudo)
APT_PACKAGES := liggghts openmpi-bin
YADE_MODULES := /usr/lib/x86_64-linux-gnu/yade-double/py/yade

.PHONY: install install-system install-python run validate test test-unit test-integration dry-run bench estimate

install: install-system install-python

# Debian packages: only when an engine or the MPI launcher is missing.
install-system:
	@if ! command -v liggghts >/dev/null 2>&1 || ! command -v mpirun >/dev/null 2>&1; then \
		echo "Installing $(APT_PACKAGES) with apt-get"; \
		$(SUDO) apt-get update -qq && \
		DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $(APT_PACKAGES); \
	else \
		echo "LIGGGHTS: $$(command -v liggghts), MPI: $$(command -v mpirun)"; \
	fi
	@# YADE without its recommends (62 packages instead of a desktop); siloflow imports its Python modules from
	@# /usr/bin/python3 and never starts its launcher, which opens ports.
	@if [ ! -d $(YADE_MODULES) ]; then \
		echo "Installing yade (no recommends) with apt-get"; \
		$(SUDO) apt-get update -qq && \
		DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends yade; \
	else \
		echo "YADE: $(YADE_MODULES)"; \
	fi

# pip is a no-op when everything is already satisfied.
install-python:
	@$(PYTHON) -m pip install --quiet --disable-pip-version-check -e ".[test]"

# The report collects every plot with its caption and the summary page (results/report.html).
# Reruns follow changed inputs and parameters, not changed siloflow code: an upgrade must not repeat hours of
# finished simulations (run ids already change with every parameter that defines a run).
run: install
	$(PYTHON) -m snakemake --cores $(CORES) --configfile $(CONFIG) --rerun-incomplete --rerun-triggers mtime params input
	$(PYTHON) -m snakemake --report results/report.html --configfile $(CONFIG)

# The validation scale (config/validation.yaml): the study's physics at the smallest scale that shows it, about
# 16 core-hours (make estimate CONFIG=config/validation.yaml). It works in results/validation/ (its own results/
# and report there, so that it never overwrites the default run's), prints the estimate of every run first and
# resumes where an interrupted run stopped.
VALIDATION_CONFIG ?= config/validation.yaml
VALIDATION_DIR    ?= results/validation

validate: install
	@mkdir -p $(VALIDATION_DIR)/results
	$(PYTHON) -m engines.planning $(VALIDATION_CONFIG) $(VALIDATION_DIR)/results
	$(PYTHON) -m snakemake --cores $(CORES) --snakefile $(CURDIR)/Snakefile --directory $(VALIDATION_DIR) \
		--configfile $(abspath $(VALIDATION_CONFIG)) --rerun-incomplete --rerun-triggers mtime params input --keep-going
	$(PYTHON) -m snakemake --snakefile $(CURDIR)/Snakefile --directory $(VALIDATION_DIR) \
		--configfile $(abspath $(VALIDATION_CONFIG)) --report $(abspath $(VALIDATION_DIR))/report.html

# One pytest worker per core (pytest-xdist). A test file runs whole on one worker (--dist loadfile), so each
# module's fixture, and so its engine runs, happens once.
PYTEST_PARALLEL := -n $(CORES) --dist loadfile

test: install
	$(PYTHON) -m pytest $(PYTEST_PARALLEL) tests

test-unit: install
	$(PYTHON) -m pytest $(PYTEST_PARALLEL) tests/unit

test-integration: install
	$(PYTHON) -m pytest $(PYTEST_PARALLEL) tests/integration

# Particle counts, steps, wall time and disk of every run of a config, before running it: make estimate CONFIG=config/thesis.yaml
estimate: install-python
	$(PYTHON) -m engines.planning $(CONFIG)

dry-run: install
	$(PYTHON) -m snakemake -n --cores $(CORES) --configfile $(CONFIG)

# Speed figures are ratios against a baseline measured in the same run (results/bench/).
bench: install
	$(PYTHON) -m tests.bench.bench_dumps results/bench/dumps.csv
	$(PYTHON) -m tests.bench.bench_coarse_graining results/bench/coarse_graining.csv
	$(PYTHON) -m tests.bench.bench_pathlines results/bench/pathlines.csv
	$(PYTHON) -m tests.bench.bench_mpi results/bench/mpi.csv
	$(PYTHON) -m tests.bench.bench_decks results/bench/decks.csv
	$(PYTHON) -m tests.bench.bench_engines results/bench/engines.csv
	$(PYTHON) -m tests.bench.bench_piv results/bench/piv.csv
