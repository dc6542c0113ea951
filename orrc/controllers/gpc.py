"""Disturbance-action control and GPC, the online controller of Agarwal, Bullins, Hazan, Kakade and
Singh, "Online Control with Adversarial Disturbances" (ICML 2019).

* :class:`DisturbanceAction` -- the fixed policy u_t = −K x_t + Σ_{i=1..H} M_i w_{t−i} (a GPC
  frozen at given M_i); a linear causal controller, so :mod:`orrc.certify` handles it exactly;
* :class:`GPC` -- the same form with M learned online by projected online gradient descent on the
  surrogate ("ideal") cost (Algorithm 1 of the paper);
* :func:`best_fixed_policy` -- the best fixed disturbance-action policy in hindsight on a given
  disturbance sequence, the comparator of GPC's regret (Theorem 5.1 of the paper).

The names follow that paper: M_i, the memory H and (κ, γ) are the book's D^{[i]}, h and (χ, δ),
since in the book M is the horizon, H Lemma 2's look-ahead, κ the receding-horizon law and γ the
attenuation level.

The disturbances are never previewed: w_{t−1} is recovered from the observed states and the input
actually applied, w_{t−1} = x_t − A x_{t−1} − B u_{t−1}, exact for a known linear system. Both
controllers are strictly causal: u_t uses x_0..x_t (equivalently w_0..w_{t−1}), never w_t.
"""
from __future__ import annotations

import math

import numpy as np

from .._validate import PY_CALL_OPS, OrrcValueError, as_array, as_bool, as_float, as_int, as_square, check_size
from .._problem import check_problem
from ..costs import QuadraticCost, psd_factor as _sqrt_psd
from ..systems import LinearSystem
from .base import Controller, Decision, Observation

__all__ = ["DisturbanceAction", "GPC", "best_fixed_policy", "strong_stability", "FixedPolicy"]


def _linear_problem(who: str, system, cost):
    check_problem(system, cost, linear=True, quadratic=True, who=who,
                  why_linear=": it recovers w_t = x_{t+1} − A x_t − B u_t, exact only for x_{t+1} = A x_t + B u_t + w_t",
                  why_quadratic=" (its surrogate cost and gradient are quadratic)")


def _gain(system, cost, K):
    """The stabilising gain K (default: the LQR gain, control.dlqr), checked."""
    if K is None:
        from .baselines import LQR

        return LQR(system, cost).K
    K = as_array("K", K, (system.m, system.n))
    rho = float(np.max(np.abs(np.linalg.eigvals(system.A - system.B @ K))))
    if rho >= 1.0:
        raise OrrcValueError(f"K must stabilise the system (A − BK Schur stable); its spectral radius is {rho:.6g}")
    return K


def strong_stability(A_cl) -> tuple[float, float]:
    """(κ, γ) with A_cl = H L H⁻¹, ‖L‖ <= 1 − γ and ‖H‖‖H⁻¹‖ <= κ: K is (κ, γ)-strongly stable
    (Definition 3.1 of Agarwal et al. 2019, after Cohen et al. 2018).

    Certificate: 1 − γ = (1 + ρ(A_cl))/2 and P solving (A_cl/(1−γ))ᵀ P (A_cl/(1−γ)) − P + I = 0
    (``scipy.linalg.solve_discrete_lyapunov``), so A_clᵀPA_cl ⪯ (1−γ)²P; with H = P^{-½},
    L = P^{½}A_cl P^{-½} has ‖L‖ <= 1 − γ and κ = √cond(P).

    Parameters
    ----------
    A_cl : (n, n) a stable closed-loop matrix A − BK.

    Returns
    -------
    tuple of float
        (κ, γ).

    Raises
    ------
    orrc.OrrcValueError
        When A_cl is not stable (ρ(A_cl) >= 1) or malformed.

    Examples
    --------
    >>> import orrc
    >>> from orrc.controllers import gpc
    >>> di = orrc.examples.double_integrator()
    >>> K = orrc.LQR(di.system, di.cost).K
    >>> kappa, gamma = gpc.strong_stability(di.system.A - di.system.B @ K)
    >>> bool(kappa >= 1 and 0 < gamma < 1)
    True
    """
    from scipy import linalg

    A_cl = as_square("A_cl", A_cl)
    rho = float(np.max(np.abs(np.linalg.eigvals(A_cl))))
    if rho >= 1.0:
        raise OrrcValueError(f"A_cl must be Schur stable (the closed loop) for a strong-stability certificate; its "
                             f"spectral radius is ρ = {rho:.6g}")
    decay = 0.5 * (1.0 + rho)
    P = linalg.solve_discrete_lyapunov(A_cl.T / decay, np.eye(A_cl.shape[0]))
    lam = np.linalg.eigvalsh(0.5 * (P + P.T))
    return float(math.sqrt(lam[-1] / lam[0])), 1.0 - decay


