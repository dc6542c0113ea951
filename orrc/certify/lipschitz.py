"""Lemma 3's Lipschitz constants α_V, α_κ (and Lemma 4's α_c, α_f S) for a concrete problem.

Lemma 3: |V_M(x, W; θ̂) - V_M(x, W; θ)| <= α_V ‖θ̂ - θ‖ and ‖κ_M(x; θ̂) - κ_M(x; θ)‖ <= α_κ ‖θ̂ - θ‖,
for θ, θ̂ in a compact set Θ. Two ways to get the constants:

* :func:`lq_lipschitz` -- a linear system with a quadratic cost: V_M(x, W; θ) = zᵀH(θ)z and
  κ_M = -G(θ)z with z = [x; vec W], G = [K L] (``orrc.solvers.lq``). The recursion that builds H
  and G is written once more in CasADi and differentiated exactly with respect to θ = vec([A B]).
  For ‖z‖ <= ρ, the mean-value theorem on the segment [θ, θ̂] ⊂ Θ gives
  α_V = ρ² sup_Θ σ_max(∂vec H/∂θ) and α_κ = ρ sup_Θ σ_max(∂vec G/∂θ) (the spectral norm of a
  matrix is at most its Frobenius norm). The supremum over the box Θ = {‖θ' - θ‖_∞ <= r} is taken
  as a MAXIMUM OVER A GRID of points of Θ (``points="grid"``: k points per coordinate, corners
  and centre included) or over random points (``points=<count>``): not a certificate (the
  supremum may lie between points), but of exact derivatives, and it converges as the grid is refined.
* :func:`sampled_lipschitz` -- any problem (nonlinear, ℓ1 costs, input bounds): the largest
  difference quotients |V(θ') - V(θ)|/‖θ' - θ‖ and ‖κ(θ') - κ(θ)‖/‖θ' - θ‖ over samples of
  (x, W, θ'): ESTIMATES (lower bounds on the true constants, valid in the sampled region), labelled
  ``estimate=True`` as :func:`orrc.certify.sampled_constants` labels its constants.

Both also give the other constants of Lemma 4: α_c, the Lipschitz constant of the cost in x on the
region, and α_f S, the Lipschitz constant of f in (x, u) over Θ (the paper writes it α_f ‖θ‖ with
‖θ‖ <= S).
"""
from __future__ import annotations

import functools
import itertools
import math
import warnings
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from .._validate import OrrcValueError, as_array, as_float, as_int, as_seed, check_size
from .._problem import check_cost, check_problem
from ..costs import L1Cost, QuadraticCost, StageCost
from ..systems import LinearSystem

__all__ = ["Lipschitz", "lq_lipschitz", "lq_value_matrices", "sampled_lipschitz"]

#: operations of one M-step solve in sampled_lipschitz (about a millisecond: an IPOPT call or a small QP)
_SOLVE_OPS = 1e6


@dataclass
class Lipschitz:
    """The constants of Lemma 3 (α_V, α_κ) and of Lemma 4 (α_c, α_f S) for one problem.

    Attributes
    ----------
    theta : the centre of Θ (the true θ); radius : Θ = {θ' : ‖θ' - θ‖_∞ <= radius}.
    rho : the region of (x, W): ‖[x; vec W]‖ <= rho (LQ), or the sampled radii (``info``).
    alpha_V, alpha_kappa : Lemma 3's constants on that region.
    alpha_c : the cost's Lipschitz constant in x on the region (|c(x', u) - c(x, u)| <= α_c ‖x' - x‖).
    alpha_f_S : the Lipschitz constant of f in (x, u) over Θ: ‖f(x', u') - f(x, u)‖ <= α_f S (‖x' - x‖ + ‖u' - u‖).
    local_V, local_kappa : the same constants from the derivatives at θ only (the local rate).
    estimate : True for sampled estimates (lower bounds); False for a grid maximum of exact derivatives.
    method : how the supremum over Θ was taken, in words.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> L = certify.lq_lipschitz(ex.system, ex.cost, M=8, radius=0.05, rho=5.0)
    >>> print(round(L.alpha_kappa, 3), L.alpha_c, L.estimate)
    6.549 10.0 False
    """

    theta: np.ndarray
    radius: float
    rho: float
    alpha_V: float
    alpha_kappa: float
    alpha_c: float
    alpha_f_S: float
    local_V: float
    local_kappa: float
    estimate: bool
    method: str
    info: dict = field(default_factory=dict, repr=False)

    def __repr__(self):
        kind = "estimated" if self.estimate else "grid maximum"
        return (f"Lipschitz({kind}, alpha_V={self.alpha_V:.4g}, alpha_kappa={self.alpha_kappa:.4g}, "
                f"alpha_c={self.alpha_c:.4g}, alpha_f_S={self.alpha_f_S:.4g}, radius={self.radius:g}, rho={self.rho:g})")


