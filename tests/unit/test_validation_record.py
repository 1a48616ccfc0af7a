"""The validation record: provenance rows, the files of a group's record, and its page, on synthetic records."""

from __future__ import annotations

import json
import math
import re
import shutil
import subprocess

import numpy as np
import pytest
import yaml
from PIL import Image

from siloflow.model.record import RunRecord, RunRecordError
from siloflow.analysis.io.validation_products import row_code_digest
from siloflow.analysis.io.validation_record import (DERIVATION, LEGACY_MARK, PRODUCTS, RUNS, TABLE, benchmark_wall_time, read_group_record, read_record,
                                           RECORD_PLOT_COLOURS, read_validation_rows, restore_products,
                                           write_group_record, write_record_plot)
from siloflow.analysis.studies.validation.agreement import NOT_REPRODUCED, Agreement
from siloflow.analysis.studies.validation.findings_summary import finding_statuses
from siloflow.analysis.studies.validation.rows import AT_SCALE
from siloflow.analysis.studies.validation.record import (RUN_COLUMNS, GroupRecord, budget_lines, findings_section,
                                                         provenance_row, record_page, run_wall_time, simulated_time,
                                                         earlier_attempt_times)
from siloflow.analysis.studies.validation.rows import row
from siloflow.engines.config import load_config_file
from tests.repo import REPO_ROOT
from siloflow.engines.layout import REPOSITORY_RECORD
from siloflow.analysis.studies.validation.findings import FINDINGS
from siloflow.analysis.studies.validation.scale import DimensionDifference, ScaleVerdict
from siloflow.cli import record as CLI
from tests.conftest import record_main

RECORD_PAGE, page, publish = CLI.RECORD_PAGE, CLI.page, CLI.publish

#: The pixels of a small plot: white, a red line and a blue one (row by row, RGB).
PIXELS = [(255, 255, 255), (255, 0, 0), (0, 0, 255), (255, 255, 255)] * 3


def _png(path):
    image = Image.new("RGB", (4, 3))
    image.putdata(PIXELS)
    image.save(path)
    return path


def _pixels(path):
    with Image.open(path) as image:
        return [tuple(int(c) for c in pixel) for pixel in np.asarray(image.convert("RGB")).reshape(-1, 3)]


def _record(run_id="sphere2-abc", stages=None, ranks=1) -> RunRecord:
    # a time step of 2^-10 s: step times are exact in binary
    stages = {"fill": {"step": 256, "time": 0.25}, "discharge": {"step": 1792, "time": 1.75}} if stages is None else stages
    return RunRecord(engine="liggghts", case="silo_flat", run_id=run_id, timestep_s=2.0**-10, n_clumps=100, n_frames=3,
                     mpi_ranks=ranks, stages=stages)


def _rows():
    density = row("Flat-bottom silo", "Filling bulk density", "sphere2-abc", 547.6, 1.7, "kg/m3", "settled fill",
                  dof=2.0, finding="S2", agreement=Agreement(NOT_REPRODUCED, "S2: 547.6 lies outside 618 to 627.4"))
    density.update(scale=AT_SCALE, scale_reason="at the study's scale for S2")
    return [density,
            row("Flat-bottom silo", "Wall share | of weight", "sphere2-abc", math.nan, math.nan, "-",
                "depth 12 mm = 3.6 particle diameters", study="")]


