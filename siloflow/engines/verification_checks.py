"""What a finished verification run (:mod:`siloflow.model.cases.verification`) must show, whatever engine ran it: the
``done`` stage marker and its frames; and the run record built from them."""

from __future__ import annotations

from pathlib import Path

from siloflow.model.record import RunRecord
from siloflow.model.cases.verification import VerificationCase
from siloflow.engines.interface import EngineRunError
from siloflow.engines.markers import Marker

__all__ = ["check_verification_run", "verification_record"]


def check_verification_run(case: VerificationCase, markers: list[Marker], frame_files: list[Path],
                           run_dir: Path) -> dict:
    """The checked stage record of a verification run.

    Raises
    ------
    EngineRunError
        When the ``done`` marker is missing or fewer frames than the run's length asks were written.
    """
    done = [m for m in markers if m.event == "done"]
    if not done:
        raise EngineRunError(f"{run_dir}: the log has no 'done' marker; the run did not reach its end")
    expected = case.steps // case.output_every + 1
    if len(frame_files) < expected:
        raise EngineRunError(f"{run_dir}: {len(frame_files)} frames written, {expected} expected")
    return {"done": done[-1].values, "n_frames": len(frame_files)}


def verification_record(engine: str, case: VerificationCase, checked: dict) -> RunRecord:
    """The run record of a checked verification run on ``engine``."""
    return RunRecord(engine=engine, case="verification", run_id=case.run_id, timestep_s=case.timestep,
                     n_clumps=len(case.spheres), n_frames=checked["n_frames"], mpi_ranks=1,
                     stages={"release": checked["done"]}, resumed_attempts=checked.get("resumed_attempts", 0),
                     output_bytes=checked.get("output_bytes", 0), labels={"problem": case.name})
