"""Bayesian calibration of particle-scale DEM parameters: the numerics, on arrays only.

The calibration is joint: one parameter vector ``theta`` (by default particle-particle sliding friction,
particle-particle rolling friction and particle-wall sliding friction per wall material, each a coefficient [-]
with prior bounds) is fitted to every measured bulk friction angle [deg] at once (one observable per shear test:
``internal`` and each wall material). It iterates, as GrainLearning's iterative Bayesian filter does with a
Gaussian-process surrogate and MCMC in place of its particle weights:

1. :func:`siloflow.calibration.bayes.design.space_filling_design` spreads the first runs over the prior box;
2. the DEM runs them (outside this package; their results come back as arrays);
3. :class:`siloflow.calibration.bayes.surrogate.Surrogate` fits each observable against ``theta``, with each run's noise
   (its standard error squared plus the seed noise of :func:`siloflow.calibration.bayes.noise.seed_noise`, measured from
   replicate runs at one parameter set);
4. :func:`siloflow.calibration.bayes.posterior.sample_posterior` samples the posterior on the surrogates, with the likelihood
   of :func:`siloflow.calibration.bayes.posterior.log_likelihood` (target uncertainty, seed noise and surrogate uncertainty
   in quadrature);
5. :func:`siloflow.calibration.bayes.design.posterior_design` places the next runs where the posterior has mass;
6. :func:`siloflow.calibration.bayes.stopping.posterior_moved` tells whether the posterior still moves; the loop stops when
   it does not, or when the run budget is spent.

Nothing here reads or writes files or runs an engine.
"""
