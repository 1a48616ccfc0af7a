"""Bayesian calibration of particle-scale DEM parameters: the numerics, on arrays only.

The calibration is joint: one parameter vector ``theta`` (by default particle-particle sliding friction,
particle-particle rolling friction and particle-wall sliding friction per wall material, each a coefficient [-]
with prior bounds) is fitted to every measured bulk friction angle [deg] at once (one observable per shear test:
``internal`` and each wall material). It iterates, as GrainLearning's iterative Bayesian filter does with a
Gaussian-process surrogate and MCMC in place of its particle weights:

1. :func:`siloflow.calibration.bayes.design.space_filling_design` spreads the first runs over the prior box, each
   parameter set on a seed of its own, the first set repeated;
2. the DEM runs them (outside this package; their results come back as arrays);
3. :class:`siloflow.calibration.bayes.surrogate.Surrogate` fits each test's observable against the parameters that
   test's runs take, with each run's noise variance (the seed noise of :func:`siloflow.calibration.bayes.noise.seed_noise`,
   pooled over every group of runs at one parameter set, or the run's own window error where larger); its bounded
   hyperparameters, their bound hits and its leave-one-out residuals are reported;
4. :func:`siloflow.calibration.bayes.posterior.sample_posterior` samples the posterior on the surrogates, with the
   likelihood of :func:`siloflow.calibration.bayes.posterior.log_likelihood`: each target's standard error, an optional
   model discrepancy and the surrogate's own uncertainty, in quadrature (a twin experiment's targets, a mean of runs,
   take the seed noise over sqrt(n) with its degrees of freedom, and Student's t); the chain is run longer while it is
   under 50 autocorrelation times (:mod:`siloflow.calibration.bayes.diagnostics`);
5. :func:`siloflow.calibration.bayes.design.posterior_design` places the next runs where the posterior has mass, and
   replicates at its mode measure the seed noise where the posterior lives;
6. :func:`siloflow.calibration.bayes.stopping.should_stop` stops the loop after two iterations in a row that did not
   move the posterior (:func:`siloflow.calibration.bayes.stopping.posterior_moved`) and whose new runs the previous
   surrogates predicted within 2 sd; or when the run budget is spent.

The credible intervals assume the DEM at the true parameters reproduces the targets up to their standard errors,
unless ``calibration.bayesian.model_discrepancy_deg`` gives a model error.

Nothing here reads or writes files or runs an engine.
"""
