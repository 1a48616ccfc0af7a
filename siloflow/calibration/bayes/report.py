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

from scipy import stats

from siloflow.calibration.bayes.joint import WALL_PARAMETER, Calibration
from siloflow.calibration.bayes.posterior import credible_interval

__all__ = ["CHART_COMPARISON_COLUMNS", "TWIN_LEVEL", "chart_comparison_rows", "engines_rows", "interval_rows",
           "twin_verdict", "TWIN_COLUMNS", "twin_rows", "predictive_columns", "predictive_rows", "predictive_verdict"]

#: How many combined standard deviations a predictive run may lie from its target and still be within (-).
WITHIN_SD = 2.0

#: The predictive check's chi-square is consistent when neither tail's probability is below this (-): a two-sided
#: test at 5 %, which fails a spread of runs too wide (the posterior or the noise model wrong) and one too narrow
#: (the noise overestimated, the intervals too wide).
PREDICTIVE_TAIL = 0.025

#: The credible level of the twin experiment's test (-): the truth must lie inside the 90 % highest-posterior-density
#: region.
TWIN_LEVEL = 0.9

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
            "discrepancy_sd_deg", "angle_deg", "angle_error_deg", "predicted_deg", "predicted_sd_deg",
            "predictive_sd_deg", "z", "pit", "allowed_sd_deg", "difference_deg", "difference_in_sd", "within",
            "window_method"]


def predictive_rows(calibration: Calibration, sets: Sequence[Mapping], summaries: Mapping[str, Mapping],
                    seed_sd_deg, target_sd_deg=None) -> list[dict]:
    """The posterior predictive check: each run at a posterior draw, on a fresh seed, against what the calibrated
    model predicts for it and against its test's target.

    Against the prediction: a run at the drawn parameters ``theta`` scatters about the surrogate's mean ``m(theta)``
    with the surrogate's sd ``s(theta)`` and the DEM's seed noise ``sigma``,

        ``z = (angle - m) / sqrt(s^2 + sigma^2)``, ``pit = Phi(z)``,

    standard normal and uniform if the model is right; :func:`predictive_verdict` tests the sum of ``z^2``. The
    run's own window error is part of its scatter over seeds, which ``sigma`` measures: it is not added again.

    Against the target: ``difference = angle - target`` over ``allowed = sqrt(target_sd^2 + discrepancy^2 +
    sigma^2)`` (deg), the spread of a run at the true parameters about the measured mean; ``within`` when
    ``|difference| <= 2 allowed``.

    Parameters
    ----------
    calibration : siloflow.calibration.bayes.joint.Calibration
        The calibration: its parameter names, tests, targets (deg) and model discrepancy (deg).
    sets : sequence of Mapping
        The predictive parameter sets as :func:`siloflow.calibration.bayes.runs.with_runs` writes them:
        ``{"theta": [...], "replicate": k, "points": {...}, "runs": {test: run id}}``, with ``predicted_deg``
        (``{test: [mean, sd]}``, deg) where the surrogates' prediction at the draw was kept.
    summaries : Mapping of str to Mapping
        ``{run id: bulk friction summary}`` (``metrics/bulk_friction.json``): ``bulk_friction_angle_deg``,
        ``bulk_friction_angle_deg_error`` (deg; null where unknown) and ``window_method``.
    seed_sd_deg : Mapping of str to float, or sequence of float
        The seed noise of each test's angle (deg), by test (or in ``calibration.tests`` order).
    target_sd_deg : Mapping of str to float, or sequence of float, optional
        The standard error of each target the likelihood took (deg; a twin's from the seed noise); default the
        calibration's.

    Returns
    -------
    list of dict
        One row per set and test, sets in order and tests in ``calibration.tests`` order, with the columns of
        :func:`predictive_columns`: the set's parameter values by name (-), ``predicted_deg`` and
        ``predicted_sd_deg`` (the surrogate's, deg; NaN where not kept), ``predictive_sd_deg`` (``sqrt(s^2 +
        sigma^2)``, deg), ``z`` and ``pit`` (-; NaN without a prediction), ``allowed_sd_deg``, ``difference_deg``
        (deg), ``difference_in_sd`` (-), ``within`` (bool).

    Raises
    ------
    ValueError
        If a set's theta does not match the parameters, a test has no run or no seed noise, or a run has no summary.
    """
    seeds = _seed_sd(calibration, seed_sd_deg)
    target_sds = _seed_sd(calibration, calibration.target_sd_deg if target_sd_deg is None else target_sd_deg)
    targets = dict(zip(calibration.tests, calibration.targets_deg.tolist()))
    discrepancy = float(calibration.discrepancy_sd_deg)
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
            mean, sd = (_number(value) for value in (chosen.get("predicted_deg") or {}).get(test, (None, None)))
            predictive = math.sqrt(sd ** 2 + seeds[test] ** 2)
            z = (angle - mean) / predictive if predictive > 0 else math.nan
            allowed = math.sqrt(target_sds[test] ** 2 + discrepancy ** 2 + seeds[test] ** 2)
            difference = angle - targets[test]
            in_sd = difference / allowed if allowed > 0 else math.nan
            rows.append({"set": index, "replicate": int(chosen.get("replicate", 0)),
                         **dict(zip(calibration.names, theta)), "test": test, "run_id": run,
                         "target_deg": targets[test], "target_sd_deg": target_sds[test], "seed_sd_deg": seeds[test],
                         "discrepancy_sd_deg": discrepancy, "angle_deg": angle, "angle_error_deg": error,
                         "predicted_deg": mean, "predicted_sd_deg": sd, "predictive_sd_deg": predictive, "z": z,
                         "pit": float(stats.norm.cdf(z)) if math.isfinite(z) else math.nan,
                         "allowed_sd_deg": allowed, "difference_deg": difference, "difference_in_sd": in_sd,
                         "within": bool(abs(in_sd) <= WITHIN_SD), "window_method": summary.get("window_method")})
    return rows


