"""A Gaussian-process surrogate of one observable (a bulk friction angle [deg]) against the parameters.

The DEM gives an observable at a handful of parameter vectors, each with its own noise; the posterior needs it
everywhere in the prior box, with an honest uncertainty where there are no runs. A Gaussian process regression
(:class:`sklearn.gaussian_process.GaussianProcessRegressor`) gives both: a mean and a standard deviation of the
noise-free observable at any parameter vector.

Choices, and why:

* inputs are normalised to [0, 1] by the prior box, so that the length-scale bounds mean the same for every
  parameter (a fraction of its prior range);
* the kernel is a constant times an anisotropic (ARD: one length scale per parameter) Matern (``nu=2.5``, twice
  differentiable, less smooth than an RBF and so less overconfident between runs) or RBF kernel, because bulk
  friction varies strongly with sliding friction and hardly with rolling friction;
* each run's noise variance is given, not fitted: its standard error squared (batch means of its steady window)
  plus the seed noise measured from replicates (:func:`siloflow.calibration.bayes.noise.seed_noise`). With few runs a fitted
  noise level is poorly determined and trades off against the length scales;
* ``normalize_y=True`` centres and scales the observable, so that the constant kernel's bounds suit any units.
  scikit-learn adds ``alpha`` to the kernel matrix of the *normalised* observable, so the given variances are divided
  by the observable's variance before they are passed as ``alpha``;
* the optimiser restarts from seeded random hyperparameters, so a fit is deterministic for a seed;
* the hyperparameters are point estimates from 10 to 20 runs, so the fit is recorded rather than trusted: the fitted
  kernel (:meth:`Surrogate.kernel_summary`), every hyperparameter at a bound and every convergence warning of the
  optimiser (:attr:`Surrogate.warnings`), and the leave-one-out residuals of the runs
  (:meth:`Surrogate.loo_residuals`, :meth:`Surrogate.loo_check`).
"""

from __future__ import annotations

import warnings
from typing import Sequence

import numpy as np
from scipy.linalg import cho_factor, cho_solve
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, Matern

from siloflow.calibration.bayes.box import as_box, as_points, to_unit

__all__ = ["Surrogate"]

_KERNELS = ("matern", "rbf")

# The smallest noise variance passed to the GP (in normalised units): keeps the kernel matrix positive definite
# when the given noise is zero, without changing a fit whose noise is not.
_JITTER = 1e-10

# Bounds of the constant (the signal variance, in units of the observable's variance across the runs): from a
# hundredth (the runs' spread is mostly their noise) to 1e4 (a signal sd a hundred times the runs' spread: room for a
# long length scale to carry a trend).
_CONSTANT_BOUNDS = (1e-2, 1e4)

# A hyperparameter is reported at a bound when |log(value / bound)| is below this: within about 1 % of it.
_AT_BOUND = 0.01


