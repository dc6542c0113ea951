"""Exact finite-horizon LQ with previewed additive disturbances (Algorithm 1, linear case).

Problem (Eq. 3 of the paper for f linear and c quadratic, no terminal cost unless
``Pf`` is given):

    V_M(x, W) = min_{u_0..u_{M-1}} Σ_{j=0}^{M-1} x_jᵀ Q_j x_j + u_jᵀ R_j u_j  (+ x_Mᵀ Pf x_M)
               s.t. x_{j+1} = A x_j + B u_j + w_j,  x_0 = x.

Solved by the backward Riccati recursion with an affine feed-forward term: with
V_j(x) = xᵀ P_j x + 2 q_jᵀ x + r_j, S_j = R_j + Bᵀ P_{j+1} B,

    K_j = S_j⁻¹ Bᵀ P_{j+1} A,      P_j = Q_j + Aᵀ P_{j+1} (A - B K_j),
    h_j = P_{j+1} w_j + q_{j+1},   u_j = -K_j x_j - S_j⁻¹ Bᵀ h_j,
    q_j = (A - B K_j)ᵀ h_j,         r_j = r_{j+1} + w_jᵀP_{j+1}w_j + 2 q_{j+1}ᵀ w_j - h_jᵀ B S_j⁻¹ Bᵀ h_j.

For a time-invariant cost, :class:`LQPreviewLaw` carries the recursion through
symbolically in W, which gives the exact closed form of the first input and of
the value as a quadratic form in (x, W):

    u_0 = -K x - L vec(W),      V_M(x, W) = [x; vec W]ᵀ H [x; vec W].
"""
from __future__ import annotations

import numpy as np

from .._validate import ARRAY_OVERHEAD_BYTES, PY_CALL_OPS, OrrcValueError, check_size

#: numpy calls per backward Riccati step (:func:`riccati_step`), for the size estimates
_STEP_CALLS = 8


def riccati_step(A, B, P_next, Q, R):
    """One backward Riccati step: (P_j, K_j, S_j⁻¹) from P_{j+1} and the stage weights Q_j, R_j.

    S_j = R_j + Bᵀ P_{j+1} B,  K_j = S_j⁻¹ Bᵀ P_{j+1} A,  P_j = Q_j + Aᵀ P_{j+1} (A - B K_j)
    (symmetrised). R_j must be positive definite (validated where cost data enter).

    Parameters
    ----------
    A, B : the system matrices (n, n), (n, m).
    P_next : (n, n) P_{j+1}.
    Q, R : the stage weights (n, n), (m, m).

    Returns
    -------
    tuple
        P_j (n, n), K_j (m, n) and S_j⁻¹ (m, m).

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import lq
    >>> # the last step: P_j = Q, K_j = 0
    >>> P, K, S_inv = lq.riccati_step(A, B, np.zeros((2, 2)), Q, R)
    >>> bool(np.allclose(P, Q)), K.shape
    (True, (1, 2))
    """
    BtP = B.T @ P_next
    Sinv = np.linalg.inv(R + BtP @ B)
    K = Sinv @ (BtP @ A)
    Pj = Q + A.T @ P_next @ (A - B @ K)
    return 0.5 * (Pj + Pj.T), K, Sinv


def riccati_steps_size(what: str, steps: int, n: int, m: int, stored: int = 3) -> None:
    """:func:`orrc._validate.check_size` for ``steps`` backward Riccati steps keeping ``stored``
    small matrices per step (0 when only the current one is kept).

    Parameters
    ----------
    what : the computation, named in the message.
    steps : the number of Riccati steps.
    n, m : the dimensions.
    stored : small matrices kept per step.

    Returns
    -------
    None
        when the computation is within the limits.

    Raises
    ------
    orrc.OrrcValueError
        When it exceeds the limits of ``orrc.config`` (a :class:`~orrc.SizeWarning` above the
        warning thresholds).

    Examples
    --------
    >>> from orrc.solvers import lq
    >>> lq.riccati_steps_size("a Riccati recursion", steps=100, n=2, m=1) is None
    True
    """
    check_size(what, nbytes=stored * (steps + 1) * (8.0 * (n * n + n * m) + ARRAY_OVERHEAD_BYTES),
               ops=steps * (_STEP_CALLS * PY_CALL_OPS + 6.0 * (n + m) ** 3), hint="lower the horizon")


def lq_law_size(M: int, n: int, m: int,
                who: str = "the exact LQ preview law (u = -Kx - L vec W, V_M = zᵀHz)") -> None:
    """:func:`orrc._validate.check_size` for :class:`LQPreviewLaw` at the horizon M (also called by a
    controller that builds the law later, e.g. Algorithm 2 at the end of its estimation phase).

    Parameters
    ----------
    M : the horizon.
    n, m : the dimensions.
    who : the computation, named in the message.

    Returns
    -------
    None
        when the law fits the limits.

    Raises
    ------
    orrc.OrrcValueError
        When it exceeds the limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> from orrc.solvers import lq
    >>> try:
    ...     lq.lq_law_size(10**6, 2, 1)
    ... except orrc.OrrcValueError as err:
    ...     print("refused")
    refused
    """
    N = M * n
    # D (N x N), H and [H; -[K L]] ((n+N)², (n+N+m)(n+N)) and one N x N temporary per step
    check_size(f"{who} at the horizon M={M} (n={n}, m={m})",
               nbytes=8.0 * (4 * (n + N) ** 2 + (n + N) * m), ops=M * (m + 4.0) * float(N + n) ** 2,
               hint="lower M (the law is O(M³n²) to build and O(M²n²) to store), or use PreviewRHC.plan, "
                    "which solves one (x, W) by the Riccati recursion in O(M n³)")


