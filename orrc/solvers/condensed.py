"""The T-step linear-quadratic problem in condensed (batch) form, from x_0 = 0.

With a stabilising gain K (pre-stabilisation keeps the matrices well conditioned for unstable A),
write u_j = −K x_j + v_j. The stacked states x = (x_0, ..., x_{T-1}) and inputs u are linear in
the stacked v and disturbances w:

    x = F v + G w,   u = F_u v + G_u w,   with x_0 = 0, x_{j+1} = (A − BK) x_j + B v_j + w_j

(x_T is not costed, as in the paper's problem without terminal cost). With Q̄ = I ⊗ Q and
R̄ = I ⊗ R the cost J = ‖x‖²_Q̄ + ‖u‖²_R̄ is strictly convex in v with Hessian
S = FᵀQ̄F + F_uᵀR̄F_u, so the clairvoyant optimum (all of w known) is v* = Φ* w with
Φ* = −S⁻¹(FᵀQ̄G + F_uᵀR̄G_u), and for any input sequence

    J(v, w) − J(v*(w), w) = ‖S^½ (v − Φ* w)‖².

A linear controller with v = Φ w (v_t = u_t + K x_t) therefore has dynamic regret
‖S^½(Φ − Φ*) w‖²: the quadratic form of the regret operator S^½(Φ − Φ*) (Goel and Hassibi 2021;
Sabag, Goel, Lale and Hassibi 2021). The controller is causal iff Φ is strictly block lower
triangular (v_t depends on w_0..w_{t-1}), whatever K.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import PY_CALL_OPS, check_size

__all__ = ["Condensed", "condensed"]


@dataclass
class Condensed:
    """The operators of the T-step problem with u = −Kx + v (see the module docstring).

    Attributes
    ----------
    T : the horizon.
    K : (m, n) the pre-stabilising gain.
    F, G : (T n, T m), (T n, T n) the stacked states x = F v + G w.
    F_u, G_u : (T m, T m), (T m, T n) the stacked inputs u = F_u v + G_u w.
    S : (T m, T m) the Hessian of the cost in v; ``S_half`` its square root.
    Phi_star : (T m, T n) the clairvoyant operator, v* = Φ* w.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import condensed, regret
    >>> c = condensed.condensed(A, B, Q, R, T=10)
    >>> c.S.shape, c.Phi_star.shape    # (T m, T m), (T m, T n)
    ((10, 10), (10, 20))
    """

    T: int
    K: np.ndarray
    F: np.ndarray
    G: np.ndarray
    F_u: np.ndarray
    G_u: np.ndarray
    S: np.ndarray
    S_half: np.ndarray
    Phi_star: np.ndarray

    def regret_operator(self, Phi) -> np.ndarray:
        """S^½ (Φ − Φ*): the dynamic regret of v = Φ w is ‖S^½(Φ − Φ*) w‖²."""
        return self.S_half @ (Phi - self.Phi_star)

    def v_operator(self, U, X) -> np.ndarray:
        """Φ of a linear controller given its input and state operators u = U w, x = X w:
        v = u + (I ⊗ K) x."""
        T = self.T
        return U + np.kron(np.eye(T), self.K) @ X


def condensed(A, B, Q, R, T: int, K=None, who: str = "the condensed T-step problem") -> Condensed:
    """The condensed operators of the T-step problem (K: the pre-stabilising gain, default 0), after
    :func:`orrc._validate.check_size` (``who`` names the computation in its message).

    Parameters
    ----------
    A, B, Q, R : the linear-quadratic problem.
    T : the horizon.
    K : the pre-stabilising gain (default 0).
    who : the computation, named in the size check's message.

    Returns
    -------
    Condensed
        the T-step operators (``F``, ``G``, ``S``, ``Phi_star``, ...).

    Raises
    ------
    orrc.OrrcValueError
        When the matrices are malformed or the computation exceeds the size limits of ``orrc.config``.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import condensed, regret
    >>> c = condensed.condensed(A, B, Q, R, T=10)
    >>> c.T, c.F.shape, c.G.shape
    (10, (20, 10), (20, 20))
    """
    n, m = B.shape
    N, P = T * n, T * m
    # the dense (T n)² and (T m)² operators with their temporaries; the loop over T²/2 blocks (three numpy
    # calls each); the products with the Kronecker weights (4 N² P), eigh (about 10 P³) and the solve
    check_size(f"{who} at T={T} (n={n}, m={m}): its condensed operators are {N} x {N} and {P} x {P} matrices",
               nbytes=8.0 * (8 * N * N + 8 * P * P + 6 * N * P),
               ops=1.5 * T * T * PY_CALL_OPS + 10.0 * P ** 3 + 2.0 * P * P * N + 4.0 * N * N * P,
               hint="lower T")
    K = np.zeros((m, n)) if K is None else np.asarray(K, float)
    Acl = A - B @ K
    powers = [np.eye(n)]
    for _ in range(T):
        powers.append(Acl @ powers[-1])
    F = np.zeros((T * n, T * m))
    G = np.zeros((T * n, T * n))
    for j in range(1, T):
        for i in range(j):
            Aji = powers[j - 1 - i]
            F[j * n:(j + 1) * n, i * m:(i + 1) * m] = Aji @ B
            G[j * n:(j + 1) * n, i * n:(i + 1) * n] = Aji
    Kbar = np.kron(np.eye(T), K)
    F_u, G_u = np.eye(T * m) - Kbar @ F, -Kbar @ G
    Qbar, Rbar = np.kron(np.eye(T), Q), np.kron(np.eye(T), R)
    S = F.T @ Qbar @ F + F_u.T @ Rbar @ F_u
    S = 0.5 * (S + S.T)
    lam, V = np.linalg.eigh(S)
    S_half = (V * np.sqrt(np.clip(lam, 0.0, None))) @ V.T
    Phi_star = -np.linalg.solve(S, F.T @ Qbar @ G + F_u.T @ Rbar @ G_u)
    return Condensed(T, K, F, G, F_u, G_u, S, S_half, Phi_star)