class Surrogate:
    """Gaussian-process surrogate of one observable against the parameters, on the prior box.

    The hyperparameters (one length scale per parameter, one constant) are maximum-likelihood point estimates from
    a few runs, so they are bounded, and every estimate at a bound is reported in :attr:`warnings`:

    * a length scale is at most 5 box widths by default. Over one box width a Matern-5/2 with ``l = 5`` correlates
      the two ends by 0.968 (an RBF by 0.980): its draws are already close to straight lines across the box, so a
      longer length scale adds no shape the runs could resolve, it only changes what a trend costs. And a trend is
      what maximising the marginal likelihood of 10 to 20 runs gives up first: the slope a stationary kernel allows
      a parameter has a standard deviation of ``sqrt(constant * 5 / 3) / l`` runs' sds per box width (Matern-5/2;
      ``sqrt(constant) / l`` for the RBF), so a weak but real dependence, comparable to the runs' noise, is
      cheapest as none: its length scale runs off to a long bound (such as 1000) and its trend is shrunk
      towards flat, and with it the posterior's ridge along that parameter. (On 15 runs in a 3-d box with noise
      sd 0.1 and trends of 20 and 0.1 across it, over eight noise draws the trend of 0.1 came out as 0.07 on
      average with the bound 1000, as 0.13 with a scatter of 0.10 with the bound 5.) At 5 the slope stays free,
      carried by the mean, so a length scale at that bound says that the observable depends on the parameter at
      most about linearly over the box; it does not tell a weak trend from none (the mean does). The price: a
      strong, nearly linear dependence, fitted most closely by very long length scales and a large constant, is
      interpolated less closely and extrapolated into the box's corners with a wider (still honest) uncertainty;
    * a length scale is at least 0.05 box widths: a range resolved by about twenty runs, more than a calibration
      will have;
    * the constant lies in [1e-2, 1e4], in units of the observable's variance across the runs.

    A length scale at its upper bound is the expected report of a parameter the observable depends on at most
    about linearly over the box (or whose effect the runs cannot resolve); at its lower bound it says the runs do
    not resolve the variation (or their noise is underestimated). Either way the fit is recorded, not hidden: see
    :meth:`kernel_summary`, :meth:`loo_residuals` and :meth:`loo_check`.

    Parameters
    ----------
    lower, upper : array_like, shape (d,)
        Prior bounds of the parameters (friction coefficients [-]); inputs are normalised by them.
    kernel : {"matern", "rbf"}
        Shape of the correlation: Matern with ``nu`` or squared exponential, each with one length scale per
        parameter, times a constant.
    nu : float
        Smoothness of the Matern kernel (1.5 or 2.5 are the usual choices).
    length_scale_bounds : (float, float)
        Bounds of each length scale, as fractions of the parameter's prior range (box units): ``(0.05, 5.0)`` by
        default, for the reasons above.
    n_restarts : int
        Restarts of the hyperparameter optimiser from random starts, drawn with ``seed``.
    seed : int
        Seed of the restarts.
    names : sequence of str, optional
        Names of the parameters, in order, for :attr:`warnings` and :meth:`kernel_summary`; without them a
        parameter is called by its index (from 0).

    Attributes
    ----------
    gp : sklearn.gaussian_process.GaussianProcessRegressor or None
        The fitted regressor (``None`` before :meth:`fit`); its ``kernel_`` holds the fitted hyperparameters (length
        scales in box-normalised units, the constant in normalised observable units).
    """

    def __init__(self, lower, upper, *, kernel: str = "matern", nu: float = 2.5,
                 length_scale_bounds: tuple[float, float] = (0.05, 5.0), n_restarts: int = 5, seed: int = 0,
                 names: Sequence[str] | None = None):
        self.lower, self.upper = as_box(lower, upper)
        if kernel not in _KERNELS:
            raise ValueError(f"unknown kernel {kernel!r}; known: {_KERNELS}")
        low, high = (float(bound) for bound in length_scale_bounds)
        if not 0.0 < low < high:
            raise ValueError(f"length_scale_bounds must be 0 < lower < upper, got {length_scale_bounds}")
        if names is not None:
            names = [str(name) for name in names]
            if len(names) != self.dimension:
                raise ValueError(f"{len(names)} names for {self.dimension} parameters")
        self.kernel = kernel
        self.nu = nu
        self.length_scale_bounds = (low, high)
        self.n_restarts = int(n_restarts)
        self.seed = seed
        self.names = names
        self.gp: GaussianProcessRegressor | None = None
        self._warnings: list[str] = []

    @property
    def dimension(self) -> int:
        """Number of parameters ``d``."""
        return self.lower.size

    @property
    def warnings(self) -> list[str]:
        """What the last fit should not hide: each hyperparameter at a bound, and each convergence warning.

        Returns
        -------
        list of str
            One sentence per finding (empty before :meth:`fit` and for a fit with none): a length scale or the
            constant within 1 % of a bound, with what that says about the runs, then the text of each
            :class:`sklearn.exceptions.ConvergenceWarning` the fit raised (a repeated one once, with its count).
        """
        return list(self._warnings)

    def _kernel(self):
        ones = np.full(self.dimension, 0.5)
        if self.kernel == "matern":
            shape = Matern(length_scale=ones, length_scale_bounds=self.length_scale_bounds, nu=self.nu)
        else:
            shape = RBF(length_scale=ones, length_scale_bounds=self.length_scale_bounds)
        # the constant is a variance of the normalised observable: above 1 where a long length scale makes a trend
        return ConstantKernel(1.0, constant_value_bounds=_CONSTANT_BOUNDS) * shape

    def _name(self, index: int) -> str:
        return self.names[index] if self.names is not None else str(index)

    def _fitted(self) -> GaussianProcessRegressor:
        if self.gp is None:
            raise RuntimeError("the surrogate is not fitted: call fit() first")
        return self.gp

    def fit(self, theta, values, noise_variance) -> "Surrogate":
        """Fit the surrogate to runs.

        Parameters
        ----------
        theta : array_like, shape (n, d)
            Parameter vectors of the runs, in the parameters' units.
        values : array_like, shape (n,)
            The observable of each run, in its units (bulk friction angle [deg]).
        noise_variance : float or array_like, shape (n,)
            Noise variance of each run's observable, in its units squared (deg^2): the run's standard error squared
            plus the seed noise variance.

        Returns
        -------
        Surrogate
            This surrogate, fitted; hyperparameters at a bound and the optimiser's convergence warnings are in
            :attr:`warnings`, not raised.
        """
        theta = as_points(theta, self.dimension, "theta")
        values = np.asarray(values, dtype=float).reshape(-1)
        if len(values) != len(theta):
            raise ValueError(f"{len(theta)} parameter vectors but {len(values)} values")
        if len(values) < 2 or not np.all(np.isfinite(values)):
            raise ValueError("a surrogate needs at least two runs with finite values")
        noise = np.broadcast_to(np.asarray(noise_variance, dtype=float), values.shape)
        if not np.all(np.isfinite(noise)) or np.any(noise < 0):
            raise ValueError("noise variances must be finite and non-negative")
        # normalize_y divides the observable by its (population) sd before alpha is added: alpha in those units
        scale = np.var(values)
        if scale == 0.0:
            raise ValueError("the runs' values are all equal: nothing to fit")
        self.gp = GaussianProcessRegressor(kernel=self._kernel(), alpha=np.maximum(noise / scale, _JITTER),
                                           normalize_y=True, n_restarts_optimizer=self.n_restarts,
                                           random_state=self.seed)
        with warnings.catch_warnings(record=True) as caught:
            # "always": a warning the filters have shown once before must still be recorded for this fit
            warnings.simplefilter("always")
            self.gp.fit(to_unit(theta, self.lower, self.upper), values)
        convergence: dict[str, int] = {}
        for record in caught:
            if issubclass(record.category, ConvergenceWarning):
                convergence[str(record.message)] = convergence.get(str(record.message), 0) + 1
            else:
                # not ours to judge: back to the caller's filters, as if never caught
                warnings.warn_explicit(record.message, record.category, record.filename, record.lineno,
                                       source=record.source)
        self._warnings = self._bound_hits() + [
            f"scikit-learn: {message}" + (f" ({count} times)" if count > 1 else "")
            for message, count in convergence.items()]
        return self

    def _bound_hits(self) -> list[str]:
        """Sentences for the fitted hyperparameters within 1 % of a bound (log space)."""
        fitted = self._fitted().kernel_
        low, high = self.length_scale_bounds
        hits = []
        for index, length_scale in enumerate(np.atleast_1d(fitted.k2.length_scale)):
            name = f"parameter {self._name(index)}"
            if abs(np.log(length_scale / high)) < _AT_BOUND:
                hits.append(f"length scale of {name} at its upper bound {high:g} (box units): over the prior box "
                            f"the observable depends on it at most about linearly (the slope is in the mean), or the "
                            f"runs cannot resolve its dependence")
            elif abs(np.log(length_scale / low)) < _AT_BOUND:
                hits.append(f"length scale of {name} at its lower bound {low:g} (box units): the observable varies "
                            f"with it faster than the runs resolve, or the runs' noise variances are too small")
        constant = fitted.k1.constant_value
        if abs(np.log(constant / _CONSTANT_BOUNDS[1])) < _AT_BOUND:
            hits.append(f"constant at its upper bound {_CONSTANT_BOUNDS[1]:g} (units of the runs' variance): the fit "
                        f"wants a trend steeper than the kernel allows, as when length scales press on their upper "
                        f"bound")
        elif abs(np.log(constant / _CONSTANT_BOUNDS[0])) < _AT_BOUND:
            hits.append(f"constant at its lower bound {_CONSTANT_BOUNDS[0]:g} (units of the runs' variance): the "
                        f"runs' spread is explained by their noise, not by the parameters")
        return hits

    def predict(self, theta) -> tuple[np.ndarray, np.ndarray]:
        """Mean and standard deviation of the noise-free observable.

        Parameters
        ----------
        theta : array_like, shape (m, d) or (d,)
            Parameter vectors, in the parameters' units.

        Returns
        -------
        mean, std : ndarray, shape (m,)
            The surrogate's mean and its standard deviation (the uncertainty of the surrogate, without the runs'
            noise), in the observable's units (deg); shape ``(1,)`` for a single vector.
        """
        gp = self._fitted()
        theta = np.asarray(theta, dtype=float)
        theta = theta[np.newaxis, :] if theta.ndim == 1 else theta
        if theta.ndim != 2 or theta.shape[1] != self.dimension:
            raise ValueError(f"theta must have shape (m, {self.dimension}), got {theta.shape}")
        mean, std = gp.predict(to_unit(theta, self.lower, self.upper), return_std=True)
        return mean, std

    def kernel_summary(self) -> dict:
        """The fitted kernel as plain data (for a JSON report).

        Returns
        -------
        dict
            ``kernel``: the fitted kernel as scikit-learn prints it; ``constant``: its constant (a variance in units
            of the runs' variance); ``length_scales``: the length scale of each parameter in box units (fractions of
            its prior range), keyed by its name, or by its index as a string without names; ``log_marginal_likelihood``:
            of the fitted hyperparameters (normalised observable); ``bounds``: ``length_scale`` and ``constant``, each
            ``[lower, upper]``; ``warnings``: :attr:`warnings`.
        """
        gp = self._fitted()
        length_scales = np.broadcast_to(gp.kernel_.k2.length_scale, (self.dimension,))
        return {
            "kernel": str(gp.kernel_),
            "constant": float(gp.kernel_.k1.constant_value),
            "length_scales": {self._name(index): float(length_scale)
                              for index, length_scale in enumerate(length_scales)},
            "log_marginal_likelihood": float(gp.log_marginal_likelihood_value_),
            "bounds": {"length_scale": [float(bound) for bound in self.length_scale_bounds],
                       "constant": [float(bound) for bound in _CONSTANT_BOUNDS]},
            "warnings": self.warnings,
        }

    def loo_residuals(self) -> np.ndarray:
        """Leave-one-out standardised residuals of the runs, with the fitted hyperparameters.

        Closed form (Rasmussen & Williams 2006, eq. 5.12): with ``K = k(X, X) + diag(alpha)`` the kernel matrix of
        the runs plus their noise variances, in the normalised units the regressor works in, the prediction of run
        ``i`` from the others has mean ``y_i - [K^-1 y]_i / [K^-1]_ii`` and variance ``1 / [K^-1]_ii`` (of a noisy
        observation: the run's noise included). Hyperparameters and normalisation (the runs' mean and sd) are those
        of the fit to all runs; only the run itself is left out.

        Returns
        -------
        ndarray, shape (n,)
            ``z_i = (y_i - mu_{-i}) / sd_{-i} = [K^-1 y]_i / sqrt([K^-1]_ii)`` [-], in the order of the runs. For an
            honest surrogate they scatter with unit spread: larger says it is over-confident, smaller
            under-confident (see :meth:`loo_check`).
        """
        gp = self._fitted()
        covariance = gp.kernel_(gp.X_train_)
        covariance[np.diag_indices_from(covariance)] += gp.alpha
        factor = cho_factor(covariance, lower=True)
        precision = cho_solve(factor, np.eye(len(covariance)))
        # y_train_ holds the runs already normalised (normalize_y=True): the units K was fitted in
        weights = cho_solve(factor, gp.y_train_)
        return weights / np.sqrt(np.diag(precision))

    def loo_check(self, low: float = 0.5, high: float = 2.0) -> dict:
        """Whether the leave-one-out residuals have about unit spread.

        Parameters
        ----------
        low, high : float
            Range of the residuals' root mean square [-] taken as consistent. With ``n`` runs the rms of ``n``
            unit normal residuals has itself a sampling spread of about ``1 / sqrt(2 n)`` (0.18 for 15 runs), and
            the residuals of a GP are correlated, so the default range ``[0.5, 2]`` flags only a gross mismatch.

        Returns
        -------
        dict
            ``rms``: root mean square of :meth:`loo_residuals` [-]; ``n``: the number of runs; ``within``: whether
            ``low <= rms <= high``; ``message``: ``None`` when within, else a sentence saying whether the surrogate
            is over-confident (rms above ``high``: the runs miss its predictions by more than its sd) or
            under-confident (rms below ``low``).
        """
        residuals = self.loo_residuals()
        rms = float(np.sqrt(np.mean(residuals ** 2)))
        n = len(residuals)
        sampling = 1.0 / np.sqrt(2.0 * n)
        if rms > high:
            message = (f"leave-one-out rms {rms:.2f} above {high:g} (sampling spread about {sampling:.2f} for {n} "
                       f"runs): the surrogate is over-confident, each run misses its prediction from the others by "
                       f"more than the predicted sd; the noise variances may be too small or the kernel too smooth")
        elif rms < low:
            message = (f"leave-one-out rms {rms:.2f} below {low:g} (sampling spread about {sampling:.2f} for {n} "
                       f"runs): the surrogate is under-confident, each run lies closer to its prediction from the "
                       f"others than the predicted sd; the noise variances may be too large")
        else:
            message = None
        return {"rms": rms, "n": n, "within": message is None, "message": message}