# -- the LQ value matrix and law as CasADi functions of θ = vec([A B]) ---------------------------------
@functools.lru_cache(maxsize=16)
def _lq_functions(n: int, m: int, M: int, Q_bytes: bytes, R_bytes: bytes):
    """CasADi Functions θ -> (vec H, vec G) and their Jacobians (the recursion of orrc.solvers.lq)."""
    Q = ca.DM(np.frombuffer(Q_bytes).reshape(n, n))
    R = ca.DM(np.frombuffer(R_bytes).reshape(m, m))
    th = ca.SX.sym("theta", n * (n + m))
    AB = ca.reshape(th, n + m, n).T
    A, B = AB[:, :n], AB[:, n:]
    P = [None] * (M + 1)
    K = [None] * M
    Sinv = [None] * M
    P[M] = ca.SX.zeros(n, n)
    for j in range(M - 1, -1, -1):
        BtP = ca.mtimes(B.T, P[j + 1])
        Sinv[j] = ca.inv(R + ca.mtimes(BtP, B))
        K[j] = ca.mtimes(Sinv[j], ca.mtimes(BtP, A))
        Pj = Q + ca.mtimes(ca.mtimes(A.T, P[j + 1]), A - ca.mtimes(B, K[j]))
        P[j] = 0.5 * (Pj + Pj.T)
    N = M * n
    C = ca.SX.zeros(n, N)
    D = ca.SX.zeros(N, N)
    L = None
    for j in range(M - 1, -1, -1):
        h = ca.horzcat(C[:, :j * n], C[:, j * n:(j + 1) * n] + P[j + 1], C[:, (j + 1) * n:])
        Bth = ca.mtimes(B.T, h)
        D = D + ca.vertcat(ca.SX.zeros(j * n, N), C, ca.SX.zeros(N - (j + 1) * n, N)) \
            + ca.horzcat(ca.SX.zeros(N, j * n), C.T, ca.SX.zeros(N, N - (j + 1) * n))
        blk = ca.SX.zeros(N, N)
        blk[j * n:(j + 1) * n, j * n:(j + 1) * n] = P[j + 1]
        D = D + blk - ca.mtimes(ca.mtimes(Bth.T, Sinv[j]), Bth)
        if j == 0:
            L = ca.mtimes(Sinv[0], Bth)
        C = ca.mtimes((A - ca.mtimes(B, K[j])).T, h)
    H = ca.vertcat(ca.horzcat(P[0], C), ca.horzcat(C.T, 0.5 * (D + D.T)))
    G = ca.horzcat(K[0], L)
    vH, vG = ca.vec(H), ca.vec(G)
    values = ca.Function("lq_HG", [th], [vH, vG])
    jac = ca.Function("lq_HG_jacobian", [th], [ca.jacobian(vH, th), ca.jacobian(vG, th)])
    return values, jac


def _check_lq(system, cost) -> None:
    check_problem(system, cost, linear=True, quadratic=True,
                  why_quadratic=" (use sampled_lipschitz otherwise)")


def _horizon(M) -> int:
    M = as_int("M", M, minimum=1)
    if M > 200:
        raise OrrcValueError(f"M = {M} is above 200: the symbolic recursion (O(M³n³) terms) would be too large")
    return M


def lq_value_matrices(system: LinearSystem, cost: QuadraticCost, M: int, theta=None):
    """(H, G) of the M-step LQ problem at θ = vec([A B]) (default: the system's own), from the CasADi
    recursion that :func:`lq_lipschitz` differentiates: V_M = zᵀHz, κ_M = -Gz, z = [x; vec W].

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem`.
    cost : a :class:`~orrc.QuadraticCost`.
    M : the horizon.
    theta : θ = vec([A B]) row by row (default: the system's own).

    Returns
    -------
    tuple of numpy.ndarray
        H (n + Mn, n + Mn) and G (m, n + Mn).

    Raises
    ------
    orrc.OrrcValueError
        When the system is not linear or the cost not quadratic, an argument is out of range, or the
        computation exceeds the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> H, G = certify.lq_value_matrices(ex.system, ex.cost, 3)
    >>> H.shape, G.shape
    ((4, 4), (1, 4))
    """
    _check_lq(system, cost)
    M = _horizon(M)
    n, m = system.n, system.m
    values, _ = _lq_functions(n, m, M, np.ascontiguousarray(cost.Q, float).tobytes(),
                              np.ascontiguousarray(cost.R, float).tobytes())
    theta = np.hstack([system.A, system.B]).ravel() if theta is None else as_array("theta", theta, (n * (n + m),))
    vH, vG = values(theta)
    K = n + M * n
    return np.asarray(vH).reshape(K, K, order="F"), np.asarray(vG).reshape(m, K, order="F")


