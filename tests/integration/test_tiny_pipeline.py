"""config/tiny.yaml, the first look: the whole default pipeline (`rule all`: the calibration, the flat-bottom silo, the
recirculating silo, the blender, the summary and the validation table) and its report, made as `make run-tiny` makes
them (`siloflow run --config config/tiny.yaml --directory results/tiny`) in a folder laid out as a clone's. Then both
example notebooks open its runs by default (no SILOFLOW_RUN), and the documentation site's build step executes them
on it (tests/notebooks.py, rendered by docs/hooks/notebooks.py).

Seven engine runs, about two minutes on two cores with the report: a whole extra pipeline beside the integration
tests that exercise each stage, so it runs in the physics tier (`make test-physics`), which keeps `make test` within
its budget.
"""

from __future__ import annotations

import csv
import importlib.util
import json
import shutil
import subprocess
import sys

import nbformat
import pytest
import yaml

from siloflow.engines.config import layered_config, load_config_file, validate_config
from tests.conftest import require_liggghts
from tests.notebooks import execute_examples, execute_notebook, figures
from tests.repo import REPO_ROOT

pytestmark = [pytest.mark.integration, pytest.mark.physics, pytest.mark.core_seconds(260)]

TINY = REPO_ROOT / "config" / "tiny.yaml"
#: The case kind each notebook reads.
NOTEBOOKS = {"silo_flat.ipynb": "silo_flat", "silo_recirculation.ipynb": "silo_recirculation"}


@pytest.fixture(scope="module")
def clone(tmp_path_factory):
    """A folder laid out as a clone's (config/tiny.yaml, examples/) in which `make run-tiny`'s command has run: its
    results are in results/tiny/results/."""
    require_liggghts()
    clone = tmp_path_factory.mktemp("clone")
    (clone / "config").mkdir()
    shutil.copy(TINY, clone / "config" / "tiny.yaml")
    (clone / "examples").mkdir()
    result = subprocess.run([sys.executable, "-m", "siloflow", "run", "--config", str(clone / "config" / "tiny.yaml"),
                             "--directory", str(clone / "results" / "tiny"), "--cores", "2"],
                            cwd=clone, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    yield clone


def _results(clone):
    return clone / "results" / "tiny" / "results"


def _one_run(clone, case: str):
    (run,) = [run for run in (_results(clone) / case).iterdir() if (run / "run.json").is_file()]
    return run


def test_the_report_and_the_main_products_of_every_stage_are_there(clone):
    results = _results(clone)
    report = results / "report.html"
    assert report.stat().st_size > 100_000
    assert report.read_text(encoding="utf-8").lstrip().lower().startswith("<!doctype html")
    # the calibration: a two-point chart per test (the internal one and the wall test on aluminium), bulk friction
    # growing with the particle's, and both frictions inverted inside their charts
    rows = list(csv.DictReader((results / "calibration" / "bulk_friction.csv").open()))
    charts = {}
    for row in rows:
        charts.setdefault(row["wall_material"] or row["test"], []).append(
            (float(row["particle_friction"]), float(row["bulk_friction"])))
    assert sorted(charts) == ["aluminium", "internal"]
    for points in charts.values():
        (low, low_bulk), (high, high_bulk) = sorted(points)
        assert (low, high) == (0.1, 0.3) and low_bulk < high_bulk
    parameters = yaml.safe_load((results / "calibration" / "parameters.yaml").read_text())
    assert 0.1 <= parameters["particle_particle"]["sliding_friction"] <= 0.3
    assert 0.1 <= parameters["particle_wall"]["aluminium"]["sliding_friction"] <= 0.3
    for test in ("internal", "aluminium"):
        assert (results / "calibration" / "charts" / f"sphere2_{test}.png").read_bytes()[:4] == b"\x89PNG"
    # the flat-bottom silo: its flow metrics, fields and synthetic PIV
    silo = _one_run(clone, "silo_flat")
    (flow,) = csv.DictReader((silo / "metrics" / "flow.csv").open())
    assert float(flow["mass_flow_rate_kg_s"]) > 0.0 and int(flow["n_clumps"]) > 1000
    for name in ("profiles.csv", "janssen.csv", "piv_accuracy.csv"):
        assert list(csv.DictReader((silo / "metrics" / name).open())), name
    # the recirculating silo: its blending metrics and the study's summary across flow patterns
    blending = json.loads((_one_run(clone, "silo_recirculation") / "metrics" / "blending.json").read_text())
    assert blending["residence_time_s"] > 0.0 and blending["recirculations"] > 2.0
    assert (results / "silo_recirculation" / "summary" / "blending.csv").is_file()
    # the blender: its steady flow and the comparison across configurations
    blender = json.loads((_one_run(clone, "blender") / "metrics" / "blender.json").read_text())
    assert blender["mass_flow_rate_standard_error_kg_s"] > 0.0
    assert (results / "blender" / "comparison" / "configurations.csv").is_file()
    # the summary page and the validation table, with rows of every stage
    assert (results / "summary" / "summary.html").is_file()
    groups = {row["group"] for row in csv.DictReader((results / "summary" / "validation.csv").open())}
    assert {"Calibration (Jenike cell)", "Flat-bottom silo", "Recirculating silo (blending)",
            "Multi-flow blender"} <= groups


@pytest.mark.parametrize("name", NOTEBOOKS)
def test_a_notebook_opens_the_tiny_run_by_default(clone, tmp_path, name):
    # started in the clone's examples/, as a Jupyter front end starts it, without SILOFLOW_RUN
    notebook = execute_notebook(name, None, tmp_path, cwd=clone / "examples")  # a failed assert cell raises
    printed = "".join(output.get("text", "") for output in notebook.cells[1].outputs)
    run = _one_run(clone, NOTEBOOKS[name])
    assert f"reading the tiny run ../results/tiny/results/{NOTEBOOKS[name]}/{run.name}" in printed
    assert len(figures(notebook)) == 3


def test_the_sites_build_step_shows_the_notebooks_executed_on_the_tiny_run(clone, tmp_path):
    written = execute_examples(clone / "results" / "tiny", tmp_path / "build" / "notebooks")
    assert sorted(path.name for path in written) == sorted(NOTEBOOKS)
    spec = importlib.util.spec_from_file_location("notebooks_hook", REPO_ROOT / "docs" / "hooks" / "notebooks.py")
    hook = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hook)
    (tmp_path / "examples").mkdir()
    for name, case in NOTEBOOKS.items():
        executed = nbformat.read(tmp_path / "build" / "notebooks" / name, as_version=4)
        assert executed.metadata["siloflow"]["run_id"] == _one_run(clone, case).name
        shutil.copy(REPO_ROOT / "examples" / name, tmp_path / "examples" / name)
        markdown, shown = hook.render(tmp_path, f"examples/{name}", f"notebooks/{case}.md")
        assert "Executed on the tiny run" in markdown and len(shown) == 3
        assert all(png.startswith(b"\x89PNG") for _, png in shown)


def test_the_tiny_config_defines_the_same_runs_alone_and_over_the_default_config():
    """`siloflow run --config config/tiny.yaml` reads it alone, over the schema's defaults; plain Snakemake in the clone
    layers it over config/config.yaml (the clone's Snakefile names it): both are the same configuration."""
    alone = validate_config(load_config_file(TINY))
    assert validate_config(layered_config([REPO_ROOT / "config" / "config.yaml", TINY])) == alone
