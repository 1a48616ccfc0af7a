"""Benchmark: the generated decks of three cases against hand-written decks of the same cases, stage by stage.

Each case runs twice, serially on one core: once from the deck siloflow generates (through the engine interface,
with all its outputs: wall force histories, settle checks, settled-fill snapshots, contact dumps, restart files)
and once from a minimal deck written by hand (``tests/bench/hand_<case>.liggghts``) with the same clumps,
materials, walls, time step, fill, particle dumps and stage lengths: each of its stages runs exactly as many steps
as the generated run's took (read from the generated log's ``SILOFLOW <event> step=...`` markers). Both logs are
split into stages at their ``SILOFLOW`` markers (:func:`siloflow.engines.liggghts.cost.stage_costs`) and each stage's
throughput is compared.

Cases
-----
silo
    The flat-bottom silo of ``config/config.yaml`` made small (:data:`SILO`: 80 mm wide, 12 mm deep, filled to
    40 mm with the default gentle pour, about 1,400 two-sphere clumps): fill, settle, open, 0.6 s of discharge.
jenike
    The Jenike shear cell of ``config/config.yaml`` as it is (40 mm cell, about 800 clumps poured, rigid lid of
    280 spheres) at one calibration point (:data:`JENIKE_POINT`): fill, level, lid, consolidate, shear 6 mm.
blender
    The ``straight`` blender made small (:data:`BLENDER`: 160 mm wide, filled 5 mm above the tube inlet with the
    tests' fast pour, about 1,600 clumps one layer deep): fill, settle, open, 0.2 s of continuous discharge.

Output
------
A table per case and stage, printed and written as CSV (``argv[1]``, default ``results/bench/decks.csv``), with
the columns ``case``, ``stage``, ``generated_steps``, ``hand_steps`` (time steps, -), ``generated_cpu_s``,
``hand_cpu_s`` (the ``Loop time`` of the stage's ``run`` commands times the process count, s: the time-step loops
only, wall-clock, which is CPU time on an otherwise idle core), ``generated_sphere_steps_per_s``,
``hand_sphere_steps_per_s`` (throughput: spheres times steps per CPU second, 1/s) and ``throughput_ratio``
(generated / hand-written throughput, -: 1.0 means the generator costs nothing; the brief asks for at least 0.95).
A stage of the generated deck without a hand-written twin (the silo-type settled-fill snapshot) has only the
generated columns. The ``whole run`` row of each case compares the CPU time of the whole simulation: both
throughputs are the hand-written run's sphere-steps per each deck's CPU seconds, so their ratio is hand-written
CPU time / generated CPU time and the generated deck's extra stages count as its cost. That row also has
``generated_process_cpu_s`` and ``hand_process_cpu_s``: the user plus system CPU time of each LIGGGHTS process (s),
which adds what the loop times leave out (set-ups between runs, reading meshes, writing files) and, unlike them,
does not count time the process waited for a core.

Timings are only as steady as the machine: on a loaded machine (or a virtual one whose host is busy) identical runs
differ by 20 % and more, so compare ratios from an otherwise idle machine.

Run with ``python -m tests.bench.bench_decks results/bench/decks.csv`` (about 8 minutes on one free core).
"""

from __future__ import annotations

import csv
import math
import re
import resource
import subprocess
import sys
import tempfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from siloflow.model.cases.blender import BlenderCase, build_blender_case
from siloflow.model.cases.jenike import JenikeCase, build_jenike_case
from siloflow.model.cases.jenike_contacts import LID_TYPE
from siloflow.model.cases.jenike_sweep import sweep_points
from siloflow.model.cases.silo_flat import SiloCase
from siloflow.engines.interface import Engine, EngineOptions, engine_for
from siloflow.engines.liggghts.cost import StageCost, stage_costs
from siloflow.engines.markers import parse_markers
from tests.bench.small_silo import default_config_with, small_silo
from tests.conftest import FAST_POUR

BENCH_DIR = Path(__file__).resolve().parent

#: ``silo_flat`` keys of the small silo (m, s, J per clump).
SILO = {"width": 0.08, "depth": 0.012, "fill_height": 0.04, "outlet_width": 0.024, "discharge_time": 0.6,
        "settle": {"kinetic_energy_threshold": 1.0e-10, "max_time": 1.0}}
#: The calibration point of the Jenike run: the first of the default sweep, with its rigid lid (friction and
#: restitution coefficients, -). ``hand_jenike.liggghts`` hard-codes its contact matrices.
JENIKE_POINT = {"shape": "sphere2", "test": "internal", "sliding_friction": 0.1, "rolling_friction": 0.0,
                "restitution": 0.1, "rotation_blocked": False}
