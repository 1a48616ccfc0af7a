"""The measured hypotheses of the validation record: for a finding of the study the record does not reproduce, or
not at the study's scale, one change that could move it, run as a sensitivity pair on a reduced case.

Each :class:`Hypothesis` names the validation group whose rows it compares, the findings it is for, and two layered
configurations: the *base*, ``config/validation.yaml`` reduced so that the pair costs a small share of the tier, and
the *variant*, the base with the one change. ``siloflow hypothesis NAME`` (``make hypothesis NAME=...``) runs both to
their validation rows and records, per row, whether the change moves the figure towards the study
(:mod:`siloflow.analysis.studies.validation.hypothesis`). The files are the clone's, named here rather than taken from
a command line, so that what the record says a hypothesis changed is what ran.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from siloflow.engines.validation_groups import GROUPS

__all__ = ["Hypothesis", "HYPOTHESES", "HYPOTHESIS_CONFIG_DIR", "hypothesis_named", "hypothesis_directory"]

#: Where the hypotheses' configuration layers are, relative to the clone (the working folder of `make`).
HYPOTHESIS_CONFIG_DIR = Path("config") / "hypotheses"
#: The validation scale the reduced cases start from.
VALIDATION_CONFIG = Path("config") / "validation.yaml"
#: Where ``siloflow hypothesis`` runs a pair, relative to its working folder: ``<this>/<name>/base`` and ``.../variant``.
HYPOTHESIS_RUNS = Path("results") / "hypotheses"


@dataclass(frozen=True)
class Hypothesis:
    """One measured hypothesis.

    Attributes
    ----------
    name : str
        Its name (``make hypothesis NAME=<name>``), also its record's file name.
    group : str
        The validation group whose rows the pair is compared by (:data:`siloflow.engines.validation_groups.GROUPS`).
    findings : tuple of str
        The findings it is for (``"S2"``); the record compares every row of the group that judges a part of one.
    statement : str
        What it supposes: the change, and why it could move the findings' figures.
    change : str
        The one change between the base and the variant, as the record names it.
    base : str
        The file, under :data:`HYPOTHESIS_CONFIG_DIR`, that reduces ``config/validation.yaml`` to the base case.
    variant : str
        The file, under :data:`HYPOTHESIS_CONFIG_DIR`, layered over the base for the variant.
    """

    name: str
    group: str
    findings: tuple[str, ...]
    statement: str
    change: str
    base: str
    variant: str

    def __post_init__(self):
        if self.group not in GROUPS:
            raise ValueError(f"hypothesis {self.name!r}: no validation group {self.group!r}; the groups are "
                             f"{', '.join(GROUPS)}")
        if not self.findings:
            raise ValueError(f"hypothesis {self.name!r} names no finding")

    def base_files(self, root: Path = Path(".")) -> tuple[Path, ...]:
        """The base's configuration files, in layering order, under the clone ``root``."""
        return (root / VALIDATION_CONFIG, root / HYPOTHESIS_CONFIG_DIR / self.base)

    def variant_files(self, root: Path = Path(".")) -> tuple[Path, ...]:
        """The variant's configuration files: the base's, then the change."""
        return (*self.base_files(root), root / HYPOTHESIS_CONFIG_DIR / self.variant)


_STIFFNESS = ("the particle and wall stiffness: the tier's Young's modulus 5e6 Pa is 0.018 of the study's 2.8e8 Pa "
              "(a time step 7.5 times longer); softer contacts overlap more, which packs a fill denser and lets "
              "clumps roll past each other more easily")

#: The hypotheses, by name.
HYPOTHESES: dict[str, Hypothesis] = {hypothesis.name: hypothesis for hypothesis in (
    Hypothesis(
        "stiffness_calibration", "calibration", ("C1", "C2", "C3", "C6", "C7"),
        f"The Jenike charts move with {_STIFFNESS}.",
        "Young's modulus of the pellets and every wall 5e6 -> 2.8e8 Pa (the study's)",
        "calibration_reduced.yaml", "stiffness_study.yaml"),
    Hypothesis(
        "stiffness_silo", "silo", ("S1", "S2", "S5"),
        f"The flat-bottom silo's fill and flow move with {_STIFFNESS}.",
        "Young's modulus of the pellets and every wall 5e6 -> 2.8e8 Pa (the study's)",
        "silo_reduced.yaml", "stiffness_study.yaml"),
    Hypothesis(
        "stiffness_blending", "blending", ("B1",),
        f"The recirculating silo's flowing bulk density moves with {_STIFFNESS}.",
        "Young's modulus of the pellets and every wall 5e6 -> 2.8e8 Pa (the study's)",
        "blending_reduced.yaml", "stiffness_study.yaml"),
    Hypothesis(
        "bed_blender", "blender", ("M1", "M2", "M3"),
        "The flow through the insert's passages, and so how the inserts blend, moves with the bed above them: the "
        "tier's bed stands 14 mm above the insert (the study's about 700 mm), so the head that feeds the passages and "
        "the tube inlet is a small share of the study's.",
        "fill height 0.225 -> 0.325 m (the bed above the insert 14 -> 114 mm), the vertical walls 0.21 -> 0.32 m to "
        "hold it",
        "blender_reduced.yaml", "bed_taller.yaml"),
    Hypothesis(
        "stiffness_gravity", "blender", ("M4",),
        "The gravity series' departures from sqrt(g) scaling move with the contact stiffness relative to the pile's "
        "weight, E / (rho g d), which at fixed material falls as 1/g: the tier's 5e6 Pa puts its 1 g run where the "
        "study's 2.8e8 Pa put its 50 g run, so softening, not the flow, may set what the tier's series shows.",
        "Young's modulus of the pellets and every wall 5e6 -> 2.5e7 Pa (fivefold, towards the study's 2.8e8)",
        "gravity_reduced.yaml", "stiffness_fivefold.yaml"),
)}


def hypothesis_named(name: str) -> Hypothesis:
    """The hypothesis ``name``; a ValueError that lists them otherwise."""
    if name not in HYPOTHESES:
        raise ValueError(f"no measured hypothesis {name!r}; the hypotheses are {', '.join(HYPOTHESES)}")
    return HYPOTHESES[name]


def hypothesis_directory(name: str, workdir: Path = Path(".")) -> Path:
    """Where the pair of hypothesis ``name`` runs: ``base/`` and ``variant/`` under it."""
    return workdir / HYPOTHESIS_RUNS / hypothesis_named(name).name
