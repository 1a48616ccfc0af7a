"""Reading the engine log: stage markers, error lines, and the checks of a finished silo run."""

from __future__ import annotations


import pytest

from siloflow.engines.interface import EngineNotFound, EngineRunError
from siloflow.engines.liggghts.run import engine_command, set_aside_previous_attempt
from siloflow.engines.liggghts.markers import error_lines
from siloflow.engines.markers import parse_markers
from siloflow.engines.silo_checks import check_silo_run
from siloflow.model.cases.silo_flat import build_silo_case

LOG = """\
print "SILOFLOW filled step=$(step) time=$(time) clumps=${n_clumps} ke_per_clump=${ke_per_clump}"
SILOFLOW filled step=26391 time=0.30456196341661323501 clumps=1395 ke_per_clump=8.89482733543151e-09
WARNING: Particle insertion: Less insertions than requested (./src/fix_insert.cpp:814)
SILOFLOW settle step=27258 time=0.31 clumps=1395 ke_per_clump=5.9e-09
SILOFLOW settled step=34194 time=0.39461148789616412591 clumps=1395 ke_per_clump=5.43629662393841e-11
SILOFLOW opened step=34194 time=0.39461148789616412591 clumps=1395 ke_per_clump=5.43629662393841e-11
SILOFLOW discharged step=86186 time=0.99461852067084310924 clumps=355 ke_per_clump=3.1e-07
"""


def test_markers_are_parsed_in_order_and_echoed_print_commands_skipped():
    markers = parse_markers(LOG)
    assert [m.event for m in markers] == ["filled", "settle", "settled", "opened", "discharged"]
    assert markers[0].values == {
        "step": 26391.0,
        "time": 0.30456196341661323501,
        "clumps": 1395.0,
        "ke_per_clump": 8.89482733543151e-09,
    }


def test_error_lines_find_errors_lost_atoms_and_crashes_but_not_warnings():
    text = LOG + "ERROR: Lost atoms: original 1596 current 1596 (./src/thermo.cpp:445)\n[vm:1] *** Process received signal ***\n"
    assert error_lines(text) == [
        "ERROR: Lost atoms: original 1596 current 1596 (./src/thermo.cpp:445)",
        "[vm:1] *** Process received signal ***",
    ]
    assert error_lines(LOG) == []


def _dumps(tmp_path, count):
    return [tmp_path / f"particles_{i}.vtk" for i in range(count)]


def test_a_complete_run_passes_the_checks(tiny_config, tmp_path):
    case = build_silo_case(tiny_config)
    log = LOG.replace("clumps=1395", f"clumps={case.fill.n_clumps}")
    record = check_silo_run(case, parse_markers(log), _dumps(tmp_path, 3), tmp_path)
    assert record["open_step"] == 34194
    assert record["n_clumps"] == case.fill.n_clumps
    assert len(record["settle_checks"]) == 1
    # the settled stage keeps the criterion it was held to, in joules and over the clump's m g d
    scale = case.settle_criterion.energy_scale
    assert record["settled"]["ke_threshold_J"] == case.settle_threshold == pytest.approx(1.67e-4 * scale, rel=1e-12)
    assert record["settled"]["ke_threshold_ratio"] == pytest.approx(1.67e-4, rel=1e-12)
    assert record["settled"]["ke_ratio"] == pytest.approx(5.43629662393841e-11 / scale, rel=1e-12)


def test_missing_clumps_are_reported(tiny_config, tmp_path):
    case = build_silo_case(tiny_config)
    with pytest.raises(EngineRunError, match=rf"only 1000 of {case.fill.n_clumps} clumps were inserted"):
        check_silo_run(case, parse_markers(LOG.replace("clumps=1395", "clumps=1000")), _dumps(tmp_path, 3), tmp_path)


def test_an_unsettled_fill_is_reported(tiny_config, tmp_path):
    case = build_silo_case(tiny_config)
    log = LOG.replace("clumps=1395", f"clumps={case.fill.n_clumps}").replace("5.43629662393841e-11", "3e-9")
    # the tiny silo settles to 1.67e-4 of the clump's m g d (6.0e-7 J): 1.0e-10 J
    expected = (r"did not settle: kinetic energy per clump 3e-09 J \(0.005 of the clump's m g d\) is above the "
                r"threshold 1e-10 J \(0.000167 of m g d, set by silo_flat.settle.kinetic_energy_ratio\) .* raise "
                r"silo_flat.settle.max_time or silo_flat.settle.kinetic_energy_ratio")
    with pytest.raises(EngineRunError, match=expected):
        check_silo_run(case, parse_markers(log), _dumps(tmp_path, 3), tmp_path)


