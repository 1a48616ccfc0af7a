"""The silo at the Bayesian posterior's draws: how far the calibration's uncertainty moves the silo's figures.

The silo runs once at the posterior mean and once at each parameter set drawn from the posterior for the predictive
check (``silo_flat.posterior_draws``). Between the draws a figure moves for two reasons: the parameters differ (the
calibration's uncertainty, wanted) and each run has its own error (the seed and the averaging window). The spread
between the draws, less the runs' own error, is the calibration's error bar of that figure.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
from scipy import stats

#: The silo figures a posterior draw gives: ``{figure: unit}``.
FIGURES = {"mass_flow_rate_kg_s": "kg/s", "base_vertical_stress_Pa": "Pa"}

#: The label of the run at the posterior mean (the others are draws).
POSTERIOR_MEAN = "posterior mean"

#: The one-sided level at which the spread between draws counts as larger than the runs' own error.
SPREAD_LEVEL = 0.95


def base_vertical_stress(janssen_rows: Sequence[Mapping]) -> tuple[float, float]:
    """The DEM's vertical stress at the base of the settled fill and its standard error (Pa): ``sigma_v_dem_Pa`` and
    ``sigma_v_dem_Pa_error`` of the row of ``metrics/janssen.csv`` deepest below the surface among those with a
    standard error (a bin without a neighbour to pair with has none); NaN as the error when no row has one."""
    if not janssen_rows:
        raise ValueError("the Janssen profile has no rows: the settled fill gave no vertical stress")
    known = [row for row in janssen_rows if _number(row.get("sigma_v_dem_Pa_error")) is not None]
    deepest = max(known or janssen_rows, key=lambda row: float(row["depth_below_surface_m"]))
    error = _number(deepest.get("sigma_v_dem_Pa_error"))
    return float(deepest["sigma_v_dem_Pa"]), math.nan if error is None else error


def _number(value) -> float | None:
    """``value`` as a finite float, None when it is empty, null or NaN."""
    if value is None or value == "":
        return None
    number = float(value)
    return number if math.isfinite(number) else None


def posterior_draw_rows(labels: Sequence[str], runs: Sequence[str], parameters: Sequence[Mapping],
                        flows: Sequence[Mapping], stresses: Sequence[tuple[float, float]]) -> list[dict]:
    """One row per run: its label, run id, the parameters it ran with and its figures with their standard errors.

    Parameters
    ----------
    labels, runs : sequence of str
        ``posterior mean`` then ``draw 0``, ``draw 1``, ...; their run ids.
    parameters : sequence of Mapping
        Each run's parameters in the layout of ``parameters.yaml`` (-).
    flows : sequence of Mapping
        Each run's ``metrics/flow.json`` (``mass_flow_rate_kg_s`` and ``mass_flow_rate_kg_s_error``, kg/s).
    stresses : sequence of (float, float)
        Each run's :func:`base_vertical_stress` (Pa).
    """
    if not len(labels) == len(runs) == len(parameters) == len(flows) == len(stresses):
        raise ValueError("one label, run id, parameter set, flow summary and stress per run")
    rows = []
    for label, run, chosen, flow, (stress, stress_error) in zip(labels, runs, parameters, flows, stresses):
        walls = {f"wall_sliding_friction.{wall}": float(values["sliding_friction"])
                 for wall, values in chosen.get("particle_wall", {}).items()}
        rows.append({"label": label, "run_id": run,
                     "sliding_friction": float(chosen["particle_particle"]["sliding_friction"]),
                     "rolling_friction": float(chosen["rolling_friction"]), **walls,
                     "mass_flow_rate_kg_s": float(flow["mass_flow_rate_kg_s"]),
                     "mass_flow_rate_kg_s_error": float(flow["mass_flow_rate_kg_s_error"]),
                     "base_vertical_stress_Pa": stress, "base_vertical_stress_Pa_error": stress_error})
    return rows


def calibration_spread(rows: Sequence[Mapping]) -> list[dict]:
    """Per figure, the calibration's error bar from the draws beside the runs' own error.

    For the draws (every row but the posterior mean's) with values :math:`v_i` and standard errors :math:`e_i`:
    the spread :math:`s` (sample standard deviation, ddof 1), the runs' own error :math:`e` (root mean square of the known
    :math:`e_i`), and the calibration's part :math:`\\sqrt{\\max(s^2 - e^2, 0)}`. Were the parameters of no
    consequence, :math:`(n - 1) s^2 / e^2` would follow a chi-square law with :math:`n - 1` degrees of freedom; the
    spread counts as larger than the runs' own error when it exceeds that law's quantile at :data:`SPREAD_LEVEL`.
    With fewer than two draws there is no spread (NaN) and no verdict (None).

    Returns
    -------
    list of dict
        Per figure: ``figure``, ``unit``, ``posterior_mean`` and ``posterior_mean_error`` (the run at the posterior
        mean), ``draws``, ``draws_mean``, ``draws_sd`` (the spread), ``run_error`` (rms), ``calibration_sd``,
        ``spread_ratio`` (:math:`s^2 / e^2`), ``critical_ratio`` and ``spread_exceeds_run_error``.
    """
    mean_rows = [row for row in rows if row["label"] == POSTERIOR_MEAN]
    draws = [row for row in rows if row["label"] != POSTERIOR_MEAN]
    result = []
    for figure, unit in FIGURES.items():
        values = np.array([row[figure] for row in draws], dtype=float)
        errors = np.array([row[f"{figure}_error"] for row in draws], dtype=float)
        count = len(values)
        spread = float(np.std(values, ddof=1)) if count >= 2 else math.nan
        known = errors[np.isfinite(errors)]
        run_error = float(np.sqrt(np.mean(known ** 2))) if len(known) else math.nan
        if count < 2 or math.isnan(run_error):
            ratio = math.nan
        elif run_error > 0:
            ratio = spread ** 2 / run_error ** 2
        else:  # runs without error: any spread is the parameters'
            ratio = math.inf if spread > 0 else math.nan
        critical = float(stats.chi2.ppf(SPREAD_LEVEL, count - 1) / (count - 1)) if count >= 2 else math.nan
        result.append({
            "figure": figure, "unit": unit,
            "posterior_mean": float(mean_rows[0][figure]) if mean_rows else math.nan,
            "posterior_mean_error": float(mean_rows[0][f"{figure}_error"]) if mean_rows else math.nan,
            "draws": count,
            "draws_mean": float(np.mean(values)) if count else math.nan,
            "draws_sd": spread,
            "run_error": run_error,
            "calibration_sd": math.sqrt(max(spread ** 2 - run_error ** 2, 0.0)) if count >= 2 else math.nan,
            "spread_ratio": ratio,
            "critical_ratio": critical,
            "spread_exceeds_run_error": None if math.isnan(ratio) else bool(ratio > critical),
        })
    return result
