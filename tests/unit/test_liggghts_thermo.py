"""LIGGGHTS' thermo output: incremental parsing of the engine's screen output, and the progress it gives."""

from __future__ import annotations

import pytest

from siloflow.engines.liggghts.thermo import ThermoProgress, ThermoRow, column_name
from siloflow.engines.progress import progress_report

# Screen output as LIGGGHTS 3.8 writes it (header names cut to 8 characters, no v_ prefix), with the noise
# between thermo rows: INFO and WARNING lines, insertion progress, run statistics, blank lines.
SCREEN = """\
LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0, compiled 2022-01-26-19:42:32 by buildd, git commit unknown)
  1 by 1 by 1 MPI processor grid
WARNING: Energy calculated for multisphere particles is currently not correct (./src/fix_multisphere.cpp:1312)
INFO: Particle insertion pour: 183.000000 particles every 1156 steps - particle rate 13717.451671
Memory usage per processor = 12.1322 Mbytes
    Step    Atoms           Time       n_clumps       ke_per_c            CPU 
       0        0              0              0              0              0 
insertion: proc 0 at 50 %
INFO: Particle insertion pour: inserted 183 particle templates (mass 3.364647e-03) at step 1
     870      366    0.010040124            183  8.8671113e-08     0.12652729 
    1740     1200    0.020080248            600  3.3277597e-07     0.25200886 
Loop time of 0.252009 on 1 procs for 1740 steps with 1200 atoms, finish time Sat Nov 21 12:23:30 2026

Pair  time (%) = 1.54284 (31.0069)
Nlocal:    906 ave 906 max 906 min
Histogram: 1 0 0 0 0 0 0 0 0 0
SILOFLOW filled step=1740 time=0.02008024800000000000 clumps=600 ke_per_clump=3.3277597e-07
Setting up run at Sat Nov 21 12:23:30 2026

    Step    Atoms           Time       n_clumps       ke_per_c            CPU 
    1740     1200    0.020080248            600  3.3277597e-07              0 
    2610     1200    0.030120372            600  6.9736642e-07     0.37364826 
Loop time of 0.37 on 1 procs for 870 steps with 1200 atoms
SILOFLOW settle step=2610 time=0.030120372 clumps=600 ke_per_clump=6.9736642e-07
"""

LAST_ROW = ThermoRow(step=2610, atoms=1200, time=0.030120372, clumps=600.0, ke_per_clump=6.9736642e-07,
                     cpu=0.37364826, extra={})


def _fed(*chunks: str) -> ThermoProgress:
    progress = ThermoProgress()
    for chunk in chunks:
        progress.feed(chunk)
    return progress


def test_whole_output_gives_the_last_row_and_marker():
    progress = _fed(SCREEN)
    assert progress.latest == LAST_ROW
    assert progress.rows_read == 5
    assert progress.markers_read == 2
    assert progress.stage == "settle"
    marker = progress.last_marker
    assert marker.event == "settle"
    assert marker.values == {"step": 2610.0, "time": 0.030120372, "clumps": 600.0, "ke_per_clump": 6.9736642e-07}
    # the block ended with its Loop time line
    assert progress.columns is None


def test_feed_returns_the_rows_each_chunk_completes():
    progress = ThermoProgress()
    first, second = SCREEN.split("Setting up run")
    rows = progress.feed(first)
    assert [row.step for row in rows] == [0, 870, 1740]
    assert rows[1] == ThermoRow(step=870, atoms=366, time=0.010040124, clumps=183.0, ke_per_clump=8.8671113e-08,
                                cpu=0.12652729)
    assert progress.stage == "filled"
    assert [row.step for row in progress.feed(second)] == [1740, 2610]


@pytest.mark.parametrize(
    "split_after",
    ["    Ste", "    Step    Atoms       ", "0.0100", "0.020080248            6", "8.8671113e-", "SILOFLOW fil",
     "ke_per_clump=3.3277597e", "Loop time of 0.2"],
)
def test_awkward_splits_give_the_same_result(split_after):
    position = SCREEN.index(split_after) + len(split_after)
    progress = _fed(SCREEN[:position], SCREEN[position:])
    assert progress.latest == LAST_ROW
    assert progress.rows_read == 5 and progress.markers_read == 2


def test_every_two_chunk_split_and_one_character_chunks_give_the_same_result():
    for position in range(len(SCREEN) + 1):
        progress = _fed(SCREEN[:position], SCREEN[position:])
        assert (progress.latest, progress.rows_read, progress.stage) == (LAST_ROW, 5, "settle"), position
    progress = _fed(*SCREEN)
    assert (progress.latest, progress.rows_read, progress.markers_read) == (LAST_ROW, 5, 2)


def test_an_unfinished_line_waits_for_its_end_or_a_flush():
    progress = ThermoProgress()
    progress.feed("    Step    Atoms           Time       n_clumps       ke_per_c            CPU\n")
    progress.feed("     870      366    0.010040124            183  8.8671113e-08     0.12652729")
    assert progress.latest is None
    assert [row.step for row in progress.flush()] == [870]
    assert progress.latest.cpu == 0.12652729
    assert progress.flush() == []


