"""Stages of a case: the ordered steps an engine must carry out, their controls and what each must output.

A case lists its stages (:attr:`SiloCase.stages` and the like); an engine checks that it can carry out each kind
(:meth:`siloflow.engines.interface.Engine.check_case`) and reports the state at the end of each stage in the run record
(``RunRecord.stages``, keyed by the stage kind).
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["OUTPUTS", "STAGE_KINDS", "Stage"]

#: Every kind of stage a case may ask for.
STAGE_KINDS = ("fill", "settle", "consolidate", "shear", "open", "discharge", "recirculate", "release")
#: What a stage may have to output: particle frames, contact forces, the force history of the walls, restart files.
OUTPUTS = ("frames", "contacts", "wall_contacts", "wall_forces", "restart")


@dataclass(frozen=True)
class Stage:
    """One step of a case.

    Attributes
    ----------
    kind : str
        One of :data:`STAGE_KINDS`.
    controls : dict
        What steers the stage, in SI units (e.g. ``duration_s``, ``kinetic_energy_threshold_J``, ``normal_force_N``).
    outputs : tuple of str
        What the engine must save during the stage (:data:`OUTPUTS`).
    """

    kind: str
    controls: dict = field(default_factory=dict)
    outputs: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.kind not in STAGE_KINDS:
            raise ValueError(f"stage kind must be one of {STAGE_KINDS}, got {self.kind!r}")
        unknown = sorted(set(self.outputs) - set(OUTPUTS))
        if unknown:
            raise ValueError(f"stage {self.kind}: unknown outputs {unknown}; known: {OUTPUTS}")
