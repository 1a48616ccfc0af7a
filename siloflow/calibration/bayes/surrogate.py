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
* the optimiser restarts from seeded random hyperparameters, so a fit is deterministic for a seed.
"""

from __future__ import annotations

import warnings

import numpy as np
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, Matern

from siloflow.calibration.bayes.box import as_box, as_points, to_unit

__all__ = ["Surrogate"]

_KERNELS = ("matern", "rbf")

# The smallest noise variance passed to the GP (in normalised units): keeps the kernel matrix positive definite
# when the given noise is zero, without changing a fit whose noise is not.
_JITTER = 1e-10


class Surrogate:
    """Gaussian-process surrogate of one observable against the parameters, on the prior box.

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
        Bounds of each length scale, as fractions of the parameter's prior range: down to 0.05 (a range resolved
        by about twenty runs, more than a calibration will have) and up to 1000 (flat: a stationary kernel
        describes a linear dependence, as of bulk friction on rolling friction, by a long length scale and a large
        constant, so both need room).
    n_restarts : int
        Restarts of the hyperparameter optimiser from random starts, drawn with ``seed``.
    seed : int
        Seed of the restarts.

    Attributes
    ----------
    gp : sklearn.gaussian_process.GaussianProcessRegressor or None
        The fitted regressor (``None`` before :meth:`fit`); its ``kernel_`` holds the fitted hyperparameters (length
        scales in box-normalised units, the constant in normalised observable units).
    """

    def __init__(self, lower, upper, *, kernel: str = "matern", nu: float = 2.5,
                 length_scale_bounds: tuple[float, float] = (0.05, 1000.0), n_restarts: int = 5, seed: int = 0):
        self.lower, self.upper = as_box(lower, upper)
        if kernel not in _KERNELS:
            raise ValueError(f"unknown kernel {kernel!r}; known: {_KERNELS}")
        self.kernel = kernel
        self.nu = nu
        self.length_scale_bounds = length_scale_bounds
        self.n_restarts = int(n_restarts)
        self.seed = seed
        self.gp: GaussianProcessRegressor | None = None

    @property
    def dimension(self) -> int:
        """Number of parameters ``d``."""
        return self.lower.size

    def _kernel(self):
        ones = np.full(self.dimension, 0.5)
        if self.kernel == "matern":
            shape = Matern(length_scale=ones, length_scale_bounds=self.length_scale_bounds, nu=self.nu)
        else:
            shape = RBF(length_scale=ones, length_scale_bounds=self.length_scale_bounds)
        # the constant is a variance of the normalised observable: above 1 where a long length scale makes a trend
        return ConstantKernel(1.0, constant_value_bounds=(1e-2, 1e4)) * shape

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
            This surrogate, fitted.
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
        with warnings.catch_warnings():
            # a length scale at its upper bound says the observable hardly depends on that parameter (the wall angle
            # on the rolling friction): an answer, not a failure of the fit
            warnings.simplefilter("ignore", ConvergenceWarning)
            self.gp.fit(to_unit(theta, self.lower, self.upper), values)
        return self

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
        if self.gp is None:
            raise RuntimeError("the surrogate is not fitted: call fit() first")
        theta = np.asarray(theta, dtype=float)
        theta = theta[np.newaxis, :] if theta.ndim == 1 else theta
        if theta.ndim != 2 or theta.shape[1] != self.dimension:
            raise ValueError(f"theta must have shape (m, {self.dimension}), got {theta.shape}")
        mean, std = self.gp.predict(to_unit(theta, self.lower, self.upper), return_std=True)
        return mean, std
