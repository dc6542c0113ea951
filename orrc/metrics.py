"""Performance measures of a closed-loop trajectory.

* :func:`attenuation_regret` -- R^p_T(γ) of Eq. (2);
* :func:`attenuation_ratio` -- the smallest γ for which R^p_T(γ) <= 0 on this trajectory;
* :func:`dynamic_regret` -- cost minus the cost of the best input sequence in hindsight.
"""
from __future__ import annotations

import numpy as np

from ._validate import OrrcValueError, as_float, check_finite_result


def _traj(traj, name: str = "traj"):
    """An orrc Trajectory whose costs are finite (an overflowed run gives no metric)."""
    from .simulate import Trajectory

    if not isinstance(traj, Trajectory):
        raise OrrcValueError(f"{name} must be an orrc Trajectory (from orrc.simulate); got {type(traj).__name__}")
    bad = np.flatnonzero(~np.isfinite(traj.costs))
    if bad.size:
        raise OrrcValueError(f"{name}.costs is not finite at {bad.size} steps (from t={bad[0]}): the run overflowed "
                             "(see the NonFiniteWarning of orrc.simulate), so its metrics are not defined")
    return traj


def attenuation_regret(traj, gamma: float, cumulative: bool = False):
    """R^p_T(γ) = Σ_{t<T} c_t(x_t, u_t) − γ Σ_{t<T} ‖w_t‖²  (Eq. 2 of the paper).

    The introduction of the paper writes its positive part (R^p_T(γ))_+ =
    max(R^p_T(γ), 0); "attenuation γ is achieved" means R^p_T(γ) stays O(1) as T
    grows, and a bounded R implies a bounded positive part, so this function
    returns the signed quantity (the more informative one) and ``max(R, 0)`` gives
    the other. ``cumulative=True`` returns the running values R^p_t(γ), t = 1..T.

    Parameters
    ----------
    traj : the :class:`~orrc.Trajectory` of a run.
    gamma : the attenuation level γ >= 0.
    cumulative : return the running values instead of the total.

    Returns
    -------
    float or numpy.ndarray
        R^p_T(γ), or (T,) the values R^p_t(γ) for t = 1..T when ``cumulative``.

    Raises
    ------
    orrc.OrrcValueError
        When ``gamma`` is negative or not finite, or the trajectory has failed steps.

    Examples
    --------
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> traj = orrc.simulate(di.system, orrc.PreviewRHC(di.system, di.cost, M=10), di.x0,
    ...                      w, T=50)
    >>> print(f"{orrc.attenuation_regret(traj, gamma=40.0):.4f}")
    -0.6526
    >>> orrc.attenuation_regret(traj, gamma=40.0, cumulative=True).shape
    (50,)
    """
    traj = _traj(traj)
    gamma = as_float("gamma", gamma, minimum=0.0)
    if not isinstance(cumulative, bool):
        raise OrrcValueError(f"cumulative must be True or False; got {cumulative!r}")
    with np.errstate(over="ignore", invalid="ignore"):
        per_step = traj.costs - gamma * np.einsum("ij,ij->i", traj.w, traj.w)
        out = np.cumsum(per_step) if cumulative else float(per_step.sum())
    return check_finite_result("R^p_T(gamma)", out, f"gamma={gamma:g} and the trajectory's costs",
                               "the sums exceed the float range")


def attenuation_ratio(traj) -> float:
    """Σ c_t / Σ ‖w_t‖²: the smallest γ with R^p_T(γ) <= 0 on this trajectory.

    Raises when the trajectory had no disturbance energy (the ratio is undefined).

    Parameters
    ----------
    traj : the :class:`~orrc.Trajectory` of a run.

    Returns
    -------
    float
        Σ_{t<T} c_t / Σ_{t<T} ‖w_t‖².

    Raises
    ------
    orrc.OrrcValueError
        When Σ ‖w_t‖² = 0, or the trajectory has failed steps.

    Examples
    --------
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> traj = orrc.simulate(di.system, orrc.PreviewRHC(di.system, di.cost, M=10), di.x0,
    ...                      w, T=50)
    >>> print(f"{orrc.attenuation_ratio(traj):.4f}")
    37.5290
    """
    traj = _traj(traj)
    energy = float(np.sum(traj.w * traj.w))
    if energy <= 0.0:
        raise OrrcValueError("the attenuation ratio needs a non-zero disturbance (Σ‖w_t‖² = 0 here)")
    with np.errstate(over="ignore", invalid="ignore"):
        ratio = float(traj.costs.sum()) / energy
    return check_finite_result("the attenuation ratio", ratio, "of the trajectory", "the total cost overflows")


def dynamic_regret(traj, reference) -> float:
    """Σ_{t<T} c_t(x_t, u_t) − Σ_{t<T} c_t(x*_t, u*_t), the cost above the best input
    sequence in hindsight. ``reference`` is the trajectory of
    :class:`~orrc.Clairvoyant` on the same problem (same x0, w, costs, T), or its
    total cost as a number.

    Parameters
    ----------
    traj : the :class:`~orrc.Trajectory` of the controller.
    reference : the clairvoyant's :class:`~orrc.Trajectory` on the same problem, or its total cost.

    Returns
    -------
    float
        Σ_{t<T} c_t(x_t, u_t) − Σ_{t<T} c_t(x*_t, u*_t) (>= 0 up to the solvers' tolerance).

    Raises
    ------
    orrc.OrrcValueError
        When the two runs are not of the same problem (T, x0, w), or the reference's solve failed.

    Examples
    --------
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> traj = orrc.simulate(di.system, orrc.PreviewRHC(di.system, di.cost, M=10), di.x0,
    ...                      w, T=50)
    >>> best = orrc.simulate(di.system, orrc.Clairvoyant(di.system, di.cost, T=50),
    ...                      di.x0, w, T=50)
    >>> print(f"{orrc.dynamic_regret(traj, best):.4f}")
    0.2222
    """
    traj = _traj(traj)
    if isinstance(reference, (int, float, np.floating)) and not isinstance(reference, bool):
        ref = as_float("reference", reference)
    else:
        reference = _traj(reference, "reference")
        if reference.T != traj.T or not np.allclose(reference.w, traj.w) or not np.allclose(reference.x[0], traj.x[0]):
            raise OrrcValueError("the reference trajectory must be on the same problem (same T, x0 and w)")
        if reference.n_failures:
            raise OrrcValueError(
                f"the reference trajectory's solve failed ({reference.n_failures} failed steps, "
                f"t={reference.failed_steps[:5].tolist()}...): it is not the optimum in hindsight, so the regret "
                "against it means nothing; re-run the clairvoyant with other solver options")
        ref = float(reference.costs.sum())
    with np.errstate(over="ignore", invalid="ignore"):
        out = float(traj.costs.sum()) - ref
    return check_finite_result("the dynamic regret", out, "of the trajectories", "the total costs overflow")
