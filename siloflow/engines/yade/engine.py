"""YADE (Debian ``yade`` 2023.02, imported from the system Python 3, headless) behind the engine interface.

:class:`YadeEngine` renders each case it builds into a Python script from ``siloflow/templates/yade/`` (every case template
extends :attr:`YadeEngine.base_template`), runs it with :mod:`siloflow.engines.yade.run` and reads its outputs back with
:mod:`siloflow.engines.yade.outputs` into the neutral objects of :mod:`model`. The rolling-resistance model differs
from the LIGGGHTS decks' (:mod:`siloflow.engines.yade.inputs` says how).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from siloflow.model.forces import WallForceHistory
from siloflow.model.frames import ParticleFrame
from siloflow.model.record import RunRecord
from siloflow.model.settled import SettledFill
from siloflow.model.cases.blender import GATE
from siloflow.model.cases.kinds import kind_of_case
from siloflow.model.cases.silo_flat import FLOOR_MESHES
from siloflow.model.cases.silo_recirculation import CHANNEL_MESHES
from siloflow.model.cost import MeasuredWork
from siloflow.engines.interface import CaseNotSupported, Engine, EngineOptions, register
from siloflow.engines.jenike_checks import JENIKE_FLOOR_WALLS, jenike_wall_forces, read_jenike_force_history
from siloflow.engines.layout import CASE_SUMMARY
from siloflow.engines.run_files import earlier_attempt_logs
from siloflow.engines.yade.cost import elapsed_cpu_seconds, measured_work as work_from_logs
from siloflow.engines.yade.blender import run_blender, write_blender_inputs
from siloflow.engines.yade.inputs import ENGINE_NAME
from siloflow.engines.yade.jenike import FORCES_NAME, check_jenike_case, jenike_contacts, run_jenike, write_jenike_inputs
from siloflow.engines.yade.outputs import read_frames, read_settled_fill, read_wall_forces
from siloflow.engines.yade.run import (ASSEMBLY_STATE, DUMP_PREFIX, SETTLED_FILL_PREFIX, YadeOptions, attempt_logs,
                                      check_programs)
from siloflow.engines.yade.silo_flat import check_silo_case, run_silo, write_silo_inputs
from siloflow.engines.yade.silo_recirculation import run_recirculation, write_recirculation_inputs
from siloflow.engines.yade.verification import run_verification, write_verification_inputs

__all__ = ["ADAPTERS", "Adapter", "YadeEngine"]

@dataclass(frozen=True)
class Adapter:
    """How YADE writes, runs and checks one case kind, and the walls that make the floor of its settled fill (None:
    it saves none)."""

    write: Callable
    run: Callable
    check: Callable
    floor_walls: tuple[str, ...] | None = None


#: The case kinds YADE runs, one adapter each, by the kind's name (:mod:`siloflow.model.cases.kinds`).
ADAPTERS = {
    "silo_flat": Adapter(write_silo_inputs, run_silo, check_silo_case, FLOOR_MESHES),
    "silo_recirculation": Adapter(write_recirculation_inputs, run_recirculation,
                                   lambda case: check_silo_case(case.silo), FLOOR_MESHES + CHANNEL_MESHES),
    "blender": Adapter(write_blender_inputs, run_blender, lambda case: check_silo_case(case.silo), (GATE,)),
    "jenike": Adapter(write_jenike_inputs, run_jenike, check_jenike_case, JENIKE_FLOOR_WALLS),
    "verification": Adapter(write_verification_inputs, run_verification, lambda case: None),
}


def _adapter(case) -> Adapter:
    kind = kind_of_case(case).name
    if kind not in ADAPTERS:
        raise CaseNotSupported(
            f"YADE has no script for {kind} cases yet; it runs {', '.join(ADAPTERS)}: set this case section's "
            "'engine' (or engine.kind) to liggghts")
    return ADAPTERS[kind]


def options_from(options: EngineOptions) -> YadeOptions:
    """The YADE options of a validated ``engine`` section (``engine.yade``)."""
    settings = dict(options.settings or {})
    return YadeOptions(python=str(settings.get("python", YadeOptions.python)),
                       threads=int(settings.get("threads", YadeOptions.threads)))


@register
class YadeEngine(Engine):
    """YADE 2023.02: scripts from ``siloflow/templates/yade/``, run headless with the system Python 3, read back."""

    name = ENGINE_NAME
    debian_package = "yade"
    base_template = "yade/base.py.j2"

    def check_case(self, case) -> None:
        """Refuse a case YADE cannot run as configured: a case kind without a script, different rolling frictions
        (YADE's rolling moment has one eta), a periodic silo depth.

        Raises
        ------
        CaseNotSupported
            Naming the config key and the limit.
        """
        _adapter(case).check(case)

    def check_installed(self, options: EngineOptions) -> None:
        check_programs(options_from(options))

    assembly_file = ASSEMBLY_STATE

    def write_inputs(self, case, run_dir: str | Path, assembly_dir: str | Path | None = None) -> Path:
        self.check_case(case)
        self.place_assembly(case, run_dir, assembly_dir)
        _adapter(case).write(case, Path(run_dir) / "deck")
        return Path(run_dir) / CASE_SUMMARY

    def run(self, case, run_dir: str | Path, options: EngineOptions) -> RunRecord:
        # one process, engine.yade.threads OpenMP threads; engine.mpi_ranks is LIGGGHTS' (siloflow.engines.config refuses it
        # when no case runs on LIGGGHTS)
        self.check_case(case)
        return _adapter(case).run(case, Path(run_dir), options_from(options))

    def measured_work(self, run_dir: str | Path) -> MeasuredWork | None:
        return work_from_logs(attempt_logs(run_dir))

    def earlier_attempt_seconds(self, run_dir: str | Path) -> list[float]:
        return [elapsed_cpu_seconds([path]) for path in earlier_attempt_logs(run_dir, attempt_logs)]

    def read_frames(self, run_dir: str | Path, record: RunRecord, on_damaged: str = "error") -> list[ParticleFrame]:
        return read_frames(run_dir, DUMP_PREFIX, on_damaged)

    def wall_forces(self, run_dir: str | Path, record: RunRecord) -> WallForceHistory:
        if record.case == "jenike":
            return jenike_wall_forces(read_jenike_force_history(Path(run_dir) / FORCES_NAME))
        return read_wall_forces(run_dir, record.timestep_s)

    def contacts(self, run_dir: str | Path, record: RunRecord, kind: str = "pair") -> list:
        if kind not in ("pair", "wall"):
            raise ValueError(f"contact kind must be 'pair' or 'wall', got {kind!r}")
        if record.case == "jenike":
            return jenike_contacts(run_dir, kind)
        if kind == "wall":
            raise ValueError(f"{record.case} runs on YADE save no particle-wall contacts")
        return [fill.contacts for fill in self.settled_fill(run_dir, record)]

    def settled_fill(self, run_dir: str | Path, record: RunRecord) -> tuple[SettledFill, ...]:
        adapter = ADAPTERS.get(record.case)
        if adapter is None or adapter.floor_walls is None:
            raise CaseNotSupported(f"{record.case} runs save no settled fill snapshot on YADE")
        return read_settled_fill(run_dir, SETTLED_FILL_PREFIX, adapter.floor_walls)
