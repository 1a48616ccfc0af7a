"""The report of a Bayesian calibration: its credible intervals, its posterior predictive check, the chart
inversion's answer beside it and the engines side by side, as plain rows (one dict per table row).

Pure functions on arrays and plain data; the workflow reads the posterior, the designs and the runs' bulk friction
and writes the tables and figures (``siloflow/workflow/scripts/bayes_report.py``, ``siloflow/workflow/scripts/bayes_engines.py``).

Units: the parameters are friction coefficients (-); angles are bulk friction angles (deg); a difference "in sd" is
a difference divided by the standard deviation named beside it (-).
"""

from __future__ import annotations

import math
from typing import Mapping, Sequence

import numpy as np

from siloflow.calibration.bayes.joint import WALL_PARAMETER, Calibration
from siloflow.calibration.bayes.posterior import credible_interval, in_credible_region

__all__ = ["CHART_COMPARISON_COLUMNS", "chart_comparison_rows", "engines_rows", "interval_rows", "twin_verdict",
           "predictive_columns", "predictive_rows", "predictive_verdict"]

#: How many combined standard deviations a predictive run may lie from its target and still be within (-).
WITHIN_SD = 2.0

#: The columns of :func:`chart_comparison_rows`, in order (the header of an empty comparison table too).
CHART_COMPARISON_COLUMNS = ("parameter", "chart_value", "chart_error", "chart_fixed", "posterior_mean",
                            "posterior_sd", "interval_lower", "interval_upper", "level", "chart_inside",
                            "conditional_mean", "conditional_sd", "conditional_samples", "conditional_window",
                            "chart_rolling_friction", "note")

ROLLING = "rolling_friction"


def _samples_of(samples, names: Sequence[str]) -> np.ndarray:
    """Posterior samples as an ``(n, d)`` float array with one column per name."""
    values = np.asarray(samples, dtype=float)
    values = values[:, np.newaxis] if values.ndim == 1 else values
    if values.ndim != 2 or values.shape[1] != len(names):
        raise ValueError(f"samples must have shape (n, {len(names)}) for the parameters {list(names)}, "
                         f"got {np.shape(samples)}")
    return values


def _number(value) -> float:
    """A float, NaN for None (a JSON or YAML null: not known)."""
    return math.nan if value is None else float(value)


def _optional(value: float) -> float | None:
    """None for NaN (written as an empty cell or a JSON null), else the float."""
    return None if math.isnan(value) else float(value)


def interval_rows(summary: Mapping, samples, names: Sequence[str], level: float = 0.9) -> list[dict]:
    """Each parameter's posterior mean, sd, median and equal-tailed credible interval.

    Parameters
    ----------
    summary : Mapping
        The posterior summary, shaped as :meth:`siloflow.calibration.bayes.posterior.PosteriorSummary.to_dict` (a
        ``posterior.json``): ``{"parameters": {name: {"mean", "sd", "median", ...}}, ...}``, in the parameters'
        units (-).
    samples : array_like, shape (n, d)
        The posterior samples the summary describes (-), one column per name.
    names : sequence of str, length d
        The parameters, in the columns' order.
    level : float
        Probability inside the interval, in (0, 1) (:func:`siloflow.calibration.bayes.posterior.credible_interval`).

    Returns
    -------
    list of dict
        One row per parameter: ``parameter``, ``mean``, ``sd``, ``median`` (-), ``interval_lower``,
        ``interval_upper`` (-; each tail holds ``(1 - level) / 2``), ``level`` (-) and ``units`` (``"-"``).
    """
    names = list(names)
    interval = np.atleast_2d(credible_interval(_samples_of(samples, names), level))
    parameters = summary["parameters"]
    missing = [name for name in names if name not in parameters]
    if missing:
        raise ValueError(f"the posterior summary has no parameter {', '.join(missing)} (it has {list(parameters)})")
    return [{"parameter": name, "mean": float(parameters[name]["mean"]), "sd": float(parameters[name]["sd"]),
             "median": float(parameters[name]["median"]), "interval_lower": float(interval[i, 0]),
             "interval_upper": float(interval[i, 1]), "level": float(level), "units": "-"}
            for i, name in enumerate(names)]


