"""The summary page of the report: the figures of merit of every stage as HTML tables for people.

Pure: the caller reads the stage results and passes plain rows; :func:`summary_html` returns the page.

Conventions of the page
-----------------------
- Every column key has a header in words with its unit: :data:`COLUMNS`, or for the keys numbered by
  recirculation or sine period :data:`COLUMN_FAMILIES`. A row with any other key is refused when the page is
  built (the error names the key), so no raw key reaches the page.
- A row may carry ``"<key>_error"`` (the standard error of ``"<key>"``, same unit) beside ``"<key>"``: the two
  print as one cell "value ± error" (:func:`format_value_with_error`). A figure of merit (kind
  :data:`ESTIMATE`) without its error prints as "value ±?" (:data:`NO_UNCERTAINTY`), so a missing uncertainty
  is visible rather than silently absent.
- Mappings and lists never reach a cell as a Python repr: the row builders below turn them into text, and any
  other non-scalar cell value is refused.
- Flags print as "yes" / "no".
- A table with more columns than rows is transposed (one row per quantity, one column per item), and every
  table sits in a horizontally scrolling box, so the page fits 1000 px.
"""

from __future__ import annotations

import html
import re
from collections.abc import Callable, Mapping, Sequence
from typing import NamedTuple

from siloflow.analysis.report.cells import (
    COUNT,
    ESTIMATE,
    FLAG,
    NO_UNCERTAINTY,
    NUMBER,
    TEXT,
    format_cell,
    is_missing,
)

__all__ = [
    "COLUMNS",
    "COLUMN_FAMILIES",
    "Column",
    "Section",
    "column_for",
    "column_header",
    "summary_html",
    "calibration_rows",
    "silo_flow_rows",
    "measured_rows",
    "recirculation_rows",
    "blender_rows",
    "fill_balance_rows",
    "significance_rows",
    "summary_sections",
]

#: Suffix of the key that carries the standard error of a column.
ERROR_SUFFIX = "_error"


class Column(NamedTuple):
    """How a column prints: its header in words, its unit ("" when dimensionless or text) and its kind."""

    header: str
    unit: str = ""
    kind: str = NUMBER