#: ``blender`` keys of the small blender (m, s, kg/m^3). 160 mm is the narrowest ``straight`` blender whose passages
#: keep ``blender.min_passage_clumps`` (4 clump sizes); the tests' fast pour fills it in a third of the default
#: pour's time. One clump layer packs loosely: 2,441 clumps poured for the default 667 kg/m^3 stood 0.2 m high on
#: average, about 430 kg/m^3, and reached into the pouring zone (which sits just above the planned crest).
BLENDER = {"width": 0.16, "fill_height": 0.15, "vertical_height": 0.16,
           "fill": {**FAST_POUR, "bulk_density_estimate": 440.0},
           "discharge": {"mode": "continuous", "time": 0.2, "steady_window": [0.1, 0.2], "profile_windows": 2},
           "pathlines": {"release_height": 0.1, "spacing": 0.0075, "integration_step": 0.001, "max_time": 200.0}}
BLENDER_CONFIGURATION = "straight"

#: The stage that follows each marker of the silo-type decks; the generated deck's snapshot has no hand-written twin.
SILO_STAGES = {None: "fill", "filled": "settle", "settled": "snapshot", "opened": "discharge", "discharged": "end"}
#: The stage that follows each marker of the Jenike decks (placing the lid runs no steps).
JENIKE_STAGES = {None: "fill", "filled": "level", "levelled": "lid", "lid_placed": "consolidate",
                 "consolidated": "shear", "sheared": "end"}
#: Material lines the hand-written decks hard-code: the generated deck must carry the same values, in the same order.
MATERIAL_PROPERTIES = ("youngsModulus", "poissonsRatio", "coefficientRestitution", "coefficientFriction",
                       "coefficientRollingFriction")
#: The lowest acceptable throughput ratio, generated / hand-written (-).
TARGET_RATIO = 0.95


@dataclass(frozen=True)
class GeneratedRun:
    """The generated run a hand-written deck copies.

    Attributes
    ----------
    run_dir : Path
        Its run directory (meshes under ``deck/meshes``).
    deck : str
        The generated deck's text.
    log : str
        Its LIGGGHTS log.
    """

    run_dir: Path
    deck: str
    log: str

    @property
    def steps(self) -> dict[str, int]:
        """The time step (-) at which the run printed each stage marker, by event (the last of a repeated one)."""
        return {marker.event: int(marker.values["step"]) for marker in parse_markers(self.log)}


@dataclass(frozen=True)
class DeckCase:
    """One case of the benchmark.

    Attributes
    ----------
    name : str
        Its name in the table.
    build : callable
        () -> (case, engine): the case and the engine that generates and runs its deck.
    hand_deck : Path
        The hand-written deck.
    variables : callable
        (case, generated run, hand-written run directory) -> the hand-written deck's ``-var`` values by name; it may
        write files the deck includes into that directory.
    stage_after : mapping of str or None to str
        The stage that follows each marker event (None: the first stage), for :func:`stage_costs`.
    describe : callable
        case -> one line saying what runs.
    """

    name: str
    build: Callable[[], tuple[Any, Engine]]
    hand_deck: Path
    variables: Callable[[Any, GeneratedRun, Path], Mapping[str, object]]
    stage_after: Mapping[str | None, str]
    describe: Callable[[Any], str]


def _deck_values(deck: str, pattern: str) -> list[str]:
    values = re.findall(pattern, deck, flags=re.MULTILINE)
    if not values:
        raise RuntimeError(f"the deck has no line matching {pattern!r}: the benchmark is out of date")
    return values


def _deck_value(deck: str, pattern: str) -> str:
    return _deck_values(deck, pattern)[0]


def check_same_materials(generated: str, hand: str) -> None:
    """Refuse to compare decks whose material tables differ (the hand-written decks hard-code them).

    Every ``property/global`` line of each of :data:`MATERIAL_PROPERTIES` is compared, in order: a deck that
    replaces its contact parameters between stages (the Jenike cell's fill and test values) must do so alike.
    """
    for name in MATERIAL_PROPERTIES:
        pattern = rf"^fix \S+ all property/global {name} (.*)$"
        mine = [value.split() for value in _deck_values(generated, pattern)]
        theirs = [value.split() for value in _deck_values(hand, pattern)]
        if mine != theirs:
            raise RuntimeError(f"{name} differs between the generated and the hand-written deck; update the latter")