def _seed_sd(calibration: Calibration, seed_sd_deg) -> dict[str, float]:
    """``{test: seed noise (deg)}`` from a mapping by test or a sequence in the calibration's test order."""
    if isinstance(seed_sd_deg, Mapping):
        missing = [test for test in calibration.tests if test not in seed_sd_deg]
        if missing:
            raise ValueError(f"no seed noise for the test(s) {', '.join(missing)} (it has {list(seed_sd_deg)})")
        return {test: _number(seed_sd_deg[test]) for test in calibration.tests}
    values = list(seed_sd_deg)
    if len(values) != len(calibration.tests):
        raise ValueError(f"{len(values)} seed noises for the {len(calibration.tests)} tests {list(calibration.tests)}")
    return {test: _number(value) for test, value in zip(calibration.tests, values)}


def predictive_columns(calibration: Calibration) -> list[str]:
    """The columns of :func:`predictive_rows`, in order (the header of a check without runs too)."""
    return ["set", "replicate", *calibration.names, "test", "run_id", "target_deg", "target_sd_deg", "seed_sd_deg",
            "angle_deg", "angle_error_deg", "allowed_sd_deg", "difference_deg", "difference_in_sd", "within",
            "window_method"]


def predictive_rows(calibration: Calibration, sets: Sequence[Mapping], summaries: Mapping[str, Mapping],
                    seed_sd_deg) -> list[dict]:
    """The posterior predictive check: each run at a posterior draw against its test's target.

    A run at parameters drawn from the posterior should give an angle about its target within the uncertainty the
    likelihood allows a run at the true parameters: the target's, the DEM's seed noise and the run's own window
    error, in quadrature,

        ``allowed = sqrt(target_sd^2 + seed_sd^2 + run_error^2)`` (deg).

    A run is ``within`` when ``|angle - target| <= 2 allowed`` (about 95 % of runs for a Gaussian spread; the
    posterior's own width adds to the spread of runs at draws from it, so a somewhat lower fraction is no alarm, a
    much lower one is).

    Parameters
    ----------
    calibration : siloflow.calibration.bayes.joint.Calibration
        The calibration: its parameter names, tests, targets (deg) and their uncertainty (deg).
    sets : sequence of Mapping
        The predictive parameter sets as :func:`siloflow.calibration.bayes.runs.with_runs` writes them:
        ``{"theta": [...], "replicate": k, "points": {...}, "runs": {test: run id}}``.
    summaries : Mapping of str to Mapping
        ``{run id: bulk friction summary}`` (``metrics/bulk_friction.json``): ``bulk_friction_angle_deg``,
        ``bulk_friction_angle_deg_error`` (deg; null where unknown) and ``window_method``.
    seed_sd_deg : Mapping of str to float, or sequence of float
        The seed noise of each test's angle (deg), by test (or in ``calibration.tests`` order).

    Returns
    -------
    list of dict
        One row per set and test, sets in order and tests in ``calibration.tests`` order: ``set`` (index),
        ``replicate``, the set's parameter values by name (-), ``test``, ``run_id``, ``target_deg``,
        ``target_sd_deg``, ``seed_sd_deg``, ``angle_deg``, ``angle_error_deg``, ``allowed_sd_deg`` (deg),
        ``difference_deg`` (``angle - target``, deg), ``difference_in_sd`` (``difference_deg / allowed_sd_deg``, -),
        ``within`` (bool; False where the allowed uncertainty is unknown) and ``window_method``.

    Raises
    ------
    ValueError
        If a set's theta does not match the parameters, a test has no run or no seed noise, or a run has no summary.
    """
    seeds = _seed_sd(calibration, seed_sd_deg)
    targets = dict(zip(calibration.tests, calibration.targets_deg.tolist()))
    target_sd = float(calibration.target_sd_deg)
    rows = []
    for index, chosen in enumerate(sets):
        theta = [float(value) for value in chosen["theta"]]
        if len(theta) != len(calibration.names):
            raise ValueError(f"set {index} has {len(theta)} parameter values for {list(calibration.names)}")
        for test in calibration.tests:
            run = chosen["runs"].get(test)
            if run is None:
                raise ValueError(f"set {index} has no run of the test {test}")
            if run not in summaries:
                raise ValueError(f"no bulk friction summary of the run {run} (set {index}, test {test})")
            summary = summaries[run]
            angle = _number(summary["bulk_friction_angle_deg"])
            error = _number(summary.get("bulk_friction_angle_deg_error"))
            allowed = math.sqrt(target_sd ** 2 + seeds[test] ** 2 + error ** 2)
            difference = angle - targets[test]
            in_sd = difference / allowed if allowed > 0 else math.nan
            rows.append({"set": index, "replicate": int(chosen.get("replicate", 0)),
                         **dict(zip(calibration.names, theta)), "test": test, "run_id": run,
                         "target_deg": targets[test], "target_sd_deg": target_sd, "seed_sd_deg": seeds[test],
                         "angle_deg": angle, "angle_error_deg": error, "allowed_sd_deg": allowed,
                         "difference_deg": difference, "difference_in_sd": in_sd,
                         "within": bool(abs(in_sd) <= WITHIN_SD), "window_method": summary.get("window_method")})
    return rows


