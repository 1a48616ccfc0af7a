"""Unit tests for siloflow.calibration.bayes.diagnostics: a deliberately short emcee chain is caught and lengthened,
and each check fires, with its numbers, on synthetic chains."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from siloflow.calibration.bayes.diagnostics import (
    ACCEPTANCE_RANGE,
    MIN_CHAIN_IN_TAU,
    MIN_ESS,
    chain_problems,
    sample_until_converged,
)
from siloflow.calibration.bayes.posterior import sample_posterior

_MEAN, _SD = np.array([0.5, 0.5]), np.array([0.1, 0.05])
_SHORT = "post-burn-in chain"


@pytest.fixture(autouse=True, scope="module")
def _one_thread():
    # these small matrices gain nothing from BLAS threads, which only contend with a simulation's cores
    with threadpool_limits(limits=1):
        yield


def _gaussian(theta):
    """Log density of an uncorrelated 2-d Gaussian inside the unit box, up to a constant (vectorised)."""
    return -0.5 * np.sum(((np.asarray(theta) - _MEAN) / _SD) ** 2, axis=-1)


def _chain(n_steps, tau, acceptance=0.4, n_walkers=32, burn=None):
    """A PosteriorSample-like object with the given diagnostics (``burn`` defaults to half the steps)."""
    burn = n_steps // 2 if burn is None else burn
    tau = np.asarray(tau, dtype=float)
    return SimpleNamespace(n_walkers=n_walkers, n_steps=n_steps, burn=burn, acceptance_fraction=acceptance,
                           autocorrelation_time=tau, effective_sample_size=n_walkers * (n_steps - burn) / tau)


def test_the_thresholds_are_the_documented_ones():
    assert (MIN_CHAIN_IN_TAU, ACCEPTANCE_RANGE, MIN_ESS) == (50, (0.15, 0.7), 1000)


# --- Real chains -----------------------------------------------------------------------------------------------------

def test_a_deliberately_short_chain_is_reported_too_short():
    sample = sample_posterior(_gaussian, [0.0, 0.0], [1.0, 1.0], n_walkers=8, n_steps=40, seed=0)
    problems = chain_problems(sample)
    short = [p for p in problems if _SHORT in p]
    assert len(short) == 1
    longest = int(np.argmax(sample.autocorrelation_time))
    assert short[0].startswith(f"the post-burn-in chain has 20 steps, fewer than 50 autocorrelation times of "
                               f"parameter {longest} ")


def test_a_short_chain_is_lengthened_until_it_spans_fifty_autocorrelation_times():
    calls = []

    def sample_once(steps):
        calls.append(steps)
        return sample_posterior(_gaussian, [0.0, 0.0], [1.0, 1.0], n_walkers=8, n_steps=steps, seed=0)

    sample, problems = sample_until_converged(sample_once, 40, max_steps=20000)
    # the chain doubled from 40 steps until it was long enough, well before the limit
    assert len(calls) > 1 and sample.n_steps == calls[-1] > 40
    assert calls == [40 * 2**i for i in range(len(calls))] and calls[-1] < 20000
    assert sample.n_steps - sample.burn >= MIN_CHAIN_IN_TAU * sample.autocorrelation_time.max()
    assert not any(_SHORT in p for p in problems)
    # what remains (acceptance, effective sample size of 8 walkers) says how long the chain was made
    assert all(p.startswith(f"after extending the chain to {sample.n_steps} steps: ") for p in problems)


# --- Each check on synthetic chains ----------------------------------------------------------------------------------

def test_a_healthy_chain_has_no_problems():
    # 1000 post-burn-in steps = 66.7 tau; acceptance 0.4; ESS 32 * 1000 / 15 = 2133
    assert chain_problems(_chain(2000, [10.0, 15.0])) == []
    # exactly 50 tau and exactly 1000 effective samples still pass
    assert chain_problems(_chain(2000, [20.0, 20.0], n_walkers=20)) == []


def test_a_short_chain_names_the_parameter_with_the_longest_tau_and_the_steps_needed():
    # 500 post-burn-in steps, tau = 12.5 of parameter 1: 625 needed; ESS = 64 * 500 / 12.5 = 2560
    problems = chain_problems(_chain(1000, [5.0, 12.5, 8.0], n_walkers=64))
    assert problems == ["the post-burn-in chain has 500 steps, fewer than 50 autocorrelation times of parameter 1 "
                        "(tau = 12.5 steps, so 625 steps are needed): tau is underestimated and the effective sample "
                        "size overstated"]


def test_an_acceptance_fraction_out_of_range_is_reported():
    assert chain_problems(_chain(2000, [10.0], acceptance=0.05)) == [
        "the acceptance fraction 0.05 lies outside 0.15-0.7: the walkers are stuck"]
    assert chain_problems(_chain(2000, [10.0], acceptance=0.85)) == [
        "the acceptance fraction 0.85 lies outside 0.15-0.7: the proposals are too timid to explore the posterior"]
    assert chain_problems(_chain(2000, [10.0], acceptance=0.15)) == []


def test_too_few_effective_samples_are_reported():
    # 8 walkers x 1000 steps / tau 10 = 800 for parameter 0; parameter 1 has 8000 / 4 = 2000
    assert chain_problems(_chain(2000, [10.0, 4.0], n_walkers=8)) == [
        "the effective sample size of parameter 0 is 800, under 1000: its 5 and 95 % quantiles are uncertain by "
        "more than about 0.01 in probability"]


def test_a_non_finite_autocorrelation_time_is_reported():
    problems = chain_problems(_chain(2000, [10.0, np.nan, np.inf]))
    assert problems == ["the autocorrelation time of parameter(s) 1, 2 is not finite: the walkers did not move in "
                        "it, or the chain is too short to estimate it"]


# --- Lengthening -----------------------------------------------------------------------------------------------------

def _recorded(tau: float):
    """A sampler of chains of autocorrelation time ``tau`` (100 walkers) and the step counts it was asked for."""
    calls = []

    def sample_once(steps):
        calls.append(steps)
        return _chain(steps, [tau], n_walkers=100)

    return calls, sample_once


def test_lengthening_stops_at_max_steps_and_reports_what_remains():
    calls, sample_once = _recorded(100.0)   # needs 5000 post-burn-in steps, 10000 in all
    sample, problems = sample_until_converged(sample_once, 40, max_steps=1000)
    assert calls == [40, 80, 160, 320, 640, 1000]
    assert sample.n_steps == 1000
    # ESS = 100 * 500 / 100 = 500 is under 1000 too
    assert problems == [
        "after extending the chain to 1000 steps, the most allowed: the post-burn-in chain has 500 steps, fewer "
        "than 50 autocorrelation times of parameter 0 (tau = 100 steps, so 5000 steps are needed): tau is "
        "underestimated and the effective sample size overstated",
        "after extending the chain to 1000 steps, the most allowed: the effective sample size of parameter 0 is "
        "500, under 1000: its 5 and 95 % quantiles are uncertain by more than about 0.01 in probability"]


def test_lengthening_stops_as_soon_as_the_chain_is_long_enough():
    calls, sample_once = _recorded(10.0)   # needs 500 post-burn-in steps, 1000 in all
    sample, problems = sample_until_converged(sample_once, 100, max_steps=100000, growth=3)
    assert calls == [100, 300, 900, 2700] and sample.n_steps == 2700 and problems == []


def test_acceptance_or_effective_sample_size_alone_do_not_lengthen_the_chain():
    calls = []

    def sample_once(steps):
        calls.append(steps)
        # 1000 post-burn-in steps = 100 tau; acceptance 0.05; ESS 8 * 1000 / 10 = 800
        return _chain(steps, [10.0], acceptance=0.05, n_walkers=8)

    sample, problems = sample_until_converged(sample_once, 2000, max_steps=100000)
    assert calls == [2000] and sample.n_steps == 2000
    # not lengthened, so no prefix
    assert problems == chain_problems(sample) and len(problems) == 2
    assert problems[0].startswith("the acceptance fraction 0.05") and problems[1].startswith(
        "the effective sample size of parameter 0 is 800")


def test_a_non_finite_tau_alone_does_not_lengthen_the_chain():
    calls = []

    def sample_once(steps):
        calls.append(steps)
        return _chain(steps, [np.nan])

    _, problems = sample_until_converged(sample_once, 2000, max_steps=100000)
    assert calls == [2000] and len(problems) == 1 and "not finite" in problems[0]


def test_lengthening_refuses_bad_settings():
    with pytest.raises(ValueError, match="max_steps"):
        sample_until_converged(lambda steps: _chain(steps, [1.0]), 100, max_steps=50)
    with pytest.raises(ValueError, match="growth"):
        sample_until_converged(lambda steps: _chain(steps, [1.0]), 100, max_steps=500, growth=1.0)
    with pytest.raises(ValueError, match="n_steps"):
        sample_until_converged(lambda steps: _chain(steps, [1.0]), 0, max_steps=500)
