"""One joint Bayesian calibration from a validated configuration: its parameters and targets, the Jenike points of a
parameter set, and each iteration's step from the runs done to the posterior and the next parameter sets.

Pure computation on arrays and plain data; the workflow reads the runs' bulk friction and writes the designs and
posteriors (``siloflow/workflow/rules/bayesian_calibration.smk``).

The parameters (friction coefficients, -): ``sliding_friction`` and ``rolling_friction`` of the particle-particle
contacts (the rolling friction also of the particle-wall contacts, as the chart sweep sets it) and
``wall_sliding_friction.<material>`` for every wall target. Every parameter set runs one Jenike test per target: the
internal test at its particle friction, each wall test at its wall friction with its particle friction. The
observables are the bulk friction angles of those tests (deg).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Mapping, Sequence

import numpy as np

from siloflow.calibration.bayes.design import posterior_design, space_filling_design
from siloflow.calibration.bayes.diagnostics import sample_until_converged
from siloflow.calibration.bayes.noise import seed_noise
from siloflow.calibration.bayes.posterior import (PosteriorSample, Prior, log_posterior, posterior_summary,
                                         sample_posterior)
from siloflow.calibration.bayes.stopping import posterior_moved, predictive_agreement, should_stop
from siloflow.calibration.bayes.surrogate import Surrogate
from siloflow.model.cases.jenike_contacts import PARTICLE_FRICTION_KEY

__all__ = ["Calibration", "IterationResult", "PREDICTIVE_SEED_OFFSET", "TWIN_SEED_OFFSET", "TestSurrogate",
           "calibration_of", "draw_estimates", "first_design", "fit_surrogates", "iterate", "next_sets",
           "point_estimate", "points_of_set", "predictive_sets", "ridge_sets", "twin_sets", "twin_targets",
           "twin_truth", "with_targets"]

#: Every parameter set runs on a seed of its own: jenike.seed plus its index among the calibration's sets (the
#: designs' sets and the runs at the mode, under calibration.bayesian.max_sets, at most 1000); the posterior
#: predictive check's draws take fresh seeds from jenike.seed + this on ...
PREDICTIVE_SEED_OFFSET = 5000
#: ... and the twin experiment's runs at the truth from jenike.seed + this on.
TWIN_SEED_OFFSET = 10000

INTERNAL = "internal"
WALL_PARAMETER = "wall_sliding_friction"


@dataclass(frozen=True)
class Calibration:
    """What one Bayesian calibration calibrates, against what.

    Attributes
    ----------
    names : tuple of str
        The parameters, in order (``sliding_friction``, ``rolling_friction``, ``wall_sliding_friction.<material>``).
    prior : Prior
        Their prior (bounds, optional truncated Gaussians).
    tests : tuple of str
        The Jenike tests, one per target (``internal`` and wall materials), in order.
    targets_deg : ndarray
        The measured bulk friction angle of each test (deg).
    target_sd_deg : ndarray
        The standard error of each target's mean (deg), one standard deviation (``calibration.target_sd_deg``); for a
        twin experiment :func:`iterate` takes it from the seed noise instead.
    shape : str
        The particle model of the runs.
    restitution : float
        The restitution of the runs (-).
    settings : Mapping
        ``calibration.bayesian``.
    fixed : Mapping
        The parameters the user holds at a value instead of calibrating them (``calibration.bayesian.fixed``), by
        name (-); every run takes them, the posterior has no dimension for them.
    discrepancy_sd_deg : float
        The model-discrepancy standard deviation of every test (deg; ``calibration.bayesian.model_discrepancy_deg``):
        0, the intervals assume none.
    truth_angles_deg : ndarray or None
        A twin experiment's runs at the truth, shape (n, k): each run's angle per test (deg), whose mean is the
        targets; None for measured targets.
    """

    names: tuple[str, ...]
    prior: Prior
    tests: tuple[str, ...]
    targets_deg: np.ndarray
    target_sd_deg: np.ndarray
    shape: str
    restitution: float
    settings: Mapping
    fixed: Mapping = field(default_factory=dict)
    discrepancy_sd_deg: float = 0.0
    truth_angles_deg: np.ndarray | None = None

    @property
    def twin(self) -> bool:
        """Whether the targets are a twin experiment's (the engine's own angles at known parameters)."""
        return self.truth_angles_deg is not None

    def inputs_of(self, test: str) -> tuple[int, ...]:
        """The indices of the free parameters a test's runs depend on: the internal test on the particle sliding and
        rolling friction, a wall test on its wall's sliding friction and both of those (its sample is poured and
        sheared at the particle friction); a surrogate of the test is fitted on these only."""
        wanted = ["sliding_friction", "rolling_friction"]
        if test != INTERNAL:
            wanted.insert(0, f"{WALL_PARAMETER}.{test}")
        return tuple(self.names.index(name) for name in wanted if name in self.names)

    @property
    def lower(self) -> np.ndarray:
        return self.prior.lower

    @property
    def upper(self) -> np.ndarray:
        return self.prior.upper


def _setting(name: str) -> str:
    """The key of ``calibration.bayesian``'s ``priors``, ``fixed`` and ``twin.truth`` that sets parameter ``name``:
    one ``wall_sliding_friction`` serves every wall material's."""
    return WALL_PARAMETER if name.startswith(f"{WALL_PARAMETER}.") else name


