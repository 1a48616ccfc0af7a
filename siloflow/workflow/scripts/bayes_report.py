"""Snakemake adapter: the report of the Bayesian calibration on one engine (siloflow.calibration.bayes.report): the final
posterior with its credible intervals, the posterior predictive check, the chart inversion's answer beside it, the
corner plot and the predictive check's figure."""

import json
from pathlib import Path

import numpy as np
import yaml

from siloflow.analysis.io.tables import write_flow_table, write_json, write_text
from siloflow.calibration.bayes.joint import calibration_of, twin_truth, with_targets
from siloflow.calibration.bayes.plots import plot_corner, plot_predictive
from siloflow.calibration.bayes.runs import completed_sets, failed_runs
from siloflow.calibration.bayes.report import (CHART_COMPARISON_COLUMNS, chart_comparison_rows, interval_rows,
                                      predictive_columns, predictive_rows, predictive_verdict, TWIN_COLUMNS,
                                      twin_rows, twin_verdict)
from siloflow.engines.logs import logged_to


def sets_of(paths):
    return [chosen for path in paths for chosen in json.loads(Path(path).read_text())["sets"]]


def summaries_of(paths):
    return {summary["run_id"]: summary for summary in (json.loads(Path(path).read_text()) for path in paths)}


with logged_to(snakemake.log[0]) as log:
    calibration = calibration_of(snakemake.config)
    twin = None
    if snakemake.input.targets:  # a twin experiment: the engine's own angles at the truth
        targets = json.loads(Path(snakemake.input.targets[0]).read_text())
        calibration = with_targets(calibration, targets["targets_deg"],
                                   np.column_stack([targets["angles_deg"][test] for test in calibration.tests]))
    engine = snakemake.wildcards.engine
    summary = json.loads(Path(snakemake.input.summary).read_text())
    posterior = np.load(snakemake.input.samples)
    samples = posterior["samples"]
    sets = sets_of(snakemake.input.designs)
    predictive_sets = sets_of([snakemake.input.predictive_design])

    intervals = interval_rows(summary, samples, calibration.names)
    write_flow_table(snakemake.output.intervals, intervals)
    ridge = [{key: value for key, value in row.items() if key != "predicted_deg"}
             | {f"predicted_{test}_{name}": value for test, (mean, sd) in row["predicted_deg"].items()
                for name, value in (("deg", mean), ("sd_deg", sd))}
             for row in summary["ridge"]]
    write_flow_table(snakemake.output.ridge, ridge)

    predictive_summaries = summaries_of(snakemake.input.predictive)
    predictive_failed = failed_runs(predictive_sets, predictive_summaries)
    for run in predictive_failed:
        log.warning("predictive draw %s: its %s run %s failed", run["theta"], run["test"], run["run_id"])
    predictive = predictive_rows(calibration, completed_sets(predictive_sets, predictive_summaries),
                                 predictive_summaries, summary["seed_sd_deg"], summary["target_sd_deg"])
    verdict = {**predictive_verdict(predictive), "failed_runs": predictive_failed}
    if predictive:
        write_flow_table(snakemake.output.predictive, predictive)
    else:
        write_text(snakemake.output.predictive, ",".join(predictive_columns(calibration)) + "\n")
        log.info("no predictive runs (calibration.bayesian.predictive_draws is 0): header only")
    plot_predictive(predictive, snakemake.output.predictive_plot)
    log.info("predictive check on %s: chi2 %s over %d runs (p upper %s, lower %s): %s; %d of %d runs within 2 sd of "
             "their target", engine, verdict["chi2"], verdict["degrees_of_freedom"], verdict["p_upper"],
             verdict["p_lower"], verdict["verdict"], verdict["within"], verdict["rows"])

    chart = None
    if snakemake.input.chart:
        chart_parameters = yaml.safe_load(Path(snakemake.input.chart[0]).read_text())
        comparison = chart_comparison_rows(calibration, samples, chart_parameters)
        write_flow_table(snakemake.output.comparison, comparison)
        chart = {row["parameter"]: row["chart_value"] for row in comparison}
        for row in comparison:
            log.info("%s: chart %s, posterior %.4g +- %.4g (90 %% interval %.4g-%.4g): %s", row["parameter"],
                     row["chart_value"], row["posterior_mean"], row["posterior_sd"], row["interval_lower"],
                     row["interval_upper"], row["note"])
    else:
        write_text(snakemake.output.comparison, ",".join(CHART_COMPARISON_COLUMNS) + "\n")
        log.info("the chart comparison was not asked for (calibration.bayesian.compare_with_chart): header only")
    truths = None
    if snakemake.input.targets:
        twin = twin_verdict(calibration, samples, posterior["log_probability"], twin_truth(calibration),
                            summary["truth_log_probability"])
        truths = twin["truth"]
        write_flow_table(snakemake.output.twin, twin_rows(twin))
        log.info("twin experiment on %s: the truth %s lies at the %.3f highest-posterior-density level: %s the 90 %% "
                 "region; per parameter sd/prior sd and z %s", engine, twin["truth"], twin["hpd_level"],
                 "inside" if twin["inside_credible_region"] else "outside",
                 {name: (round(p["sd_over_prior_sd"], 3), round(p["z"], 2)) for name, p in twin["parameters"].items()})
    else:
        write_text(snakemake.output.twin, ",".join(TWIN_COLUMNS) + "\n")
    plot_corner(samples, calibration.names, snakemake.output.corner, truths=truths, chart=chart)

    final_iteration = len(snakemake.input.designs) - 1
    write_json(snakemake.output.posterior, {**summary, "engine": engine, "intervals": intervals,
                                            "predictive": verdict, "final_iteration": final_iteration,
                                            "sets": len(sets), "runs": len(snakemake.input.runs),
                                            "predictive_sets": len(predictive_sets),
                                            "predictive_runs": len(snakemake.input.predictive),
                                            "targets_deg": dict(zip(calibration.tests, calibration.targets_deg.tolist())),
                                            "twin": twin})
    log.info("posterior on %s after iteration %d: %d sets, %d runs; %s", engine, final_iteration, len(sets),
             len(snakemake.input.runs), {row["parameter"]: round(row["mean"], 4) for row in intervals})