def _domain(deck: str) -> list[float]:
    """(x_lo, x_hi, y_lo, y_hi, z_lo, z_hi) of the deck's simulation box (m)."""
    return [float(value) for value in _deck_value(deck, r"^region domain block (.+) units box$").split()]


def silo_variables(case: SiloCase, generated: GeneratedRun, hand_dir: Path) -> dict[str, object]:
    """The ``-var`` values of ``hand_silo.liggghts`` and ``hand_blender.liggghts`` (m, s, clumps/s, m/s, steps)."""
    steps = generated.steps
    x_lo, x_hi, _, _, z_lo, z_hi = _domain(generated.deck)
    zone_x_lo, zone_x_hi, _, _, zone_z_lo, zone_z_hi = case.fill.zone
    return {
        "xlo": x_lo, "xhi": x_hi, "depth": case.depth, "zlo": z_lo, "zhi": z_hi,
        "skin": _deck_value(generated.deck, r"^neighbor (\S+) bin$"), "dt": case.timestep,
        "meshes": generated.run_dir / "deck" / "meshes", "thermo_every": _deck_value(generated.deck, r"^thermo (\d+)$"),
        "zone_xlo": zone_x_lo, "zone_xhi": zone_x_hi, "zone_zlo": zone_z_lo, "zone_zhi": zone_z_hi,
        "clumps_to_pour": case.fill.n_clumps, "rate": case.fill.particle_rate, "insert_every": case.fill.insert_every,
        "v_ins": case.fill.insertion_velocity,
        "fill_steps": steps["filled"], "settle_steps": steps["settled"] - steps["filled"],
        "discharge_steps": steps["discharged"] - steps["opened"], "dump_every": case.dump_every,
    }


def blender_variables(case: BlenderCase, generated: GeneratedRun, hand_dir: Path) -> dict[str, object]:
    """The ``-var`` values of ``hand_blender.liggghts``: the silo's (the blender deck is the silo deck's)."""
    return silo_variables(case.silo, generated, hand_dir)


def jenike_variables(case: JenikeCase, generated: GeneratedRun, hand_dir: Path) -> dict[str, object]:
    """The ``-var`` values of ``hand_jenike.liggghts`` (m, s, kg/m^3, N, m/s, steps); writes the lid spheres' file.

    The file ``lid_spheres.liggghts`` in ``hand_dir`` creates the generated deck's lid spheres, at the height
    ``${lid_z}`` the deck measures.
    """
    lid = case.rigid_lid
    if lid is None or len(case.fill.region_centres) != 2:
        raise RuntimeError("hand_jenike.liggghts is an internal test with a rigid lid; the Jenike point is not")
    lid_spheres = hand_dir / "lid_spheres.liggghts"
    lid_spheres.write_text("".join(f"create_atoms {LID_TYPE} single {float(x)!r} {float(y)!r} ${{lid_z}} units box\n"
                                   for x, y in lid.positions))
    steps = generated.steps
    x_lo, x_hi, y_lo, y_hi, z_lo, z_hi = case.domain
    centre_1, centre_2 = case.fill.region_centres
    return {
        "xlo": x_lo, "xhi": x_hi, "ylo": y_lo, "yhi": y_hi, "zlo": z_lo, "zhi": z_hi,
        "skin": _deck_value(generated.deck, r"^neighbor (\S+) bin$"), "dt": case.timestep,
        "meshes": generated.run_dir / "deck" / "meshes", "thermo_every": _deck_value(generated.deck, r"^thermo (\d+)$"),
        "centre_1": centre_1, "centre_2": centre_2, "fill_radius": case.fill.region_radius,
        "fill_zlo": case.fill.region_z[0], "fill_zhi": case.fill.region_z[1], "clumps_to_fill": case.fill.n_clumps,
        "fill_steps": steps["filled"], "level_z": case.fill.level_z,
        # the first step after levelling is its own run (LIGGGHTS removes the partner spheres there)
        "level_steps": steps["levelled"] - steps["filled"] - 1,
        "lid_gap": lid.height_above_sample, "lid_spheres": lid_spheres, "lid_d": 2.0 * lid.sphere_radius,
        "lid_density": lid.density, "lid_sphere_weight": lid.sphere_weight, "normal_force": lid.normal_force,
        "ramp_steps": case.ramp_steps, "hold_steps": steps["consolidated"] - steps["lid_placed"] - case.ramp_steps,
        "shear_velocity": case.shear_velocity, "shear_steps": steps["sheared"] - steps["consolidated"],
        "dump_every": case.dump_every,
    }