class DisturbanceAction(Controller):
    """u_t = −K x_t + Σ_{i=1..H} M_i w_{t−i}, with M = (M_1, ..., M_H) fixed (shape (H, m, n)).

    The disturbance-action policy class of Agarwal et al. (2019), Definition 4.1; a GPC frozen
    at its learned M. w_{t−i} is recovered from the observed states and applied inputs; before
    t = i it is zero (the run starts at t = 0). ``K`` defaults to the LQR gain.

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem`.
    cost : its :class:`~orrc.QuadraticCost`.
    M : (H, m, n) the fixed M_1..M_H.
    K : the stabilising gain (default: the LQR gain).

    Examples
    --------
    With M = 0 it is the LQR law:

    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> policy = orrc.DisturbanceAction(di.system, di.cost, np.zeros((3, 1, 2)))
    >>> print(f"{orrc.simulate(di.system, policy, di.x0, w, T=50).costs.sum():.4f}")
    10.5812
    """

    name = "disturbance action"

    def __init__(self, system: LinearSystem, cost: QuadraticCost, M, K=None):
        _linear_problem(type(self).__name__, system, cost)
        self.system, self.cost = system, cost
        self.K = _gain(system, cost, K)
        M = as_array("M", M)
        n, m = system.n, system.m
        if M.ndim != 3 or M.shape[1:] != (m, n) or M.shape[0] < 1:
            raise OrrcValueError(f"M must have shape (H, m, n) = (H, {m}, {n}) with H >= 1; got shape {M.shape}")
        self.M = M.copy()
        self.H = M.shape[0]
        self.preview_w = self.preview_c = 0
        self.reset()

    def reset(self) -> None:
        n = self.system.n
        self._w = np.zeros((self.H + (getattr(self, "H_state", 0) or 0) + 1, n))  # newest first
        self._x_prev = self._u_prev = None
        self._t = 0

    def _observe(self, obs: Observation) -> None:
        """Recover w_{t−1} = x_t − A x_{t−1} − B u_{t−1} and push it into the history (newest first)."""
        if obs.t == 0:
            self.reset()
        elif self._x_prev is None or obs.t != self._t:
            raise RuntimeError(f"{self.name} must be run step by step from t = 0 (call simulate)")
        else:
            w = obs.x - self.system.A @ self._x_prev - self.system.B @ self._u_prev
            self._w = np.roll(self._w, 1, axis=0)
            self._w[0] = w

    def _act(self, obs: Observation, M) -> np.ndarray:
        u = -self.K @ obs.x + np.einsum("imn,in->m", M, self._w[:self.H])
        self._x_prev, self._u_prev = np.array(obs.x), u
        self._t = obs.t + 1
        return u

    def control(self, obs: Observation) -> Decision:
        self._observe(obs)
        return Decision(u=self._act(obs, self.M))


FixedPolicy = DisturbanceAction


