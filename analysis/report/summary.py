"""The summary page of the report: the figures of merit of every stage as HTML tables.

Pure: the caller reads the stage results and passes plain rows; :func:`summary_html` returns the page.
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence

__all__ = ["summary_html", "format_cell", "calibration_rows", "silo_flow_rows", "recirculation_rows", "summary_sections"]


def format_cell(value) -> str:
    """A table cell: numbers with 4 significant digits, NaN and None as "n/a", text escaped."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "n/a"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.4g}"
    return html.escape(str(value))


def _table(rows: Sequence[Mapping]) -> str:
    columns: list[str] = []
    for row in rows:
        columns += [key for key in row if key not in columns]
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in columns)
    body = "".join(
        "<tr>" + "".join(f"<td>{format_cell(row.get(c))}</td>" for c in columns) + "</tr>" for row in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def summary_html(title: str, sections: Sequence[tuple[str, str, Sequence[Mapping]]]) -> str:
    """A self-contained HTML page: a heading, then per section its title, a sentence and a table of rows.

    Parameters
    ----------
    title : str
        Page title.
    sections : sequence of (str, str, sequence of mapping)
        ``(section title, explanation, rows)``; the columns are the rows' keys in order of first appearance. A
        section without rows says so instead of a table.
    """
    parts = [f"<h1>{html.escape(title)}</h1>"]
    for heading, explanation, rows in sections:
        parts.append(f"<h2>{html.escape(heading)}</h2><p>{html.escape(explanation)}</p>")
        parts.append(_table(rows) if rows else "<p><em>Not run in this configuration.</em></p>")
    style = ("body{font-family:sans-serif;margin:2em}table{border-collapse:collapse;margin-bottom:1.5em}"
             "th,td{border:1px solid #bbb;padding:3px 8px;text-align:right}th{background:#eee}")
    return (f"<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{html.escape(title)}</title>"
            f"<style>{style}</style></head><body>{''.join(parts)}</body></html>\n")


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


#: The columns of a silo run's flow summary (metrics/flow.json) on the summary page.
SILO_FLOW_COLUMNS = ("run_id", "n_clumps", "filling_bulk_density_kg_m3", "mass_flow_rate_kg_s",
                     "beverloo_mass_flow_rate_kg_s", "beverloo_ratio")
#: The columns of the recirculating-silo summary table on the summary page.
RECIRCULATION_COLUMNS = ("flow_pattern", "layout", "residence_time_s", "t_s_over_t_d", "vrr_nr1", "vrr_nr2", "vrr_nr3",
                         "vrr_nr4", "prediction_rms_error")


def silo_flow_rows(flows: Sequence[Mapping]) -> list[dict]:
    """One row per flat-bottom silo run: its flow summary's :data:`SILO_FLOW_COLUMNS`."""
    return [{key: flow[key] for key in SILO_FLOW_COLUMNS} for flow in flows]


def recirculation_rows(rows: Sequence[Mapping]) -> list[dict]:
    """The recirculating-silo summary rows cut to :data:`RECIRCULATION_COLUMNS` (missing ones as None)."""
    return [{key: row.get(key) for key in RECIRCULATION_COLUMNS} for row in rows]


def summary_sections(parameters: Mapping, flows: Sequence[Mapping], measured: Sequence[Mapping],
                     recirculation: Sequence[Mapping], blender: Sequence[Mapping]) -> list[tuple[str, str, list]]:
    """The sections of the summary page (:func:`summary_html`) from the results of every stage.

    Parameters
    ----------
    parameters : mapping
        The calibration's chosen parameters (``results/calibration/parameters.yaml`` as read).
    flows : sequence of mapping
        The flow summary of each flat-bottom silo run (``metrics/flow.json``).
    measured, recirculation, blender : sequence of mapping
        Rows of the measured-profile comparisons, of the recirculating-silo summary and of the blender comparison.
    """
    return [
        ("Calibration", f"Contact parameters chosen from the Jenike shear sweep (particle model {parameters.get('shape')}, "
                        f"rolling friction {parameters.get('rolling_friction')}), with the band that reproduces the "
                        f"target angles {parameters.get('targets_deg')} deg within {parameters.get('tolerance_deg')} deg.",
         calibration_rows(parameters)),
        ("Silo validation", "Steady discharge rate of each flat-bottom silo run against Beverloo's prediction.",
         silo_flow_rows(flows)),
        ("Silo against measurements", "Velocity profile errors against the measured profiles.", list(measured)),
        ("Blending", "Mean residence time, RTD spread and VRR after each recirculation per flow pattern and batch "
                     "layout, and the RMS error of the LTI prediction.", recirculation_rows(recirculation)),
        ("Blender", "Insert configurations compared (see the blender comparison table).", list(blender)),
    ]