def predictive_verdict(rows: Sequence[Mapping]) -> dict:
    """The posterior predictive check's statistic and verdict.

    The runs' ``z`` (:func:`predictive_rows`) are standard normal if the calibrated model (the surrogates and the seed
    noise) predicts runs at posterior draws right, so ``chi2 = sum z^2`` follows a chi-square with as many degrees of
    freedom as runs. The check is ``consistent`` when neither tail probability is below :data:`PREDICTIVE_TAIL`.

    Parameters
    ----------
    rows : sequence of Mapping
        Rows of :func:`predictive_rows` (their ``z`` and ``within``).

    Returns
    -------
    dict
        ``rows`` (count), ``within`` (count within 2 allowed sd of the target), ``fraction`` (``within / rows``, -;
        None without rows), ``unknown`` (rows without an allowed uncertainty), ``chi2`` (-), ``degrees_of_freedom``
        (the rows with a finite ``z``), ``p_upper`` and ``p_lower`` (the chi-square's upper and lower tail
        probabilities, -), ``verdict`` (``"consistent"``, ``"runs scatter more than predicted"``, ``"runs scatter
        less than predicted"`` or ``"no runs with a prediction"``) and ``mean_pit`` (-).
    """
    count = len(rows)
    within = sum(1 for row in rows if row["within"])
    unknown = sum(1 for row in rows if row.get("allowed_sd_deg") is None or math.isnan(float(row["allowed_sd_deg"])))
    z = np.array([float(row["z"]) for row in rows if row.get("z") is not None and math.isfinite(float(row["z"]))])
    verdict = {"rows": count, "within": within, "fraction": within / count if count else None, "unknown": unknown,
               "chi2": None, "degrees_of_freedom": int(z.size), "p_upper": None, "p_lower": None,
               "verdict": "no runs with a prediction", "mean_pit": None}
    if z.size:
        chi2 = float(np.sum(z ** 2))
        p_upper, p_lower = float(stats.chi2.sf(chi2, z.size)), float(stats.chi2.cdf(chi2, z.size))
        verdict.update(chi2=chi2, p_upper=p_upper, p_lower=p_lower, mean_pit=float(np.mean(stats.norm.cdf(z))),
                       verdict=("runs scatter more than predicted" if p_upper < PREDICTIVE_TAIL
                                else "runs scatter less than predicted" if p_lower < PREDICTIVE_TAIL
                                else "consistent"))
    return verdict


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