#: The header and unit of every column key the summary page shows.
COLUMNS: dict[str, Column] = {
    # calibration
    "contact": Column("Contact", kind=TEXT),
    "sliding_friction": Column("Sliding friction coefficient"),
    "lower": Column("Band, lower end"),
    "upper": Column("Band, upper end"),
    "band_clipped": Column("Band clipped at the swept range", kind=FLAG),
    "note": Column("Note", kind=TEXT),
    # flat-bottom silo
    "run_id": Column("Run", kind=TEXT),
    "n_clumps": Column("Particles", kind=COUNT),
    "filling_bulk_density_kg_m3": Column("Filling bulk density", "kg/m³", ESTIMATE),
    "mass_flow_rate_kg_s": Column("Flow rate", "kg/s", ESTIMATE),
    "beverloo_mass_flow_rate_kg_s": Column("Beverloo flow rate", "kg/s"),
    "beverloo_ratio": Column("Flow rate / Beverloo", kind=ESTIMATE),
    # silo against measured profiles
    "z_m": Column("Height above the outlet", "m"),
    "window": Column("Averaging window", kind=TEXT),
    "n_points": Column("Points compared", kind=COUNT),
    "mean_error_percent": Column("Mean error", "%"),
    "rms_error_m_s": Column("RMS error", "m/s"),
    "max_abs_error_m_s": Column("Largest error", "m/s"),
    "fraction_within_uncertainty": Column("Fraction within the measurement uncertainty"),
    # recirculating silo
    "flow_pattern": Column("Flow pattern", kind=TEXT),
    "layout": Column("Batch layout", kind=TEXT),
    "residence_time_s": Column("Hold-up residence time (stagnant zones included)", "s", ESTIMATE),
    "transit_residence_time_s": Column("Transit residence time, Little's law", "s", ESTIMATE),
    "rtd_mean_ids_transit_s": Column("Transit residence time, tracer mean", "s", ESTIMATE),
    "t_s_over_t_d": Column("First appearance / discharge time t_s/t_d", kind=ESTIMATE),
    "prediction_rms_error": Column("LTI prediction RMS error (blue fraction)"),
    "vrr_ceiling": Column("VRR counting-noise ceiling"),
    # blender
    "configuration": Column("Configuration", kind=TEXT),
    "exterior_v_z_m_s": Column("Mean vertical velocity, exterior annulus", "m/s", ESTIMATE),
    "interior_v_z_m_s": Column("Mean vertical velocity, interior annulus", "m/s", ESTIMATE),
    "tube_v_z_m_s": Column("Mean vertical velocity, tube", "m/s", ESTIMATE),
    "rtd_mean_s": Column("Mean residence time t_m", "s", ESTIMATE),
    "rtd_spread": Column("RTD spread σ/t_m", kind=ESTIMATE),
    "ts_over_td": Column("First appearance / discharge time t_s/t_d", kind=ESTIMATE),
    "recirculations_to_homogenise": Column("Recirculations to homogenise"),
    # how many seeds a row combines (replicates: N)
    "replicates": Column("Seeds", kind=COUNT),
    # the blender comparison's differences (comparison/significance.csv)
    "figure": Column("Figure", kind=TEXT),
    "configuration_a": Column("Configuration A", kind=TEXT),
    "configuration_b": Column("Configuration B", kind=TEXT),
    "difference": Column("A − B", kind=ESTIMATE),
    "significance": Column("Larger than 2 standard errors?", kind=TEXT),
    # the settled fill's force balance (metrics/fill_balance.json)
    "case": Column("Case", kind=TEXT),
    "support_ratio": Column("Walls + floor / weight"),
    "floor_ratio": Column("Floor / weight"),
    "walls_ratio": Column("Walls / weight"),
    "silo_like": Column("Walls carry part of the weight (silo-like)", kind=FLAG),
    "balance_passed": Column("Force balance passed", kind=FLAG),
    # the validation table (summary/validation.csv)
    "value": Column("Value", kind=ESTIMATE),
    "unit": Column("Unit", kind=TEXT),
    "finding": Column("Finding of the study", kind=TEXT),
    "dof": Column("Degrees of freedom of the error", kind=TEXT),
    "study": Column("The study", kind=TEXT),
    "agreement": Column("Agreement", kind=TEXT),
    "agreement_reason": Column("Why", kind=TEXT),
    "differs": Column("Defined otherwise than the study", kind=TEXT),
    "scale": Column("At the study's scale", kind=TEXT),
    "scale_reason": Column("What differs from the study's scale", kind=TEXT),
    "evidence": Column("From the run", kind=TEXT),
    # the verification table (verification/verification.csv)
    "quantity": Column("Quantity", kind=TEXT),
    "engine": Column("Engine", kind=TEXT),
    "closed_form": Column("Closed form"),
    "measured": Column("Measured"),
    "error": Column("Relative error"),
    "tolerance": Column("Tolerance"),
    "passes": Column("Within tolerance", kind=FLAG),
    # the cross-engine table (cross_engine/cross_engine.csv)
    "liggghts_mean": Column("LIGGGHTS, mean over seeds"),
    "liggghts_std": Column("LIGGGHTS, standard deviation"),
    "liggghts_seeds": Column("LIGGGHTS seeds", kind=COUNT),
    "yade_mean": Column("YADE, mean over seeds"),
    "yade_std": Column("YADE, standard deviation"),
    "yade_seeds": Column("YADE seeds", kind=COUNT),
    "difference_error": Column("Standard error of the difference"),
    "difference_in_errors": Column("Difference / its standard error"),
    "larger_than_2_errors": Column("Larger than 2 standard errors", kind=FLAG),
}

#: The blender comparison's VRR columns, one per sine period (a fraction of the mean residence time).
_PERIOD_VRR = re.compile(r"vrr_at_(\d+(?:\.\d+)?)_tm")

#: Families of numbered keys: (pattern, header from the match, unit, kind).
COLUMN_FAMILIES: tuple[tuple[re.Pattern, Callable[[re.Match], str], str, str], ...] = (
    (re.compile(r"vrr_nr(\d+)"), lambda match: f"VRR after recirculation {int(match[1])}", "", ESTIMATE),
    (re.compile(r"vrr_at_ceiling_nr(\d+)"),
     lambda match: f"VRR after recirculation {int(match[1])} at the counting-noise ceiling", "", FLAG),
    (_PERIOD_VRR, lambda match: f"VRR, sine period {match[1]} t_m", "", ESTIMATE),
    (re.compile(r"vrr_at_(\d+(?:\.\d+)?)_tm_at_ceiling"),
     lambda match: f"VRR, sine period {match[1]} t_m, at the counting-noise ceiling", "", FLAG),
    (re.compile(r"contacts_at_(\d+)_mm"), lambda match: f"Contacts / weight above, plane at {int(match[1])} mm", "",
     NUMBER),
)


