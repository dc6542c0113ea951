"""Accepting an SQP answer: the checks of :mod:`orrc.solvers.nlp` ("Accepting an SQP answer") as one
compiled CasADi function of the answer where the solver left it, and their verdict.

``sqpmethod`` stops at a point whose KKT residuals are small; it checks neither the signs of the bound
multipliers nor that the point is better than the initial guess. A converged answer is accepted only if

1. the bound multipliers are complementary: Σ_i λ⁺_i (ub_i − z_i) + λ⁻_i (z_i − lb_i) ≤ 1e-8 |J| + 1e-12,
2. J ≤ J_g + 1e-8 |J_g| + ‖λ_g‖₁ ‖g‖_∞ + 1e-12, with J_g the cost of the guess's inputs rolled out
   through the dynamics (where that rollout is finite and within the state bounds),

and J and z are finite. :func:`acceptance_function` computes the quantities of both checks and the verdict
in one CasADi call; :func:`rejection` says why an answer is not accepted, from the same quantities.
"""
from __future__ import annotations

import math

import casadi as ca

#: the acceptance checks of an SQP answer: relative and absolute slack
ACCEPT_RTOL, ACCEPT_ATOL = 1e-8, 1e-12


def rejection(quantities, value: float) -> str | None:
    """Why a converged SQP answer to Eq. (3), the M-step problem of Algorithm 1, is not accepted, or None.

    The checks of the module docstring, on the quantities :func:`acceptance_function` computes:
    complementary bound multipliers, and an objective not above the cost of the initial guess's inputs.

    Parameters
    ----------
    quantities : sequence of float
        The first output of :func:`acceptance_function`, as a list: [Σ λ·gap, J_g, 1 if the guess's
        rollout is usable else 0, ‖λ_g‖₁, ‖g‖_∞, ...] (entries past the fifth are not read).
    value : float
        J, the objective of the converged answer.

    Returns
    -------
    str or None
        The reason the answer is rejected, in words, or None when it is accepted.

    Examples
    --------
    An answer of cost 1 when the guess's inputs cost 0.5 is a worse stationary point:

    >>> from orrc.solvers.acceptance import rejection
    >>> rejection([0.0, 2.0, 1.0, 0.0, 0.0], 1.0) is None
    True
    >>> print(rejection([0.0, 0.5, 1.0, 0.0, 0.0], 1.0))
    objective 1 above the cost 0.5 of the initial guess's inputs (a feasible point): SQP stopped at a
    worse stationary point
    >>> print(rejection([1e-3, 2.0, 1.0, 0.0, 0.0], 1.0))
    bound multipliers not complementary (Σ λ·gap = 0.001 > 1e-08·|J| with J = 1)
    """
    complementarity, J_guess, rollout_ok, lam_g_1, g_inf = quantities[:5]
    if not complementarity <= ACCEPT_RTOL * abs(value) + ACCEPT_ATOL:
        return (f"bound multipliers not complementary (Σ λ·gap = {complementarity:.3g} > "
                f"{ACCEPT_RTOL:g}·|J| with J = {value:.6g})")
    if not rollout_ok == 1.0:
        return None  # the guess's rollout overflows or leaves the state bounds: no feasible comparison point
    slack = ACCEPT_RTOL * abs(J_guess) + lam_g_1 * g_inf
    if value > J_guess + slack + ACCEPT_ATOL:
        return (f"objective {value:.8g} above the cost {J_guess:.8g} of the initial guess's inputs "
                "(a feasible point): SQP stopped at a worse stationary point")
    return None