def test_a_truncated_log_is_reported(tiny_config, tmp_path):
    case = build_silo_case(tiny_config)
    truncated = "\n".join(LOG.splitlines()[:4])
    with pytest.raises(EngineRunError, match="no 'settled' stage marker"):
        check_silo_run(case, parse_markers(truncated), _dumps(tmp_path, 3), tmp_path)


def test_missing_dumps_are_reported(tiny_config, tmp_path):
    case = build_silo_case(tiny_config)
    log = LOG.replace("clumps=1395", f"clumps={case.fill.n_clumps}")
    with pytest.raises(EngineRunError, match="expected particle dumps of the discharge, found 0"):
        check_silo_run(case, parse_markers(log), [], tmp_path)


def test_engine_command_serial_and_mpi():
    # the screen line-buffered (stdbuf, coreutils: on every Debian), so that the progress line sees each thermo row
    assert engine_command("deck/in.liggghts", executable="true") == ["stdbuf", "-oL", "true", "-in", "deck/in.liggghts",
                                                                     "-log", "log.liggghts"]
    assert engine_command("d", executable="true", mpi_ranks=2, mpirun="true") == [
        "true", "-np", "2", "--oversubscribe", "stdbuf", "-oL", "true", "-in", "d", "-log", "log.liggghts"]


def test_missing_executable_is_a_clear_error_naming_its_key():
    with pytest.raises(EngineNotFound, match=r"^config key 'engine.liggghts.executable': LIGGGHTS executable "
                                             r"'no-such-liggghts' is not an executable on PATH"):
        engine_command("d", executable="no-such-liggghts")
    with pytest.raises(EngineNotFound, match=r"^config key 'engine.mpirun': MPI launcher 'no-such-mpirun' "
                                             r"\(engine.mpi_ranks is 2\)"):
        engine_command("d", executable="true", mpi_ranks=2, mpirun="no-such-mpirun")
    engine_command("d", executable="true", mpi_ranks=1, mpirun="no-such-mpirun")  # serial: no launcher needed


def test_an_earlier_attempt_is_moved_aside_not_deleted(tmp_path):
    (tmp_path / "dumps").mkdir()
    (tmp_path / "dumps" / "particles_0.vtk").write_text("old")
    (tmp_path / "log.liggghts").write_text("old log")
    moved = set_aside_previous_attempt(tmp_path)
    assert (moved / "dumps" / "particles_0.vtk").read_text() == "old"
    assert (moved / "log.liggghts").read_text() == "old log"
    assert not (tmp_path / "dumps").exists()
    assert set_aside_previous_attempt(tmp_path) is None


def test_a_periodic_run_that_lost_clumps_is_reported(tiny_config, tmp_path):
    case = build_silo_case(tiny_config)
    n = case.fill.n_clumps
    log = LOG.replace("clumps=1395", f"clumps={n}").replace("clumps=355", f"clumps={n - 3}")
    # a batch silo drains: fewer clumps at the end is the point
    assert check_silo_run(case, parse_markers(log), _dumps(tmp_path, 3), tmp_path)["discharged"]["clumps"] == n - 3
    with pytest.raises(EngineRunError, match=rf"{n} clumps were inserted but {n - 3} remain after the 'discharged' stage"):
        check_silo_run(case, parse_markers(log), _dumps(tmp_path, 3), tmp_path, clumps_conserved=True)
    conserved = log.replace(f"clumps={n - 3}", f"clumps={n}")
    assert check_silo_run(case, parse_markers(conserved), _dumps(tmp_path, 3), tmp_path, clumps_conserved=True)


def test_a_discharge_after_the_recirculations_needs_its_marker_and_keeps_the_recirculation_conserved(tiny_config,
                                                                                                       tmp_path):
    """The recirculating silo with a discharge after it: the clumps are counted at 'recirculated' (all there), the
    'discharged' stage after it drains and is kept in the record; without its marker the run did not finish."""
    case = build_silo_case(tiny_config)
    n = case.fill.n_clumps
    log = LOG.replace("clumps=1395", f"clumps={n}").replace("clumps=355", "clumps=40").replace(
        "SILOFLOW discharged", f"SILOFLOW recirculated step=60000 time=0.7 clumps={n} ke_per_clump=1e-7\nSILOFLOW discharged")
    checked = check_silo_run(case, parse_markers(log), _dumps(tmp_path, 3), tmp_path, last_stage="recirculated",
                             clumps_conserved=True, then="discharged")
    assert checked["recirculated"]["clumps"] == n and checked["discharged"]["clumps"] == 40
    unfinished = log.split("SILOFLOW discharged")[0]
    with pytest.raises(EngineRunError, match="the log has no 'discharged' stage marker"):
        check_silo_run(case, parse_markers(unfinished), _dumps(tmp_path, 3), tmp_path, last_stage="recirculated",
                       clumps_conserved=True, then="discharged")