def test_windows_line_endings_are_read():
    progress = _fed(SCREEN.replace("\n", "\r\n"))
    assert progress.latest == LAST_ROW and progress.stage == "settle"


def test_header_with_the_v_prefix_and_extra_columns():
    # the thermo_style of the Jenike deck, spelt with the v_ prefix of its variables
    text = (
        "Step Atoms Time v_n_clumps v_ke_per_clump v_sample_top v_lid_fz CPU\n"
        "16901 662 0.19504383 331 5.7985802e-12 0.0084476655 12.5 0.0003\n"
    )
    progress = _fed(text)
    assert progress.columns == ("step", "atoms", "time", "n_clumps", "ke_per_clump", "sample_top", "lid_fz", "cpu")
    assert progress.latest == ThermoRow(step=16901, atoms=662, time=0.19504383, clumps=331.0,
                                        ke_per_clump=5.7985802e-12, cpu=0.0003,
                                        extra={"sample_top": 0.0084476655, "lid_fz": 12.5})


def test_truncated_extra_columns_keep_their_header_names():
    text = (
        "    Step    Atoms           Time       n_clumps       ke_per_c       sample_t            CPU \n"
        "   16900      673     0.19503229          336.5  5.9736479e-12   0.0084885193              0 \n"
    )
    row = _fed(text).latest
    assert row.clumps == 336.5 and row.extra == {"sample_t": 0.0084885193}


def test_header_without_ke_and_cpu_columns_leaves_them_unknown():
    row = _fed("Step Atoms Time v_n_clumps\n10 4 0.5 2\n").latest
    assert row == ThermoRow(step=10, atoms=4, time=0.5, clumps=2.0, ke_per_clump=None, cpu=None)


@pytest.mark.parametrize(
    "bad_row",
    [
        "    1800     1200    0.0200x0248            600  3.3e-07     0.3",  # not a number
        "    1800     1200    0.0200            600  3.3e-07",  # a column missing
        "    1800     1200    0.0200            600  3.3e-07   0.3   7",  # a column too many
        "    1800.5   1200    0.0200            600  3.3e-07     0.3",  # fractional step
        "    1800     1200       nan            600  3.3e-07     0.3",  # no time
        "    1800     1200       inf            600  3.3e-07     0.3",
        "    1800     1200    0.0200           -nan  3.3e-07     0.3",
        "ERROR: Lost atoms: original 1200 current 1198 (../thermo.cpp:389)",
        "",
        "   ",
    ],
)
def test_malformed_rows_and_other_lines_are_ignored(bad_row):
    first, second = SCREEN.split("Setting up run")
    progress = _fed(first)
    before = progress.latest
    # inside the second thermo block, before its last row
    head, tail = second.split("    2610")
    progress.feed(head + bad_row + "\n")
    assert progress.latest == ThermoRow(step=1740, atoms=1200, time=0.020080248, clumps=600.0,
                                        ke_per_clump=3.3277597e-07, cpu=0.0)
    assert before.step == 1740
    progress.feed("    2610" + tail)
    assert progress.latest == LAST_ROW


def test_numbers_outside_a_thermo_block_are_not_rows():
    text = (
        "0 0 0 0 0 0\n"  # before any header
        "Step Atoms Time n_clumps ke_per_c CPU\n"
        "10 20 0.1 10 1e-9 0.5\n"
        "Loop time of 0.5 on 1 procs for 10 steps with 20 atoms\n"
        "20 40 0.2 20 1e-9 0.9\n"  # after the block ended
    )
    progress = _fed(text)
    assert progress.rows_read == 1 and progress.latest.step == 10


def test_echoed_print_commands_are_not_markers():
    progress = _fed('print "SILOFLOW settled step=$(step) time=$(time) clumps=${n_clumps}"\n'
                    "SILOFLOW opened step=50 time=0.5 clumps=20 ke_per_clump=1e-9\n"
                    "SILOFLOW\n")
    assert progress.stage == "opened" and progress.markers_read == 1
    assert progress.last_marker.values["step"] == 50.0


def test_feed_refuses_bytes():
    with pytest.raises(ValueError, match="str"):
        ThermoProgress().feed(b"Step Atoms Time")


@pytest.mark.parametrize("word, name", [("Step", "step"), ("v_n_clumps", "n_clumps"), ("ke_per_c", "ke_per_clump"),
                                        ("v_ke_per", "ke_per_clump"), ("CPU", "cpu"), ("sample_t", "sample_t")])
def test_column_names(word, name):
    assert column_name(word) == name


def test_progress_from_parsed_output():
    parsed = _fed(SCREEN)
    progress = progress_report(parsed.latest, 0.06, 10.0, stage=parsed.stage, run_id="tiny")
    assert progress.fraction == pytest.approx(0.030120372 / 0.06, rel=1e-12)
    assert str(progress) == "run tiny: 0.0301 / 0.0600 s simulated (50 %), 600 clumps, stage settle, elapsed 10 s, ETA 9.9 s"