def jenike_case() -> tuple[JenikeCase, Engine]:
    """The Jenike run of :data:`JENIKE_POINT` on the default configuration, rigid lid, and its engine."""
    config = default_config_with("jenike", {})
    points = sweep_points(config["jenike"]["sweep"], lid=config["jenike"]["lid"])
    point = {**JENIKE_POINT, "lid": "rigid"}
    if JENIKE_POINT not in points and point not in points:
        raise RuntimeError(f"{JENIKE_POINT} is not a point of the default Jenike sweep: the benchmark is out of date")
    return build_jenike_case(config, point), engine_for(config, "jenike")


def blender_case() -> tuple[BlenderCase, Engine]:
    """The small blender (:data:`BLENDER` on the default configuration) and its engine."""
    config = default_config_with("blender", BLENDER)
    return build_blender_case(config, BLENDER_CONFIGURATION), engine_for(config, "blender")


CASES = (
    DeckCase("silo", lambda: small_silo(SILO), BENCH_DIR / "hand_silo.liggghts", silo_variables, SILO_STAGES,
             lambda case: f"{case.fill.n_clumps} clumps, time step {case.timestep:.4g} s"),
    DeckCase("jenike", jenike_case, BENCH_DIR / "hand_jenike.liggghts", jenike_variables, JENIKE_STAGES,
             lambda case: f"{case.fill.n_clumps} clumps poured, lid of {case.rigid_lid.n_spheres} spheres, "
                          f"time step {case.timestep:.4g} s"),
    DeckCase("blender", blender_case, BENCH_DIR / "hand_blender.liggghts", blender_variables, SILO_STAGES,
             lambda case: f"{case.configuration} insert, {case.silo.fill.n_clumps} clumps, {case.mode} discharge, "
                          f"time step {case.silo.timestep:.4g} s"),
)


def _var_text(value: object) -> str:
    # repr keeps every digit of a float (numpy's too, which a plain repr would print as np.float64(...))
    return repr(float(value)) if isinstance(value, float) else str(value)


def run_hand_deck(deck: Path, run_dir: Path, variables: Mapping[str, object], executable: str = "liggghts") -> str:
    """Run a hand-written deck in ``run_dir`` (no shell: every value is one argument) and return its log."""
    (run_dir / "frames").mkdir(parents=True, exist_ok=True)
    command = [executable, "-in", str(deck), "-log", "log.liggghts"]
    for name, value in variables.items():
        command += ["-var", name, _var_text(value)]
    subprocess.run(command, cwd=run_dir, check=True, stdout=subprocess.DEVNULL)
    return (run_dir / "log.liggghts").read_text()