def acceptance_function(z, g, p, U, J_roll, X_roll, lbz, ubz, state_bounded: bool, shift) -> ca.Function:
    """The acceptance checks of an SQP answer to Eq. (3), the M-step problem of Algorithm 1, as one
    CasADi function.

    The function maps the solver's answer, its multipliers, the parameters, the guess's inputs and the
    answer's objective J to the quantities of the checks (module docstring) and the next guess:
    (z, g, λ_x, λ_g, p, vec U_guess, J) -> ([Σ_i λ⁺_i (ub_i − z_i) + λ⁻_i (z_i − lb_i), J_g (the cost of the
    guess's inputs rolled out), 1 if that rollout is finite (and within the state bounds) else 0,
    ‖λ_g‖₁, ‖g‖_∞, 1 if z is finite else 0, 1 if the answer is accepted else 0], z[shift]: the guess of
    the next step, the answer shifted by one step, for the warm loop to copy when it accepts). The verdict
    is that of :func:`rejection` on the others and J finite, computed with the same floating-point
    operations in the same order (so the same verdict). A multiplier on an absent (infinite) bound makes
    the first one infinite. (Finiteness: |Σ x| < inf; CasADi simplifies x * 0 to 0.)

    Parameters
    ----------
    z, g : casadi.SX
        The NLP's decision variables [vec U; x̃_1..x̃_M] and constraints (only their sizes are read).
    p, U : casadi.SX
        Symbols of the NLP's parameters and of the guess's inputs vec U.
    J_roll, X_roll : casadi.SX
        Expressions in (p, U): the cost of the inputs U rolled out through the dynamics, and the states
        of that rollout.
    lbz, ubz : array_like
        The bounds on z (±inf where absent).
    state_bounded : bool
        Whether the rollout must stay within the state bounds of z (entries past vec U) to be usable.
    shift : list of int
        The entries of z that make the next step's guess, in order.

    Returns
    -------
    casadi.Function
        ``acceptance(z, g, lam_x, lam_g, p, U, J)`` with the outputs (the seven quantities, z[shift]).

    Examples
    --------
    One step of x⁺ = x + u, z = (u, x̃_1), the cost u² + x̃_1²; the guess's input is 0, which costs 1:

    >>> import casadi as ca
    >>> import numpy as np
    >>> from orrc.solvers.acceptance import acceptance_function, rejection
    >>> u, x1, x, U = (ca.SX.sym(s) for s in ("u", "x1", "x", "U"))
    >>> check = acceptance_function(ca.vertcat(u, x1), x1 - (x + u), x, U,
    ...                             U**2 + (x + U)**2, x + U, [-1.0, -np.inf],
    ...                             [1.0, np.inf], False, [1, 1])
    >>> quantities, guess = check([-0.5, 0.5], 0.0, [0.0, 0.0], 1.0, 1.0, 0.0, 0.5)
    >>> quantities      # the minimiser (cost 0.5) is accepted: the last entry is 1
    DM([0, 1, 1, 1, 0, 1, 1])
    >>> rejection(list(quantities.full().ravel()), 0.5) is None
    True
    """
    zs, gs, lam_x, lam_g = (ca.SX.sym(name, v.numel()) for name, v in (("z", z), ("g", g), ("lam_x", z),
                                                                       ("lam_g", g)))
    lb, ub = ca.DM(lbz), ca.DM(ubz)
    # λ_i's term by the bounds z_i has: the general form's value wherever z is finite (an infinite z is
    # rejected anyway). Entries without bounds, whose every multiplier is infinitely wrong, are one group:
    # their terms are 0 or inf (NaN with a NaN λ), and so is the group's, added last.
    terms, free = [], []
    for i in range(z.numel()):
        lam, zi, lo, hi = lam_x[i], zs[i], float(lbz[i]), float(ubz[i])
        if math.isinf(lo) and math.isinf(hi):
            free.append(ca.fabs(lam))
        elif math.isinf(lo) or math.isinf(hi):
            terms.append(ca.fabs(lam) * ca.if_else(lam != 0, ca.if_else(lam > 0, hi - zi, zi - lo), 0))
        else:   # two finite bounds: the gap is finite, and λ = 0 adds 0
            terms.append(ca.fabs(lam) * ca.if_else(lam > 0, hi - zi, zi - lo))
    complementarity = ca.sum1(ca.vertcat(*terms)) if terms else ca.SX(0)
    if free:
        lam_free = ca.sum1(ca.vertcat(*free))
        complementarity = complementarity + ca.if_else(lam_free != 0, lam_free * math.inf, 0)
    roll = ca.Function("guess_rollout", [p, U], [J_roll, X_roll])
    ps, Us, J = ca.SX.sym("p", p.numel()), ca.SX.sym("U", U.numel()), ca.SX.sym("J")

    def finite(v):   # the sum is finite (as solve() tests the answer: isfinite(z.sum()))
        return ca.fabs(ca.sum1(v)) < ca.inf

    J_g, X_g = roll(ps, Us)
    rollout_ok = ca.logic_and(finite(J_g), finite(X_g))
    if state_bounded:
        n_u = U.numel()
        rollout_ok = ca.logic_and(rollout_ok, ca.logic_and(ca.mmin(X_g - lb[n_u:]) >= 0,
                                                           ca.mmin(ub[n_u:] - X_g) >= 0))
    lam_g_1, g_inf = ca.sum1(ca.fabs(lam_g)), (ca.mmax(ca.fabs(gs)) if g.numel() else ca.SX(0))
    # rejection(): complementary multipliers, and J not above the guess's cost where its rollout is usable
    slack = ACCEPT_RTOL * ca.fabs(J_g) + lam_g_1 * g_inf
    not_worse = ca.logic_or(ca.logic_not(rollout_ok), ca.logic_not(J > J_g + slack + ACCEPT_ATOL))
    accepted = ca.logic_and(ca.logic_and(finite(J), finite(zs)),
                            ca.logic_and(complementarity <= ACCEPT_RTOL * ca.fabs(J) + ACCEPT_ATOL, not_worse))
    out = ca.vertcat(complementarity, J_g, ca.if_else(rollout_ok, 1, 0), lam_g_1, g_inf,
                     ca.if_else(finite(zs), 1, 0), ca.if_else(accepted, 1, 0))
    return ca.Function("acceptance", [zs, gs, lam_x, lam_g, ps, Us, J], [ca.cse(out), zs[shift]])