def calibration_of(config: Mapping) -> Calibration:
    """The Bayesian calibration a validated configuration defines: the targets of ``calibration.targets_deg`` whose
    test is in ``jenike.sweep.tests`` (the internal one first, then the walls in the targets' order)."""
    settings = config["calibration"]["bayesian"]
    priors = settings["priors"]
    sweep_tests = config["jenike"]["sweep"]["tests"]
    targets = {test: angle for test, angle in config["calibration"]["targets_deg"].items() if test in sweep_tests}
    tests = tuple(sorted(targets, key=lambda test: test != INTERNAL))
    walls = [test for test in tests if test != INTERNAL]
    every = ("sliding_friction", "rolling_friction", *(f"{WALL_PARAMETER}.{wall}" for wall in walls))
    held = settings["fixed"]
    fixed = {name: float(held[_setting(name)]) for name in every if held[_setting(name)] is not None}
    names = tuple(name for name in every if name not in fixed)
    chosen = [priors[_setting(name)] for name in names]
    mean = np.array([np.nan if p["mean"] is None else p["mean"] for p in chosen])
    sd = np.array([np.nan if p["sd"] is None else p["sd"] for p in chosen])
    prior = Prior(np.array([p["lower"] for p in chosen], dtype=float), np.array([p["upper"] for p in chosen], dtype=float),
                  mean, sd)
    standard_errors = config["calibration"]["target_sd_deg"]
    return Calibration(names, prior, tests, np.array([targets[test] for test in tests], dtype=float),
                       np.array([standard_errors[test] for test in tests], dtype=float), config["calibration"]["shape"],
                       float(config["jenike"]["sweep"]["restitution"]), settings, fixed,
                       float(settings["model_discrepancy_deg"]))


def with_targets(calibration: Calibration, targets_deg: Mapping[str, float], truth_angles_deg=None) -> Calibration:
    """The calibration against other targets (deg) of the same tests: a twin experiment's, the mean of its runs at
    the truth, whose angles (shape (n, k), deg, one column per test) ``truth_angles_deg`` gives (their scatter is
    pooled into the seed noise, which gives the targets' standard error)."""
    missing = [test for test in calibration.tests if test not in targets_deg]
    if missing:
        raise ValueError(f"no target for the tests {missing}")
    truth = None
    if truth_angles_deg is not None:
        truth = np.atleast_2d(np.asarray(truth_angles_deg, dtype=float))
        if truth.shape[1] != len(calibration.tests) or not np.all(np.isfinite(truth)):
            raise ValueError(f"the truth's runs need one finite angle per test {list(calibration.tests)}, got shape "
                             f"{truth.shape}")
    return replace(calibration, targets_deg=np.array([targets_deg[test] for test in calibration.tests], dtype=float),
                   truth_angles_deg=truth)


def twin_truth(calibration: Calibration) -> np.ndarray:
    """The twin experiment's known parameters (``calibration.bayesian.twin.truth``), in the calibration's order."""
    truth = calibration.settings["twin"]["truth"]
    return np.array([truth[_setting(name)] for name in calibration.names], dtype=float)


def twin_sets(calibration: Calibration) -> list[dict]:
    """The twin experiment's runs at the truth: ``twin.replicates`` sets, seeds apart from the design's."""
    theta = twin_truth(calibration).tolist()
    return [{"theta": theta, "replicate": TWIN_SEED_OFFSET + k} for k in range(calibration.settings["twin"]["replicates"])]