def test_the_provenance_row_names_the_run_its_engine_and_its_time():
    got = provenance_row(_record(ranks=2), "silo", "3.8.0+repack1", [11, 12, 13], "abc123", 61.5, [12.0, 8.25], "2026-11-28",
                         2)
    assert list(got) == list(RUN_COLUMNS)
    assert got == {"run_id": "sphere2-abc", "group": "silo", "case": "silo_flat", "engine": "liggghts", "engine_version": "3.8.0+repack1",
                   "seeds": "11 12 13", "commit": "abc123", "simulated_time_s": 1.75, "wall_time_s": 61.5,
                   "earlier_attempts_s": 20.25, "attempts": 2, "attempt_times_s": "12.0 8.2 61.5", "cores": 2,
                   "date": "2026-11-28"}
    assert provenance_row(_record(), "silo", "3.8", [1], "c", 1.0, [], "2026-11-28")["attempts"] == ""
    # the time of all its attempts; a record written before earlier attempts were timed gives the last one's only
    assert run_wall_time(got) == 81.75
    assert run_wall_time({key: value for key, value in got.items() if key != "earlier_attempts_s"}) == 61.5
    # a run resumed from a restart file counts its steps on while LIGGGHTS' clock starts again at zero: the step
    # decides; a stage without a step gives its time; a record with neither, NaN
    assert simulated_time(_record(stages={"fill": {"step": 256, "time": 0.25},
                                          "discharge": {"step": 1792, "time": 0.5}})) == 1.75
    assert simulated_time(_record(stages={"fill": {"time": 0.25}})) == 0.25
    assert math.isnan(simulated_time(_record(stages={"fill": {"clumps": 3}})))


@pytest.mark.parametrize("key, value", [("run_id", "sphere2-abc\n"), ("engine", "liggghts\n")])
def test_a_run_record_s_names_are_matched_whole(key, value):
    """A run id or engine name with a trailing newline (which ``$`` alone lets through) is refused, naming the key."""
    assert RunRecord.from_dict(_record().to_dict()).run_id == "sphere2-abc"
    with pytest.raises(RunRecordError, match=f"run record: key '{key}': .* does not match"):
        RunRecord.from_dict({**_record().to_dict(), key: value})


def test_a_group_record_round_trips_and_replaces_its_old_plots(tmp_path):
    plot = _png(tmp_path / "source.png")
    runs = [provenance_row(_record(), "silo", "3.8", [1, 2, 3], "0123456789", 60.0, [], "2026-11-28")]
    folder = tmp_path / "silo"
    folder.mkdir()
    _png(folder / "old.png")
    write_group_record(folder, _rows(), runs, {"profiles.png": plot})
    back = read_group_record(folder)
    assert back.plots == ["profiles.png"] and _pixels(folder / "profiles.png") == PIXELS
    assert back.runs == [{**{k: str(v) for k, v in runs[0].items()}}]  # text: a commit of digits stays text
    assert back.rows[0] == {**_rows()[0], "dof": "2.0"}
    assert math.isnan(back.rows[1]["value"]) and back.rows[1]["study"] == ""
    assert read_validation_rows(folder / TABLE)[0]["study"] == _rows()[0]["study"]
    assert read_record(tmp_path, ["calibration", "silo"]) == {"silo": back}
    with pytest.raises(ValueError, match="a PNG file name without a folder"):
        write_group_record(folder, _rows(), runs, {"../x.png": plot})
    with pytest.raises(ValueError, match="needs rows and runs"):
        write_group_record(folder, [], runs, {})


