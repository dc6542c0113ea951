"""Performance measures of a closed-loop trajectory.

* :func:`attenuation_regret` -- R^p_T(γ) of Eq. (2);
* :func:`attenuation_ratio` -- the smallest γ for which R^p_T(γ) <= 0 on this trajectory;
* :func:`dynamic_regret` -- cost minus the cost of the best input sequence in hindsight.
"""
from __future__ import annotations

import numpy as np

from ._validate import OrrcValueError, as_float


def _traj(traj):
    from .simulate import Trajectory

    if not isinstance(traj, Trajectory):
        raise OrrcValueError(f"expected an orrc Trajectory (from orrc.simulate); got {type(traj).__name__}")
    return traj


def attenuation_regret(traj, gamma: float, cumulative: bool = False):
    """R^p_T(γ) = Σ_{t<T} c_t(x_t, u_t) − γ Σ_{t<T} ‖w_t‖²  (Eq. 2 of the paper).

    The introduction of the paper writes its positive part (R^p_T(γ))_+ =
    max(R^p_T(γ), 0); "attenuation γ is achieved" means R^p_T(γ) stays O(1) as T
    grows, and a bounded R implies a bounded positive part, so this function
    returns the signed quantity (the more informative one) and ``max(R, 0)`` gives
    the other. ``cumulative=True`` returns the running values R^p_t(γ), t = 1..T.
    """
    traj = _traj(traj)
    gamma = as_float("gamma", gamma, minimum=0.0)
    per_step = traj.costs - gamma * np.einsum("ij,ij->i", traj.w, traj.w)
    return np.cumsum(per_step) if cumulative else float(per_step.sum())


def attenuation_ratio(traj) -> float:
    """Σ c_t / Σ ‖w_t‖²: the smallest γ with R^p_T(γ) <= 0 on this trajectory.

    Raises when the trajectory had no disturbance energy (the ratio is undefined).
    """
    traj = _traj(traj)
    energy = float(np.sum(traj.w * traj.w))
    if energy <= 0.0:
        raise OrrcValueError("the attenuation ratio needs a non-zero disturbance (Σ‖w_t‖² = 0 here)")
    return float(traj.costs.sum()) / energy


def dynamic_regret(traj, reference) -> float:
    """Σ_{t<T} c_t(x_t, u_t) − Σ_{t<T} c_t(x*_t, u*_t), the cost above the best input
    sequence in hindsight. ``reference`` is the trajectory of
    :class:`~orrc.Clairvoyant` on the same problem (same x0, w, costs, T), or its
    total cost as a number."""
    traj = _traj(traj)
    if isinstance(reference, (int, float, np.floating)):
        ref = float(reference)
    else:
        reference = _traj(reference)
        if reference.T != traj.T or not np.allclose(reference.w, traj.w) or not np.allclose(reference.x[0], traj.x[0]):
            raise OrrcValueError("the reference trajectory must be on the same problem (same T, x0 and w)")
        ref = float(reference.costs.sum())
    return float(traj.costs.sum()) - ref
