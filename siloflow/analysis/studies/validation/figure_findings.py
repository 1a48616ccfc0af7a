"""Which of the study's findings each figure draws beside its result, with the band the record judges it by.

A figure that supports a finding draws it (:mod:`siloflow.analysis.io.plot_style`: a :class:`StudyValue` as a band
and a line, a :class:`StudyNote` as a legend entry). The choice of finding per figure is made here, once, so that the
report and the record draw the same finding for the same figure and with the same band as its row
(:func:`siloflow.analysis.studies.validation.agreement.study_band` with the configuration's tolerances).
"""

from __future__ import annotations

from siloflow.analysis.io.plot_style import StudyNote, StudyValue
from siloflow.analysis.studies.validation.agreement import AgreementTolerances, study_band
from siloflow.analysis.studies.validation.blending import NR_STUDY, PATTERNS
from siloflow.analysis.studies.validation.findings import PARTS, Part

__all__ = ["study_value", "study_note", "CHART_FINDINGS", "calibration_chart_findings", "janssen_findings",
           "kinematic_findings", "insert_findings", "gravity_findings", "vrr_findings"]


def study_value(part: Part, band: tuple[float, float] | None = None, series: str | None = None) -> StudyValue:
    """The number a part of a finding states, to draw beside the result (e.g. ``PARTS["C2.sphere2"]``).

    Parameters
    ----------
    part : Part
        A part that states a number (``part.value``).
    band : tuple of float, optional
        ``(low, high)`` in the part's unit, e.g. ``study_band(part, tolerances)``.
    series : str, optional
        The series it belongs to (:attr:`~siloflow.analysis.io.plot_style.StudyValue.series`).

    Returns
    -------
    StudyValue
        With the finding's id (the part's id up to its first dot), value and unit; approximate unless the study
        states the number with a band or as exact.

    Raises
    ------
    ValueError
        When the part states no number (a trend, an order, a configured value).
    """
    if part.value is None:
        raise ValueError(f"{part.id} states no number ({part.kind}); draw it as a StudyNote")
    approximate = part.band is None and part.tolerance not in (None, "no_band_relative")
    return StudyValue(part.id.split(".")[0], part.value, part.unit, band, series, approximate)


def study_note(part: Part, text: str | None = None) -> StudyNote:
    """What a part of a finding states in words, e.g. ``PARTS["M2.outlet_order"]``: ``tube > interior annulus >
    exterior annulus``; ``text`` (None: :meth:`Part.stated`) replaces it, with the finding's id kept."""
    return StudyNote(part.id.split(".")[0], part.stated() if text is None else text)


#: The finding a calibration chart of each test carries: its plateau of bulk friction (coefficient, -) per shape.
CHART_FINDINGS = {"internal": "C2", "aluminium": "C3"}
#: The inserts the study measured at the insert outlet: the diverging insert's velocity ratios (M1) and the converging
#: insert's order of the three passages (M2).
M1_PASSAGES = ("exterior", "interior", "tube")


def calibration_chart_findings(shape: str, test: str, tolerances: AgreementTolerances) -> list[StudyValue]:
    """The plateau of bulk friction the study found for ``shape`` in ``test`` (C2 internal, C3 wall), with its band.

    Parameters
    ----------
    shape : str
        The particle model (``sphere``, ``sphere2``, ``sphere4``); a shape the study did not run draws none.
    test : str
        The Jenike test (``internal``, ``aluminium``); a test without a plateau finding draws none.
    tolerances : AgreementTolerances
        The record's tolerances (``validation.agreement``), for the band.

    Returns
    -------
    list of StudyValue
        At most one, in bulk friction coefficient (-).
    """
    finding = CHART_FINDINGS.get(test)
    part = PARTS.get(f"{finding}.{shape}") if finding else None
    if part is None:
        return []
    return [study_value(part, band=study_band(part, tolerances), series=shape)]


def janssen_findings() -> list[StudyNote]:
    """S1: the vertical stress at the end of filling agrees with Janssen's."""
    return [StudyNote("S1", "DEM in good agreement with Janssen")]


def kinematic_findings() -> list[StudyNote]:
    """S5: the kinematic constant B decreases with the height above the outlet (DEM and experiment)."""
    return [study_note(PARTS["S5.dem"], "B decreases with height")]


def insert_findings(configuration: str, tolerances: AgreementTolerances) -> list[StudyValue | StudyNote]:
    """What the study measured at the insert outlet of ``configuration`` (PIV, continuous discharge).

    Parameters
    ----------
    configuration : str
        ``diverging``: M1's velocity of each passage over the cross-section mean, with its band; ``converging``: M2's
        order of the passages; any other insert: none.
    tolerances : AgreementTolerances
        The record's tolerances, for M1's bands.

    Returns
    -------
    list of StudyValue or StudyNote
    """
    if configuration == "diverging":
        return [study_value(PARTS[f"M1.{passage}"], band=study_band(PARTS[f"M1.{passage}"], tolerances),
                              series=passage) for passage in M1_PASSAGES]
    if configuration == "converging":
        return [study_note(PARTS["M2.outlet_order"])]
    return []


def gravity_findings() -> list[StudyNote]:
    """M4: the mass flow rate and the cross-section mean velocity scale with the square root of gravity."""
    return [StudyNote("M4", "mean v scales with sqrt(g)")]


def vrr_findings(tolerances: AgreementTolerances) -> list[dict]:
    """B4: the VRR at the end of the study's 4 recirculations, per flow pattern, as
    :func:`siloflow.analysis.studies.silo_recirculation.vrr_summary_plot.plot_vrr_summary` draws it beside the
    discharge after the recirculations.

    Parameters
    ----------
    tolerances : AgreementTolerances
        The record's tolerances, for the band (B4 states its own: 8-13 internal, 4-6 semi-mass flow).

    Returns
    -------
    list of dict
        ``{"id", "flow_pattern", "at", "low", "high"}`` per flow pattern, at Nr = 4 [-], the band in VRR [-].
    """
    return [{"id": "B4", "flow_pattern": pattern, "at": float(NR_STUDY),
             **dict(zip(("low", "high"), study_band(PARTS[f"B4.{suffix}"], tolerances)))}
            for pattern, suffix in PATTERNS.items()]