def _count(points, grid: int, p: int) -> int:
    """The number of points of Θ: grid^p for points="grid", else points + 1 (θ itself)."""
    if isinstance(points, str):
        if points != "grid":
            raise OrrcValueError(f"points must be 'grid' or a number of random points; got {points!r}")
        return grid ** p
    return as_int("points", points, minimum=1) + 1


def _box_points(theta: np.ndarray, radius: float, points, grid: int, seed) -> np.ndarray:
    p = theta.size
    if isinstance(points, str):
        axes = [np.linspace(-radius, radius, grid) if grid > 1 else np.zeros(1)] * p
        return theta + np.array(list(itertools.product(*axes)))
    rng = as_seed("seed", seed)
    return np.vstack([theta, theta + radius * rng.uniform(-1.0, 1.0, (points, p))])


def _cost_lipschitz(cost: StageCost, x_radius: float) -> tuple[float, str]:
    if isinstance(cost, QuadraticCost):
        return 2.0 * float(np.linalg.eigvalsh(cost.Q)[-1]) * x_radius, "2 λ_max(Q) x_radius (exact on the ball)"
    if isinstance(cost, L1Cost):
        return float(np.linalg.norm(cost.q)), "‖q‖₂ (exact, global)"
    return math.nan, "not computed for this cost"