def twin_targets(calibration: Calibration, angles_deg) -> dict:
    """The twin experiment's targets: the mean angle of the runs at the truth per test (deg), with its standard error
    from these runs alone (deg; None from one run; the calibration pools their scatter with the other replicates')
    and the runs' angles (deg).

    Parameters
    ----------
    angles_deg : array_like, shape (n, k)
        The truth runs' angles, one row per run, one column per test.
    """
    angles = np.atleast_2d(np.asarray(angles_deg, dtype=float))
    error = angles.std(axis=0, ddof=1) / np.sqrt(len(angles)) if len(angles) > 1 else [None] * len(calibration.tests)
    return {"targets_deg": dict(zip(calibration.tests, angles.mean(axis=0).tolist())),
            "standard_error_deg": dict(zip(calibration.tests, [None if e is None else float(e) for e in error])),
            "angles_deg": {test: angles[:, column].tolist() for column, test in enumerate(calibration.tests)}}


def points_of_set(calibration: Calibration, theta: Sequence[float], replicate: int = 0) -> list[dict]:
    """The Jenike points of one parameter set, one per test (:func:`siloflow.model.cases.jenike.build_jenike_case`); a
    replicate ``k`` > 0 adds k to the seed."""
    values = {**calibration.fixed, **dict(zip(calibration.names, map(float, theta)))}
    common = {"shape": calibration.shape, "rolling_friction": values["rolling_friction"],
              "restitution": calibration.restitution, "rotation_blocked": False}
    points = []
    for test in calibration.tests:
        if test == INTERNAL:
            point = {**common, "test": INTERNAL, "sliding_friction": values["sliding_friction"]}
        else:
            point = {**common, "test": test, "sliding_friction": values[f"{WALL_PARAMETER}.{test}"],
                     PARTICLE_FRICTION_KEY: values["sliding_friction"]}
        points.append({**point, **({"replicate": replicate} if replicate else {})})
    return points


def first_design(calibration: Calibration) -> list[dict]:
    """The first iteration's parameter sets: a Latin hypercube of ``initial_sets`` over the prior box, the first
    set run ``replicates`` times, whose spread is the seed noise. Every set runs on its own seed (``replicate``: its
    index, added to jenike.seed), so that no two sets share the seed's packing.

    Returns
    -------
    list of dict
        ``{"theta": [...], "replicate": k}`` per set.
    """
    settings = calibration.settings
    design = space_filling_design(calibration.lower, calibration.upper, settings["initial_sets"], settings["seed"])
    sets = [{"theta": row.tolist(), "replicate": index} for index, row in enumerate(design)]
    sets += [{"theta": design[0].tolist(), "replicate": len(design) + k - 1} for k in range(1, settings["replicates"])]
    return sets


