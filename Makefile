# siloflow: the two commands a newcomer needs are `make run` and `make test`.
# Both install what is missing first (Debian packages, then the Python package) and are idempotent.

PYTHON   ?= python3
CONFIG   ?= config/config.yaml
CORES    ?= 2
SUDO     := $(shell [ "$$(id -u)" = "0" ] || echo sudo)
APT_PACKAGES := liggghts openmpi-bin
YADE_MODULES := /usr/lib/x86_64-linux-gnu/yade-double/py/yade

.PHONY: install install-system install-python run verify bayesian validate validate-status test test-physics test-unit test-integration dry-run bench estimate docs

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

# pip is a no-op when everything is already satisfied. The docs extra builds the documentation site (`make docs`,
# which `make test` checks).
install-python:
	@$(PYTHON) -m pip install --quiet --disable-pip-version-check -e ".[test,docs]"

# Snakemake goes through siloflow.engines.workflow_lock: after a killed run it removes the stale Snakemake lock first, and it
# refuses to start (unlocking nothing) while another run is live in the same directory.
RUN_SNAKEMAKE = $(PYTHON) -m siloflow.engines.workflow_lock --snakefile $(CURDIR)/Snakefile

# The report collects every plot with its caption and the summary page (RUN_DIR/results/report.html).
# Reruns follow changed inputs and parameters, not changed siloflow code: an upgrade must not repeat hours of
# finished simulations (run ids already change with every parameter that defines a run), and the outputs a killed run
# left unfinished are redone. The workflow's own profile (profiles/default/) sets that policy for every Snakemake
# call, these and a plain `snakemake` alike. RUN_DIR is where results/ and .snakemake/ go.
RUN_DIR ?= .

run: install
	$(PYTHON) -m siloflow.engines.config_yaml $(abspath $(CONFIG))
	$(RUN_SNAKEMAKE) --directory $(abspath $(RUN_DIR)) --configfile $(abspath $(CONFIG)) --cores $(CORES)
	$(RUN_SNAKEMAKE) --directory $(abspath $(RUN_DIR)) --configfile $(abspath $(CONFIG)) \
		--report $(abspath $(RUN_DIR))/results/report.html

# The checks the demo tier leaves out of `make run` (config/checks.yaml over CONFIG): the DEM verification suite,
# the one-particle-thick recirculating silo and the lid comparison, then the report with their pages.
CHECKS_CONFIG := $(CURDIR)/config/checks.yaml

verify: install
	$(PYTHON) -m siloflow.engines.config_yaml $(abspath $(CONFIG)) $(CHECKS_CONFIG)
	$(RUN_SNAKEMAKE) --directory $(abspath $(RUN_DIR)) --configfile $(abspath $(CONFIG)) $(CHECKS_CONFIG) \
		--cores $(CORES)
	$(RUN_SNAKEMAKE) --directory $(abspath $(RUN_DIR)) --configfile $(abspath $(CONFIG)) $(CHECKS_CONFIG) \
		--report $(abspath $(RUN_DIR))/results/report.html

# The joint Bayesian calibration (calibration.bayesian, its own target): per engine, Jenike runs placed by the
# posterior until it stops moving or the run budget is spent, the predictive check and the chart's answer beside it;
# its report is RUN_DIR/results/report-bayesian.html.
bayesian: install
	$(PYTHON) -m siloflow.engines.config_yaml $(abspath $(CONFIG))
	$(RUN_SNAKEMAKE) bayesian_calibration --directory $(abspath $(RUN_DIR)) --configfile $(abspath $(CONFIG)) \
		--cores $(CORES)
	$(RUN_SNAKEMAKE) bayesian_calibration --directory $(abspath $(RUN_DIR)) --configfile $(abspath $(CONFIG)) \
		--report $(abspath $(RUN_DIR))/results/report-bayesian.html