def column_for(key: str) -> Column:
    """The :class:`Column` of a row key.

    Raises
    ------
    ValueError
        If the key has no header (it names the key): add it to :data:`COLUMNS`.
    """
    if key in COLUMNS:
        return COLUMNS[key]
    for pattern, header, unit, kind in COLUMN_FAMILIES:
        match = pattern.fullmatch(str(key))
        if match:
            return Column(header(match), unit, kind)
    raise ValueError(f"the summary page has no header for the column {key!r}: "
                     "add it to siloflow.analysis.report.summary.COLUMNS")


def column_header(key: str) -> str:
    """The header text of a row key: its words, then its unit in parentheses if it has one."""
    column = column_for(key)
    return f"{column.header} ({column.unit})" if column.unit else column.header


# --------------------------------------------------------------------------- tables


def _error_key(key: str) -> str:
    return f"{key}{ERROR_SUFFIX}"


def _shown_columns(rows: Sequence[Mapping]) -> tuple[list[str], set[str]]:
    """(the keys shown as columns in order of first appearance, the keys whose errors the rows carry)."""
    keys: list[str] = []
    for row in rows:
        keys += [key for key in row if key not in keys]
    present = set(keys)
    errors = {key for key in keys if _error_key(key) in present}
    shown = [key for key in keys
             if not (isinstance(key, str) and key.endswith(ERROR_SUFFIX) and key[: -len(ERROR_SUFFIX)] in present)]
    for key in shown:
        column_for(key)  # refuse a key without a header before anything is drawn
    return shown, errors


def _cell_text(row: Mapping, key: str, errors: set[str]) -> str:
    try:
        return format_cell(row.get(key), column_for(key).kind, row.get(_error_key(key)), key in errors)
    except (TypeError, ValueError) as error:
        raise type(error)(f"column {key!r}: {error}") from None


def _cell(row: Mapping, key: str, errors: set[str]) -> str:
    align = ' class="text"' if column_for(key).kind == TEXT else ""
    return f"<td{align}>{_cell_text(row, key, errors)}</td>"


def _label_columns(columns: Sequence[str]) -> list[str]:
    """The columns that name a row: the leading text columns (e.g. flow pattern and layout), at least one."""
    labels = []
    for key in columns[:-1]:
        if column_for(key).kind != TEXT:
            break
        labels.append(key)
    return labels or list(columns[:1])


def _table(rows: Sequence[Mapping]) -> str:
    """One table; transposed (one row per quantity, one column per row, headed by the row's leading text
    columns) when it has more columns than rows, so that a wide table grows down the page instead."""
    columns, errors = _shown_columns(rows)
    headers = {key: html.escape(column_header(key)) for key in columns}
    if len(columns) > len(rows):
        labels = _label_columns(columns)
        quantities = columns[len(labels):]
        head = f'<th scope="col">{", ".join(headers[key] for key in labels)}</th>' + "".join(
            f'<th scope="col">{", ".join(_cell_text(row, key, errors) for key in labels)}</th>' for row in rows)
        body = "".join(
            f'<tr><th scope="row">{headers[key]}</th>' + "".join(_cell(row, key, errors) for row in rows) + "</tr>"
            for key in quantities)
        layout = ' class="transposed"'
    else:
        head = "".join(f'<th scope="col">{headers[key]}</th>' for key in columns)
        body = "".join("<tr>" + "".join(_cell(row, key, errors) for key in columns) + "</tr>" for row in rows)
        layout = ""
    return (f'<div class="table-box"><table{layout}><thead><tr>{head}</tr></thead><tbody>{body}</tbody>'
            "</table></div>")


# --------------------------------------------------------------------------- page


class Section(NamedTuple):
    """One section of the summary page: a title, a sentence saying what the table shows, its rows and a
    legend (a short paragraph under the table; "" for none)."""

    title: str
    explanation: str
    rows: Sequence[Mapping]
    legend: str = ""


