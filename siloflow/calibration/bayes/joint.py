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
from siloflow.calibration.bayes.noise import seed_noise
from siloflow.calibration.bayes.posterior import (PosteriorSample, Prior, log_posterior, posterior_summary,
                                         sample_posterior)
from siloflow.calibration.bayes.stopping import posterior_moved
from siloflow.calibration.bayes.surrogate import Surrogate
from siloflow.model.cases.jenike import PARTICLE_FRICTION_KEY

__all__ = ["Calibration", "IterationResult", "TWIN_SEED_OFFSET", "calibration_of", "draw_estimates", "first_design",
           "iterate", "next_sets", "point_estimate", "points_of_set", "predictive_sets", "ridge_sets", "twin_sets",
           "twin_targets", "twin_truth", "with_targets"]

#: The twin experiment's runs at the truth take seeds from jenike.seed + this on, apart from the design's replicates.
TWIN_SEED_OFFSET = 100

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
    target_sd_deg : float
        Their uncertainty (deg), one standard deviation.
    shape : str
        The particle model of the runs.
    restitution : float
        The restitution of the runs (-).
    settings : Mapping
        ``calibration.bayesian``.
    fixed : Mapping
        The parameters the user holds at a value instead of calibrating them (``calibration.bayesian.fixed``), by
        name (-); every run takes them, the posterior has no dimension for them.
    """

    names: tuple[str, ...]
    prior: Prior
    tests: tuple[str, ...]
    targets_deg: np.ndarray
    target_sd_deg: float
    shape: str
    restitution: float
    settings: Mapping
    fixed: Mapping = field(default_factory=dict)

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
    return Calibration(names, prior, tests, np.array([targets[test] for test in tests], dtype=float),
                       float(config["calibration"]["tolerance_deg"]), config["calibration"]["shape"],
                       float(config["jenike"]["sweep"]["restitution"]), settings, fixed)


def with_targets(calibration: Calibration, targets_deg: Mapping[str, float]) -> Calibration:
    """The calibration against other targets (deg) of the same tests (a twin experiment's)."""
    missing = [test for test in calibration.tests if test not in targets_deg]
    if missing:
        raise ValueError(f"no target for the tests {missing}")
    return replace(calibration, targets_deg=np.array([targets_deg[test] for test in calibration.tests], dtype=float))


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
    (deg; None from one run).

    Parameters
    ----------
    angles_deg : array_like, shape (n, k)
        The truth runs' angles, one row per run, one column per test.
    """
    angles = np.atleast_2d(np.asarray(angles_deg, dtype=float))
    error = angles.std(axis=0, ddof=1) / np.sqrt(len(angles)) if len(angles) > 1 else [None] * len(calibration.tests)
    return {"targets_deg": dict(zip(calibration.tests, angles.mean(axis=0).tolist())),
            "standard_error_deg": dict(zip(calibration.tests, [None if e is None else float(e) for e in error]))}


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
    set run ``replicates`` times (seeds + 0, 1, ...), whose spread is the seed noise.

    Returns
    -------
    list of dict
        ``{"theta": [...], "replicate": k}`` per set.
    """
    settings = calibration.settings
    design = space_filling_design(calibration.lower, calibration.upper, settings["initial_sets"], settings["seed"])
    sets = [{"theta": row.tolist(), "replicate": 0} for row in design]
    sets += [{"theta": design[0].tolist(), "replicate": k} for k in range(1, settings["replicates"])]
    return sets


@dataclass(frozen=True)
class IterationResult:
    """One iteration's posterior.

    Attributes
    ----------
    sample : PosteriorSample
        The posterior samples on the surrogates, with the sampler's diagnostics.
    seed_sd_deg : ndarray
        The DEM's seed noise of each test's angle (deg), from the replicates, and its degrees of freedom.
    seed_dof : int
    shift : float or None
        How far the posterior moved from the previous iteration's (:func:`siloflow.calibration.bayes.stopping.posterior_moved`);
        None at the first.
    moved : bool
        Whether it moved by more than ``stop_shift`` (True at the first).
    surrogates : list of Surrogate
        One per test.
    """

    sample: PosteriorSample
    seed_sd_deg: np.ndarray
    seed_dof: int
    shift: float | None
    moved: bool
    surrogates: list

    def summary(self, calibration: Calibration) -> dict:
        """Plain data: the posterior summary, the seed noise, the sampler's diagnostics, the shift."""
        return {
            **posterior_summary(self.sample.samples, calibration.names).to_dict(),
            "seed_sd_deg": dict(zip(calibration.tests, self.seed_sd_deg.tolist())),
            "seed_noise_degrees_of_freedom": self.seed_dof,
            "acceptance_fraction": self.sample.acceptance_fraction,
            "autocorrelation_time": self.sample.autocorrelation_time.tolist(),
            "effective_sample_size": self.sample.effective_sample_size.tolist(),
            "shift": self.shift,
            "moved": self.moved,
            "ridge": ridge_sets(calibration, self.sample.samples, self.sample.log_probability, self.surrogates),
        }


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


def iterate(calibration: Calibration, theta, angles_deg, angle_errors_deg, previous_samples=None) -> IterationResult:
    """Fit a surrogate of each test's angle to the runs done, sample the posterior on them and compare it with the
    previous iteration's.

    Parameters
    ----------
    calibration : Calibration
    theta : array_like, shape (n, d)
        The parameter set of each run set (replicates repeat a row).
    angles_deg, angle_errors_deg : array_like, shape (n, k)
        Each run set's bulk friction angle per test and its standard error (deg).
    previous_samples : ndarray, optional
        The previous iteration's posterior samples.

    Returns
    -------
    IterationResult
    """
    theta = np.asarray(theta, dtype=float)
    angles = np.asarray(angles_deg, dtype=float)
    errors = np.asarray(angle_errors_deg, dtype=float)
    variance, dof = seed_noise(_replicate_groups(theta, angles))
    seed_variance = np.atleast_1d(np.asarray(variance, dtype=float))
    settings = calibration.settings
    surrogates = []
    for column in range(len(calibration.tests)):
        # a run's scatter about the mean over seeds is the seed noise, or its own window's error where that is larger
        noise = np.maximum(errors[:, column] ** 2, seed_variance[column])
        surrogates.append(Surrogate(calibration.lower, calibration.upper, seed=settings["seed"]).fit(
            theta, angles[:, column], noise))
    seed_sd = np.sqrt(seed_variance)
    log_probability = log_posterior(calibration.prior, surrogates, calibration.targets_deg,
                                    np.full(len(calibration.tests), calibration.target_sd_deg), seed_sd)
    sample = sample_posterior(log_probability, calibration.lower, calibration.upper, settings["walkers"],
                              settings["steps"], settings["seed"],
                              initial=calibration.prior.sample(settings["walkers"], settings["seed"]))
    if previous_samples is None:
        return IterationResult(sample, seed_sd, int(dof), None, True, surrogates)
    moved, shift = posterior_moved(previous_samples, sample.samples, settings["stop_shift"])
    return IterationResult(sample, seed_sd, int(dof), float(shift), bool(moved), surrogates)


def next_sets(calibration: Calibration, samples, done_theta, sets_done: int, iteration: int) -> list[dict]:
    """The next iteration's parameter sets: ``sets_per_iteration`` where the posterior has mass, away from the runs
    done, within what the budget (``max_sets``, less the predictive draws) leaves."""
    settings = calibration.settings
    left = settings["max_sets"] - settings["predictive_draws"] - sets_done
    n = min(settings["sets_per_iteration"], left)
    if n <= 0:
        return []
    chosen = posterior_design(samples, n, calibration.lower, calibration.upper, settings["seed"] + iteration,
                              existing=np.asarray(done_theta, dtype=float))
    return [{"theta": row.tolist(), "replicate": 0} for row in chosen]


def predictive_sets(calibration: Calibration, samples) -> list[dict]:
    """``predictive_draws`` parameter sets drawn from the posterior samples (without replacement), for the
    posterior predictive check."""
    samples = np.asarray(samples, dtype=float)
    rng = np.random.default_rng(calibration.settings["seed"] + 1000)
    count = min(calibration.settings["predictive_draws"], len(samples))
    rows = rng.choice(len(samples), size=count, replace=False)
    return [{"theta": samples[row].tolist(), "replicate": 0} for row in rows]


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