def predictive_verdict(rows: Sequence[Mapping]) -> dict:
    """How many predictive runs lie within two allowed standard deviations of their target.

    Parameters
    ----------
    rows : sequence of Mapping
        Rows of :func:`predictive_rows` (their ``within``).

    Returns
    -------
    dict
        ``rows`` (count), ``within`` (count), ``fraction`` (``within / rows``, -; None without rows) and
        ``unknown`` (count of the rows whose allowed uncertainty is unknown, a run without its error: not within).
    """
    count = len(rows)
    within = sum(1 for row in rows if row["within"])
    unknown = sum(1 for row in rows if row.get("allowed_sd_deg") is None or math.isnan(float(row["allowed_sd_deg"])))
    return {"rows": count, "within": within, "fraction": within / count if count else None, "unknown": unknown}


def _chart_values(calibration: Calibration, chart_parameters: Mapping) -> dict[str, tuple[float, float]]:
    """``{parameter: (chart value, its error)}`` (-) of the parameters the chart inverted; NaN for an unknown error."""
    found = {}
    internal = chart_parameters.get("particle_particle")
    walls = chart_parameters.get("particle_wall") or {}
    for name in calibration.names:
        if name == "sliding_friction" and internal:
            entry = internal
        elif name.startswith(f"{WALL_PARAMETER}.") and name.split(".", 1)[1] in walls:
            entry = walls[name.split(".", 1)[1]]
        else:
            continue
        found[name] = (float(entry["sliding_friction"]), _number(entry.get("sliding_friction_error")))
    return found