#: Fits the page in 1000 px: a bounded body, tables that scroll sideways inside it rather than overflow.
STYLE = ("body{font-family:sans-serif;max-width:1000px;margin:2em auto;padding:0 1em;box-sizing:border-box}"
         ".table-box{max-width:100%;overflow-x:auto;margin-bottom:0.5em}"
         "table{border-collapse:collapse}"
         "th,td{border:1px solid #bbb;padding:3px 8px;text-align:right;vertical-align:top}"
         "td{white-space:nowrap}th{background:#eee}"
         "th[scope=row],td.text{text-align:left}td.text{white-space:normal}"
         "p.legend{font-size:90%;color:#444;margin-top:0.3em}")

#: The page's key to its figures, shown under the title.
PAGE_LEGEND = (f"Figures are given as value ± standard error, the error to 2 significant digits and the value to "
               f"the same decimal place; \"{NO_UNCERTAINTY}\" marks a figure whose uncertainty is not estimated yet; "
               "n/a: not available.")


def summary_html(title: str, sections: Sequence[Section | tuple], intro: str = "") -> str:
    """A self-contained HTML page: a heading and the key to the figures, then per section its title, a sentence,
    a table of rows and an optional legend.

    Parameters
    ----------
    title : str
        Page title.
    intro : str, optional
        A paragraph under the key to the figures ("" for none).
    sections : sequence of Section or of (str, str, sequence of mapping[, str])
        ``(section title, explanation, rows[, legend])``; the columns are the rows' keys in order of first
        appearance, each ``"<key>_error"`` merged into the cell of ``"<key>"``. A section without rows says so
        instead of a table.

    Raises
    ------
    ValueError
        If a row has a key without a header in :data:`COLUMNS` (the message names it).
    TypeError
        If a cell value is not a scalar (a mapping or a list).
    """
    parts = [f"<h1>{html.escape(title)}</h1><p class=\"legend\">{html.escape(PAGE_LEGEND)}</p>"]
    if intro:
        parts.append(f"<p>{html.escape(intro)}</p>")
    for section in sections:
        section = Section(*section)
        parts.append(f"<h2>{html.escape(section.title)}</h2><p>{html.escape(section.explanation)}</p>")
        parts.append(_table(section.rows) if section.rows else "<p><em>Not run in this configuration.</em></p>")
        if section.legend and section.rows:
            parts.append(f"<p class=\"legend\">{html.escape(section.legend)}</p>")
    return (f"<!DOCTYPE html><html><head><meta charset=\"utf-8\">"
            f"<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"><title>{html.escape(title)}"
            f"</title><style>{STYLE}</style></head><body>{''.join(parts)}</body></html>\n")


# --------------------------------------------------------------------------- rows of each stage


def _with_errors(row: Mapping, keys: Sequence[str], aliases: Mapping[str, str] | None = None) -> dict:
    """The given keys of a row (missing ones as None), each with ``"<key>_error"`` when the row has it (or,
    failing that, the older error key ``aliases[key]``)."""
    picked = {}
    for key in keys:
        picked[key] = row.get(key)
        for source in (_error_key(key), (aliases or {}).get(key)):
            if source is not None and source in row:
                picked[_error_key(key)] = row[source]
                break
    return picked


def _config_number(value) -> str:
    # Settings read from the configuration print as they were written (0.1, not 0.1000).
    return "n/a" if is_missing(value) else f"{float(value):g}"


def _degrees(value) -> str:
    angle = float(value)
    return f"{angle:.1f}°" if round(angle, 1) == angle else f"{angle:g}°"


def _targets_text(targets: Mapping) -> str:
    """``{"internal": 30.0, "aluminium": 9.5}`` as "internal 30.0°, aluminium 9.5°"."""
    return ", ".join(f"{name} {_degrees(angle)}" for name, angle in targets.items())


def calibration_rows(parameters: Mapping) -> list[dict]:
    """Rows of the calibration result (``results/calibration/parameters.yaml`` as read): the chosen sliding
    friction of each contact with its band, then the contacts whose target could not be reached (with the
    reason) and those not tested."""
    rows = []
    if "particle_particle" in parameters:
        rows.append({"contact": "particle-particle", **parameters["particle_particle"]})
    for wall, values in (parameters.get("particle_wall") or {}).items():
        rows.append({"contact": f"particle-{wall}", **values})
    for test, reason in (parameters.get("unreachable") or {}).items():
        rows.append({"contact": test, "sliding_friction": None, "note": f"target not reached: {reason}"})
    for wall in parameters.get("not_tested") or []:
        rows.append({"contact": f"particle-{wall}", "sliding_friction": None, "note": "not tested; config value kept"})
    return rows


