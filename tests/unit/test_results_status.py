"""What a results folder holds for a configuration, classified on names and times (exact answers)."""

from __future__ import annotations

from siloflow.engines.results_status import (FINISHED, TO_DO, UNFINISHED, FolderListing, results_status, scan_results,
                                             status_lines)
from siloflow.model.cost import RunEstimate


def _estimate(run_id: str, kind: str) -> RunEstimate:
    return RunEstimate(run_id=run_id, kind=kind, clumps=1, spheres=1, steps=1, sphere_steps=1.0, simulated_time_s=1.0,
                       wall_time_s=1.0, dump_frames=0, dump_bytes=0, mpi_ranks=1)


PLAN = [_estimate("a", "jenike"), _estimate("b", "jenike"), _estimate("c", "jenike"), _estimate("s", "silo_flat")]


def test_each_planned_run_is_finished_unfinished_or_to_do_in_plan_order():
    listing = FolderListing(folders={"jenike": {"a", "b", "old"}, "silo_flat": set()},
                            records={("jenike", "a"): 10.0, ("jenike", "old"): 50.0}, report_time=20.0)
    status = results_status(PLAN, listing)
    assert status.states == {"jenike": {FINISHED: ["a"], UNFINISHED: ["b"], TO_DO: ["c"]},
                             "silo_flat": {FINISHED: [], UNFINISHED: [], TO_DO: ["s"]}}
    assert status.not_planned == {"jenike": ["old"]}
    assert status.counts() == {FINISHED: 1, UNFINISHED: 1, TO_DO: 2}
    # the record of a run this configuration does not plan does not make its report stale
    assert status.report_stale is False


def test_a_report_older_than_a_planned_runs_record_is_stale_and_no_report_is_none():
    records = {("jenike", "a"): 30.0}
    assert results_status(PLAN, FolderListing({"jenike": {"a"}}, records, report_time=20.0)).report_stale is True
    assert results_status(PLAN, FolderListing({"jenike": {"a"}}, records, report_time=None)).report_stale is None


def test_the_status_lines():
    status = results_status(PLAN, FolderListing({"jenike": {"a", "b", "old"}}, {("jenike", "a"): 30.0}, 20.0))
    assert status_lines(status, "results") == [
        "jenike: 1 finished, 1 unfinished, 1 to do",
        "  unfinished (the next run resumes it): b",
        "silo_flat: 1 to do",
        "jenike: 1 folder(s) this configuration does not plan (another configuration's, or runs whose parameters "
        "have changed since; kept): old",
        "in all: 1 finished, 1 unfinished, 2 to do, under results/",
        "report: stale (older than a finished run it shows); `siloflow run` writes it again",
    ]


def test_scan_reads_run_folders_records_and_the_report_and_skips_other_folders(tmp_path):
    results = tmp_path / "results"
    root = results / "calibration" / "runs"  # the Jenike runs' case root
    (root / "a" / "deck").mkdir(parents=True)
    (root / "a" / "run.json").write_text("{}")
    (root / "plots").mkdir()  # a folder that is no run: neither inputs nor a record
    (root / "table.csv").write_text("")
    listing = scan_results(results, ["jenike", "silo_flat"], tmp_path / "report.html")
    assert listing.folders == {"jenike": {"a"}, "silo_flat": set()}
    assert set(listing.records) == {("jenike", "a")} and listing.report_time is None