@dataclass(frozen=True)
class IterationResult:
    """One iteration's posterior.

    Attributes
    ----------
    sample : PosteriorSample
        The posterior samples on the surrogates, with the sampler's diagnostics.
    seed_sd_deg : ndarray
        The DEM's seed noise of each test's angle (deg), pooled over every replicate group (the first design's, the
        runs at the mode, a twin's runs at the truth), and its degrees of freedom.
    seed_dof : int
    shift : float or None
        How far the posterior moved from the previous iteration's (:func:`siloflow.calibration.bayes.stopping.posterior_moved`);
        None at the first.
    moved : bool
        Whether it moved by more than ``stop_shift`` (True at the first).
    surrogates : list of TestSurrogate
        One per test.
    target_sd_deg : ndarray
        The standard error of each target the likelihood took (deg).
    target_dof : float or None
        Its degrees of freedom (a twin's, from the seed noise; the likelihood is then Student's t), None for measured
        targets (Gaussian).
    warnings : list of str
        What a reader must know of this posterior: hyperparameters at a bound, leave-one-out residuals off unit
        spread, a chain too short for its autocorrelation time, acceptance or effective sample size out of range.
    agreement : dict or None
        This iteration's new runs against the previous iteration's surrogates
        (:func:`siloflow.calibration.bayes.stopping.predictive_agreement`); None at the first.
    moved_history : tuple of bool
        ``moved`` of every iteration so far, this one last.
    stop, stop_reason : bool, str
        Whether the calibration stops after this iteration (:func:`siloflow.calibration.bayes.stopping.should_stop`) and why.
    truth_log_probability : float or None
        A twin experiment's log posterior at the truth, on the same scale as ``sample.log_probability``; None for
        measured targets.
    predicted_mean, predicted_std : ndarray, shape (n, k)
        The surrogates' mean and sd of each test's angle at every sample (deg): the posterior predictive check's
        expectation for a run at a drawn sample.
    leave_one_out : list of dict
        Each test surrogate's leave-one-out check (:meth:`siloflow.calibration.bayes.surrogate.Surrogate.loo_check`).
    """

    sample: PosteriorSample
    seed_sd_deg: np.ndarray
    seed_dof: int
    shift: float | None
    moved: bool
    surrogates: list
    target_sd_deg: np.ndarray
    target_dof: float | None
    warnings: list
    agreement: dict | None
    moved_history: tuple
    stop: bool
    stop_reason: str
    truth_log_probability: float | None
    predicted_mean: np.ndarray
    predicted_std: np.ndarray
    leave_one_out: list

    def summary(self, calibration: Calibration) -> dict:
        """Plain data: the posterior summary, the seed noise and the targets' standard errors, the surrogates' fitted
        kernels and leave-one-out checks, the sampler's diagnostics, the warnings, the shift and the stopping
        decision."""
        return {
            **posterior_summary(self.sample.samples, calibration.names).to_dict(),
            "seed_sd_deg": dict(zip(calibration.tests, self.seed_sd_deg.tolist())),
            "seed_noise_degrees_of_freedom": self.seed_dof,
            "target_sd_deg": dict(zip(calibration.tests, self.target_sd_deg.tolist())),
            "target_degrees_of_freedom": self.target_dof,
            "model_discrepancy_deg": calibration.discrepancy_sd_deg,
            "surrogates": {test: {**surrogate.surrogate.kernel_summary(), "inputs": list(surrogate.names),
                                  "leave_one_out": check}
                           for test, surrogate, check in zip(calibration.tests, self.surrogates, self.leave_one_out)},
            "acceptance_fraction": self.sample.acceptance_fraction,
            "autocorrelation_time": self.sample.autocorrelation_time.tolist(),
            "effective_sample_size": self.sample.effective_sample_size.tolist(),
            "chain_steps": self.sample.n_steps,
            "warnings": list(self.warnings),
            "shift": self.shift,
            "moved": self.moved,
            "moved_history": list(self.moved_history),
            "agreement": self.agreement,
            "stop": self.stop,
            "stop_reason": self.stop_reason,
            "truth_log_probability": self.truth_log_probability,
            "ridge": ridge_sets(calibration, self.sample.samples, self.sample.log_probability, self.surrogates),
        }


class TestSurrogate:
    """The surrogate of one test's angle on the parameters its runs depend on (:meth:`Calibration.inputs_of`); it
    predicts from the whole parameter vector, so that the posterior evaluates every test alike.

    Parameters
    ----------
    surrogate : Surrogate
        Fitted on the columns ``columns`` of the parameter vectors.
    columns : sequence of int
        The indices of its inputs in the calibration's parameters.
    names : sequence of str
        Their names.
    """

    __test__ = False  # not a pytest test class, whatever its name

    def __init__(self, surrogate: Surrogate, columns: Sequence[int], names: Sequence[str]):
        self.surrogate = surrogate
        self.columns = list(columns)
        self.names = tuple(names)

    def predict(self, theta) -> tuple[np.ndarray, np.ndarray]:
        """Mean and sd of the test's angle (deg) at parameter vectors ``theta``, shape (m, d) or (d,) (-)."""
        theta = np.asarray(theta, dtype=float)
        theta = theta[np.newaxis, :] if theta.ndim == 1 else theta
        return self.surrogate.predict(theta[:, self.columns])