def test_a_record_plot_is_a_palette_png_of_the_same_pixels_with_transparency_on_white(tmp_path):
    write_record_plot(_png(tmp_path / "plot.png"), tmp_path / "record.png")
    with Image.open(tmp_path / "record.png") as written:
        assert written.format == "PNG" and written.mode == "P"
    assert _pixels(tmp_path / "record.png") == PIXELS
    # a transparent pixel lands on white, a half-transparent black one on mid grey
    image = Image.new("RGBA", (2, 1))
    image.putdata([(0, 0, 0, 0), (0, 0, 0, 128)])
    image.save(tmp_path / "alpha.png")
    write_record_plot(tmp_path / "alpha.png", tmp_path / "alpha_record.png")
    assert _pixels(tmp_path / "alpha_record.png") == [(255, 255, 255), (127, 127, 127)]
    # more colours than the palette holds: at most RECORD_PLOT_COLOURS remain, each pixel near its own
    ramp = [(i % 256, i // 4, 255 - i % 256) for i in range(1024)]
    image = Image.new("RGB", (1024, 1))
    image.putdata(ramp)
    image.save(tmp_path / "ramp.png")
    write_record_plot(tmp_path / "ramp.png", tmp_path / "ramp_record.png")
    written = _pixels(tmp_path / "ramp_record.png")
    assert len(set(written)) <= RECORD_PLOT_COLOURS
    assert np.abs(np.array(written) - np.array(ramp)).max() <= 16


def test_the_record_keeps_png_plots_and_refuses_another_format_before_anything_runs(tmp_path, capsys):
    """A workflow with plots.format pdf or svg cannot make the record, whose page shows PNG plots: the writer refuses
    such a plot and writes nothing, and `make validate GROUP=<name>` refuses such a configuration first."""
    plot = tmp_path / "profiles.pdf"
    plot.write_bytes(b"%PDF-1.4")
    runs = [provenance_row(_record(), "silo", "3.8", [1], "c0ffee", 60.0, [], "2026-11-28")]
    message = r"the validation record keeps png plots .*, not pdf: make it with plots.format: png"
    with pytest.raises(ValueError, match=message):
        write_group_record(tmp_path / "silo", _rows(), runs, {"profiles.png": plot})
    assert not (tmp_path / "silo").exists()
    raw = load_config_file(REPO_ROOT / "config" / "validation.yaml")
    config = tmp_path / "validation_pdf.yaml"
    config.write_text(yaml.safe_dump({**raw, "plots": {"format": "pdf"}}, sort_keys=False))
    assert record_main(["check", "--group", "blender_1", "--config", str(config), "--record", str(tmp_path)]) == 2
    assert re.search(message, capsys.readouterr().err)
    assert record_main(["check", "--group", "blender_1", "--config", str(REPO_ROOT / "config" / "validation.yaml"), "--record", str(tmp_path)]) == 0


def test_a_table_without_the_validation_columns_is_refused(tmp_path):
    path = tmp_path / "table.csv"
    path.write_text("figure,value\nx,1\n")
    with pytest.raises(ValueError, match="needs the columns group, case, finding, value_error"):
        read_validation_rows(path)


def test_a_table_written_by_older_row_code_is_read_with_no_verdict(tmp_path):
    path = tmp_path / "table.csv"
    path.write_text("group,figure,case,value,value_error,unit,study_value,scale_shows,evidence\n"
                    "Silo,Density,r,564.0,1.0,kg/m3,667,yes,deep enough\n")
    (entry,) = read_validation_rows(path)
    assert (entry["finding"], entry["agreement"], entry["scale"], entry["study"]) == ("-", "-", "-", "667")
    assert entry["value"] == 564.0 and entry["evidence"] == f"({LEGACY_MARK}) deep enough"


def test_the_page_renders_status_runs_rows_and_both_verdicts():
    # the silo group ran in two parts: silo_1 made two runs side by side, silo_2 one
    # silo_2's run was interrupted once: its attempt before the last took 900 s, which counts
    runs = [provenance_row(_record(), "silo_1", "3.8", [1], "c0ffee", 5400.0, [], "2026-11-28", 1),
            provenance_row(_record("sphere2-def"), "silo_1", "3.8", [2], "c0ffee", 1800.0, [], "2026-11-29", 1),
            provenance_row(_record("sphere2-jkl"), "silo_2", "3.8", [3], "c0ffee", 900.0, [900.0], "2026-11-29", 2)]
    # the series' record also lists the base run it compares against, made by the silo group
    # and its record predates the time of earlier attempts
    series = [{key: value for key, value in
               provenance_row(_record("sphere2-ghi"), "silo_series", "3.8", [1], "c0ffee", 3600.0, [], "2026-11-29").items()
               if key not in ("earlier_attempts_s", "attempts", "attempt_times_s")}, runs[0]]
    groups = {"silo": GroupRecord(rows=_rows(), runs=runs, plots=["profiles.png"]),
              "silo_series": GroupRecord(rows=_rows()[:1], runs=series)}
    status = {"calibration": "missing", "silo": "stale", "silo_series": "complete"}
    wall = CLI.measured_wall_times(groups, cores=2)
    assert wall == {"silo": {"silo_1": 5400.0, "silo_2": 1800.0}, "silo_series": {"silo_series": 3600.0}}
    text = record_page(groups, status, {"calibration": 86400.0, "silo": 2 * 86400.0}, wall, 2,
                       "config/validation.yaml", "config/thesis.yaml", {"silo": ["silo_1", "silo_2"]},
                       {"sphere2-abc": 5000.0, "sphere2-def": 2000.0, "sphere2-jkl": 2900.0, "calibration-x": 1800.0})
    lines = text.splitlines()
    assert lines[0] == "# The validation record"
    # the page opens with the study it compares with, by the thesis's chapters, and what its study column quotes
    assert lines[1:4] == [
        "",
        "The record compares siloflow with a published study: a PhD thesis on DEM and PIV of HDPE pellet flow and "
        "blending in planar silos and a multi-flow blender, done with EDEM 2.7; siloflow runs the study's method on "
        "LIGGGHTS and YADE instead ([What siloflow reproduces](../index.md#what-siloflow-reproduces)). The pellets are "
        "multisphere clumps with rolling friction (§4.2), calibrated by Jenike direct shear tests (ch. 4: the "
        "calibration groups); the flat-bottom silo is validated against PIV (ch. 3 and 5: the silo groups); blending "
        "in the recirculating silo is measured by residence time distributions and variance reduction ratios (ch. 6: "
        "the blending group); the multi-flow blender has a cone-in-cone insert and a blending tube (ch. 7 and App. A: "
        "the blender group). Section numbers are the thesis's. The \"study\" column quotes the study's figure or "
        "finding that a row is judged against, \"-\" where the study gives none.",
        ""]
    assert lines[4].startswith("The study's comparisons at the validation scale (`config/validation.yaml`)")
    # the estimate of the recorded runs beside their recorded core time: 9900 s over 9000 s is 1.10; the series'
    # own run is not planned (no estimate), its base run is not its own
    assert "| calibration | missing | 0 | - | - | - | 0 | 0 | 0 |" in lines
    assert "| silo | stale | 3 | 2.50 h | 2.75 h (1.10) | silo_1 1.50 h, silo_2 0.50 h | 2 | 1 | 1 |" in lines
    assert "| silo_series | complete | 1 | 1.00 h | - | 1.00 h | 1 | 1 | 1 |" in lines
    assert "Not recorded yet: `make validate GROUP=calibration`." in lines
    # the stale group runs in parts: the page names them
    assert ("**Stale**: the runs below are not those `config/validation.yaml` now plans, or the code that writes the "
            "rows changed since they were recorded; `make validate GROUP=silo_1`, then `make validate GROUP=silo_2` "
            "brings the record up to date (`make validate-status` says which).") in lines
    assert ("3 runs on liggghts 3.8, 1 core(s) each, code c0ffee, 2026-11-28 to 2026-11-29; run ids and seeds in "
            "[`silo/runs.csv`](silo/runs.csv). 1 run(s) ran in more than one attempt (carried over parts, or "
            "interrupted and run again); their attempts before the last took 0.25 h, counted in the group's times "
            "above.") in lines
    assert "For 1 run(s) the record gives the time of the last attempt only." in text
    # a run that did not note its own commit: the page says whose commit the record holds
    assert "2 runs on liggghts 3.8, 1 core(s) each, code c0ffee, unknown (the record was written by c0ffee)" in text
    study = _rows()[0]["study"]
    # one short line per row, its evidence folded below the rows
    assert (f"| Flat-bottom silo | Filling bulk density | sphere2-abc | 548 ± 1.7 kg/m3 | S2 | {study} | not reproduced "
            "| at scale |") in lines
    assert "| Flat-bottom silo | Wall share \\| of weight | sphere2-abc | not measured | - | - | - | - |" in lines
    silo = lines[lines.index("## silo"):lines.index("## silo_series")]
    assert silo.index('<details markdown="1">') > silo.index("| table | figure | case | value | finding | study | "
                                                              "agreement | scale |")
    assert "<summary>Why each row is judged so: its evidence (2 rows)</summary>" in silo
    assert ("| Filling bulk density | sphere2-abc | S2 | S2: 547.6 lies outside 618 to 627.4; at the study's scale for "
            "S2; settled fill |") in silo
    assert silo.index("</details>") > silo.index('<details markdown="1">')
    assert "runs this group in about" not in text  # no row of these groups is off the study's scale
    # the group's figure beside its rows, before them: one figure takes the page's width
    assert '<img src="silo/profiles.png" alt="profiles.png" width="100%">' in silo
    assert silo.index('<img src="silo/profiles.png" alt="profiles.png" width="100%">') < silo.index(
        "| table | figure | case | value | finding | study | agreement | scale |")
    # a configuration that plans none of a group's recorded runs: the estimate of those it plans, said to be others
    others = record_page(groups, status, {}, wall, 2, "config/validation.yaml", "config/thesis.yaml",
                         planned_core_s={"silo": 7200.0})
    assert "| silo | stale | 3 | 2.50 h | 2.00 h for the runs now planned, none recorded |" in others
    # with the findings' summary: it says which groups' rows are not those the configuration and the row code make
    summary = record_page(groups, status, {}, wall, 2, "config/validation.yaml", "config/thesis.yaml", verdicts={})
    assert ("Not complete against `config/validation.yaml` and today's row code: calibration, silo (see [The "
            "groups](#the-groups))") in summary



def test_the_budget_paragraph_adds_the_complete_groups_records_to_the_others_estimates():
    runs = [provenance_row(_record(), "silo_1", "3.8", [1], "c0ffee", 5400.0, [600.0], "2026-11-28", 1),
            provenance_row(_record("sphere2-def", ranks=2), "silo_2", "3.8", [2], "c0ffee", 1800.0, [], "2026-11-29")]
    groups = {"silo": GroupRecord(rows=_rows(), runs=runs)}
    status = {"calibration": "missing", "silo": "complete"}
    wall = {"silo": {"silo_1": 6000.0, "silo_2": 1800.0}}
    hypothesis = {"hypothesis": "stiffness_silo", "core_hours": 1.5}  # two rows of one pair
    lines = budget_lines(groups, status, wall, {"calibration": 7200.0, "silo": 1.0}, [hypothesis, hypothesis], 2,
                         3 * 3600.0, 1.5 * 3600.0)
    # silo: (5400 + 600) s on one core and 1800 s on two, 9600 s; the calibration's estimate 7200 s: 16800 s of 10800
    assert lines == ["**Budget**: the complete groups recorded 2.67 h of core time and the runs the other groups plan "
                     "are estimated at 2.00 h: 4.67 h against the tier's 3.00 h on 2 cores, over it by 1.67 h. The "
                     "longest part of a complete group, silo_1, took 1.67 h of wall time, over a part's 1.50 h. The "
                     "measured hypotheses are counted apart: 1 recorded, 1.50 h of core time."]
    # all complete and within: no estimate, and each part within its budget
    within = budget_lines(groups, {"silo": "complete"}, wall, {}, [], 2, 3 * 3600.0, 2 * 3600.0)
    assert within == ["**Budget**: the complete groups recorded 2.67 h of core time: 2.67 h against the tier's 3.00 h "
                      "on 2 cores, within it. The longest part of a complete group, silo_1, took 1.67 h of wall time, "
                      "within a part's 2.00 h."]

def test_publish_copies_what_the_pipeline_recorded_and_leaves_other_groups(tmp_path):
    workdir, record_dir = tmp_path / "work", tmp_path / "docs"
    plot = _png(tmp_path / "p.png")
    runs = [provenance_row(_record(), "silo", "3.8", [1], "c0ffee", 60.0, [], "2026-11-28")]
    recorded = write_group_record(workdir / "results" / "summary" / "record" / "silo", _rows(), runs,
                                  {"janssen.png": plot})
    write_group_record(record_dir / "blender", _rows(), runs, {})
    assert publish(workdir, record_dir, ["calibration", "silo"]) == ["silo"]
    assert (record_dir / "silo" / "janssen.png").read_bytes() == (recorded / "janssen.png").read_bytes() and (record_dir / "silo" / RUNS).is_file()
    assert (record_dir / "blender" / RUNS).is_file()


def test_a_record_keeps_the_products_other_groups_read_and_restores_only_what_is_missing(tmp_path):
    """A group another group reads keeps its runs' products under their working-directory paths; a later session
    restores the missing ones and leaves what it already has."""
    workdir, record_dir = tmp_path / "work", tmp_path / "docs"
    summary = "results/calibration/runs/sphere2-abc/metrics/bulk_friction.json"
    run = "results/calibration/runs/sphere2-abc/run.json"
    for name, text in ((summary, '{"bulk_friction": 0.5}'), (run, '{"run_id": "sphere2-abc"}')):
        (workdir / name).parent.mkdir(parents=True, exist_ok=True)
        (workdir / name).write_text(text)
    runs = [provenance_row(_record(), "calibration", "3.8", [1], "c0ffee", 60.0, [], "2026-11-28")]
    source = workdir / "results" / "summary" / "record" / "calibration"
    write_group_record(source, _rows(), runs, {}, {summary: workdir / summary, run: workdir / run})
    assert read_group_record(source).products == [summary, run]
    assert publish(workdir, record_dir, ["calibration"]) == ["calibration"]
    kept = record_dir / "calibration"
    assert (kept / PRODUCTS / summary).read_text() == '{"bulk_friction": 0.5}'
    # republished with fewer products, the record drops the one no longer made
    write_group_record(kept, _rows(), runs, {}, {summary: kept / PRODUCTS / summary})
    assert read_group_record(kept).products == [summary]
    write_group_record(kept, _rows(), runs, {}, {summary: workdir / summary, run: workdir / run})
    # a fresh machine: one product is already there (a user's), the other is restored
    fresh = tmp_path / "fresh"
    (fresh / run).parent.mkdir(parents=True)
    (fresh / run).write_text("mine")
    assert restore_products(kept, fresh) == [fresh / summary]
    # restored together, with one time: none looks newer than another, so Snakemake makes none of them again
    write_group_record(kept, _rows(), runs, {}, {summary: workdir / summary, run: workdir / run,
                                                 "results/x/metrics/a.json": workdir / run})
    again = tmp_path / "again"
    assert len({path.stat().st_mtime_ns for path in restore_products(kept, again)}) == 1
    assert (fresh / summary).read_text() == '{"bulk_friction": 0.5}' and (fresh / run).read_text() == "mine"
    assert restore_products(kept, fresh) == [fresh / "results/x/metrics/a.json"]
    with pytest.raises(ValueError, match="a path inside the working directory"):
        write_group_record(kept, _rows(), runs, {}, {"../outside.json": workdir / run})


def test_the_record_s_products_are_not_ignored_by_git(tmp_path):
    """The products a record keeps sit under ``products/results/...``, as in the workflow's working directory: the
    repository's .gitignore ignores only its top-level ``results/``, so that they are committed with the record.
    Checked by git itself in a fresh repository holding that .gitignore."""
    shutil.copy(REPO_ROOT / ".gitignore", tmp_path / ".gitignore")
    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)

    def ignored(path: str) -> bool:
        return subprocess.run(["git", "-C", str(tmp_path), "check-ignore", "-q", "--no-index", path],
                              check=False).returncode == 0

    product = f"{REPOSITORY_RECORD}/silo/{PRODUCTS}/results/silo_flat/sphere2-abc/run.json"
    assert not ignored(product), f"git ignores {product}"
    assert ignored("results/silo_flat/x/run.json")


def test_the_committed_page_is_rebuilt_from_the_committed_record(monkeypatch):
    """docs/validation/README.md is what `make validate` writes from the record files beside it, nothing typed in."""
    monkeypatch.chdir(REPO_ROOT)  # the page names the configs as `make validate` passes them, from the repository
    record_dir = REPO_ROOT / "docs" / "validation"
    assert (record_dir / RECORD_PAGE).read_text() == page("config/validation.yaml", "config/thesis.yaml", record_dir)


def test_the_wall_time_is_read_from_snakemake_s_benchmark(tmp_path):
    path = tmp_path / "run_benchmark.tsv"
    path.write_text("s\th:m:s\tmax_rss\tcpu_time\n121.57\t0:02:01\t132.63\t51.95\n")
    assert benchmark_wall_time(path) == 121.57
    path.write_text("s\th:m:s\n1.5\t0:00:01\n2.5\t0:00:02\n")
    assert benchmark_wall_time(path) == 2.5
    path.write_text("time,rss\n1,2\n")
    with pytest.raises(ValueError, match="not a Snakemake benchmark"):
        benchmark_wall_time(path)


def test_the_findings_section_counts_per_chapter_lists_what_is_not_reproduced_and_why_parts_are_unmeasured():
    at_scale = ScaleVerdict("S2", "silo_flat", True, (), True, "density", "at the study's scale")
    fill = DimensionDifference("fill_height", 0.1, 0.27, 0.37, 30.0, "at least 0.9 of the study's", "the head")
    shallow = ScaleVerdict("S1", "silo_flat", False, (fill,), True, "stress", "")
    off = row("Silo", "Janssen", "r", 1.3, 0.01, "-", "e", finding="S1.janssen",
              agreement=Agreement(NOT_REPRODUCED, "S1.janssen: 1.3 outside 0.9 to 1.1"))
    off.update(scale="not at scale")
    statuses = finding_statuses([_rows()[0], off])
    lines = findings_section(statuses, {"S2": at_scale, "S1": shallow}, {"S3.mass_flow": "no experiment rate"},
                             "config/validation.yaml")
    assert lines[0] == "## Does siloflow reproduce the study?"
    header = lines.index("| chapter | reproduced | not reproduced | not resolved | not at the study's scale | not measured |")
    assert lines[header + 3] == "| 5 | 0 | 1 | 0 | 1 | 4 |" and lines[header + 2] == "| 4 | 0 | 0 | 0 | 0 | 7 |"
    failed = lines.index("### Findings not reproduced")
    assert lines[failed + 2].startswith("- **S2** (§5.4.2, §3.10): ")
    assert lines[failed + 3].startswith("  - Filling bulk density (sphere2-abc): 548 ± 1.7 kg/m3; the study: ")
    assert "- S1.janssen: Janssen (r): 1.3 ± 0.01; the study: ratio about 1 (about_relative); S1.janssen: 1.3 outside 0.9 to 1.1" in lines
    assert "| S1 | §5.4.1 | not at the study's scale | 1 | no | fill height 0.37 | - |" in lines
    assert "| S2 | §5.4.2, §3.10 | not reproduced | 1 | yes | - | - |" in lines
    assert "- S3.mass_flow: no experiment rate" in lines
    assert any(line.startswith("- C1.finite_at_zero: its group's rows in this record predate it") for line in lines)


def test_every_finding_of_the_study_is_on_the_record_page():
    text = (REPO_ROOT / "docs" / "validation" / "README.md").read_text(encoding="utf-8")
    missing = [item.id for item in FINDINGS if f"\n| {item.id} | " not in text]
    assert not missing, f"findings without a line on the record's page: {missing}"


def test_rederive_writes_a_group_s_rows_again_from_the_products_its_record_keeps(tmp_path, capsys):
    config = str(REPO_ROOT / "config" / "validation.yaml")
    shutil.copytree(REPO_ROOT / "docs" / "validation" / "silo", tmp_path / "silo")
    derivation = json.loads((tmp_path / "silo" / DERIVATION).read_text())
    (tmp_path / "silo" / DERIVATION).write_text(json.dumps({**derivation, "row_code": "older"}))
    (tmp_path / "silo" / TABLE).write_text("group,figure,case,value,value_error,unit,study_value,scale_shows,evidence\n"
                                           "Silo,Density,r,1.0,0.1,kg/m3,667,yes,old\n")
    # runs the configuration no longer plans: their dimensions are not its own, so their rows are not judged on them
    runs = (tmp_path / "silo" / RUNS).read_text().splitlines()
    (tmp_path / "silo" / RUNS).write_text("\n".join([runs[0], *(re.sub(r"^[^,]+", f"sphere2-{k:010d}", line)
                                                               for k, line in enumerate(runs[1:]))]) + "\n")
    assert record_main(["rederive", "--record", str(tmp_path), "--config", config]) == 2
    assert ("silo: its recorded runs are not those " + config + " plans, so their rows cannot be judged on its "
            "dimensions: `make validate GROUP=silo` records it again") in capsys.readouterr().err
    # the same record as if its runs were those the configuration plans: derived again with today's row code
    planned = sorted(CLI._planned(config)["silo"])
    (tmp_path / "silo" / RUNS).write_text("\n".join([runs[0], *(re.sub(r"^[^,]+", run_id, line)
                                                               for run_id, line in zip(planned, runs[1:]))]) + "\n")
    assert record_main(["rederive", "--record", str(tmp_path), "--config", config]) == 0
    assert "rows of silo derived again from the products its record keeps" in capsys.readouterr().out
    again = read_group_record(tmp_path / "silo")
    committed = read_group_record(REPO_ROOT / "docs" / "validation" / "silo").rows
    judged = ("scale", "scale_reason")  # on this configuration's dimensions, not those the committed rows were
    assert [{k: v for k, v in row.items() if k not in judged} for row in again.rows] == [
        {k: v for k, v in row.items() if k not in judged} for row in committed]
    assert again.derivation["row_code"] == row_code_digest() and again.runs and again.products
    # a record that keeps no derivation cannot be derived again: it is recorded again
    shutil.copytree(REPO_ROOT / "docs" / "validation" / "blender", tmp_path / "blender")
    (tmp_path / "blender" / DERIVATION).unlink(missing_ok=True)
    assert record_main(["rederive", "--group", "blender", "--record", str(tmp_path), "--config", config]) == 2
    assert "blender: its record keeps no derivation" in capsys.readouterr().err


def test_a_run_carried_over_several_parts_counts_its_last_attempt_in_its_part_and_each_earlier_one_as_a_call():
    # two fills of 2.25 + 2.25 + 1 h side by side over three parts, the second a little slower in its last part
    runs = [provenance_row(_record(), "silo_3", "3.8", [1], "c0ffee", 3600.0, [8100.0, 8000.0], "2026-12-07", 1),
            provenance_row(_record("sphere2-def"), "silo_3", "3.8", [2], "c0ffee", 3900.0, [8050.0, 8100.0],
                           "2026-12-07", 1)]
    assert earlier_attempt_times(runs[0]) == [8100.0, 8000.0]
    # a record without attempt times: its earlier attempts' total as one; none when zero
    assert earlier_attempt_times({"earlier_attempts_s": 50.0}) == [50.0]
    assert earlier_attempt_times({"earlier_attempts_s": 0.0, "attempt_times_s": ""}) == []
    groups = {"silo": GroupRecord(rows=_rows(), runs=runs)}
    wall = CLI.measured_wall_times(groups, cores=2, sliced=frozenset({"sphere2-abc", "sphere2-def"}))
    assert wall == {"silo": {"silo_3": 3900.0, "silo earlier attempt 1": 8100.0, "silo earlier attempt 2": 8100.0}}
    # not carried over parts: interrupted and run again inside its part, which took it all its attempts
    assert CLI.measured_wall_times(groups, cores=2) == {"silo": {"silo_3": 3900.0 + 16150.0}}


def test_the_runs_the_validation_plan_carries_over_several_parts_are_its_long_silo_runs():
    made = CLI._plan(str(REPO_ROOT / "config" / "validation.yaml"))[1]
    sliced = CLI.sliced_runs(made)
    kinds = {e.run_id: e.kind for runs in made.values() for e in runs}
    # the two 270 mm fills, the front-wall series' fill and the two 12 s recirculations; no Jenike or blender run
    assert sorted(kinds[run] for run in sliced) == ["silo_flat"] * 3 + ["silo_recirculation"] * 2
