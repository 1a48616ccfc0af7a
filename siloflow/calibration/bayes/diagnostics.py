"""Whether an MCMC chain can be trusted: its length in autocorrelation times, its acceptance fraction and its
effective sample size, and a chain lengthened until it is long enough.

:func:`siloflow.calibration.bayes.posterior.sample_posterior` records these diagnostics; this module checks them.
A chain that is too short has an underestimated autocorrelation time (emcee's estimate is then a lower bound), so its
effective sample size is overstated too and the posterior's quantiles are noisier than they look. The remedy is more
steps, which :func:`sample_until_converged` takes; an acceptance fraction out of range or too few effective samples
with a long enough chain point to the sampler's set-up (walkers, moves, starting positions) and are only reported.

The checks are duck-typed: any object with the attributes of
:class:`siloflow.calibration.bayes.posterior.PosteriorSample` (``n_walkers``, ``n_steps``, ``burn``,
``acceptance_fraction``, ``autocorrelation_time``, ``effective_sample_size``) will do. Nothing here reads or writes
files.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

__all__ = ["MIN_CHAIN_IN_TAU", "ACCEPTANCE_RANGE", "MIN_ESS", "chain_problems", "sample_until_converged"]

#: emcee's documentation recommends a chain of at least 50 autocorrelation times for a reliable estimate of tau.
MIN_CHAIN_IN_TAU = 50
#: The stretch move's healthy acceptance is about 0.2-0.5; outside 0.15-0.7 the ensemble is stuck or too timid.
ACCEPTANCE_RANGE = (0.15, 0.7)
#: 1000 effective samples give a 5 or 95 % quantile to about +-0.01 in probability (sqrt(0.05 * 0.95 / 1000)).
MIN_ESS = 1000

# the kinds of problem _checks tells apart; only a short chain is cured by more steps
_SHORT = "short"
_ACCEPTANCE = "acceptance"
_ESS = "ess"
_TAU = "tau"


def _checks(sample) -> list[tuple[str, str]]:
    """The failed checks of a chain as ``(kind, sentence)`` pairs, in the order of :func:`chain_problems`."""
    tau = np.atleast_1d(np.asarray(sample.autocorrelation_time, dtype=float))
    finite = np.isfinite(tau)
    length = int(sample.n_steps) - int(sample.burn)
    problems = []
    if finite.any():
        # the longest finite tau sets the length needed; a non-finite one is reported on its own below
        longest = int(np.argmax(np.where(finite, tau, -np.inf)))
        needed = MIN_CHAIN_IN_TAU * tau[longest]
        if length < needed:
            problems.append((_SHORT, (
                f"the post-burn-in chain has {length} steps, fewer than {MIN_CHAIN_IN_TAU} autocorrelation times of "
                f"parameter {longest} (tau = {tau[longest]:.3g} steps, so {math.ceil(needed)} steps are needed): "
                f"tau is underestimated and the effective sample size overstated")))
    acceptance = float(sample.acceptance_fraction)
    low, high = ACCEPTANCE_RANGE
    if not low <= acceptance <= high:
        if acceptance < low:
            cause = "the walkers are stuck"
        elif acceptance > high:
            cause = "the proposals are too timid to explore the posterior"
        else:
            cause = "it is not a number"
        problems.append((_ACCEPTANCE, (
            f"the acceptance fraction {acceptance:.3g} lies outside {low}-{high}: {cause}")))
    if finite.any():
        ess = np.atleast_1d(np.asarray(sample.effective_sample_size, dtype=float))
        smallest = int(np.argmin(np.where(finite, ess, np.inf)))
        if ess[smallest] < MIN_ESS:
            problems.append((_ESS, (
                f"the effective sample size of parameter {smallest} is {ess[smallest]:.0f}, under {MIN_ESS}: its "
                f"5 and 95 % quantiles are uncertain by more than about 0.01 in probability")))
    if not finite.all():
        indices = ", ".join(str(i) for i in np.flatnonzero(~finite))
        problems.append((_TAU, (
            f"the autocorrelation time of parameter(s) {indices} is not finite: the walkers did not move in it, "
            f"or the chain is too short to estimate it")))
    return problems


def chain_problems(sample) -> list[str]:
    """The failed checks of an MCMC chain, as plain sentences.

    The checks, in this order:

    * the post-burn-in chain, ``n_steps - burn`` steps, is at least :data:`MIN_CHAIN_IN_TAU` times the longest
      finite autocorrelation time (the sentence names that parameter's index, its tau and the steps needed);
    * the acceptance fraction lies within :data:`ACCEPTANCE_RANGE`;
    * the smallest effective sample size, over the parameters with a finite tau, is at least :data:`MIN_ESS`;
    * every autocorrelation time is finite.

    Parameters
    ----------
    sample : PosteriorSample-like
        An object with ``n_walkers``, ``n_steps`` and ``burn`` (int; steps per walker, burn-in included, and the
        steps discarded), ``acceptance_fraction`` (float, the mean over the walkers, dimensionless),
        ``autocorrelation_time`` (array, shape (d,), steps) and ``effective_sample_size`` (array, shape (d,),
        independent samples), as :class:`siloflow.calibration.bayes.posterior.PosteriorSample` has.

    Returns
    -------
    list of str
        One sentence per failed check; empty when the chain is healthy.
    """
    return [sentence for _, sentence in _checks(sample)]


def sample_until_converged(sample_once: Callable, n_steps: int, *, max_steps: int,
                           growth: float = 2) -> tuple[object, list[str]]:
    """Sample a chain, lengthening it while it is shorter than :data:`MIN_CHAIN_IN_TAU` autocorrelation times.

    Only a short chain is cured by more steps: an acceptance fraction out of range, too few effective samples or a
    non-finite tau on their own do not lengthen it (they call for other walkers, moves or starting positions).
    Each attempt is a new chain of the given length, not a continuation, so ``sample_once`` needs no state.

    Parameters
    ----------
    sample_once : callable
        ``sample_once(steps)`` returns a PosteriorSample-like object (see :func:`chain_problems`) of ``steps`` steps
        per walker, burn-in included; e.g.
        ``lambda steps: sample_posterior(log_probability, lower, upper, n_walkers, steps, seed)``.
    n_steps : int
        Steps per walker of the first chain.
    max_steps : int
        Most steps per walker of any chain, at least ``n_steps``.
    growth : float
        Factor by which each new chain is longer than the one before (above 1); the last one is cut to
        ``max_steps``.

    Returns
    -------
    sample : PosteriorSample-like
        The last chain sampled.
    problems : list of str
        :func:`chain_problems` of that chain. When the chain was lengthened, each sentence begins
        ``"after extending the chain to N steps: "`` (``"... N steps, the most allowed: "`` once at ``max_steps``),
        so that a reader knows how long a chain they describe.
    """
    steps, max_steps = int(n_steps), int(max_steps)
    if steps < 1:
        raise ValueError(f"n_steps must be positive, got {n_steps}")
    if max_steps < steps:
        raise ValueError(f"max_steps must be at least n_steps = {steps}, got {max_steps}")
    if not growth > 1:
        raise ValueError(f"growth must exceed 1, got {growth}")
    sample = sample_once(steps)
    checks = _checks(sample)
    extended = False
    while steps < max_steps and any(kind == _SHORT for kind, _ in checks):
        # at least one more step, so that a growth barely above 1 still ends
        steps = min(max_steps, max(steps + 1, math.ceil(growth * steps)))
        sample = sample_once(steps)
        checks = _checks(sample)
        extended = True
    problems = [sentence for _, sentence in checks]
    if not extended:
        return sample, problems
    limit = ", the most allowed" if steps == max_steps else ""
    return sample, [f"after extending the chain to {steps} steps{limit}: {sentence}" for sentence in problems]