class GPC(DisturbanceAction):
    """GPC (Agarwal, Bullins, Hazan, Kakade and Singh 2019, Algorithm 1): the disturbance-action
    controller u_t = −K x_t + Σ_{i=1..H} M_i^{(t)} w_{t−i}, learned online.

    After playing u_t, the policy takes one projected gradient step on the surrogate cost
    f_t(M) = c(y_t(M), v_t(M)) (the paper's "ideal cost", Definition 4.2): y_t(M) is the state at
    t of the fixed policy M started from y = 0 at t − H (the paper truncates the state's memory at
    H steps), driven by the recovered disturbances, and v_t(M) = −K y_t(M) + Σ_i M_i w_{t−i}. It
    is a convex quadratic in M; its gradient is exact (forward sensitivities).

    Parameters
    ----------
    H : the memory (default 10: this package's choice, not the paper's). The paper's Theorem 5.1
        takes H = γ⁻¹ log(T κ²) for a (κ, γ)-strongly stable K, which grows with T.
    lr : the step size η (default 0.05: this package's choice for disturbances of size about 1; the
        paper tunes a constant η ∝ 1/√T to the horizon). With ``decay=True`` (default) the step at
        t is lr/√(t+1), the anytime schedule of online gradient descent (Zinkevich 2003).
        **A deliberate deviation from Algorithm 1**, which keeps η constant: an online controller
        that runs for an unknown time cannot tune η to T, and a constant step not tuned to T keeps
        chasing the latest disturbances, so its regret against the best fixed policy grows
        linearly in T (the comparison chapter fits it over T). ``decay=False`` restores the
        constant step of the paper.
    K : the stabilising gain (default: the LQR gain, ``control.dlqr``; the paper allows any
        (κ, γ)-strongly stable K).
    radius : the projection set 𝓜 = {M : ‖M_i‖₂ <= radius·(1 − γ)^{i−1}} (spectral norms). Default
        radius = κ_B κ³ with κ_B = max(1, ‖B‖₂) and (κ, γ) from :func:`strong_stability` (a
        certificate, not the tightest pair). Checked against the source: Algorithm 1 of Agarwal
        et al. (2019) defines 𝓜 by ‖M^{[i−1]}‖ <= κ³κ_B(1 − γ)^i, with M^{[i−1]} our M_i, i.e. one
        factor (1 − γ) tighter than this default, whose first block is bounded by the radius
        itself. ``radius=κ_B κ³ (1 − γ)`` (``gpc.radius * (1 - gpc.gamma_ss)``) gives the published
        set exactly.

    ``record()`` gives ``M`` (T, H, m, n), the policy played at each step, ``w`` (T, n), the
    recovered disturbances (w_{t−1} at row t; row 0 is zero) and ``lr`` (T,), the steps taken.

    Examples
    --------
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> gpc = orrc.GPC(di.system, di.cost, H=5)
    >>> traj = orrc.simulate(di.system, gpc, di.x0, w, T=50)
    >>> gpc.M.shape   # the learned M_1..M_H
    (5, 1, 2)
    """

    name = "GPC"

    def __init__(self, system: LinearSystem, cost: QuadraticCost, H: int = 10, lr: float = 0.05, K=None,
                 radius: float | None = None, decay: bool = True):
        _linear_problem("GPC", system, cost)
        H = as_int("H", H, minimum=1)
        self.lr = as_float("lr", lr, minimum=0.0, strict_min=True)
        self.decay = as_bool("decay", decay)
        n, m = system.n, system.m
        p = H * m * n
        # one step: the surrogate's forward sensitivities, H steps of (n + m) x p products, and H SVDs
        check_size(f"GPC's online gradient step with memory H={H} (n={n}, m={m}): {p} parameters",
                   nbytes=8.0 * (6 * p + 4 * (n + m) * p), ops=H * (4.0 * (n + m) * (n + m) * p + 12 * PY_CALL_OPS),
                   hint="lower H")
        self.H_state = H
        super().__init__(system, cost, np.zeros((H, system.m, system.n)), K)
        kappa, gamma_s = strong_stability(system.A - system.B @ self.K)
        self.kappa, self.gamma_ss = kappa, gamma_s
        if radius is None:
            radius = max(1.0, float(np.linalg.norm(system.B, 2))) * kappa ** 3
        self.radius = as_float("radius", radius, minimum=0.0, strict_min=True)
        self.bounds = self.radius * (1.0 - gamma_s) ** np.arange(H)
        self.reset()

    def reset(self) -> None:
        super().reset()
        self.M = np.zeros((self.H, self.system.m, self.system.n))
        self._hist_M, self._hist_w, self._hist_lr = [], [], []

    def _project(self, M):
        """Euclidean projection onto 𝓜: clip the singular values of each M_i at its bound."""
        out = np.empty_like(M)
        for i, Mi in enumerate(M):
            U, s, Vt = np.linalg.svd(Mi, full_matrices=False)
            out[i] = (U * np.minimum(s, self.bounds[i])) @ Vt
        return out

    def surrogate(self, M):
        """(f_t(M), ∇f_t(M)) for the current history of recovered disturbances (see the class doc)."""
        A, B, K, Q, R = self.system.A, self.system.B, self.K, self.cost.Q, self.cost.R
        n, m, H = self.system.n, self.system.m, self.H
        p = H * m * n
        Hs = self.H_state
        w = self._w                      # w[j] = w_{t−1−j}
        eye_m = np.eye(m)

        def D(s_back):                   # ∂(Σ_i M_i w_{s−i})/∂M at the step s = t − s_back
            win = w[s_back:s_back + H]   # w_{s−1}, ..., w_{s−H}
            if len(win) < H:
                win = np.vstack([win, np.zeros((H - len(win), n))])
            return np.einsum("ab,ic->aibc", eye_m, win).reshape(m, p), win

        y, Jy = np.zeros(n), np.zeros((n, p))
        theta = M.reshape(-1)
        for s_back in range(Hs, 0, -1):  # s = t − Hs, ..., t − 1
            Ds, _ = D(s_back)
            v = -K @ y + Ds @ theta
            Jv = -K @ Jy + Ds
            ws = w[s_back - 1]           # w_s = w_{t−1−(s_back−1)}
            y, Jy = A @ y + B @ v + ws, A @ Jy + B @ Jv
        Dt, _ = D(0)
        v = -K @ y + Dt @ theta
        Jv = -K @ Jy + Dt
        f = float(y @ Q @ y + v @ R @ v)
        grad = 2.0 * (Jy.T @ (Q @ y) + Jv.T @ (R @ v))
        return f, grad.reshape(H, m, n)

    def control(self, obs: Observation) -> Decision:
        self._observe(obs)
        u = self._act(obs, self.M)
        self._hist_M.append(self.M.copy())
        self._hist_w.append(self._w[0].copy() if obs.t > 0 else np.zeros(self.system.n))
        eta = self.lr / math.sqrt(obs.t + 1) if self.decay else self.lr
        self._hist_lr.append(eta)
        _, grad = self.surrogate(self.M)
        self.M = self._project(self.M - eta * grad)
        return Decision(u=u)

    def record(self) -> dict:
        return {"M": np.array(self._hist_M), "w": np.array(self._hist_w), "lr": np.array(self._hist_lr)}

    def frozen(self, M=None) -> DisturbanceAction:
        """The fixed policy with M (default: the last one learned) and this K: a linear controller."""
        return DisturbanceAction(self.system, self.cost, self.M if M is None else M, self.K)