def _backward_gains(A, B, Qs, Rs, Pf):
    """P_0..P_M, K_0..K_{M-1} and S_j⁻¹ for time-varying Q_j, R_j (the Riccati part)."""
    M = len(Qs)
    n, m = B.shape
    riccati_steps_size(f"the Riccati recursion over the horizon M={M} (n={n}, m={m})", M, n, m)
    P = [None] * (M + 1)
    K = [None] * M
    Sinv = [None] * M
    P[M] = np.zeros((n, n)) if Pf is None else Pf
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is checked (and raised) below
        for j in range(M - 1, -1, -1):
            P[j], K[j], Sinv[j] = riccati_step(A, B, P[j + 1], Qs[j], Rs[j])
    if not (np.all(np.isfinite(P[0])) and np.all(np.isfinite(K[0]))):
        raise OrrcValueError(
            f"the Riccati recursion over M={M} steps overflows (P_0 is not finite): the weights or the "
            "horizon are too large for this (A, B) (an unstabilisable mode grows like its eigenvalue^(2M)); "
            "rescale Q, R or shorten M")
    return P, K, Sinv


def solve(A, B, Qs, Rs, x, W, Pf=None):
    """Solve the M-step problem exactly for one (x, W): returns (U (M,m), X (M+1,n), V_M).

    ``Qs`` (M, n, n), ``Rs`` (M, m, m) are the stage weights of the horizon
    (time-varying allowed); ``W`` (M, n) the previewed disturbances.

    Parameters
    ----------
    A, B : the system matrices.
    Qs : (M, n, n) the state weights of the horizon.
    Rs : (M, m, m) the input weights.
    x : (n,) the current state.
    W : (M, n) the previewed disturbances.
    Pf : (n, n) an optional terminal weight.

    Returns
    -------
    tuple
        U (M, m), X (M + 1, n) and V_M.

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
    >>> from orrc.solvers import lq
    >>> U, X, V = lq.solve(A, B, np.array([Q] * 5), np.array([R] * 5), np.array([1.0, 0.0]),
    ...                    np.zeros((5, 2)))
    >>> U.shape, X.shape, round(V, 4)
    ((5, 1), (6, 2), 4.9199)
    """
    M = len(Qs)
    P, K, Sinv = _backward_gains(A, B, Qs, Rs, Pf)
    n, m = B.shape
    q = np.zeros(n)
    r = 0.0
    k = np.zeros((M, m))
    for j in range(M - 1, -1, -1):
        w = W[j]
        h = P[j + 1] @ w + q
        Bth = B.T @ h
        k[j] = Sinv[j] @ Bth
        r = r + w @ P[j + 1] @ w + 2 * q @ w - Bth @ k[j]
        q = (A - B @ K[j]).T @ h
    X = np.empty((M + 1, n))
    U = np.empty((M, m))
    X[0] = x
    for j in range(M):
        U[j] = -K[j] @ X[j] - k[j]
        X[j + 1] = A @ X[j] + B @ U[j] + W[j]
    value = float(x @ P[0] @ x + 2 * q @ x + r)
    return U, X, value


_BLAS = []  # the threadpoolctl controller of the loaded BLAS, made on first use


def _one_blas_thread():
    """A context in which numpy's BLAS runs on one thread (threadpoolctl, imported on first use)."""
    if not _BLAS:
        from threadpoolctl import ThreadpoolController

        _BLAS.append(ThreadpoolController())
    return _BLAS[0].limit(limits=1, user_api="blas")


