# siloflow: the two commands a newcomer needs are `make run` and `make test`.
# Both install what is missing first (Debian packages, then siloflow into a virtual environment of its own) and are
# idempotent. Every target runs siloflow's own command (`siloflow`, here `$(SILOFLOW)`) from that environment.

SYSTEM_PYTHON ?= python3
VENV          ?= .venv
PYTHON        ?= $(VENV)/bin/python
SILOFLOW       = $(PYTHON) -m siloflow
CONFIG        ?= config/config.yaml
# One --config per file, so that CONFIG="config/config.yaml config/bayesian_twin.yaml" layers the second over the first.
CONFIG_ARGS    = $(addprefix --config ,$(CONFIG))
CORES         ?= 2
SUDO          := $(shell [ "$$(id -u)" = "0" ] || echo sudo)
APT_PACKAGES  := liggghts openmpi-bin
YADE_MODULES  := /usr/lib/x86_64-linux-gnu/yade-double/py/yade
PIP            = $(PYTHON) -m pip install --quiet --disable-pip-version-check

.PHONY: install install-system install-python install-test install-docs run run-tiny check verify bayesian validate hypothesis \
	validate-status test test-physics test-unit test-integration dry-run bench bench-assembly estimate docs

# What running needs; the test and documentation extras come with `make test` and `make docs` only.
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
	@# YADE without its recommends (62 packages instead of a desktop). Its scripts run under Debian's /usr/bin/python3,
	@# which imports YADE's modules; siloflow's environment never imports them and never starts YADE's launcher,
	@# which opens ports.
	@if [ ! -d $(YADE_MODULES) ]; then \
		echo "Installing yade (no recommends) with apt-get"; \
		$(SUDO) apt-get update -qq && \
		DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends yade; \
	else \
		echo "YADE: $(YADE_MODULES)"; \
	fi

