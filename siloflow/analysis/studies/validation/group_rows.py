"""One validation group's rows from the products of the runs behind it, as read: the same function for the
workflow's rows step and for re-deriving a recorded group's rows from the products its record keeps.

The reference configuration's seeds become one summary and lend their spread, relative to each figure, to the
configurations run once (:mod:`siloflow.analysis.numerics.reference_spread`) before the rows are judged; the rows'
degrees of freedom are then the reference's seeds - 1 (:func:`seed_dof`), since every error either is that spread
or may be replaced by it. Pure: the readers are :mod:`siloflow.analysis.io.validation_products`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import MappingProxyType

from siloflow.analysis.numerics.reference_spread import SeedSpread, floor_table, seed_note, with_reference_spread
from siloflow.analysis.studies.validation import blender, blending, calibration, silo
from siloflow.analysis.studies.validation.agreement import AgreementTolerances
from siloflow.analysis.studies.validation.rows import with_scale

__all__ = ["ROW_CODE", "MADE", "UNMADE", "seed_dof", "group_rows", "judged_rows"]

#: The modules whose code decides a group's rows: a record written by other code is stale.
ROW_CODE = ("siloflow.analysis.studies.validation.rows", "siloflow.analysis.studies.validation.agreement",
            "siloflow.analysis.studies.validation.findings", "siloflow.analysis.studies.validation.scale",
            "siloflow.analysis.studies.validation.calibration", "siloflow.analysis.studies.validation.silo",
            "siloflow.analysis.studies.validation.blending", "siloflow.analysis.studies.validation.blender",
            "siloflow.analysis.studies.validation.group_rows",
            "siloflow.analysis.numerics.reference_spread",
            # the averaging window's sources the silo's rows compare fields.json with
            "siloflow.analysis.studies.silo_flat.field_clock")

#: The finding parts the groups' rows can make, and those they cannot, each with what would make it.
MADE = (*calibration.MADE, *silo.MADE, *blending.MADE, *blender.MADE)
UNMADE = MappingProxyType({**calibration.UNMADE, **silo.UNMADE, **blending.UNMADE, **blender.UNMADE})


def seed_dof(spread: SeedSpread) -> float | None:
    """Degrees of freedom of errors that carry a spread between ``spread.seeds`` seeds (seeds - 1), None when
    there is no spread (one seed: within-run errors from many samples)."""
    return float(spread.seeds - 1) if spread.seeds >= 2 else None


def _silo(data: Mapping, params: Mapping, tolerances: AgreementTolerances) -> list[dict]:
    runs = data["runs"]
    run_ids = [run["case"]["run_id"] for run in runs]
    base, others, spread = with_reference_spread(runs, run_ids, set(params["reference"]))
    dof = seed_dof(spread)
    base_id = base["case"]["run_id"]
    if params["group"] == "silo":
        return silo.silo_rows(silo.SiloRun(**base), tolerances, dof, seed_note(base_id, spread, True))
    labels = params["labels"]
    series = [(labels[base_id], silo.SiloRun(**base), seed_note(base_id, spread, True))]
    series += [(labels[run], silo.SiloRun(**summary), seed_note(labels[base_id], spread, False))
               for run, summary in others]
    return silo.front_wall_series_rows(series, params["profile_height"], tolerances, dof)


def _seeded(data: Mapping, params: Mapping, name: Callable[[Mapping], str]) -> list[dict]:
    """Each run's summary with its seed note and degrees of freedom, the reference's seeds combined first."""
    runs = data["runs"]
    reference, others, spread = with_reference_spread(runs, [run["case"]["run_id"] for run in runs],
                                                      set(params["reference"]))
    dof = seed_dof(spread)
    chosen = [{**reference, "note": seed_note(name(reference), spread, True), "dof": dof}]
    chosen += [{**summary, "note": seed_note(name(reference), spread, False), "dof": dof} for _, summary in others]
    return chosen


def _recirculation(data, params, tolerances):
    return blending.recirculation_rows(_seeded(data, params, lambda run: run["summary"]["flow_pattern"]), tolerances)


def _blender(data, params, tolerances):
    runs = _seeded(data, params, lambda run: f"{run['summary']['configuration']} at "
                                             f"{float(run['summary']['gravity_factor']):g} g")
    return blender.blender_rows(runs, tolerances) + blender.gravity_rows(runs, tolerances)


def _calibration(data, params, tolerances):
    points, spread, replicated = floor_table(data["points"], ("bulk_friction", "bulk_friction_angle_deg"))
    rows = calibration.calibration_rows(points, data.get("parameters"), params["base_restitution"], params["lid"],
                                        params["shear_velocity"], {test: tuple(band) for test, band in
                                                                   params["targets"].items()},
                                        tolerances, seed_dof(spread), sections=params["sections"])
    if spread.seeds >= 2:
        reference = "; ".join(f"{row['shape']} {row['test']}, particle friction {row['particle_friction']}, rolling "
                              f"{row['rolling_friction']}" for row in replicated)
        relative = max(spread.values()) if spread else float("nan")
        for entry in rows:
            entry["evidence"] += (f"; each point's error is the larger of its within-run error and {relative:.2%} of "
                                  f"its value: the standard deviation between the {spread.seeds} seeds of the "
                                  f"reference point ({reference}) relative to its mean; {spread.seeds - 1} degrees "
                                  "of freedom")
    else:
        for entry in rows:
            entry["evidence"] += "; within-run errors only: no point of this group was run with several seeds"
    return rows


ROWS = {"jenike": _calibration, "silo_flat": _silo, "silo_recirculation": _recirculation, "blender": _blender}


def group_rows(kind: str, data: Mapping, params: Mapping, tolerances: AgreementTolerances) -> list[dict]:
    """A group's rows before their scale verdicts.

    Parameters
    ----------
    kind : str
        The group's case kind.
    data : mapping
        Its products as read (:func:`siloflow.analysis.io.validation_products.read_group_products`); for the
        Jenike cell, its ``summaries`` combined into sweep points (``points``,
        :func:`siloflow.calibration.table.point_table`) by the caller.
    params : mapping
        The keys of the configuration its rows use (``group``, ``reference`` run ids, and per kind: ``labels`` and
        ``profile_height`` for the silo; ``sections``, ``base_restitution``, ``lid``, ``shear_velocity``, ``targets``
        for the Jenike cell).
    tolerances : AgreementTolerances
    """
    if kind not in ROWS:
        raise ValueError(f"no validation rows for case kind {kind!r}; the kinds are {', '.join(ROWS)}")
    return ROWS[kind](data, params, tolerances)


def judged_rows(kind: str, data: Mapping, params: Mapping, validation: Mapping,
                judge: Callable[[str, bool], object]) -> list[dict]:
    """:func:`group_rows` with the ``validation`` configuration section's tolerances, then each row's scale verdict
    from ``judge(finding_id, definition_as_study)`` (:func:`~siloflow.analysis.studies.validation.rows.with_scale`)."""
    rows = group_rows(kind, data, params, AgreementTolerances.from_config(validation))
    return with_scale(rows, judge)
