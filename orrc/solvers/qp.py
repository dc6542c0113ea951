"""The M-step problem of Algorithm 1 for a linear system and an ℓ1 state cost, as one QP.

    V_M(x, W) = min_{u_0..u_{M-1} ∈ U} Σ_{j=0}^{M-1} qᵀ|x̃_j| + u_jᵀ R u_j
                s.t. x̃_{j+1} = A x̃_j + B u_j + w_j,  x̃_0 = x.

With the states condensed, x̃_j = A^j x + Σ_{i<j} A^{j-1-i}(B u_i + w_i) = Φ_j x + Γ_j u + Ψ_j W,
and an epigraph variable s_j >= |x̃_j| for j = 1..M-1 (x̃_0 = x is fixed, x̃_M is not costed),
it is the convex quadratic program

    min_{u, s}  uᵀ(I ⊗ R)u + Σ_j qᵀ s_j   s.t.  s_j - Γ_j u >= Φ_j x + Ψ_j W,  s_j + Γ_j u >= -(Φ_j x + Ψ_j W),

whose matrices do not depend on (x, W): it is built once (CasADi ``qpsol`` with its active-set
solver ``qrqp``, parameters (x, vec W)) and solved exactly at every step, in tens of
microseconds, which is what the exploration-trade-off studies of Theorem 2 need.
"""
from __future__ import annotations

import time

import casadi as ca
import numpy as np

from .plan import Plan

QRQP = {"print_iter": False, "print_header": False, "print_info": False, "error_on_fail": False,
        "print_time": False}