# The virtual environment. Debian's python3 refuses pip installs into itself (PEP 668, "externally-managed-
# environment"), and a machine's own interpreter may not be Debian's: a venv of whichever python3 comes first on PATH
# behaves the same on both. Debian ships the venv module apart (python3-venv).
$(VENV)/bin/python:
	@if ! $(SYSTEM_PYTHON) -c "import ensurepip, venv" >/dev/null 2>&1; then \
		echo "Installing python3-venv with apt-get"; \
		$(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq python3-venv; \
	fi
	$(SYSTEM_PYTHON) -m venv $(VENV)

# pip runs again only when pyproject.toml changed since (a stamp per set of extras, kept in the environment).
$(VENV)/.installed-run: pyproject.toml | $(PYTHON)
	@mkdir -p $(VENV)
	$(PIP) -e .
	@touch $@
$(VENV)/.installed-test: pyproject.toml | $(PYTHON)
	@mkdir -p $(VENV)
	$(PIP) -e ".[test]"
	@touch $@
$(VENV)/.installed-docs: pyproject.toml | $(PYTHON)
	@mkdir -p $(VENV)
	$(PIP) -e ".[docs]"
	@touch $@

install-python: $(VENV)/.installed-run
install-test: install-system $(VENV)/.installed-test
install-docs: $(VENV)/.installed-docs

# `siloflow run`: checks the configuration before anything runs, runs the workflow under a launcher that removes the
# stale Snakemake lock a killed run left (and refuses while another run is live in the same folder), then writes the
# report (RUN_DIR/results/report.html, every plot with its caption and a summary page). Reruns follow changed inputs
# and parameters, not changed siloflow code: an upgrade must not repeat hours of finished simulations (run ids
# change with every parameter that defines a run), and the outputs a killed run left unfinished are redone (the
# workflow's own profile, siloflow/workflow/profiles/default/). RUN_DIR is where results/ and .snakemake/ go.
RUN_DIR ?= .

run: install
	$(SILOFLOW) run $(CONFIG_ARGS) --directory $(RUN_DIR) --cores $(CORES)

# A first result in minutes: the tiny configuration (numbers without physical meaning), into results/tiny/; the
# example notebooks open its runs by default.
TINY_DIR ?= results/tiny

run-tiny: install
	$(SILOFLOW) run --config config/tiny.yaml --directory $(TINY_DIR) --cores $(CORES)

# Validate CONFIG and plan it; nothing runs.
check: install-python
	$(SILOFLOW) check $(CONFIG_ARGS) --cores $(CORES)

# The checks the demo tier leaves out of `make run` (config/checks.yaml over CONFIG): the DEM verification suite,
# the one-particle-thick recirculating silo and the lid comparison, then the report with their pages.
CHECKS_CONFIG := config/checks.yaml

verify: install
	$(SILOFLOW) run $(CONFIG_ARGS) --config $(CHECKS_CONFIG) --directory $(RUN_DIR) --cores $(CORES)

# The joint Bayesian calibration (calibration.bayesian, its own target): per engine, Jenike runs placed by the
# posterior until it stops moving or the run budget is spent, the predictive check and the chart's answer beside it;
# its report is RUN_DIR/results/report-bayesian.html.
bayesian: install
	$(SILOFLOW) run $(CONFIG_ARGS) --directory $(RUN_DIR) --cores $(CORES) --target bayesian_calibration \
		--report $(RUN_DIR)/results/report-bayesian.html

# The validation scale (config/validation.yaml): the study's physics at the smallest scale that shows it
# (make estimate CONFIG=config/validation.yaml prints its cost, per group and part). It works in results/validation/
# (its own results/ and reports there, so that it never overwrites the default run's), prints the estimate of every run
# first and resumes where an interrupted run stopped. `make validate GROUP=<name>` runs one group
# (siloflow.engines.validation_groups: calibration, calibration_shapes, calibration_checks, silo, silo_series,
# blending, blender), or one part of a group longer than a working session (blending_1, blending_2); each group's record
# is written and copied into docs/validation/ once all its runs have finished, whichever part finished them. A group
# that compares against another group's runs (calibration_checks, silo_series) starts from the products of those runs
# that the other group's record keeps (docs/validation/<group>/products/), restored into results/validation/ where
# missing, so that it runs on a machine other than the one that made them.
# `make validate-status` says which groups of the record in docs/validation/ are complete, stale or missing.
VALIDATION_CONFIG ?= config/validation.yaml
VALIDATION_DIR    ?= results/validation
VALIDATION_RECORD ?= docs/validation
FULL_SCALE_CONFIG ?= config/thesis.yaml
VALIDATION_RUN     = $(SILOFLOW) run --config $(VALIDATION_CONFIG) --directory $(VALIDATION_DIR) --cores $(CORES)
GROUP             ?=

validate: install
	@mkdir -p $(VALIDATION_DIR)/results
	$(if $(GROUP),$(SILOFLOW) record restore --group '$(GROUP)' --config $(VALIDATION_CONFIG) \
		--record $(VALIDATION_RECORD) --directory $(VALIDATION_DIR))
	$(SILOFLOW) estimate --config $(VALIDATION_CONFIG) --directory $(VALIDATION_DIR) --cores $(CORES)
	$(VALIDATION_RUN) $(if $(GROUP),--target 'validate_$(GROUP)' --part-deadline) --keep-going --no-report
	@groups="$$($(SILOFLOW) record finished --config $(VALIDATION_CONFIG) --directory $(VALIDATION_DIR) \
		$(if $(GROUP),--group '$(GROUP)'))" || exit 1; \
	for group in $$groups; do \
		$(VALIDATION_RUN) --target validate_$$group --report $(VALIDATION_DIR)/report-$$group.html && \
		$(SILOFLOW) record publish --directory $(VALIDATION_DIR) --record $(VALIDATION_RECORD) --group $$group \
		|| exit 1; \
	done
	$(SILOFLOW) record page --config $(VALIDATION_CONFIG) --full-scale $(FULL_SCALE_CONFIG) --record $(VALIDATION_RECORD)

# A measured hypothesis of the validation record (siloflow.engines.hypotheses; `siloflow hypothesis --help` lists them):
# a reduced case and the same with one change, run to the rows of the findings it is for, in
# $(VALIDATION_DIR)/results/hypotheses/NAME/; each call stops its engine runs at a part's deadline and the next carries
# them on; once both are made, docs/validation/hypotheses/NAME.csv and the record's page say where the change moves
# each row.
NAME ?=
hypothesis: install
	$(SILOFLOW) hypothesis '$(NAME)' --cores $(CORES) --directory $(VALIDATION_DIR) --record $(VALIDATION_RECORD)
	$(SILOFLOW) record page --config $(VALIDATION_CONFIG) --full-scale $(FULL_SCALE_CONFIG) --record $(VALIDATION_RECORD)

validate-status: install-python
	$(SILOFLOW) record status --config $(VALIDATION_CONFIG) --record $(VALIDATION_RECORD)

# One pytest worker per core (pytest-xdist). A test file runs whole on one worker (--dist loadfile), so each
# module's fixture, and so its engine runs, happens once. Files go out in the order tests/conftest.py sorts them,
# the longest first (--no-loadscope-reorder keeps xdist from putting the files with the most tests first).
# Two tiers. `make test`: the unit tests and the integration tests that run every engine on every case and stage at
# the smallest size that exercises them. `make test-physics`: the tests marked `physics` (pyproject.toml), physics
# checks that need larger or extra runs. .ci/run runs both; test-unit and test-integration run their folder's tests
# of both tiers. The unit tests build the documentation site and the tiny pipeline's test its notebooks' pages, so
# the docs extra comes too.
PYTEST_PARALLEL := -n $(CORES) --dist loadfile --no-loadscope-reorder

test: install-test install-docs
	$(PYTHON) -m pytest $(PYTEST_PARALLEL) -m "not physics" tests siloflow/api siloflow/analysis/numerics

test-physics: install-test install-docs
	$(PYTHON) -m pytest $(PYTEST_PARALLEL) -m physics tests

test-unit: install-test install-docs
	$(PYTHON) -m pytest $(PYTEST_PARALLEL) tests/unit

test-integration: install-test install-docs
	$(PYTHON) -m pytest $(PYTEST_PARALLEL) tests/integration

# Particle counts, steps, wall time and disk of every run of a config, before running it:
# make estimate CONFIG=config/thesis.yaml
estimate: install-python
	$(SILOFLOW) estimate $(CONFIG_ARGS) --directory $(RUN_DIR) --cores $(CORES)

dry-run: install
	$(SILOFLOW) run $(CONFIG_ARGS) --directory $(RUN_DIR) --cores $(CORES) --dry-run

# Speed figures are ratios against a baseline measured in the same run (results/bench/).
bench: install-test
	$(PYTHON) -m tests.bench.bench_dumps results/bench/dumps.csv
	$(PYTHON) -m tests.bench.bench_coarse_graining results/bench/coarse_graining.csv
	$(PYTHON) -m tests.bench.bench_pathlines results/bench/pathlines.csv
	$(PYTHON) -m tests.bench.bench_mpi results/bench/mpi.csv
	$(PYTHON) -m tests.bench.bench_decks results/bench/decks.csv
	$(PYTHON) -m tests.bench.bench_engines results/bench/engines.csv
	$(PYTHON) -m tests.bench.bench_piv results/bench/piv.csv

# 1 against 2 MPI ranks on the validation tier's 270 mm assembly (a flat-bottom silo run of the tier: from its settled
# fill, or for a run a part stopped before that, its own continuation): make bench-assembly
# ASSEMBLY=results/validation/results/silo_flat/<run>
ASSEMBLY ?=
bench-assembly: install-test
	$(if $(ASSEMBLY),,$(error name the flat-bottom silo run whose fill the benchmark starts from: ASSEMBLY=<run folder>))
	$(PYTHON) -m tests.bench.bench_mpi_assembly '$(ASSEMBLY)' results/bench/mpi_assembly.csv

# The documentation site (mkdocs.yml, docs/): --strict fails on a broken link, a missing page or a docstring the API
# reference cannot render. The example notebooks are shown executed on the tiny run (made first where missing;
# executed into build/notebooks/, which the hook docs/hooks/notebooks.py renders). Open $(DOCS_SITE)/index.html.
DOCS_SITE ?= build/site

docs: install-docs run-tiny
	$(PYTHON) -m tests.notebooks --tiny $(TINY_DIR)
	NO_MKDOCS_2_WARNING=1 $(PYTHON) -m mkdocs build --strict --site-dir $(DOCS_SITE)