# The validation scale (config/validation.yaml): the study's physics at the smallest scale that shows it
# (make estimate CONFIG=config/validation.yaml prints its cost, per group and part). It works in results/validation/
# (its own results/ and reports there, so that it never overwrites the default run's), prints the estimate of every run
# first and resumes where an interrupted run stopped. `make validate GROUP=<name>` runs one group
# (siloflow.engines.validation_groups: calibration, calibration_shapes, calibration_checks, silo, silo_series, blending,
# blender), or one part of a group longer than a working session (silo_1, silo_2, ...); each group's record is written
# and copied into docs/validation/ once all its runs have finished, whichever part finished them. A group that compares
# against another group's runs (calibration_checks, silo_series) starts from the products of those runs that the
# other group's record keeps (docs/validation/<group>/products/), restored into results/validation/ where missing,
# so that it runs on a machine other than the one that made them.
# `make validate-status` says which groups of the record in docs/validation/ are complete, stale or missing.
VALIDATION_CONFIG ?= config/validation.yaml
VALIDATION_DIR    ?= results/validation
VALIDATION_RECORD ?= docs/validation
FULL_SCALE_CONFIG ?= config/thesis.yaml
VALIDATION_RECORD_CLI = $(PYTHON) $(CURDIR)/workflow/scripts/validation_record_cli.py
# the target goes before these options: --configfile takes every word after it
VALIDATION_OPTIONS = --directory $(abspath $(VALIDATION_DIR)) --configfile $(abspath $(VALIDATION_CONFIG))
GROUP             ?=

validate: install
	@mkdir -p $(VALIDATION_DIR)/results
	$(if $(GROUP),$(VALIDATION_RECORD_CLI) restore '$(GROUP)' $(VALIDATION_CONFIG) $(VALIDATION_RECORD) $(VALIDATION_DIR))
	$(PYTHON) -m siloflow.engines.planning $(VALIDATION_CONFIG) $(VALIDATION_DIR)/results --cores $(CORES)
	$(RUN_SNAKEMAKE) $(if $(GROUP),validate_$(GROUP)) $(VALIDATION_OPTIONS) --cores $(CORES) \
		--keep-going
	@groups="$$($(VALIDATION_RECORD_CLI) finished $(VALIDATION_CONFIG) $(VALIDATION_DIR) $(if $(GROUP),'$(GROUP)'))" || exit 1; \
	for group in $$groups; do \
		$(RUN_SNAKEMAKE) validate_$$group $(VALIDATION_OPTIONS) --cores $(CORES) && \
		$(RUN_SNAKEMAKE) validate_$$group $(VALIDATION_OPTIONS) --report $(abspath $(VALIDATION_DIR))/report-$$group.html && \
		$(VALIDATION_RECORD_CLI) publish $(VALIDATION_DIR) $(VALIDATION_RECORD) $$group || exit 1; \
	done
	$(VALIDATION_RECORD_CLI) page $(VALIDATION_CONFIG) $(FULL_SCALE_CONFIG) $(VALIDATION_RECORD)

validate-status: install-python
	$(VALIDATION_RECORD_CLI) status $(VALIDATION_CONFIG) $(VALIDATION_RECORD)

# One pytest worker per core (pytest-xdist). A test file runs whole on one worker (--dist loadfile), so each
# module's fixture, and so its engine runs, happens once. Files go out in the order tests/conftest.py sorts them,
# the longest first (--no-loadscope-reorder keeps xdist from putting the files with the most tests first).
# Two tiers. `make test`: the unit tests and the integration tests that run every engine on every case and stage at
# the smallest size that exercises them. `make test-physics`: the tests marked `physics` (pyproject.toml), physics
# checks that need larger or extra runs. .ci/run runs both; test-unit and test-integration run their folder's tests
# of both tiers.
PYTEST_PARALLEL := -n $(CORES) --dist loadfile --no-loadscope-reorder

test: install
	$(PYTHON) -m pytest $(PYTEST_PARALLEL) -m "not physics" tests siloflow/api siloflow/analysis/numerics

test-physics: install
	$(PYTHON) -m pytest $(PYTEST_PARALLEL) -m physics tests

test-unit: install
	$(PYTHON) -m pytest $(PYTEST_PARALLEL) tests/unit

test-integration: install
	$(PYTHON) -m pytest $(PYTEST_PARALLEL) tests/integration

# Particle counts, steps, wall time and disk of every run of a config, before running it: make estimate CONFIG=config/thesis.yaml
estimate: install-python
	$(PYTHON) -m siloflow.engines.planning $(CONFIG) --cores $(CORES)

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

# The documentation site (mkdocs.yml, docs/): --strict fails on a broken link, a missing page or a docstring the API
# reference cannot render. Open $(DOCS_SITE)/index.html.
DOCS_SITE ?= build/site

docs: install-python
	NO_MKDOCS_2_WARNING=1 $(PYTHON) -m mkdocs build --strict --site-dir $(DOCS_SITE)