def _policy_cost_quadratic(system, cost, K, H, w, T, x0):
    """Σ_{t<T} c_t of the fixed policy M as F θ + f (stacked [Q^½x_t; R^½u_t]), θ = vec M."""
    A, B = system.A, system.B
    n, m = system.n, system.m
    p = H * m * n
    Qh, Rh = _sqrt_psd(cost.Q), _sqrt_psd(cost.R)
    eye_m = np.eye(m)
    x, Jx = x0.copy(), np.zeros((n, p))
    rows_F, rows_f = [], []
    wpad = np.vstack([np.zeros((H, n)), w[:T]])           # wpad[H + s] = w_s
    for t in range(T):
        win = wpad[t:t + H][::-1]                            # w_{t−1}, ..., w_{t−H}
        Dt = np.einsum("ab,ic->aibc", eye_m, win).reshape(m, p)
        u0, Ju = -K @ x, -K @ Jx + Dt
        rows_F += [Qh @ Jx, Rh @ Ju]
        rows_f += [Qh @ x, Rh @ u0]
        x, Jx = A @ x + B @ u0 + w[t], A @ Jx + B @ Ju
    return np.vstack(rows_F), np.concatenate(rows_f)


def best_fixed_policy(system: LinearSystem, cost: QuadraticCost, w, T: int, H: int, K=None, x0=None,
                      bounds=None):
    """The best fixed disturbance-action policy in hindsight: argmin_M Σ_{t<T} c(x_t^M, u_t^M) on the
    disturbance sequence ``w`` (from ``x0``, default 0), over 𝓜 = {‖M_i‖₂ <= bounds[i−1]} (default:
    no bound).

    The comparator of GPC's regret (Agarwal et al. 2019, Theorem 5.1). The total cost of a fixed
    policy is a convex quadratic ‖Fθ + f‖² in θ = vec M (exact rollout). Unconstrained: a least-
    squares solve; when that minimiser leaves 𝓜, the constrained minimum is solved with cvxpy
    (Clarabel). Returns (M (H, m, n), the total cost of the policy, recomputed by a rollout).

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem`.
    cost : its :class:`~orrc.QuadraticCost`.
    w : (L, n) the disturbances, L >= T.
    T : the horizon.
    H : the memory of the policy class.
    K : the stabilising gain (default: the LQR gain).
    x0 : the initial state (default 0).
    bounds : (H,) the bounds on ‖M_i‖₂ (default: none).

    Returns
    -------
    tuple
        M (H, m, n), the best fixed policy, and its total cost Σ_{t<T} c_t (recomputed by a rollout).

    Raises
    ------
    orrc.OrrcValueError
        When an argument is malformed or the problem exceeds the size limits.

    Examples
    --------
    >>> import orrc
    >>> from orrc.controllers import gpc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(40, 2, 0.1, seed=0)
    >>> M, total = gpc.best_fixed_policy(di.system, di.cost, w, T=30, H=3)
    >>> M.shape
    (3, 1, 2)
    """
    _linear_problem("best_fixed_policy", system, cost)
    n, m = system.n, system.m
    T = as_int("T", T, minimum=1)
    H = as_int("H", H, minimum=1)
    w = as_array("w", w)
    if w.ndim != 2 or w.shape[1] != n or len(w) < T:
        raise OrrcValueError(f"w must have shape (L, {n}) with L >= T = {T}; got shape {w.shape}")
    K = _gain(system, cost, K)
    x0 = np.zeros(n) if x0 is None else as_array("x0", x0, (n,))
    p = H * m * n
    check_size(f"best_fixed_policy's least squares over T={T} steps with H={H} (n={n}, m={m}): a "
               f"{T * (n + m)} x {p} matrix", nbytes=8.0 * 3 * T * (n + m) * p,
               ops=T * (4.0 * (n + m) * n * p + 10 * PY_CALL_OPS) + 2.0 * T * (n + m) * p * p, hint="lower T or H")
    F, f = _policy_cost_quadratic(system, cost, K, H, w, T, x0)
    theta = np.linalg.lstsq(F, -f, rcond=None)[0]
    M = theta.reshape(H, m, n)
    if bounds is not None:
        bounds = as_array("bounds", bounds, (H,))
        if any(np.linalg.norm(Mi, 2) > b * (1 + 1e-9) for Mi, b in zip(M, bounds)):
            import cvxpy as cp

            th = cp.Variable(H * m * n)
            cons = [cp.norm(cp.reshape(th[i * m * n:(i + 1) * m * n], (m, n), order="C"), 2) <= bounds[i]
                    for i in range(H)]
            cp.Problem(cp.Minimize(cp.sum_squares(F @ th + f)), cons).solve(solver="CLARABEL")
            if th.value is None:
                raise RuntimeError("the constrained best fixed policy could not be solved (Clarabel)")
            M = np.asarray(th.value).reshape(H, m, n)
    total = float(np.sum((F @ M.reshape(-1) + f) ** 2))
    return M, total