def lq_lipschitz(system: LinearSystem, cost: QuadraticCost, M: int, radius: float, rho: float,
                 points="grid", grid: int = 3, x_radius: float | None = None, seed=0) -> Lipschitz:
    """α_V, α_κ of Lemma 3 for x+ = Ax + Bu + w, c = xᵀQx + uᵀRu, θ = vec([A B]) (see the module).

    Parameters
    ----------
    system, cost, M : the true problem (its θ is the centre of Θ).
    radius : Θ = {θ' : ‖θ' - θ‖_∞ <= radius} (θ and every estimate θ̂ must lie in it).
    rho : the region ‖[x; vec W]‖ <= rho of the claims.
    points : "grid" (``grid`` points per coordinate: k^p points; the size is estimated first and refused
        above ``orrc.config``'s limits) or a number of random points of Θ (plus θ itself).
    x_radius : the state radius for α_c (default rho).

    α_V = ρ² max_points σ_max(∂vec H/∂θ), α_κ = ρ max_points σ_max(∂vec G/∂θ), α_f S = max_points
    max(‖A'‖₂, ‖B'‖₂) (‖A δx + B δu‖ <= max(‖A‖, ‖B‖)(‖δx‖ + ‖δu‖)), α_c = 2 λ_max(Q) x_radius.

    Returns
    -------
    Lipschitz
        α_V, α_κ (grid maxima of exact derivatives), α_c, α_f S and the local rates at θ.

    Raises
    ------
    orrc.OrrcValueError
        When the system is not linear or the cost not quadratic, an argument is out of range, or the
        computation exceeds the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> L = certify.lq_lipschitz(ex.system, ex.cost, M=8, radius=0.05, rho=5.0)
    >>> bool(L.alpha_V >= L.local_V > 0)    # the maximum over Θ is at least the rate at θ
    True
    """
    _check_lq(system, cost)
    M = _horizon(M)
    radius = as_float("radius", radius, minimum=0.0, strict_min=True)
    rho = as_float("rho", rho, minimum=0.0, strict_min=True)
    x_radius = rho if x_radius is None else as_float("x_radius", x_radius, minimum=0.0, strict_min=True)
    grid = as_int("grid", grid, minimum=1)
    as_seed("seed", seed)
    n, m = system.n, system.m
    theta = np.hstack([system.A, system.B]).ravel()
    p, K = theta.size, n + M * n
    count = _count(points, grid, p)
    check_size(f"lq_lipschitz at {count:.3g} points of Θ ({'grid=' + str(grid) + ' per coordinate of θ, p = ' + str(p) if isinstance(points, str) else 'points=' + str(points)}), M={M}",
               nbytes=count * (K * K + m * K) * p * 8.0 * 2, ops=count * p * (K * K * M * n + K ** 3),
               hint="lower grid (the grid has grid^p points), or pass points=<count> for random points of Θ")
    pts = _box_points(theta, radius, points, grid, seed)
    how = (f"maximum over a grid of {grid}^{p} points of Θ" if isinstance(points, str)
           else f"maximum over random {len(pts) - 1} points of Θ and θ")
    _, jac = _lq_functions(n, m, M, np.ascontiguousarray(cost.Q, float).tobytes(),
                           np.ascontiguousarray(cost.R, float).tobytes())
    JH_all, JG_all = jac.map(len(pts))(pts.T)
    # the mapped Jacobians sit side by side, point after point: columns i p .. i p + p - 1 are point i's
    JH_all = np.asarray(JH_all).reshape(-1, len(pts), p)
    JG_all = np.asarray(JG_all).reshape(-1, len(pts), p)
    sH = np.array([np.linalg.norm(JH_all[:, i, :], 2) for i in range(len(pts))])
    sG = np.array([np.linalg.norm(JG_all[:, i, :], 2) for i in range(len(pts))])
    if not (np.all(np.isfinite(sH)) and np.all(np.isfinite(sG))):
        raise OrrcValueError("the LQ law is not defined everywhere on Θ (R + BᵀPB singular?): lower radius")
    centre = int(np.argmin(np.abs(pts - theta).sum(axis=1)))
    AB = pts.reshape(len(pts), n, n + m)
    Lf = max(max(np.linalg.norm(ab[:, :n], 2), np.linalg.norm(ab[:, n:], 2)) for ab in AB)
    ac, how_c = _cost_lipschitz(cost, x_radius)
    method = (f"{how} (exact CasADi derivatives of the LQ value matrix H and law G = [K L]; the supremum over Θ is "
              f"taken as this maximum: not a certificate); ‖[x; vec W]‖ <= {rho:g}; alpha_c: {how_c}")
    return Lipschitz(theta=theta, radius=radius, rho=rho, alpha_V=float(rho ** 2 * sH.max()),
                     alpha_kappa=float(rho * sG.max()), alpha_c=ac, alpha_f_S=float(Lf),
                     local_V=float(rho ** 2 * sH[centre]), local_kappa=float(rho * sG[centre]), estimate=False,
                     method=method, info={"points": pts, "sigma_H": sH, "sigma_G": sG, "x_radius": x_radius})