def calibration_explanation(parameters: Mapping) -> str:
    """The sentence over the calibration table: particle model, rolling friction, targets and tolerance."""
    model = [f"particle model {parameters['shape']}"] if parameters.get("shape") else []
    if parameters.get("rolling_friction") is not None:
        model.append(f"rolling friction {_config_number(parameters['rolling_friction'])}")
    text = "Contact parameters chosen from the Jenike shear sweep" + (f" ({', '.join(model)})" if model else "")
    targets = parameters.get("targets_deg") or {}
    if targets:
        text += f", with the band that reproduces the target bulk friction angles ({_targets_text(targets)})"
        if parameters.get("tolerance_deg") is not None:
            text += f" within ±{_degrees(parameters['tolerance_deg'])}"
    return text + "."


#: The columns of a silo run's flow summary (metrics/flow.json) on the summary page.
SILO_FLOW_COLUMNS = ("run_id", "n_clumps", "filling_bulk_density_kg_m3", "mass_flow_rate_kg_s",
                     "beverloo_mass_flow_rate_kg_s", "beverloo_ratio")
#: Error keys flow.json writes under another name than "<key>_error".
SILO_FLOW_ERROR_ALIASES = {"mass_flow_rate_kg_s": "mass_flow_rate_stderr_kg_s"}
#: The columns of the measured-profile comparison (metrics/measured_comparison.csv) on the summary page.
MEASURED_COLUMNS = ("z_m", "window", "n_points", "mean_error_percent", "rms_error_m_s", "max_abs_error_m_s",
                    "fraction_within_uncertainty")
#: The columns of the recirculating-silo summary table on the summary page.
RECIRCULATION_COLUMNS = ("flow_pattern", "layout", "residence_time_s", "t_s_over_t_d", "vrr_nr1", "vrr_nr2", "vrr_nr3",
                         "vrr_nr4", "prediction_rms_error")
#: Little's law on the clumps that pass within the run, two ways, shown when the summary table has them.
RECIRCULATION_TRANSIT_COLUMNS = ("transit_residence_time_s", "rtd_mean_ids_transit_s")
#: The counting-noise ceiling of the VRR and the flags of the VRRs at it, shown when the summary table has them.
RECIRCULATION_CEILING_COLUMNS = ("vrr_ceiling", "vrr_at_ceiling_nr1", "vrr_at_ceiling_nr2", "vrr_at_ceiling_nr3",
                                 "vrr_at_ceiling_nr4")
#: The fixed columns of the blender comparison (comparison/configurations.csv) on the summary page; its
#: ``vrr_at_<f>_tm`` columns follow, as many as the configuration asks for.
BLENDER_COLUMNS = ("configuration", "mass_flow_rate_kg_s", "exterior_v_z_m_s", "interior_v_z_m_s", "tube_v_z_m_s",
                   "rtd_mean_s", "rtd_spread", "ts_over_td", "recirculations_to_homogenise")


def silo_flow_rows(flows: Sequence[Mapping]) -> list[dict]:
    """One row per flat-bottom silo run: its flow summary's :data:`SILO_FLOW_COLUMNS` with their errors.

    The flow rate's standard error is ``mass_flow_rate_kg_s_error`` or, as flow.json writes it today,
    ``mass_flow_rate_stderr_kg_s``. Without an own error, the Beverloo ratio's is the flow rate's divided by the
    Beverloo prediction (the prediction counted exact).
    """
    rows = []
    for flow in flows:
        row = _with_errors(flow, SILO_FLOW_COLUMNS, SILO_FLOW_ERROR_ALIASES)
        rate_error, prediction = row.get("mass_flow_rate_kg_s_error"), row.get("beverloo_mass_flow_rate_kg_s")
        if "beverloo_ratio_error" not in row and not is_missing(rate_error) and not is_missing(prediction) and prediction:
            row["beverloo_ratio_error"] = float(rate_error) / abs(float(prediction))
        rows.append(row)
    return rows


def measured_rows(rows: Sequence[Mapping]) -> list[dict]:
    """The measured-profile comparison rows cut to :data:`MEASURED_COLUMNS` (with their errors, if any)."""
    return [_with_errors(row, MEASURED_COLUMNS) for row in rows]