def twin_verdict(calibration: Calibration, samples, log_probability, truth, truth_log_probability,
                 level: float = TWIN_LEVEL) -> dict:
    """Whether a twin experiment brought its known parameters back, and how much it learnt.

    The test: the truth's highest-posterior-density level, the posterior probability of the parameters more probable
    than the truth, estimated as the fraction of samples whose log posterior exceeds the truth's. The truth passes
    when that level is at most ``level``: it lies inside the ``level`` HPD region, whatever the posterior's shape (a
    ridge, a bound). Beside it, per parameter and along the posterior's principal axes (in units of the prior sd, where
    the prior is isotropic): the posterior sd over the prior sd (1: nothing learnt) and the truth's z-score.

    Parameters
    ----------
    calibration : siloflow.calibration.bayes.joint.Calibration
        Its parameter names and prior.
    samples : array_like, shape (n, d)
        The posterior samples (-).
    log_probability : array_like, shape (n,)
        Their log posterior.
    truth : array_like, shape (d,)
        The parameters the engine made the targets with (-).
    truth_log_probability : float
        The log posterior at the truth, on the samples' scale (-inf outside the prior).
    level : float
        The credible level of the test.

    Returns
    -------
    dict
        ``level``, ``hpd_level`` (-), ``inside_credible_region`` (bool, the verdict), ``truth`` by name, ``parameters``
        (per name: ``truth``, ``mean``, ``sd``, ``prior_sd``, ``sd_over_prior_sd``, ``z``, the equal-tailed interval
        ``lower``, ``upper`` at ``level`` and ``inside``) and ``axes`` (per principal axis, widest first:
        ``loadings`` by name, ``sd_over_prior_sd``, ``truth_z``).
    """
    names = list(calibration.names)
    values = _samples_of(samples, names)
    log_p = np.asarray(log_probability, dtype=float).reshape(-1)
    if log_p.size != len(values):
        raise ValueError(f"{log_p.size} log probabilities for {len(values)} samples")
    truth = np.asarray(truth, dtype=float).reshape(-1)
    hpd_level = float(np.mean(log_p > float(truth_log_probability)))
    mean, sd = values.mean(axis=0), values.std(axis=0, ddof=1)
    prior_sd = calibration.prior.standard_deviation
    intervals = np.atleast_2d(credible_interval(values, level))
    parameters = {name: {"truth": float(truth[i]), "mean": float(mean[i]), "sd": float(sd[i]),
                         "prior_sd": float(prior_sd[i]), "sd_over_prior_sd": float(sd[i] / prior_sd[i]),
                         "z": float((truth[i] - mean[i]) / sd[i]), "lower": float(intervals[i, 0]),
                         "upper": float(intervals[i, 1]),
                         "inside": bool(intervals[i, 0] <= truth[i] <= intervals[i, 1])}
                  for i, name in enumerate(names)}
    scaled = values / prior_sd
    covariance = np.atleast_2d(np.cov(scaled, rowvar=False))
    eigenvalues, eigenvectors = np.linalg.eigh(covariance)
    offset = (truth - mean) / prior_sd
    axes = []
    for k in np.argsort(eigenvalues)[::-1]:
        vector = eigenvectors[:, k] * (1.0 if eigenvectors[np.argmax(np.abs(eigenvectors[:, k])), k] > 0 else -1.0)
        width = math.sqrt(max(float(eigenvalues[k]), 0.0))
        axes.append({"loadings": dict(zip(names, vector.tolist())), "sd_over_prior_sd": width,
                     "truth_z": float(vector @ offset / width) if width > 0 else math.nan})
    return {"level": level, "hpd_level": hpd_level, "inside_credible_region": bool(hpd_level <= level),
            "truth": dict(zip(names, truth.tolist())), "parameters": parameters, "axes": axes}


#: The columns of :func:`twin_rows` (a report without a twin experiment writes them as its header only).
TWIN_COLUMNS = ("quantity", "truth", "posterior_mean", "posterior_sd", "sd_over_prior_sd", "truth_z", "hpd_level",
                "level", "inside")


def twin_rows(verdict: Mapping) -> list[dict]:
    """The twin experiment's table: one row per parameter, then per principal axis of the posterior, then the verdict.

    Parameters
    ----------
    verdict : mapping
        :func:`twin_verdict`'s result.

    Returns
    -------
    list of dict
        With :data:`TWIN_COLUMNS`. A parameter's row: its ``truth``, ``posterior_mean``, ``posterior_sd`` (-),
        ``sd_over_prior_sd`` (1: the runs taught nothing), the truth's ``truth_z`` and whether the truth lies in its
        equal-tailed ``level`` interval (``inside``). An axis's row (``axis k: a*name + ...``, widest first, in prior
        sd units): its ``sd_over_prior_sd`` and ``truth_z``. The last row, ``truth (all parameters)``: the truth's
        ``hpd_level`` and whether it lies inside the ``level`` HPD region, the experiment's verdict. Cells a row does
        not have are empty.
    """
    empty = dict.fromkeys(TWIN_COLUMNS, "")
    rows = [{**empty, "quantity": name, "truth": p["truth"], "posterior_mean": p["mean"], "posterior_sd": p["sd"],
             "sd_over_prior_sd": p["sd_over_prior_sd"], "truth_z": p["z"], "level": verdict["level"],
             "inside": p["inside"]} for name, p in verdict["parameters"].items()]
    for k, axis in enumerate(verdict["axes"], start=1):
        combination = " + ".join(f"{weight:.3f}*{name}" for name, weight in axis["loadings"].items())
        rows.append({**empty, "quantity": f"axis {k}: {combination}", "sd_over_prior_sd": axis["sd_over_prior_sd"],
                     "truth_z": axis["truth_z"]})
    rows.append({**empty, "quantity": "truth (all parameters)", "hpd_level": verdict["hpd_level"],
                 "level": verdict["level"], "inside": verdict["inside_credible_region"]})
    return rows