def fit_surrogates(calibration: Calibration, theta, angles_deg, noise_variance) -> list[TestSurrogate]:
    """One Gaussian-process surrogate per test, each on the parameters its runs depend on.

    Parameters
    ----------
    theta : array_like, shape (n, d)
        The runs' parameter sets (-).
    angles_deg : array_like, shape (n, k)
        Each run's angle per test (deg).
    noise_variance : array_like, shape (n, k)
        Each run's noise variance per test (deg^2).
    """
    theta = np.asarray(theta, dtype=float)
    angles = np.asarray(angles_deg, dtype=float)
    noise = np.asarray(noise_variance, dtype=float)
    surrogates = []
    for column, test in enumerate(calibration.tests):
        inputs = list(calibration.inputs_of(test))
        if not inputs:
            raise ValueError(f"the {test} test depends on no free parameter: every one it takes is held fixed")
        names = [calibration.names[i] for i in inputs]
        surrogate = Surrogate(calibration.lower[inputs], calibration.upper[inputs], names=names,
                              seed=calibration.settings["seed"])
        surrogates.append(TestSurrogate(surrogate.fit(theta[:, inputs], angles[:, column], noise[:, column]), inputs,
                                        names))
    return surrogates


def ridge_sets(calibration: Calibration, samples, log_probability, surrogates, count: int = 7) -> list[dict]:
    """Parameter sets along the posterior's ridge, which reproduce the targets about equally well.

    The samples are ordered along the posterior's longest axis (the first principal component of the samples scaled
    by the prior box) and cut into ``count`` bins between its 5 % and 95 % quantiles; from each bin the sample of the
    highest posterior density is taken, with each test's angle its surrogates predict there (deg, mean and sd).

    Parameters
    ----------
    samples : array_like, shape (n, d)
        Posterior samples (-).
    log_probability : array_like, shape (n,)
        Their log posterior.
    surrogates : sequence
        One per test, ``predict(theta) -> (mean, std)`` (deg).
    count : int
        Sets to return (fewer when bins are empty).

    Returns
    -------
    list of dict
        ``{"position": p, <parameter>: value, ..., "predicted_deg": {test: [mean, sd]}}``, ``p`` the bin centre along
        the axis as a fraction of the 5-95 % span (0 to 1).
    """
    samples = np.asarray(samples, dtype=float)
    log_probability = np.asarray(log_probability, dtype=float)
    scaled = (samples - calibration.lower) / (calibration.upper - calibration.lower)
    centred = scaled - scaled.mean(axis=0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    along = centred @ axis
    low, high = np.quantile(along, [0.05, 0.95])
    edges = np.linspace(low, high, count + 1)
    chosen = []
    for index in range(count):
        inside = np.flatnonzero((along >= edges[index]) & (along <= edges[index + 1]))
        if inside.size == 0:
            continue
        best = inside[np.argmax(log_probability[inside])]
        theta = samples[best]
        predicted = {test: [float(v) for v in (mean[0], std[0])]
                     for test, (mean, std) in zip(calibration.tests,
                                                 (surrogate.predict(theta[np.newaxis, :]) for surrogate in surrogates))}
        chosen.append({"position": (index + 0.5) / count, **dict(zip(calibration.names, theta.tolist())),
                       "predicted_deg": predicted})
    return chosen


def _replicate_groups(theta: np.ndarray, angles: np.ndarray) -> list[np.ndarray]:
    """The angles of the runs at each parameter set, grouped by identical parameters."""
    _, inverse = np.unique(theta, axis=0, return_inverse=True)
    return [angles[inverse.reshape(-1) == group] for group in range(inverse.max() + 1)]


def _run_noise(errors: np.ndarray, seed_variance: np.ndarray) -> np.ndarray:
    """Each run's noise variance per test (deg^2): its scatter about the mean over seeds is the seed noise, or its own
    window's error where that is larger."""
    return np.maximum(errors ** 2, seed_variance[np.newaxis, :])


def iterate(calibration: Calibration, theta, angles_deg, angle_errors_deg, previous_samples=None, *,
            previous_count: int = 0, moved_history: Sequence[bool] = ()) -> IterationResult:
    """Fit a surrogate of each test's angle to the runs done, sample the posterior on them, compare it with the
    previous iteration's and decide whether the calibration stops.

    Parameters
    ----------
    calibration : Calibration
    theta : array_like, shape (n, d)
        The parameter set of each run set (replicates repeat a row), the previous iterations' first.
    angles_deg, angle_errors_deg : array_like, shape (n, k)
        Each run set's bulk friction angle per test and its standard error (deg).
    previous_samples : ndarray, optional
        The previous iteration's posterior samples.
    previous_count : int
        How many of the run sets the previous iterations made (the rest are this iteration's): the previous
        iteration's surrogates, fitted on those, predict the new ones (the stopping rule's agreement).
    moved_history : sequence of bool
        ``moved`` of the previous iterations, oldest first.

    Returns
    -------
    IterationResult
    """
    theta = np.asarray(theta, dtype=float)
    angles = np.asarray(angles_deg, dtype=float)
    errors = np.asarray(angle_errors_deg, dtype=float)
    groups = _replicate_groups(theta, angles)
    if calibration.twin:
        groups.append(calibration.truth_angles_deg)
    variance, dof = seed_noise(groups)
    seed_variance = np.atleast_1d(np.asarray(variance, dtype=float))
    seed_sd = np.sqrt(seed_variance)
    settings = calibration.settings
    if calibration.twin:
        # the targets are a mean of runs at the truth: their error is the seed noise over sqrt(n), known only from
        # the replicates' dof squared deviations
        target_sd, target_dof = seed_sd / np.sqrt(len(calibration.truth_angles_deg)), float(dof)
    else:
        target_sd, target_dof = np.asarray(calibration.target_sd_deg, dtype=float), None
    surrogates = fit_surrogates(calibration, theta, angles, _run_noise(errors, seed_variance))
    warnings = [f"{test} surrogate: {message}" for test, surrogate in zip(calibration.tests, surrogates)
                for message in surrogate.surrogate.warnings]
    leave_one_out = [surrogate.surrogate.loo_check() for surrogate in surrogates]
    warnings += [f"{test} surrogate: {check['message']}" for test, check in zip(calibration.tests, leave_one_out)
                 if check["message"]]
    log_probability = log_posterior(calibration.prior, surrogates, calibration.targets_deg, target_sd,
                                    calibration.discrepancy_sd_deg, target_dof)
    initial = calibration.prior.sample(settings["walkers"], settings["seed"])
    sample, problems = sample_until_converged(
        lambda steps: sample_posterior(log_probability, calibration.lower, calibration.upper, settings["walkers"],
                                       steps, settings["seed"], initial=initial),
        settings["steps"], max_steps=max(settings["steps"], settings["max_steps"]))
    warnings += [f"sampler: {problem}" for problem in problems]
    predictions = [surrogate.predict(sample.samples) for surrogate in surrogates]
    predicted_mean = np.column_stack([mean for mean, _ in predictions])
    predicted_std = np.column_stack([std for _, std in predictions])
    truth = None
    if calibration.twin:
        truth = float(log_probability(twin_truth(calibration)))
    agreement = None
    if previous_samples is None:
        moved, shift = True, None
    else:
        moved, shift = posterior_moved(previous_samples, sample.samples, settings["stop_shift"])
        moved, shift = bool(moved), float(shift)
        if 2 <= previous_count < len(theta):
            before = slice(0, previous_count)
            earlier = fit_surrogates(calibration, theta[before], angles[before],
                                     _run_noise(errors[before], seed_variance))
            new = theta[previous_count:]
            mean, std = (np.column_stack(columns) for columns in zip(*(s.predict(new) for s in earlier)))
            agreement = predictive_agreement(angles[previous_count:], mean, std, seed_sd)
    history = (*map(bool, moved_history), moved)
    stop, reason = should_stop(history, bool(agreement and agreement["within"]))
    return IterationResult(sample, seed_sd, int(dof), shift, moved, surrogates, np.asarray(target_sd, dtype=float),
                           target_dof, warnings, agreement, history, stop, reason, truth, predicted_mean,
                           predicted_std, leave_one_out)


def next_sets(calibration: Calibration, samples, log_probability, done_theta, sets_done: int,
              iteration: int) -> list[dict]:
    """The next iteration's parameter sets: ``sets_per_iteration`` where the posterior has mass, away from the runs
    done, and ``mode_replicates`` at the posterior's mode (its sample of highest density), whose spread joins the
    seed noise; within what the budget (``max_sets``, less the predictive draws) leaves. Each set on a seed of its
    own (``replicate``: its index among the calibration's sets)."""
    settings = calibration.settings
    left = settings["max_sets"] - settings["predictive_draws"] - sets_done
    at_mode = min(settings["mode_replicates"], max(left, 0))
    n = min(settings["sets_per_iteration"], left - at_mode)
    samples = np.asarray(samples, dtype=float)
    chosen = []
    if n > 0:
        chosen = [row.tolist() for row in posterior_design(samples, n, calibration.lower, calibration.upper,
                                                           settings["seed"] + iteration,
                                                           existing=np.asarray(done_theta, dtype=float))]
    mode = samples[int(np.argmax(np.asarray(log_probability, dtype=float)))].tolist()
    chosen += [mode] * at_mode
    return [{"theta": theta, "replicate": sets_done + index} for index, theta in enumerate(chosen)]


def predictive_sets(calibration: Calibration, samples, predicted_mean=None, predicted_std=None) -> list[dict]:
    """``predictive_draws`` parameter sets drawn from the posterior samples (without replacement), each on a fresh
    seed, for the posterior predictive check; with the surrogates' mean and sd of each test's angle at the draw
    (``predicted_deg``: ``{test: [mean, sd]}``, deg) where they are given (shape (n, k), one row per sample)."""
    samples = np.asarray(samples, dtype=float)
    rng = np.random.default_rng(calibration.settings["seed"] + 1000)
    count = min(calibration.settings["predictive_draws"], len(samples))
    rows = rng.choice(len(samples), size=count, replace=False)
    sets = []
    for index, row in enumerate(rows):
        chosen = {"theta": samples[row].tolist(), "replicate": PREDICTIVE_SEED_OFFSET + index}
        if predicted_mean is not None:
            chosen["predicted_deg"] = {test: [float(predicted_mean[row, column]), float(predicted_std[row, column])]
                                       for column, test in enumerate(calibration.tests)}
        sets.append(chosen)
    return sets


def point_estimate(calibration: Calibration, summary: Mapping, engine: str) -> dict:
    """The posterior mean as the parameters a silo takes (``silo_flat.parameters: bayesian``), in the layout of the
    chart inversion's ``parameters.yaml`` (:func:`siloflow.calibration.parameters.apply_calibrated_parameters`), each value
    with its posterior sd as ``<key>_error``.

    Parameters
    ----------
    summary : Mapping
        The final posterior's summary (``posterior.json``: ``parameters.<name>.mean`` and ``.sd``).
    engine : str
        The engine the posterior is of.
    """
    return _silo_parameters(calibration, summary["parameters"],
                            f"the joint Bayesian calibration's posterior mean on {engine}")


def draw_estimates(calibration: Calibration, sets: Sequence[Mapping], engine: str) -> list[dict]:
    """The posterior draws of the predictive check (``predictive/design.json``'s sets) as parameters a silo takes, in
    the layout of :func:`point_estimate`, so that silo runs at them (``silo_flat.posterior_draws``) give the flow
    rate and the stresses an error bar from the calibration. A draw is one value: every ``<key>_error`` is 0.

    Parameters
    ----------
    sets : sequence of Mapping
        The drawn sets, each with ``theta`` in the calibration's parameter order (-).
    engine : str
        The engine the posterior is of.
    """
    return [_silo_parameters(calibration, {name: {"mean": value, "sd": 0.0}
                                           for name, value in zip(calibration.names, chosen["theta"], strict=True)},
                             f"posterior draw {number} of the joint Bayesian calibration on {engine}")
            for number, chosen in enumerate(sets)]


def _silo_parameters(calibration: Calibration, parameters: Mapping, source: str) -> dict:
    """``parameters`` (``{name: {"mean", "sd"}}`` of the free parameters) with the fixed ones, in the layout of the
    chart inversion's ``parameters.yaml``."""
    # a parameter held fixed has its value and no spread
    values = {**{name: {"mean": value, "sd": 0.0} for name, value in calibration.fixed.items()}, **parameters}

    def estimate(name: str) -> dict:
        return {"sliding_friction": float(values[name]["mean"]), "sliding_friction_error": float(values[name]["sd"])}

    walls = [name.split(".", 1)[1] for name in values if name.startswith(f"{WALL_PARAMETER}.")]
    return {
        "source": source,
        "shape": calibration.shape,
        "rolling_friction": float(values["rolling_friction"]["mean"]),
        "rolling_friction_error": float(values["rolling_friction"]["sd"]),
        "particle_particle": estimate("sliding_friction"),
        "particle_wall": {wall: estimate(f"{WALL_PARAMETER}.{wall}") for wall in walls},
    }