class LQPreviewLaw:
    """The exact receding-horizon law of a time-invariant LQ problem with preview M.

    Attributes
    ----------
    K : (m, n)         feedback on x_t
    L : (m, M n)       feed-forward on vec(w_t, ..., w_{t+M-1})
    H : (n+Mn, n+Mn)   V_M(x, W) = zᵀ H z with z = [x; vec W]
    P : list of P_j    the Riccati matrices P_0..P_M

    Parameters
    ----------
    A, B : the system matrices (n, n), (n, m).
    Q, R : the stage weights.
    M : the horizon.
    Pf : (n, n) an optional terminal weight.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import lq
    >>> law = lq.LQPreviewLaw(A, B, Q, R, 5)
    >>> law.K.shape, law.L.shape, law.H.shape
    ((1, 2), (1, 10), (12, 12))
    """

    def __init__(self, A, B, Q, R, M, Pf=None):
        n, m = B.shape
        lq_law_size(M, n, m)
        self.A, self.B, self.M, self.n, self.m = A, B, M, n, m
        Qs = np.broadcast_to(Q, (M, n, n))
        Rs = np.broadcast_to(R, (M, m, m))
        P, K, Sinv = _backward_gains(A, B, Qs, Rs, Pf)
        N = M * n
        C = np.zeros((n, N))          # q_j = C_j vec W
        D = np.zeros((N, N))          # r_j = vec Wᵀ D_j vec W
        for j in range(M - 1, -1, -1):
            sl = slice(j * n, (j + 1) * n)
            h = C.copy()
            h[:, sl] += P[j + 1]          # h_j = P_{j+1} w_j + q_{j+1}
            Bth = B.T @ h
            D[sl, :] += C                 # + 2 q_{j+1}ᵀ w_j (split symmetrically)
            D[:, sl] += C.T
            D[sl, sl] += P[j + 1]
            D -= Bth.T @ Sinv[j] @ Bth
            if j == 0:
                self.L = Sinv[0] @ Bth
            C = (A - B @ K[j]).T @ h
        self.K = K[0]
        self.P = P
        H = np.zeros((n + N, n + N))
        H[:n, :n] = P[0]
        H[:n, n:] = C
        H[n:, :n] = C.T
        H[n:, n:] = 0.5 * (D + D.T)
        if not (np.all(np.isfinite(H)) and np.all(np.isfinite(self.L))):
            raise OrrcValueError(
                f"the exact LQ preview law at M={M} overflows (H or L is not finite): rescale Q, R or shorten M")
        self.H = H
        # -[K L]: one matrix-vector product per step gives u = -K x - L vec W (input)
        self._G = -np.hstack([self.K, self.L])
        # [H; -[K L]]: one matrix-vector product gives both H z and u (input_and_value)
        self._HG = np.vstack([H, self._G])

    def first_input(self, x, W):
        """κ_M(x) = -K x - L vec W."""
        return -self.K @ x - self.L @ W.reshape(-1)

    def input(self, x, W):
        """κ_M(x) = -[K L] [x; vec W], one product (the closed-loop hot path of :class:`orrc.PreviewRHC`,
        whose values come from :meth:`values` after the run)."""
        return self._G @ np.concatenate((x, W.reshape(-1)))

    def feedforward(self, W_windows, chunk: int = 4096) -> np.ndarray:
        """−L vec W_t for many windows at once: the part of κ_M that does not depend on x_t.

        W_windows : (k, k_w, n) with k_w <= M rows each (the rows after k_w count as zero, as in a
        plan that has not seen them). One matrix product per ``chunk`` windows; row t depends on
        window t only. Returns (k, m), so that κ_M(x_t, W_t) = −K x_t + (this)[t].
        """
        k, kw, n = W_windows.shape
        out = np.empty((k, self.m))
        Lt = -self.L[:, :kw * n].T
        with _one_blas_thread():
            for s in range(0, k, chunk):
                rows = min(chunk, k - s)
                out[s:s + rows] = W_windows[s:s + rows].reshape(rows, kw * n) @ Lt
        return out

    def values(self, X, W_windows, chunk: int = 4096) -> np.ndarray:
        """V_M(x_t, W_t) = z_tᵀ H z_t, z_t = [x_t; vec W_t], for many (x_t, W_t) at once.

        X : (k, n); W_windows : (k, M, n). One matrix product per ``chunk`` rows (so the
        temporaries stay at chunk·(n + Mn) numbers whatever k is); each value equals
        :meth:`value` of its row up to round-off. The products run on one BLAS thread
        (threadpoolctl): on a loaded 2-core machine a multi-threaded product of this size waits
        for its descheduled second thread, and took 12 to 20 ms instead of 2 ms (T = 1000, M = 50, n = 4).
        """
        k, n = len(X), self.n
        out = np.empty(k)
        with _one_blas_thread():
            for s in range(0, k, chunk):
                rows = min(chunk, k - s)
                Z = np.empty((rows, n + self.M * n))  # [x_t, w_t, ..., w_{t+M-1}]: one copy of each window
                Z[:, :n] = X[s:s + rows]
                Z[:, n:].reshape(rows, self.M, n)[...] = W_windows[s:s + rows]
                out[s:s + rows] = np.einsum("ij,ij->i", Z @ self.H, Z)
        return out

    def input_and_value(self, x, W):
        """(κ_M(x), V_M(x, W)) from one product with the stacked [H; -[K L]].

        The closed-loop hot path of :class:`orrc.PreviewRHC`;
        equal to (:meth:`first_input`, :meth:`value`).
        """
        z = np.concatenate((x, W.reshape(-1)))
        y = self._HG @ z
        k = z.shape[0]
        return y[k:], float(z @ y[:k])

    def value(self, x, W) -> float:
        """V_M(x, W) = [x; vec W]ᵀ H [x; vec W]."""
        z = np.concatenate([x, W.reshape(-1)])
        return float(z @ self.H @ z)