def _children_cpu_seconds() -> float:
    """User plus system CPU time of this process's finished children so far (s)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


@dataclass(frozen=True)
class CaseResult:
    """Both runs of one case.

    Attributes
    ----------
    description : str
        What ran (:attr:`DeckCase.describe`).
    generated, hand : dict of str to StageCost
        Each deck's stage costs (:func:`stage_costs`).
    generated_process_cpu_s, hand_process_cpu_s : float
        Each LIGGGHTS process's user plus system CPU time (s): set-ups between runs, reading and writing included,
        which the ``Loop time`` lines leave out.
    """

    description: str
    generated: dict[str, StageCost]
    hand: dict[str, StageCost]
    generated_process_cpu_s: float
    hand_process_cpu_s: float


def run_case(bench: DeckCase, scratch: Path) -> CaseResult:
    """Run one case from its generated deck, then from its hand-written deck, in ``scratch/<case>/``."""
    case, engine = bench.build()
    generated_dir, hand_dir = scratch / bench.name / "generated", scratch / bench.name / "hand"
    engine.write_inputs(case, generated_dir)
    deck = (generated_dir / "deck" / "in.liggghts").read_text()
    check_same_materials(deck, bench.hand_deck.read_text())
    start = _children_cpu_seconds()
    engine.run(case, generated_dir, EngineOptions(mpi_ranks=1))
    generated_cpu = _children_cpu_seconds() - start
    generated = GeneratedRun(generated_dir, deck, (generated_dir / "log.liggghts").read_text())
    hand_dir.mkdir(parents=True)
    variables = bench.variables(case, generated, hand_dir)
    start = _children_cpu_seconds()
    hand_log = run_hand_deck(bench.hand_deck, hand_dir, variables)
    hand_cpu = _children_cpu_seconds() - start
    return CaseResult(bench.describe(case), stage_costs(generated.log, bench.stage_after),
                      stage_costs(hand_log, bench.stage_after), generated_cpu, hand_cpu)


def case_rows(name: str, stage_after: Mapping[str | None, str], result: CaseResult) -> list[dict]:
    """The table rows of one case: each stage that ran, in deck order, and the whole run (units: module docstring)."""
    generated, hand = result.generated, result.hand
    rows = []
    for stage in dict.fromkeys(stage_after.values()):
        mine, theirs = generated.get(stage), hand.get(stage)
        if mine is None and theirs is None:
            continue
        row: dict = {"case": name, "stage": stage}
        if mine is not None:
            row.update(generated_steps=mine.steps, generated_cpu_s=mine.seconds,
                       generated_sphere_steps_per_s=mine.sphere_steps_per_second)
        if theirs is not None:
            row.update(hand_steps=theirs.steps, hand_cpu_s=theirs.seconds,
                       hand_sphere_steps_per_s=theirs.sphere_steps_per_second)
        if mine is not None and theirs is not None:
            row["throughput_ratio"] = mine.sphere_steps_per_second / theirs.sphere_steps_per_second
        rows.append(row)
    generated_s = sum(cost.seconds for cost in generated.values())
    hand_s = sum(cost.seconds for cost in hand.values())
    work = sum(cost.sphere_steps for cost in hand.values())
    rows.append({"case": name, "stage": "whole run",
                 "generated_steps": sum(cost.steps for cost in generated.values()),
                 "hand_steps": sum(cost.steps for cost in hand.values()),
                 "generated_cpu_s": generated_s, "hand_cpu_s": hand_s,
                 "generated_sphere_steps_per_s": work / generated_s, "hand_sphere_steps_per_s": work / hand_s,
                 "throughput_ratio": hand_s / generated_s,
                 "generated_process_cpu_s": result.generated_process_cpu_s,
                 "hand_process_cpu_s": result.hand_process_cpu_s})
    return rows


FIELDS = ["case", "stage", "generated_steps", "hand_steps", "generated_cpu_s", "hand_cpu_s",
          "generated_sphere_steps_per_s", "hand_sphere_steps_per_s", "throughput_ratio",
          "generated_process_cpu_s", "hand_process_cpu_s"]


def _cell(row: dict, field: str, width: int, scale: float = 1.0, digits: int = 1) -> str:
    value = row.get(field)
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return f"{'-':>{width}}"
    if isinstance(value, int):
        return f"{value:>{width}d}"
    return f"{value / scale:>{width}.{digits}f}"


def format_table(rows: list[dict]) -> str:
    """The rows as a fixed-width table (CPU seconds, millions of sphere-steps per CPU second, ratio), then each case's
    process CPU times."""
    lines = [f"{'case':<8} {'stage':<11} {'steps gen':>9} {'hand':>7} {'CPU s gen':>9} {'hand':>6} "
             f"{'M sph-steps/s gen':>17} {'hand':>5} {'ratio':>6}"]
    for row in rows:
        ratio = row.get("throughput_ratio")
        flag = " *" if ratio is not None and ratio < TARGET_RATIO else ""
        lines.append(f"{row['case']:<8} {row['stage']:<11} {_cell(row, 'generated_steps', 9)} "
                     f"{_cell(row, 'hand_steps', 7)} {_cell(row, 'generated_cpu_s', 9)} {_cell(row, 'hand_cpu_s', 6)} "
                     f"{_cell(row, 'generated_sphere_steps_per_s', 17, 1e6, 2)} "
                     f"{_cell(row, 'hand_sphere_steps_per_s', 5, 1e6, 2)} {_cell(row, 'throughput_ratio', 6, 1.0, 3)}{flag}")
    lines.append(f"ratio = generated / hand-written throughput; * below {TARGET_RATIO}; whole run: hand-written CPU s / "
                 "generated CPU s")
    for row in rows:
        if row.get("generated_process_cpu_s"):
            lines.append(f"{row['case']}: process CPU time (user + system) generated {row['generated_process_cpu_s']:.1f} s, "
                         f"hand-written {row['hand_process_cpu_s']:.1f} s, hand-written / generated "
                         f"{row['hand_process_cpu_s'] / row['generated_process_cpu_s']:.3f}")
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    output = Path(argv[1] if len(argv) > 1 else "results/bench/decks.csv")
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for bench in CASES:
            result = run_case(bench, Path(scratch))
            print(f"{bench.name}: {result.description}", flush=True)
            rows += case_rows(bench.name, bench.stage_after, result)
    output.parent.mkdir(parents=True, exist_ok=True)
    with open(output, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=FIELDS)
        writer.writeheader()
        writer.writerows(rows)
    print(format_table(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv))
