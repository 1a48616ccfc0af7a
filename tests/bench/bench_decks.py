"""Benchmark: the generated flat-bottom silo deck against a hand-written deck of the same case, stage by stage.

A small silo (80 mm wide, 12 mm deep, filled to 40 mm with the default gentle pour, about 1,400 two-sphere
clumps) runs twice, serially: once from the deck siloflow generates (through the engine interface, with its wall
force history, settle checks, settled-fill snapshot and restart files) and once from
``tests/bench/hand_silo.liggghts``, a minimal deck written by hand with the same clumps, materials, walls, time
step, pour and particle dumps, whose fill and settle run exactly as many steps as the generated run took. Both
logs are split into stages at their ``SILOFLOW`` markers (:func:`engines.liggghts.cost.stage_costs`), and each
stage's throughput (sphere-steps per CPU second) is compared: the ratio generated / hand-written is the figure
(1.0: the generator costs nothing; the brief asks for at least 0.95). Prints a table and writes it as CSV
(``argv[1]``, default ``results/bench/decks.csv``).

Run with ``python -m tests.bench.bench_decks results/bench/decks.csv`` (a few minutes on one core).
"""

from __future__ import annotations

import csv
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from engines.interface import EngineOptions
from engines.liggghts.cost import stage_costs
from engines.markers import parse_markers
from tests.bench.small_silo import small_silo

HAND_DECK = Path(__file__).resolve().parent / "hand_silo.liggghts"
SILO = {"width": 0.08, "depth": 0.012, "fill_height": 0.04, "outlet_width": 0.024, "discharge_time": 0.6,
        "settle": {"kinetic_energy_threshold": 1.0e-10, "max_time": 1.0}}
#: The stage that follows each marker of either deck; the generated deck's snapshot has no hand-written twin.
STAGE_AFTER = {None: "fill", "filled": "settle", "settled": "snapshot", "opened": "discharge", "discharged": "end"}
#: Material lines the hand-written deck hard-codes: the generated deck must carry the same values.
MATERIAL_PROPERTIES = ("youngsModulus", "poissonsRatio", "coefficientRestitution", "coefficientFriction",
                       "coefficientRollingFriction")


def _deck_value(deck: str, pattern: str) -> str:
    match = re.search(pattern, deck, flags=re.MULTILINE)
    if match is None:
        raise RuntimeError(f"the generated deck has no line matching {pattern!r}: the benchmark is out of date")
    return match.group(1)


def check_same_materials(generated: str, hand: str) -> None:
    """Refuse to compare decks whose material tables differ (the hand-written deck hard-codes the defaults)."""
    for name in MATERIAL_PROPERTIES:
        pattern = rf"^fix \S+ all property/global {name} (.*)$"
        if _deck_value(generated, pattern).split() != _deck_value(hand, pattern).split():
            raise RuntimeError(f"{name} differs between the generated and the hand-written deck; update {HAND_DECK.name}")


def hand_variables(case, generated_deck: str, log_text: str, meshes: Path) -> dict[str, str]:
    """The ``-var`` values of the hand-written deck: the case's numbers and the generated run's stage lengths."""
    markers = {marker.event: int(marker.values["step"]) for marker in parse_markers(log_text)
               if marker.event in ("filled", "settled")}
    x_min, x_max, _, _, z_min, z_max = case.fill.zone
    values = {
        "xlo": -0.5 * case.width, "xhi": 0.5 * case.width, "depth": case.depth, "zlo": -case.sink_depth,
        "zhi": case.domain_top, "skin": _deck_value(generated_deck, r"^neighbor (\S+) bin$"), "dt": case.timestep,
        "meshes": meshes, "thermo_every": _deck_value(generated_deck, r"^thermo (\d+)$"),
        "zone_xlo": x_min, "zone_xhi": x_max, "zone_zlo": z_min, "zone_zhi": z_max,
        "clumps_to_pour": case.fill.n_clumps, "rate": case.fill.particle_rate, "insert_every": case.fill.insert_every, "v_ins": case.fill.insertion_velocity,
        "fill_steps": markers["filled"], "settle_steps": markers["settled"] - markers["filled"],
        "discharge_steps": case.discharge_steps, "dump_every": case.dump_every,
    }
    return {name: repr(value) if isinstance(value, float) else str(value) for name, value in values.items()}


def run_hand_deck(run_dir: Path, variables: dict[str, str], executable: str = "liggghts") -> str:
    """Run the hand-written deck in ``run_dir`` (no shell: every value is one argument) and return its log."""
    (run_dir / "frames").mkdir(parents=True)
    command = [executable, "-in", str(HAND_DECK), "-log", "log.liggghts"]
    for name, value in variables.items():
        command += ["-var", name, value]
    subprocess.run(command, cwd=run_dir, check=True, stdout=subprocess.DEVNULL)
    return (run_dir / "log.liggghts").read_text()


def main(argv: list[str]) -> int:
    output = Path(argv[1] if len(argv) > 1 else "results/bench/decks.csv")
    case, engine = small_silo(SILO)
    with tempfile.TemporaryDirectory() as scratch:
        generated_dir, hand_dir = Path(scratch) / "generated", Path(scratch) / "hand"
        engine.write_inputs(case, generated_dir)
        generated_deck = (generated_dir / "deck" / "in.liggghts").read_text()
        check_same_materials(generated_deck, HAND_DECK.read_text())
        engine.run(case, generated_dir, EngineOptions(mpi_ranks=1))
        generated_log = (generated_dir / "log.liggghts").read_text()
        variables = hand_variables(case, generated_deck, generated_log, generated_dir / "deck" / "meshes")
        hand_log = run_hand_deck(hand_dir, variables)
    generated, hand = stage_costs(generated_log, STAGE_AFTER), stage_costs(hand_log, STAGE_AFTER)
    rows = []
    for stage in ("fill", "settle", "snapshot", "discharge"):
        mine, theirs = generated.get(stage), hand.get(stage)
        if mine is None:
            continue
        row = {"stage": stage, "generated_steps": mine.steps, "generated_cpu_s": mine.seconds,
               "generated_sphere_steps_per_s": mine.sphere_steps_per_second}
        if theirs is not None:
            row.update(hand_steps=theirs.steps, hand_cpu_s=theirs.seconds,
                       hand_sphere_steps_per_s=theirs.sphere_steps_per_second,
                       throughput_ratio=mine.sphere_steps_per_second / theirs.sphere_steps_per_second)
        rows.append(row)
    total_generated = sum(cost.seconds for cost in generated.values())
    total_hand = sum(cost.seconds for cost in hand.values())
    rows.append({"stage": "whole run", "generated_cpu_s": total_generated, "hand_cpu_s": total_hand,
                 "throughput_ratio": total_hand / total_generated})
    fields = ["stage", "generated_steps", "hand_steps", "generated_cpu_s", "hand_cpu_s",
              "generated_sphere_steps_per_s", "hand_sphere_steps_per_s", "throughput_ratio"]
    output.parent.mkdir(parents=True, exist_ok=True)
    with open(output, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=fields)
        writer.writeheader()
        writer.writerows(rows)
    print(f"silo of {case.fill.n_clumps} clumps, time step {case.timestep:.4g} s; ratio = generated / hand-written")
    for row in rows:
        ratio = row.get("throughput_ratio")
        print(f"{row['stage']:>10}: generated {row['generated_cpu_s']:8.1f} s"
              + (f", hand-written {row['hand_cpu_s']:8.1f} s" if "hand_cpu_s" in row else ", no hand-written twin")
              + (f", ratio {ratio:.3f}" if ratio is not None else ""))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv))