class L1QP:
    """Eq. (3), the M-step problem of Algorithm 1, for x+ = Ax + Bu + w and c(x, u) = qᵀ|x| + uᵀRu, as
    one exact QP (see the module).

    Parameters
    ----------
    A, B : ndarray
        The system's matrices, (n, n) and (n, m).
    q : ndarray
        The weights (n,) >= 0 of the ℓ1 state cost qᵀ|x|.
    R : ndarray
        The (m, m) positive definite input weight.
    M : int
        The horizon (>= 1).
    input_bounds : tuple of ndarray, optional
        (lo, hi) arrays of length m (±inf allowed), the set U; None: no bounds.

    Examples
    --------
    x⁺ = x + u + w with c = |x| + 0.1u² from x = 1 without disturbances: the plan moves the state to 0
    in one step (cost 1 + 0.1) and then rests.

    >>> import numpy as np
    >>> from orrc.solvers.qp import L1QP
    >>> qp = L1QP(np.eye(1), np.eye(1), np.ones(1), 0.1 * np.eye(1), M=3)
    >>> plan = qp.solve(np.ones(1), np.zeros((3, 1)))
    >>> plan.success, round(plan.value, 6), plan.inputs.ravel().round(6) + 0.0
    (True, 1.1, array([-1.,  0.,  0.]))
    """

    def __init__(self, A, B, q, R, M: int, input_bounds=None):
        n, m = B.shape
        self.A, self.B, self.q, self.R, self.M, self.n, self.m = A, B, q, R, M, n, m
        nu, ns = M * m, (M - 1) * n
        powers = [np.eye(n)]
        for _ in range(M):
            powers.append(A @ powers[-1])
        # the predicted states x̃_1..x̃_M = Sx x + Su vec U + Sw vec W; rows of x̃_1..x̃_{M-1} enter the QP
        self._Sx = np.vstack(powers[1:M + 1])
        self._Su = np.zeros((M * n, nu))
        self._Sw = np.zeros((M * n, M * n))
        for j in range(1, M + 1):
            for i in range(j):
                self._Su[(j - 1) * n:j * n, i * m:(i + 1) * m] = powers[j - 1 - i] @ B
                self._Sw[(j - 1) * n:j * n, i * n:(i + 1) * n] = powers[j - 1 - i]
        Phi, Gam, Psi = self._Sx[:ns], self._Su[:ns], self._Sw[:ns]
        self.nu, self.ns = nu, ns
        v = ca.SX.sym("v", nu + ns)
        p = ca.SX.sym("p", n + M * n)
        u, s = v[:nu], v[nu:]
        self._Rs = np.kron(np.eye(M), R)
        f = ca.bilin(ca.DM(self._Rs), u, u) + (ca.dot(ca.DM(np.tile(q, M - 1)), s) if ns else 0)
        if ns:
            c = ca.mtimes(ca.DM(Phi), p[:n]) + ca.mtimes(ca.DM(Psi), p[n:])
            gu = ca.mtimes(ca.DM(Gam), u)
            g = ca.vertcat(s - gu - c, s + gu + c)
        else:
            g = ca.SX(0, 1)
        self.solver = ca.qpsol("l1qp", "qrqp", {"x": v, "p": p, "f": f, "g": g}, QRQP)
        lo, hi = (np.full(m, -np.inf), np.full(m, np.inf)) if input_bounds is None else input_bounds
        self.lbx = np.concatenate([np.tile(lo, M), np.zeros(ns)])
        self.ubx = np.concatenate([np.tile(hi, M), np.full(ns, np.inf)])
        # zero-copy evaluation (Function.buffer): the arguments live in numpy arrays, set once
        self._buf, self._eval = self.solver.buffer()
        self._args = [np.zeros(self.solver.nnz_in(i)) for i in range(self.solver.n_in())]
        self._res = [np.zeros(self.solver.nnz_out(i)) for i in range(self.solver.n_out())]
        a = dict(zip(self.solver.name_in(), self._args))
        a["lbx"][:], a["ubx"][:], a["ubg"][:] = self.lbx, self.ubx, np.inf
        self._p = a["p"]
        for i, arr in enumerate(self._args):
            self._buf.set_arg(i, memoryview(arr))
        for i, arr in enumerate(self._res):
            self._buf.set_res(i, memoryview(arr))
        self._qs = np.tile(q, M)

    def solve(self, x, W) -> Plan:
        """Solve Eq. (3) from state x with preview W; the value includes qᵀ|x| of the first step.

        A failed solve is reported (``success=False``, the status, ``fallback``), not warned: the
        controller's failure ladder (:mod:`orrc.controllers.failures`) decides what to apply.

        Parameters
        ----------
        x : ndarray
            The state (n,).
        W : ndarray
            The previewed disturbances w_0..w_{M-1}, (M, n).

        Returns
        -------
        Plan
            The inputs (M, m), the predicted states (M + 1, n), V_M and the solver's report.

        Examples
        --------
        >>> import numpy as np
        >>> from orrc.solvers.qp import L1QP
        >>> qp = L1QP(np.eye(1), np.eye(1), np.ones(1), 0.1 * np.eye(1), M=2)
        >>> qp.solve(np.ones(1), np.full((2, 1), 0.5)).states.ravel().round(6) + 0.0
        array([1. , 0. , 0.5])
        """
        M, n, m = self.M, self.n, self.m
        t0 = time.perf_counter()
        self._p[:n] = x
        self._p[n:] = W.reshape(-1)
        self._eval()
        elapsed = time.perf_counter() - t0
        stats = self._buf.stats()
        success = bool(stats.get("success", False))
        status = str(stats.get("return_status", "unknown"))
        v = self._res[0]
        U = v[:self.nu].reshape(M, m).copy()
        fallback = None
        if not success or not np.all(np.isfinite(v)):   # reported, not warned: the controller's ladder decides
            success = False
            fallback = "the solver's last iterate"
            if not np.all(np.isfinite(U)):
                U = np.clip(np.zeros((M, m)), self.lbx[:m], self.ubx[:m])
                fallback = "zero inputs (the solver's iterate is not finite)"
        u = U.reshape(-1)
        X = np.vstack([x, (self._Sx @ x + self._Su @ u + self._Sw @ W.reshape(-1)).reshape(M, n)])
        value = float(np.abs(X[:M]).reshape(-1) @ self._qs + u @ self._Rs @ u)
        return Plan(inputs=U, states=X, value=value, success=success, status=status,
                    iterations=int(stats.get("iter_count", 0)), solve_time=elapsed, fallback=fallback,
                    solver="qrqp")
