"""LIGGGHTS (LIGGGHTS-PUBLIC 3.8, Debian ``liggghts``) behind the engine interface.

:class:`LiggghtsEngine` dispatches each case kind to its deck module (:mod:`siloflow.engines.liggghts.silo_flat`,
:mod:`~siloflow.engines.liggghts.silo_recirculation`, :mod:`~siloflow.engines.liggghts.blender`, :mod:`~siloflow.engines.liggghts.jenike`) and
reads the engine's files back into the neutral objects of :mod:`model`. Its templates live in
``siloflow/templates/liggghts/``; every case template extends :attr:`LiggghtsEngine.base_template`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from siloflow.model.forces import WallForceHistory
from siloflow.model.frames import ParticleFrame
from siloflow.model.record import RunRecord
from siloflow.model.settled import SettledFill
from siloflow.model.cases.jenike import JenikeCase
from siloflow.model.cases.kinds import case_kind, kind_of_case
from siloflow.model.cases.verification import VerificationCase
from siloflow.model.cost import MeasuredWork
from siloflow.engines.interface import CaseNotSupported, DumpFile, Engine, EngineOptions, register
from siloflow.engines.layout import CASE_SUMMARY
from siloflow.engines.run_files import earlier_attempt_logs
from siloflow.model.cases.blender import GATE
from siloflow.engines.liggghts.blender import run_blender, write_blender_inputs
from siloflow.engines.liggghts.contacts import read_contacts
from siloflow.engines.liggghts.dump_files import match_dump_files, read_dump_files
from siloflow.engines.liggghts.dumps import list_dumps, read_frames
from siloflow.engines.liggghts.forces import read_jenike_forces, read_wall_forces
from siloflow.engines.liggghts.inputs import ENGINE_NAME
from siloflow.engines.jenike_checks import JENIKE_FLOOR_WALLS
from siloflow.engines.liggghts.jenike import (
    PAIR_CONTACT_PREFIX,
    SETTLED_CONTACT_PREFIX,
    WALL_CONTACT_PREFIX,
    read_jenike_pair_contacts,
    read_jenike_wall_contacts,
    run_jenike,
    write_jenike_inputs,
)
from siloflow.engines.liggghts.cost import elapsed_seconds, measured_work as work_from_logs
from siloflow.engines.liggghts.run import ASSEMBLY_RESTART, CONTACT_PREFIX, DUMP_PREFIX, attempt_logs, check_programs
from siloflow.engines.liggghts.settled import read_settled_fill
from siloflow.model.cases.silo_flat import FLOOR_MESHES
from siloflow.engines.liggghts.silo_flat import run_silo, write_silo_inputs
from siloflow.engines.liggghts.silo_recirculation import run_recirculation, write_recirculation_inputs
from siloflow.engines.liggghts.verification import run_verification, write_verification_inputs

__all__ = ["ADAPTERS", "Adapter", "LiggghtsEngine", "MIN_RESTITUTION"]

#: LIGGGHTS 3.8 refuses a coefficient of restitution at or below this value (it requires 0.05 < e <= 1).
MIN_RESTITUTION = 0.05

def _table_pairs(table) -> list[tuple[str, str, float, str]]:
    """The particle's pairs of a material table (its first material is the particle's), keyed ``contacts``."""
    return [(table.names[0], table.names[j], float(value), "contacts") for j, value in enumerate(table.restitution[0])]


def _silo_pairs(case) -> list[tuple[str, str, float, str]]:
    return _table_pairs(case.materials)


def _wrapped_silo_pairs(case) -> list[tuple[str, str, float, str]]:
    """The pairs of a case built around a silo (the recirculating silo, the blender)."""
    return _table_pairs(case.silo.materials)


def _jenike_pairs(case: JenikeCase) -> list[tuple[str, str, float, str]]:
    names = case.materials.names
    found = []
    # the sweep point sets the test's restitution and, unless jenike.fill.restitution is set, the pour's: name it first
    for contacts, key in ((case.test_contacts, "jenike.sweep.restitution"), (case.fill_contacts, "jenike.fill.restitution")):
        for j, value in enumerate(contacts.restitution[0]):
            found.append((names[0], names[j], float(value), key))
    return found


def _verification_pairs(case: VerificationCase) -> list[tuple[str, str, float, str]]:
    return [("sphere", "sphere", case.restitution, f"verification problem {case.name}")]


@dataclass(frozen=True)
class Adapter:
    """How LIGGGHTS renders and runs one case kind.

    Attributes
    ----------
    write, run : callable
        ``write(case, deck_dir)`` and ``run(case, run_dir, *, executable, mpi_ranks, mpirun) -> RunRecord``.
    restitution_pairs : callable
        ``(case) -> [(material a, material b, restitution, config key), ...]``: every pair with a particle in it,
        which LIGGGHTS' restitution limit is checked on.
    floor_walls : tuple of str or None
        The walls (meshes) that make the floor of its settled fill; None: it saves none.
    """

    write: Callable
    run: Callable
    restitution_pairs: Callable
    floor_walls: tuple[str, ...] | None = None


#: The case kinds LIGGGHTS runs, one adapter each, by the kind's name (:mod:`siloflow.model.cases.kinds`): the plates and
#: gate of the silos, the blender's gate (its hopper and inserts are walls) and the Jenike cell's base make floors.
ADAPTERS = {
    "silo_flat": Adapter(write_silo_inputs, run_silo, _silo_pairs, FLOOR_MESHES),
    "silo_recirculation": Adapter(write_recirculation_inputs, run_recirculation, _wrapped_silo_pairs, FLOOR_MESHES),
    "blender": Adapter(write_blender_inputs, run_blender, _wrapped_silo_pairs, (GATE,)),
    "jenike": Adapter(write_jenike_inputs, run_jenike, _jenike_pairs, JENIKE_FLOOR_WALLS),
    "verification": Adapter(write_verification_inputs, run_verification, _verification_pairs),
}


def _adapter(case) -> tuple[str, Adapter]:
    """The name of ``case``'s kind and LIGGGHTS' adapter for it."""
    kind = kind_of_case(case).name
    if kind not in ADAPTERS:
        raise CaseNotSupported(f"LIGGGHTS has no deck for {kind} cases; it runs {', '.join(ADAPTERS)}")
    return kind, ADAPTERS[kind]


@register
class LiggghtsEngine(Engine):
    """LIGGGHTS-PUBLIC 3.8: decks from ``siloflow/templates/liggghts/``, run serially or under MPI, read back."""

    name = ENGINE_NAME
    debian_package = "liggghts"
    base_template = "liggghts/base.lmp.j2"

    def check_case(self, case) -> None:
        """Refuse a case LIGGGHTS cannot run: a restitution at or below 0.05, a stage sequence it has no deck for.

        Raises
        ------
        CaseNotSupported
            Naming the config key, the value and the limit.
        """
        name, adapter = _adapter(case)
        kinds = tuple(stage.kind for stage in case.stages())
        kind = case_kind(name)
        if not kind.runs_stages(kinds):
            runs = " or ".join(str(stages) for stages in dict.fromkeys((kind.stages, kind.stages + kind.final_stages)))
            raise CaseNotSupported(f"{name} run {case.run_id}: LIGGGHTS has no deck for the stages {kinds}; "
                                   f"it runs {runs}")
        for a, b, value, key in adapter.restitution_pairs(case):
            if not value > MIN_RESTITUTION:
                raise CaseNotSupported(
                    f"config key '{key}': restitution {value:g} of the pair [{a}, {b}] is not accepted by LIGGGHTS 3.8, "
                    f"which requires {MIN_RESTITUTION} < e <= 1 ({name} run {case.run_id}); raise it (the study "
                    "found bulk behaviour insensitive to restitution) or run this case on another engine"
                )

    def check_installed(self, options: EngineOptions) -> None:
        check_programs(str(dict(options.settings or {}).get("executable", "liggghts")), options.mpi_ranks,
                       options.mpirun)

    assembly_file = ASSEMBLY_RESTART

    def write_inputs(self, case, run_dir: str | Path, assembly_dir: str | Path | None = None) -> Path:
        self.check_case(case)
        self.place_assembly(case, run_dir, assembly_dir)
        _adapter(case)[1].write(case, Path(run_dir) / "deck")
        return Path(run_dir) / CASE_SUMMARY

    def run(self, case, run_dir: str | Path, options: EngineOptions) -> RunRecord:
        self.check_case(case)
        settings = dict(options.settings or {})
        return _adapter(case)[1].run(case, Path(run_dir), executable=settings.get("executable", "liggghts"),
                                  mpi_ranks=options.mpi_ranks, mpirun=options.mpirun)

    def measured_work(self, run_dir: str | Path) -> MeasuredWork | None:
        return work_from_logs(path.read_text(errors="replace") for path in attempt_logs(run_dir))

    def earlier_attempt_seconds(self, run_dir: str | Path) -> list[float]:
        return [elapsed_seconds(path.read_text(errors="replace")) for path in earlier_attempt_logs(run_dir, attempt_logs)]

    def read_frames(self, run_dir: str | Path, record: RunRecord, on_damaged: str = "error") -> list[ParticleFrame]:
        return list(read_frames(Path(run_dir) / "dumps", DUMP_PREFIX, record.timestep_s, on_damaged=on_damaged))

    def wall_forces(self, run_dir: str | Path, record: RunRecord) -> WallForceHistory:
        if record.case == "jenike":
            return read_jenike_forces(run_dir)
        return read_wall_forces(run_dir)

    def contacts(self, run_dir: str | Path, record: RunRecord, kind: str = "pair") -> list:
        if kind not in ("pair", "wall"):
            raise ValueError(f"contact kind must be 'pair' or 'wall', got {kind!r}")
        dumps = Path(run_dir) / "dumps"
        if record.case != "jenike":
            if kind == "wall":
                raise ValueError(f"{record.case} runs save no particle-wall contacts")
            return [read_contacts(path) for path in list_dumps(dumps, CONTACT_PREFIX, ".txt")]
        if kind == "pair":
            return [read_jenike_pair_contacts(path) for path in list_dumps(dumps, PAIR_CONTACT_PREFIX, ".txt")]
        return [read_jenike_wall_contacts(path) for path in list_dumps(dumps, WALL_CONTACT_PREFIX, ".txt")]

    def settled_fill(self, run_dir: str | Path, record: RunRecord) -> tuple[SettledFill, ...]:
        dumps = Path(run_dir) / "dumps"
        adapter = ADAPTERS.get(record.case)
        if adapter is None or adapter.floor_walls is None:
            raise CaseNotSupported(f"{record.case} runs save no settled fill snapshot on LIGGGHTS")
        if record.case == "jenike":
            return read_settled_fill(dumps, record.timestep_s, adapter.floor_walls, SETTLED_CONTACT_PREFIX,
                                     read_jenike_pair_contacts)
        return read_settled_fill(dumps, record.timestep_s, adapter.floor_walls)

    def dump_files(self, folder: str | Path, pattern: str) -> list[DumpFile]:
        return match_dump_files(folder, pattern)

    def read_dump_files(self, files, timestep: float, *, density: float | None = None,
                        on_damaged: str = "error") -> list[ParticleFrame]:
        return read_dump_files(files, timestep, density=density, on_damaged=on_damaged)