def sampled_lipschitz(model, cost: StageCost, M: int, theta, radius: float, n_samples: int = 40,
                      x_radius: float = 1.0, w_radius: float = 0.1, input_bounds=None, seed=0,
                      solver_options=None) -> Lipschitz:
    """Sampled estimates of α_V, α_κ (Lemma 3) for any problem: the largest difference quotients.

    ``model`` is a :class:`~orrc.ParametricSystem` (its NLP is built once, θ' is a parameter) or a
    :class:`~orrc.LinearParametricSystem` (exact LQ/QP path at each θ'). For ``n_samples`` draws of
    x (uniform in ‖x‖ <= x_radius), W (each w_k uniform in ‖w‖ <= w_radius) and θ' (uniform in the box
    of half-width ``radius`` around ``theta``) it solves Algorithm 1's problem at θ and θ' and keeps

        α_V ≈ max |V(x, W; θ') - V(x, W; θ)| / ‖θ' - θ‖,    α_κ ≈ max ‖κ(x; θ') - κ(x; θ)‖ / ‖θ' - θ‖.

    ESTIMATES (``estimate=True``): a maximum over samples is a lower bound on the true supremum, valid only
    in the sampled region. α_c: exact for quadratic and ℓ1 costs; α_f S: the largest ‖[∂f/∂x ∂f/∂u]‖₂
    over the samples (also an estimate). Failed solves are dropped (``info['failures']``).

    Parameters
    ----------
    model : a :class:`~orrc.ParametricSystem`.
    cost : the stage cost.
    M : the horizon.
    theta : (p,) the centre of Θ.
    radius : the half-width of the box Θ.
    n_samples : the number of samples.
    x_radius, w_radius : the sampled radii of x and of each w_k.
    input_bounds : (lo, hi), the set U.
    seed : the samples' seed.
    solver_options : options for the CasADi path.

    Returns
    -------
    Lipschitz
        the estimated constants (``estimate`` True: lower bounds on the true suprema).

    Raises
    ------
    orrc.OrrcValueError
        When the model, θ or an argument is malformed, or the samples exceed the size limits.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> L = certify.sampled_lipschitz(orrc.ParametricSystem.linear(1, 1), ex.cost, 4,
    ...                               [1.2, 1.0], radius=0.05, n_samples=4, seed=0)
    >>> L.estimate
    True
    """
    from ..controllers.preview import PreviewRHC
    from ..disturbances import Ball
    from ..parametric import LinearParametricSystem, ParametricSystem

    if not isinstance(model, ParametricSystem):
        raise OrrcValueError(f"model must be an orrc.ParametricSystem; got {type(model).__name__}")
    check_cost(cost)
    M = as_int("M", M, minimum=1)
    theta = model.check_theta(theta)
    radius = as_float("radius", radius, minimum=0.0, strict_min=True)
    n_samples = as_int("n_samples", n_samples, minimum=1)
    rng = as_seed("seed", seed)
    check_size(f"sampled_lipschitz with n_samples={n_samples} (two M-step solves each, M={M})",
               ops=2.0 * n_samples * _SOLVE_OPS * max(1, M // 10), hint="lower n_samples")
    x_radius = as_float("x_radius", x_radius, minimum=0.0, strict_min=True)
    w_radius = as_float("w_radius", w_radius, minimum=0.0)
    n, p = model.n, model.n_params
    exact = isinstance(model, LinearParametricSystem)

    def planner(th):
        if exact:
            return PreviewRHC(model.at(th), cost, M, input_bounds=input_bounds, solver_options=solver_options)
        rhc = planner.shared
        rhc.set_theta(th)
        return rhc

    if not exact:
        planner.shared = PreviewRHC(model, cost, M, input_bounds=input_bounds, solver_options=solver_options,
                                    theta=theta)
    base = PreviewRHC(model.at(theta), cost, M, input_bounds=input_bounds, solver_options=solver_options) if exact \
        else None
    xs = Ball(x_radius, n).sample(n_samples, rng)
    Ws = Ball(max(w_radius, 1e-300), n).sample(n_samples * M, rng).reshape(n_samples, M, n) if w_radius > 0 \
        else np.zeros((n_samples, M, n))
    ths = theta + radius * rng.uniform(-1.0, 1.0, (n_samples, p))
    qV, qK, failures = [], [], 0
    Jx = ca.Function("fx", [model._sym[0], model._sym[1], model._sym[2], model._sym[3]],
                     [ca.horzcat(ca.jacobian(model._sym[4], model._sym[0]), ca.jacobian(model._sym[4], model._sym[1]))])
    Lf = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for x, W, th in zip(xs, Ws, ths):
            d = float(np.linalg.norm(th - theta))
            if d == 0:
                continue
            p0 = (base if exact else planner(theta)).plan(x, W)
            p1 = planner(th).plan(x, W)
            if not (p0.success and p1.success):
                failures += 1
                continue
            qV.append(abs(p1.value - p0.value) / d)
            qK.append(float(np.linalg.norm(p1.inputs[0] - p0.inputs[0])) / d)
            for t_ in (theta, th):
                J = np.asarray(Jx(x, p0.inputs[0], W[0], t_))
                Lf = max(Lf, float(np.linalg.norm(J, 2)))
    if not qV:
        raise OrrcValueError(f"all {n_samples} sampled solves failed; reduce x_radius/w_radius/radius")
    ac, how_c = _cost_lipschitz(cost, x_radius)
    method = (f"sampled estimate ({len(qV)} pairs of solves): the largest difference quotients, lower bounds on the "
              f"true constants, valid only for ‖x‖ <= {x_radius:g}, ‖w‖ <= {w_radius:g}, ‖θ' - θ‖_∞ <= {radius:g}; "
              f"not a certificate; alpha_c: {how_c}")
    return Lipschitz(theta=theta, radius=radius, rho=x_radius, alpha_V=float(max(qV)), alpha_kappa=float(max(qK)),
                     alpha_c=ac, alpha_f_S=Lf, local_V=float("nan"), local_kappa=float("nan"), estimate=True,
                     method=method, info={"quotients_V": np.array(qV), "quotients_kappa": np.array(qK),
                                          "failures": failures, "x_radius": x_radius, "w_radius": w_radius})