def recirculation_rows(rows: Sequence[Mapping]) -> list[dict]:
    """The recirculating-silo summary rows cut to :data:`RECIRCULATION_COLUMNS` (missing ones as None), then those of
    :data:`RECIRCULATION_TRANSIT_COLUMNS`, :data:`RECIRCULATION_CEILING_COLUMNS` and the seed count the row has, with
    their errors when the table has them."""
    optional = RECIRCULATION_TRANSIT_COLUMNS + RECIRCULATION_CEILING_COLUMNS + ("replicates",)
    return [_with_errors(row, RECIRCULATION_COLUMNS + tuple(key for key in optional if key in row)) for row in rows]


def blender_rows(rows: Sequence[Mapping]) -> list[dict]:
    """The blender comparison rows: :data:`BLENDER_COLUMNS`, then every ``vrr_at_<f>_tm`` column of the row, with
    their errors when the table has them, then the VRR ceiling with its flags and the seed count when the table
    has them; other columns are left out."""
    picked = []
    for row in rows:
        keys = BLENDER_COLUMNS + tuple(key for key in row if _PERIOD_VRR.fullmatch(str(key)))
        keys += tuple(key for key in row if key == "vrr_ceiling" or str(key).endswith("_tm_at_ceiling"))
        keys += ("replicates",) if "replicates" in row else ()
        picked.append(_with_errors(row, keys))
    return picked


def significance_rows(rows: Sequence[Mapping]) -> list[dict]:
    """The blender comparison's differences (``comparison/significance.csv`` as read), one row per figure and pair
    of configurations: the figure in words, the pair, A − B with its standard error and whether it exceeds twice
    that error ("unknown" where an error is not known)."""
    return [{"figure": column_header(str(row["figure"])), "configuration_a": row["configuration_a"],
             "configuration_b": row["configuration_b"], "difference": row["difference"],
             "difference_error": row["difference_error"], "significance": row["significance"]} for row in rows]


def fill_balance_rows(balances: Sequence[Mapping]) -> list[dict]:
    """One row per settled fill (``metrics/fill_balance.json`` as read): the shares of the weight that the walls and
    floor carry, and the contacts' share of the weight above each plane."""
    rows = []
    for balance in balances:
        row = {"case": balance["case"], "run_id": balance["run_id"], "n_clumps": balance["clumps"]}
        row.update({key: balance[key] for key in ("support_ratio", "floor_ratio", "walls_ratio", "silo_like")})
        for plane in balance["planes"]:
            row[f"contacts_at_{round(plane['height_m'] * 1e3)}_mm"] = plane["contact_ratio"]
        row["balance_passed"] = not balance["problems"]
        rows.append(row)
    return rows


CALIBRATION_LEGEND = ("Band: the sliding friction range whose bulk friction angle lies within the target "
                      "± tolerance, the calibration's uncertainty. Band clipped: the band reaches the end of the "
                      "swept friction range, so that end is only a bound.")
SILO_LEGEND = ("Flow rate: slope of the discharged mass over the steady window. Beverloo flow rate: the "
               "correlation's prediction at the filling bulk density; the ratio's uncertainty is the flow "
               "rate's alone.")
MEASURED_LEGEND = "Errors of the simulated vertical velocity against each measured profile."
BLENDING_LEGEND = ("Hold-up residence time: all clumps above the outlet over the throughput, stagnant zones "
                   "included (Nr is counted in it). Transit residence time: the clumps that pass within the run, by "
                   "Little's law (their hold-up over their throughput) and as the tracer's mean; the two agree "
                   "within their errors when the run is steady. t_s/t_d: first appearance of the tracer over the "
                   "time to discharge all of it. VRR after recirculation n: variance reduction ratio "
                   "σ_in²/σ_out² of the outlet blue fraction during pass n. At the counting-noise ceiling: the VRR "
                   "is close to the largest one the windows' particle counts can measure, so it is only a lower "
                   "bound.")
FILL_LEGEND = ("Forces on the settled fill before its outlet opens, as shares of its weight. Walls + floor: 1 at "
               "rest. Walls: positive when they carry part of the weight by friction, as in a silo (Janssen); "
               "negative when they hold the fill down, a stress state a violent pour locks in. Contacts / weight "
               "above: the load the contacts carry across a horizontal plane over the weight of the clumps above "
               "it; at most 1 in a silo.")