def chart_comparison_rows(calibration: Calibration, samples, chart_parameters: Mapping, level: float = 0.9, *,
                          window: float = 0.02, min_samples: int = 50) -> list[dict]:
    """The chart inversion's friction beside the posterior's, for the same targets.

    The chart (:func:`siloflow.calibration.inversion.invert_calibration`) reads each target off one curve at the fixed
    rolling friction ``calibration.rolling_friction``; the posterior lets the rolling friction vary with the rest.
    Its marginals therefore answer another question than the chart: the like-for-like comparison is the posterior
    conditioned near the chart's rolling friction, the mean over the samples whose rolling friction lies within
    ``+- window`` of it (when at least ``min_samples`` do; else none is given).

    Parameters
    ----------
    calibration : siloflow.calibration.bayes.joint.Calibration
        The calibration: its parameter names (``sliding_friction``, ``rolling_friction``,
        ``wall_sliding_friction.<material>``) and targets.
    samples : array_like, shape (n, d)
        Posterior samples (-), one column per ``calibration.names``.
    chart_parameters : Mapping
        What ``invert_calibration`` wrote to ``parameters.yaml``: ``rolling_friction`` (-), ``particle_particle``
        (``sliding_friction`` and ``sliding_friction_error``, -; the internal target) and ``particle_wall``
        (the same per wall material). A target the chart could not reach is absent and gets no row.
    level : float
        Probability of the posterior's equal-tailed credible interval, in (0, 1).
    window : float
        Half-width of the rolling friction window of the conditioned posterior (-).
    min_samples : int
        Samples the window needs for a conditioned mean.

    Returns
    -------
    list of dict
        One row per parameter the chart gives, in ``calibration.names`` order, with the columns
        :data:`CHART_COMPARISON_COLUMNS`: ``chart_value`` and ``chart_error`` (-; the error None where unknown),
        ``chart_fixed`` (True for the rolling friction, which the chart does not fit), the posterior's
        ``posterior_mean``, ``posterior_sd``, ``interval_lower``, ``interval_upper`` (-) at ``level``,
        ``chart_inside`` (whether the chart's value lies in that interval), ``conditional_mean`` and
        ``conditional_sd`` (-; None for the rolling friction itself and when fewer than ``min_samples`` samples lie
        in the window), ``conditional_samples`` (count in the window), ``conditional_window`` (-),
        ``chart_rolling_friction`` (-) and a ``note``.

    Raises
    ------
    ValueError
        If the chart is of another particle shape than the calibration, or the samples do not match its parameters.
    """
    names = list(calibration.names)
    values = _samples_of(samples, names)
    shape = chart_parameters.get("shape")
    if shape is not None and shape != calibration.shape:
        raise ValueError(f"the chart inverted {shape} particles, the Bayesian calibration calibrates "
                         f"{calibration.shape}")
    rolling = float(chart_parameters["rolling_friction"])
    interval = np.atleast_2d(credible_interval(values, level))
    mean, sd = values.mean(axis=0), values.std(axis=0, ddof=1)
    if ROLLING in names:
        near = np.abs(values[:, names.index(ROLLING)] - rolling) <= window
    else:  # held fixed in the Bayesian calibration: every sample has the same rolling friction
        near = np.full(len(values), abs(calibration.fixed[ROLLING] - rolling) <= window)
    count = int(near.sum())
    enough = count >= min_samples
    conditional_mean = values[near].mean(axis=0) if enough else None
    conditional_sd = values[near].std(axis=0, ddof=1) if enough else None
    chart = _chart_values(calibration, chart_parameters)
    chart[ROLLING] = (rolling, math.nan)
    rows = []
    for i, name in enumerate(names):
        if name not in chart:
            continue
        value, error = chart[name]
        fixed = name == ROLLING
        if fixed:
            note = ("fixed in the chart inversion (calibration.rolling_friction), not fitted; the posterior's "
                    "marginal beside it")
        elif enough:
            note = f"conditioned on |rolling_friction - {rolling:g}| <= {window:g}: {count} samples"
        else:
            note = (f"only {count} samples with |rolling_friction - {rolling:g}| <= {window:g} (fewer than "
                    f"{min_samples}): no conditioned mean")
        lower, upper = float(interval[i, 0]), float(interval[i, 1])
        rows.append({"parameter": name, "chart_value": value, "chart_error": _optional(error), "chart_fixed": fixed,
                     "posterior_mean": float(mean[i]), "posterior_sd": float(sd[i]), "interval_lower": lower,
                     "interval_upper": upper, "level": float(level), "chart_inside": bool(lower <= value <= upper),
                     "conditional_mean": None if fixed or not enough else float(conditional_mean[i]),
                     "conditional_sd": None if fixed or not enough else float(conditional_sd[i]),
                     "conditional_samples": count, "conditional_window": float(window),
                     "chart_rolling_friction": rolling, "note": note})
    return rows


