"""The estimation phase of Algorithm 2: excitation signals and three estimators (Section 4.2).

One module per concept:

* :mod:`orrc.estimation.excitation` -- bounded, seeded excitation inputs: :func:`gaussian`,
  :func:`prbs`, :func:`multisine`;
* :mod:`orrc.estimation.data` -- the data set D = {(x_{k+1}, x_k, u_k, w_k)} (:func:`transitions`)
  and the :class:`Estimate` every estimator returns (θ̂, data rank, residual, ‖θ̂ - θ‖);
* :mod:`orrc.estimation.linear` -- :func:`least_squares_linear` for x+ = Ax + Bu + w (exact once
  the data are persistently exciting, when w is given);
* :mod:`orrc.estimation.parametric` -- :func:`least_squares_parametric` for a
  :class:`~orrc.ParametricSystem` affine in θ (x+ = x + f(x, u) + g(x, u)θ + w);
* :mod:`orrc.estimation.edmd` -- EDMD with inputs (a lifted linear model on a dictionary ψ(x):
  :func:`polynomial_dictionary`, :func:`rbf_dictionary`), :func:`edmd`, :class:`EDMDModel`,
  :func:`prediction_error`.

Every estimator reports ``error`` = ‖θ̂ - θ‖ when the true θ is given, so that the paper's
accuracy g(N) can be measured; EDMD has no true θ, and its prediction error on fresh data takes
that role.
"""
from .data import Estimate, RankWarning, Transitions, transitions
from .edmd import (EDMD, Dictionary, EDMDModel, edmd, polynomial_dictionary, prediction_error,
                   rbf_dictionary)
from .excitation import gaussian, multisine, prbs
from .linear import LinearEstimate, least_squares_linear
from .parametric import least_squares_parametric
from . import data, excitation, linear, parametric  # noqa: F401  (orrc.estimation.edmd is the function, as orrc.simulate is)

__all__ = ["Estimate", "LinearEstimate", "EDMDModel", "RankWarning", "Transitions", "transitions",
           "gaussian", "prbs", "multisine", "least_squares_linear", "least_squares_parametric",
           "Dictionary", "polynomial_dictionary", "rbf_dictionary", "edmd", "EDMD", "prediction_error"]