BLENDER_LEGEND = ("Mean vertical velocity: the mean v_z of each passage (negative: downwards). VRR, sine period "
                  "f t_m: variance reduction ratio of a sine input whose period is f times the mean residence time. "
                  "Recirculations to homogenise: its error is the spread of the answer over first passes redrawn "
                  "within their counting noise (one excursion of the curve more or less moves it by a whole "
                  "recirculation), with the window's resolution; n/a: not homogenised within the simulated passes. "
                  "At the counting-noise ceiling: the VRR is within a factor 2 of the largest one the tracers can "
                  "resolve, so it is only a lower bound.")


DIFFERENCES_LEGEND = ("A − B: the difference of a figure between two configurations with the standard error of the "
                      "difference (the two errors in quadrature). Larger than 2 standard errors: significant; not "
                      "significant otherwise; unknown where an error is not known or a VRR is at its counting-noise "
                      "ceiling (only a lower bound). With one seed per configuration the errors are the runs' own "
                      "(batch means, tracer counts); replicates: N >= 3 adds the spread over seeds.")


AGAINST_THE_STUDY = ("Rows of the validation table (the report's validation page) that a finding of the study states, "
                     "with their agreement and whether this configuration is at the study's scale for the finding. "
                     "The validation scale (`make validate`, config/validation.yaml) runs the study nearer its own "
                     "scale; its record is docs/validation/.")


AGAINST_THE_STUDY_LEGEND = ("Agreement: the row's 95 % interval against the study's band, or the sign or order of a "
                            "trend; \"not resolved\" when its error or steadiness cannot tell. Scale: judged from the "
                            "configuration alone, never from a result.")


def summary_sections(parameters: Mapping, flows: Sequence[Mapping], measured: Sequence[Mapping],
                     recirculation: Sequence[Mapping], blender: Sequence[Mapping],
                     balances: Sequence[Mapping] = (), blender_differences: Sequence[Mapping] = (),
                     findings: Sequence[Mapping] | None = None) -> list[Section]:
    """The sections of the summary page (:func:`summary_html`) from the results of every stage.

    Parameters
    ----------
    parameters : mapping
        The calibration's chosen parameters (``results/calibration/parameters.yaml`` as read).
    flows : sequence of mapping
        The flow summary of each flat-bottom silo run (``metrics/flow.json``).
    measured, recirculation, blender : sequence of mapping
        Rows of the measured-profile comparisons, of the recirculating-silo summary and of the blender comparison.
    balances : sequence of mapping
        The force balance of each settled fill (``metrics/fill_balance.json``).
    blender_differences : sequence of mapping
        The blender comparison's differences (``comparison/significance.csv``).
    findings : sequence of mapping, optional
        The validation rows judged against a finding of the study: finding, figure, case, agreement, scale, note
        (:func:`siloflow.analysis.studies.validation.table.against_the_study`); None leaves the section out.
    """
    limits = []
    if findings is not None:
        limits = [Section("Against the study's findings", AGAINST_THE_STUDY,
                          list(findings) or [{"note": "No row of this configuration's validation table is judged "
                                                      "against a finding of the study."}],
                          AGAINST_THE_STUDY_LEGEND)]
    return [
        Section("Calibration", calibration_explanation(parameters), calibration_rows(parameters),
                CALIBRATION_LEGEND),
        Section("Silo validation", "Steady discharge rate of each flat-bottom silo run against Beverloo's prediction.",
                silo_flow_rows(flows), SILO_LEGEND),
        Section("Silo against measurements", "Velocity profile errors against the measured profiles.",
                measured_rows(measured), MEASURED_LEGEND),
        Section("Blending", "Residence time, RTD shape (t_s/t_d) and VRR after each recirculation per flow pattern "
                            "and batch layout, and the RMS error of the LTI prediction.",
                recirculation_rows(recirculation), BLENDING_LEGEND),
        Section("Blender", "Insert configurations compared (see the blender comparison table).",
                blender_rows(blender), BLENDER_LEGEND),
        Section("Blender: differences", "Which differences between the insert configurations are larger than "
                                        "their uncertainty.", significance_rows(blender_differences),
                DIFFERENCES_LEGEND),
        Section("Settled fills", "How each settled fill carries its weight before the outlet opens.",
                fill_balance_rows(balances), FILL_LEGEND),
    ] + limits