def engines_rows(posteriors: Mapping[str, Mapping]) -> list[dict]:
    """Each parameter's posterior on every engine side by side.

    Parameters
    ----------
    posteriors : Mapping of str to Mapping
        ``{engine: posterior summary}`` in the order to show, each shaped as
        :meth:`siloflow.calibration.bayes.posterior.PosteriorSummary.to_dict` (other keys are ignored):
        ``{"parameters": {name: {"mean", "sd", "q05", "q95", ...}}}`` (-).

    Returns
    -------
    list of dict
        One row per parameter (in the order of first appearance over the engines, each engine's parameters in the
        order of its ``correlation["names"]`` where it has them, else of its ``parameters``): ``parameter``, then
        per engine ``<engine>_mean``, ``<engine>_sd``, ``<engine>_q05``, ``<engine>_q95`` (-; None where that
        engine has no such parameter). With exactly two engines ``a`` and ``b`` also ``<b>_minus_<a>`` (difference
        of the means, -) and ``<b>_minus_<a>_in_sd``: that difference over the combined sd
        ``sqrt(sd_a^2 + sd_b^2)`` (-; None where either is missing or the combined sd is zero).
    """
    engines = list(posteriors)
    if not engines:
        raise ValueError("no engine's posterior to compare")
    names: list[str] = []
    for engine in engines:
        parameters = posteriors[engine]["parameters"]
        # the calibration's order, which the correlation keeps (a JSON file written with sorted keys loses it)
        ordered = (posteriors[engine].get("correlation") or {}).get("names") or list(parameters)
        names += [name for name in ordered if name in parameters and name not in names]
    rows = []
    for name in names:
        row: dict = {"parameter": name}
        for engine in engines:
            marginal = posteriors[engine]["parameters"].get(name)
            for key in ("mean", "sd", "q05", "q95"):
                row[f"{engine}_{key}"] = None if marginal is None else float(marginal[key])
        if len(engines) == 2:
            first, second = engines
            difference = combined = None
            if row[f"{first}_mean"] is not None and row[f"{second}_mean"] is not None:
                difference = row[f"{second}_mean"] - row[f"{first}_mean"]
                combined = math.hypot(row[f"{first}_sd"], row[f"{second}_sd"])
            row[f"{second}_minus_{first}"] = difference
            row[f"{second}_minus_{first}_in_sd"] = difference / combined if combined else None
        rows.append(row)
    return rows


def twin_verdict(names: Sequence[str], samples, truth, level: float = 0.9) -> dict:
    """Whether a twin experiment brought its known parameters back.

    Parameters
    ----------
    names : sequence of str
        The parameters, in the samples' order.
    samples : array_like, shape (n, d)
        The posterior samples (-).
    truth : array_like, shape (d,)
        The parameters the engine made the targets with (-).
    level : float
        The credible level (0.9: the 90 % region).

    Returns
    -------
    dict
        ``truth`` by name; ``inside_credible_region``: whether the truth lies inside the joint region at ``level``
        (:func:`siloflow.calibration.bayes.posterior.in_credible_region`, a Gaussian approximation of the posterior);
        ``marginals``: per parameter the equal-tailed interval at ``level`` and whether it holds the truth.
    """
    samples = np.asarray(samples, dtype=float)
    truth = np.asarray(truth, dtype=float)
    intervals = credible_interval(samples, level)
    return {
        "level": level,
        "truth": dict(zip(names, truth.tolist())),
        "inside_credible_region": bool(in_credible_region(samples, truth, level)),
        "marginals": {name: {"truth": float(truth[i]), "lower": float(intervals[i][0]), "upper": float(intervals[i][1]),
                             "inside": bool(intervals[i][0] <= truth[i] <= intervals[i][1])}
                      for i, name in enumerate(names)},
    }
